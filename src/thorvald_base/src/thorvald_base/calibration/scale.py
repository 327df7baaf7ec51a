"""The radii's common factor alone, from straight legs driven between standstills.

Why. The calibration drive determines the combinations of the radii and offsets that its odometry
saw; the common factor of the radii it takes mostly from turns and spins, where the wheels slip
sideways and fight through the turn. A field robot drives most of its distance straight along rows,
and there every radius reads a little differently (a -0.1 to -0.6 % distance error on the field
route after the calibration drive and the balance, docs/odometry-report.md). Driven again, straight,
with the calibration in effect (offsets calibrated and the wheels balanced, so nothing fights), the
legs tell that factor directly: every radius times k scales every rim speed, so base_driver's
odometry (linear in the rim speeds) moves k times as far.

The measurement. A leg runs from one standstill to the next (no wheel turning faster than MOVING).
At each standstill, base_link's position is averaged over the standstill's second half (the robot
settled on its tyres): ground truth's (the simulator's pose, or GNSS fixes, whose noise averages out
there, where a path length would grow with it) and odometry's (the drive states replayed with the
values in effect). The factor is k = sum of ground truth's leg lengths / sum of odometry's. A leg
whose odometry path is more than STRAIGHT longer than its chord turned, and is left out: a chord
tells a path's length only on a straight leg. The standard uncertainty is that of the legs' ratios
about k (a regression through the origin), nan with a single leg.

GNSS: the antenna's lever arm cancels between standstills of one heading (a straight leg does not
turn), so the IMU's yaw is not needed for the factor.

The heading (``heading=True``, ``calibrate_odometry --fit straight``). The same legs tell how far the
odometry turns on a straight line where the frame does not: on five ``field`` seeds the calibrated
odometry read 0.1 to 1.1 degrees of turn per 15 m row, the same way on every row a field robot drives
forwards, up to 0.9 m at the end of the field route. Each leg's heading change, odometry's against
ground truth's (the simulator's yaw or the IMU's; each averaged over the standstills' second halves,
as the positions are), against the leg's signed travel along base_link's x gives odometry's
``yaw_per_metre`` [rad/m] by least squares through zero (:class:`OdometryCorrection`): a correction of
the odometry alone. Tilting the radii across the robot instead changes what base_driver commands, and
the frame, driven differently, turned differently (on ``field:1`` a tilt fitted so took the rows'
error from 1.0 to 0.6 degrees a row, not to 0).

Pure: numpy, no rospy, no messages.
"""

import math
from dataclasses import dataclass, replace
from typing import Callable, List, Optional, Tuple, Union

import numpy as np

from thorvald_model import with_drive_params
from thorvald_model.values import RobotConfig

from ..errors import CalibrationError
from ..kinematics.calculator import MAX_YAW_PER_METRE, NO_CORRECTION, OdometryCorrection
from ..plugins import load_calculator
from .estimate import GNSS, MOVING, SIMULATOR, Calibration, ParameterEstimate
from .odometry_error import as_read_with, replay, truth_path
from .recording import DriveRecording, GnssTruth, PoseTruth
from .through_origin import slope_sd, through_origin
from .turns import truth_yaw

STILL = 0.5  # [s] a standstill shorter than this does not end a leg
MIN_LEG = 0.5  # [m] of odometry: a shorter leg tells little of a factor
STRAIGHT = 0.005  # a leg whose odometry path is longer than its chord by more than this share turned


@dataclass(frozen=True)
class Leg:
    start: float  # [s] the mean time of the standstill before it
    end: float  # [s] and after it
    truth_m: float  # ground truth's chord [m]
    odometry_m: float  # odometry's chord [m]
    path_m: float  # odometry's path length [m]
    truth_turn: float = 0.0  # [rad] ground truth's heading change
    odometry_turn: float = 0.0  # [rad] odometry's, with the values in effect
    forward_m: float = 0.0  # [m] odometry's travel along base_link's x (signed)

    @property
    def straight(self) -> bool:
        return self.odometry_m >= MIN_LEG and self.path_m <= self.odometry_m * (1.0 + STRAIGHT)


@dataclass(frozen=True)
class ScaleFit:
    factor: float  # k: every radius times this
    sd: float  # its standard uncertainty [-] (nan from a single leg)
    legs: Tuple[Leg, ...]  # every leg between standstills, straight or not
    ground_truth: str  # SIMULATOR or GNSS
    in_effect: OdometryCorrection = NO_CORRECTION  # the odometry's correction the legs were replayed with
    yaw_per_metre: Optional[float] = None  # [rad/m] what the legs add to in_effect's; None: not fitted
    yaw_per_metre_sd: float = math.nan
    odometry_turns_after: Tuple[float, ...] = ()  # [rad] each used leg's odometry heading change with it

    @property
    def used(self) -> Tuple[Leg, ...]:
        return tuple(leg for leg in self.legs if leg.straight)

    @property
    def correction(self) -> OdometryCorrection:
        """The odometry's correction in effect, with the fitted yaw_per_metre added (if fitted)."""
        if self.yaw_per_metre is None:
            return self.in_effect
        return replace(self.in_effect, yaw_per_metre=self.in_effect.yaw_per_metre + self.yaw_per_metre)

    def calibration(self, config: RobotConfig) -> Calibration:
        """Every radius of the configuration in effect times the factor; the offsets kept."""
        parameters = []
        for i, drive in enumerate(config.drives):
            r = drive.r_wheel
            parameters.append(ParameterEstimate(f"drive{i}", i, "r_wheel", r * self.factor, r * self.sd, r, True))
            if drive.steerable:
                reason = "the radii alone were fitted, from straight legs (--fit scale or straight)"
                parameters.append(
                    ParameterEstimate(
                        f"drive{i}", i, "steering_offset", drive.steering_offset, math.nan, drive.steering_offset,
                        False, reason,
                    )
                )  # fmt: skip
        used = self.used
        rms = math.sqrt(sum((leg.truth_m - self.factor * leg.odometry_m) ** 2 for leg in used) / len(used))
        return Calibration(self.ground_truth, tuple(parameters), None, rms, len(used), 0.0)


def common_scale(
    config: RobotConfig,
    recording: DriveRecording,
    truth: Union[PoseTruth, GnssTruth],
    calculator_for: Callable = load_calculator,
    *,
    heading: bool = False,
    in_effect: OdometryCorrection = NO_CORRECTION,
) -> ScaleFit:
    """The radii's common factor from the straight legs between the recording's standstills, and with
    heading odometry's yaw_per_metre on top of the correction in effect (the module's docstring);
    CalibrationError when it holds no straight leg of at least MIN_LEG, or the heading asks for more
    than MAX_YAW_PER_METRE."""
    if recording.drives != len(config.drives):
        raise CalibrationError(f"the recording has {recording.drives} drives, the robot {len(config.drives)}")
    legs = _legs(config, recording, truth, calculator_for, in_effect)
    used = [leg for leg in legs if leg.straight]
    if not used:
        raise CalibrationError(
            f"--fit scale: no straight leg of at least {MIN_LEG:g} m between two standstills of at least {STILL:g} s "
            f"({len(legs)} legs, {sum(leg.odometry_m >= MIN_LEG for leg in legs)} long enough): drive straight "
            "legs with stops between them (the straight manoeuvre)"
        )
    truth_m = np.array([leg.truth_m for leg in used])
    odo_m = np.array([leg.odometry_m for leg in used])
    factor = float(np.sum(truth_m) / np.sum(odo_m))
    sd = slope_sd(odo_m, truth_m, factor)
    fit = ScaleFit(factor, sd, tuple(legs), GNSS if isinstance(truth, GnssTruth) else SIMULATOR, in_effect)
    return _with_heading(fit, config, recording, truth, calculator_for) if heading else fit


def _legs(config, recording, truth, calculator_for, correction: OdometryCorrection) -> List[Leg]:
    """Every leg between standstills, odometry replayed on the configuration with the correction."""
    t_odo, x_odo, y_odo, yaw_odo = replay(config, recording, calculator_for, correction=correction)
    t, x, y, _ = truth_path(truth)
    heading = truth_yaw(truth, t_odo)
    along = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(x_odo), np.diff(y_odo)))])
    stands = []
    for a, b in _standstills(recording):
        half = (t_odo >= (a + b) / 2.0) & (t_odo <= b)
        seen = (t >= (a + b) / 2.0) & (t <= b)
        if np.any(seen):  # ground truth holds samples there
            odo = tuple(float(np.mean(v[half])) for v in (x_odo, y_odo, along, yaw_odo, heading))
            stands.append(((a + b) / 2.0, float(np.mean(x[seen])), float(np.mean(y[seen])), odo))
    legs = []
    for (ta, xa, ya, oa), (tb, xb, yb, ob) in zip(stands, stands[1:]):
        dx, dy = ob[0] - oa[0], ob[1] - oa[1]
        forward = math.cos(oa[3]) * dx + math.sin(oa[3]) * dy  # along base_link's x at the start
        chord = math.hypot(dx, dy)
        legs.append(
            Leg(ta, tb, math.hypot(xb - xa, yb - ya), chord, ob[2] - oa[2], ob[4] - oa[4], ob[3] - oa[3], forward)
        )
    return legs


def _with_heading(fit: ScaleFit, config, recording, truth, calculator_for) -> ScaleFit:
    """The fit with odometry's yaw_per_metre from the legs' heading (the module's docstring), the
    legs replayed with the radii's factor applied."""
    scaled = with_drive_params(config, [(i, "r_wheel", d.r_wheel * fit.factor) for i, d in enumerate(config.drives)])
    legs = _legs(scaled, as_read_with(recording, config, scaled), truth, calculator_for, fit.in_effect)
    used = [leg for leg, first in zip(legs, fit.legs) if first.straight] if len(legs) == len(fit.legs) else []
    if not used:
        raise CalibrationError("--fit straight: the legs changed with the radii's factor applied")
    forward = np.array([leg.forward_m for leg in used])
    error = np.array([leg.truth_turn - leg.odometry_turn for leg in used])
    if not forward @ forward > MIN_LEG**2:
        raise CalibrationError(
            "--fit straight: the straight legs do not go along base_link's x, which yaw_per_metre is per metre of"
        )
    rate, sd = through_origin(forward, error)
    total = fit.in_effect.yaw_per_metre + rate
    if abs(total) > MAX_YAW_PER_METRE:
        raise CalibrationError(
            f"--fit straight: the legs ask odometry for {total:+.5f} rad of yaw per metre, beyond "
            f"+-{MAX_YAW_PER_METRE:g}: more than a calibration (a bent frame, a broken module, or ground truth of "
            "another drive)"
        )
    after = tuple(leg.odometry_turn + rate * leg.forward_m for leg in used)
    return replace(fit, yaw_per_metre=rate, yaw_per_metre_sd=sd, odometry_turns_after=after)


def _standstills(recording: DriveRecording) -> List[Tuple[float, float]]:
    """(first, last sample time [s]) of each run of samples where no wheel turns faster than MOVING,
    lasting at least STILL."""
    still = np.max(np.abs(recording.speed), axis=1, initial=0.0) <= MOVING
    out, first = [], None
    for n, s in enumerate(still):
        if s and first is None:
            first = n
        if first is not None and (not s or n == len(still) - 1):
            last = n if s else n - 1
            if recording.t[last] - recording.t[first] >= STILL:
                out.append((float(recording.t[first]), float(recording.t[last])))
            first = None
    return out


__all__ = ["MIN_LEG", "STILL", "STRAIGHT", "Leg", "ScaleFit", "common_scale"]
