"""What a drive determines of the drives' radii and steering offsets, through the odometry itself, and
a fit of that alone, the rest kept at the values in effect.

The question. base_driver's odometry is the body twist its estimator takes from the drive states
(:meth:`BaseCalculator.body_twist`). A user calibrates so that this twist is ground truth's; which
radii and offsets it uses only matters through that twist. On a rigid frame of speed-controlled
wheels, ground truth sees the wheels' common motion, so some combinations of the parameters change
the odometry and others do not (a straight line cannot tell the front wheels' radii from the rear
ones': both only scale vx). This module finds those combinations from the drive itself, says how
well it determines each, fits the determined ones and leaves the others at the values in effect.

The model. Drive i read steering θ and rim speed s (q = s e^{iθ}, a complex wheel velocity) with the
values in effect; with m_i = k_i e^{iδ_i} (its radius k_i times the one in effect, its steering δ_i
further left) the wheel really moved at m_i q_i. The estimator is linear in the wheel velocities
(the least-squares rigid-body fit base_driver uses), so the odometry's twist is

    T(m) = sum_i a_i T(q_i alone) + b_i T(i q_i alone),    m_i = a_i + i b_i

linear in p = (a_i, b_i) (b_i only for drives that steer): the columns come from base_driver's own
estimator fed one wheel at a time, no second copy of the kinematics. Per sample the residual is
ground truth's (vx, vy, L wz) less T, L the drives' RMS distance from base_link (so a turn's error
weighs as a wheel's speed error does).

The fit: maximum a posteriori, each parameter known beforehand to its prior (``RADIUS_PRIOR`` of a
radius, ``OFFSET_PRIOR`` of an offset: the field's build tolerances), the residuals' noise sigma
estimated from the fit. In the prior's units the Jacobian's singular value decomposition J = U S V^T
gives the combinations (the columns of V) and how strongly the drive sees each (s_j); its standard
uncertainty after the drive would be sigma / sqrt(s_j^2 + sigma^2) of the prior's, and a combination
is *determined* when that is less than ``DETERMINED``. Along a determined combination the fit moves
by s_j / (s_j^2 + sigma^2) times the data's projection (the posterior mean); every other combination
stays exactly at the values in effect (a weakly seen one would chase the drive's errors, which are
not white: slip, wheels fighting each other). Exact for the estimator's linear model; the noise model is
white per residual (consecutive samples that share a slip are not modelled: a lower bound).

Pure: numpy, no rospy, no messages.
"""

import math
from dataclasses import dataclass
from typing import Callable, List, Optional, Sequence, Tuple

import numpy as np

from thorvald_model.values import RobotConfig

from ..errors import CalibrationError
from ..plugins import load_calculator
from .estimate import MOVING, SIMULATOR, Calibration, ParameterEstimate
from .recording import DriveRecording, PoseTruth

RADIUS_PRIOR = 0.01  # relative: a tyre's radius known to 1 % before calibration
OFFSET_PRIOR = math.radians(0.5)  # [rad]: a module homed to within half a degree
DETERMINED = 0.5  # of the prior's uncertainty: a combination left less uncertain than this is determined
NOISE_FLOOR = 1e-6  # [m/s]: sigma's floor, so that a noiseless drive still weighs the prior
SHOWN = 0.1  # a combination's description names the parameters weighing at least this much in it
ITERATIONS = 5  # of sigma's estimate and the fit
FAR = 5.0  # priors: moved further, the drive's errors are not the model's (a loaded tyre may sit 3 to 4 % small)


@dataclass(frozen=True)
class Combination:
    """One direction of the parameters, in units of their priors (a unit vector)."""

    strength: float  # its singular value over the largest
    sd: float  # its standard uncertainty after the fit, as a share of the prior's (1: the drive says nothing)
    parts: Tuple[Tuple[str, float], ...]  # (parameter, weight) of weight at least SHOWN, largest first
    determined: bool
    vector: Tuple[float, ...] = ()  # every parameter's weight, in ObservableFit.names' order

    def describe(self) -> str:
        terms = " ".join(f"{w:+.2f} {name}" for name, w in self.parts)
        state = "determined" if self.determined else "kept at the values in effect"
        return f"{terms}: strength {self.strength:.2g}, {self.sd:.0%} of its prior uncertainty left ({state})"


@dataclass(frozen=True)
class ObservableFit:
    names: Tuple[str, ...]  # "drive0.r_wheel", "drive0.steering_offset", ...
    in_effect: Tuple[float, ...]
    values: Tuple[float, ...]
    sd: Tuple[float, ...]  # standard uncertainty after the fit [m or rad]: the prior's where nothing is determined
    combinations: Tuple[Combination, ...]  # strongest first
    sigma: float  # [m/s] the residuals' noise, per residual
    observations: int  # samples used

    @property
    def determined(self) -> Tuple[Combination, ...]:
        return tuple(c for c in self.combinations if c.determined)

    def value(self, name: str) -> float:
        return self.values[self.names.index(name)]

    def calibration(self, turned: float = float("nan")) -> Calibration:
        """As :func:`~thorvald_base.calibration.calibrate` gives it (every parameter set: what the drive
        does not determine at its value in effect), for the calibration file and the replay."""
        parameters = []
        for (index, key, value), before, sd in zip(self.changes(), self.in_effect, self.sd):
            parameters.append(ParameterEstimate(f"drive{index}", index, key, value, sd, before, True))
        return Calibration(SIMULATOR, tuple(parameters), None, self.sigma, self.observations, turned)

    def far(self, priors: float = FAR) -> List[Tuple[str, float]]:
        """(parameter, how many of its priors it moved) of the parameters the fit moved further than
        ``priors`` of them: a drive whose errors are not the model's (slip, wheels fighting each other
        through a turn) is fitted by moving parameters far along the combinations it sees weakly."""
        out = []
        for name, value, before in zip(self.names, self.values, self.in_effect):
            moved = (
                (value / before - 1.0) / RADIUS_PRIOR if name.endswith("r_wheel") else (value - before) / OFFSET_PRIOR
            )
            if abs(moved) > priors:
                out.append((name, moved))
        return out

    def changes(self) -> List[Tuple[int, str, float]]:
        """(drive index, key, value) of every parameter: set_drive_params' and the calibration file's."""
        out = []
        for name, value in zip(self.names, self.values):
            drive, key = name.split(".")
            out.append((int(drive[len("drive") :]), key, value))
        return out


def along_undetermined(
    fit: ObservableFit, values: Sequence[float], radii: Sequence[float], offsets: Optional[Sequence[float]] = None
) -> Tuple[float, ...]:
    """values (of fit.names, e.g. another fit's) moved towards each drive's radius in radii [m] (what
    the wheels' torques tell: :mod:`.torque_balance`) and, if given, its steering offset in offsets
    [rad] (what the frame's resistance tells: :mod:`.toe_balance`) along the combinations the drive did
    not determine only: every determined combination keeps values' (what ground truth saw of the
    odometry stays as it saw it), the rest takes the radii's and offsets' (without offsets: with the
    offsets the radii are mixed with). In units of the priors, as the combinations are."""
    unit = np.array([RADIUS_PRIOR if n.endswith("r_wheel") else OFFSET_PRIOR for n in fit.names])
    delta = np.zeros(len(fit.names))
    for i, name in enumerate(fit.names):
        k = int(name.split(".")[0][len("drive") :])
        if name.endswith("r_wheel"):
            delta[i] = math.log(radii[k] / values[i]) / RADIUS_PRIOR
        elif offsets is not None:
            delta[i] = (offsets[k] - values[i]) / OFFSET_PRIOR
    for c in fit.determined:
        v = np.asarray(c.vector)
        delta -= v * float(v @ delta)
    out = []
    for name, value, d, u in zip(fit.names, values, delta, unit):
        out.append(float(value * math.exp(d * u)) if name.endswith("r_wheel") else float(value + d * u))
    return tuple(out)


def observable_fit(
    config: RobotConfig,
    recording: DriveRecording,
    truth: PoseTruth,
    calculator_for: Callable = load_calculator,
) -> ObservableFit:
    """The fit of what the drive determines (the module's docstring); CalibrationError when the
    recording is of another robot or holds no moving sample inside ground truth's time."""
    drives = config.drives
    if recording.drives != len(drives):
        raise CalibrationError(f"the recording has {recording.drives} drives, the robot {len(drives)}")
    calc = calculator_for(config)
    t = recording.t
    inside = (t >= truth.t[0]) & (t <= truth.t[-1]) if len(truth) >= 2 else np.zeros(len(t), bool)
    twist = np.stack([np.interp(t[inside], truth.t, v) for v in (truth.vx, truth.vy, truth.wz)], axis=1)
    steering, speed = recording.steering[inside], recording.speed[inside]
    moving = (np.max(np.abs(speed), axis=1, initial=0.0) > MOVING) | (np.hypot(twist[:, 0], twist[:, 1]) > MOVING)
    steering, speed, twist = steering[moving], speed[moving], twist[moving]
    if not len(twist):
        raise CalibrationError("no moving sample inside ground truth's time")
    radius = _lever(config)
    columns, names, in_effect, prior = _columns(calc, config, steering, speed, radius)
    truth_rows = (twist * np.array([1.0, 1.0, radius])).reshape(-1)
    base = sum(c for c, name in zip(columns, names) if name.endswith(".r_wheel"))  # a = 1, b = 0: the values in effect
    y = truth_rows - base
    jac = np.stack(columns, axis=1) * prior  # in the priors' units
    u, s, vt = np.linalg.svd(jac, full_matrices=False)
    uy = u.T @ y
    # sigma starts from the least squares' residuals (every combination the drive sees at all): what
    # the model cannot explain whatever the parameters
    seen = s > s[0] * 1e-9
    rest = y - jac @ (vt.T[:, seen] @ (uy[seen] / s[seen]))
    sigma = max(float(np.sqrt(rest @ rest / max(len(y) - int(np.sum(seen)), 1))), NOISE_FLOOR)
    for _ in range(ITERATIONS):  # sigma from the fit's residuals, the fit from sigma
        step = vt.T @ (_gain(s, sigma) * uy)
        rest = y - jac @ step
        dof = max(len(y) - float(np.sum(s**2 / (s**2 + sigma**2))), 1.0)
        sigma = max(float(np.sqrt(rest @ rest / dof)), NOISE_FLOOR)
    step = vt.T @ (_gain(s, sigma) * uy)
    left = sigma / np.sqrt(s**2 + sigma**2)  # the uncertainty left along each combination, of the prior's
    covariance = vt.T @ np.diag(left**2) @ vt
    p = np.array([1.0 if n.endswith(".r_wheel") else 0.0 for n in names]) + step * prior
    values, sd = _values(config, names, p, np.sqrt(np.diag(covariance)) * prior)
    combinations = tuple(
        Combination(
            float(sv / s[0]) if s[0] > 0 else 0.0,
            float(lv),
            tuple((names[k], float(w)) for k, w in sorted(enumerate(v), key=lambda kw: -abs(kw[1])) if abs(w) >= SHOWN),
            bool(lv < DETERMINED),
            tuple(float(w) for w in v),
        )
        for sv, lv, v in zip(s, left, vt)
    )
    return ObservableFit(tuple(names), tuple(in_effect), values, sd, combinations, sigma, len(twist))


def _gain(s: np.ndarray, sigma: float) -> np.ndarray:
    """How far the fit moves along each combination per unit of the data's projection on it: the
    posterior's s / (s^2 + sigma^2) along a determined one, nothing along the others. A drive's errors
    are not white (slip on a patch, wheels fighting through a turn), and a weakly seen combination
    would chase them: on a simulated field robot the posterior mean moved radii 25 of their priors
    along combinations left at 50 to 98 % of their prior uncertainty."""
    determined = sigma / np.sqrt(s**2 + sigma**2) < DETERMINED
    return np.where(determined, s / (s**2 + sigma**2), 0.0)


def _lever(config: RobotConfig) -> float:
    """[m] the drives' RMS distance from base_link (at least 0.1 m): a turn rate's weight."""
    return max(math.sqrt(sum(d.x**2 + d.y**2 for d in config.drives) / len(config.drives)), 0.1)


def _columns(calc, config: RobotConfig, steering, speed, radius: float):
    """The odometry's twist rows of each parameter (a_i: drive i's wheel velocity alone; b_i: it turned
    a quarter left), from the robot's own estimator; their names, values in effect and priors."""
    n, count = len(steering), len(config.drives)
    columns, names, in_effect, prior = [], [], [], []
    scale = np.array([1.0, 1.0, radius])
    for i, drive in enumerate(config.drives):
        turns = [(0.0, "r_wheel", drive.r_wheel, RADIUS_PRIOR)]
        if drive.steerable:
            turns.append((math.pi / 2.0, "steering_offset", drive.steering_offset, OFFSET_PRIOR))
        for turn, key, value, sd in turns:
            rows = np.zeros((n, 3))
            for j in range(n):
                alone = [0.0] * count
                alone[i] = float(speed[j, i])
                angles = [float(a) for a in steering[j]]
                angles[i] += turn
                twist = calc.body_twist(angles, alone)
                rows[j] = (twist.vx, twist.vy, twist.wz)
            columns.append((rows * scale).reshape(-1))
            names.append(f"drive{i}.{key}")
            in_effect.append(value)
            prior.append(sd)
    return columns, names, in_effect, np.array(prior)


def _values(config: RobotConfig, names: Sequence[str], p: np.ndarray, sd: np.ndarray):
    """(values, standard uncertainties) in the robot file's units from p = (a_i, b_i) and their sds."""
    values, sds = [], []
    index = {name: k for k, name in enumerate(names)}
    for name, k in index.items():
        drive, key = name.split(".")
        d = config.drives[int(drive[len("drive") :])]
        a = p[index[f"{drive}.r_wheel"]]
        b = p[index[f"{drive}.steering_offset"]] if f"{drive}.steering_offset" in index else 0.0
        if key == "r_wheel":
            values.append(float(math.hypot(a, b) * d.r_wheel))
            sds.append(float(sd[k] * d.r_wheel))
        else:
            values.append(float(d.steering_offset + math.atan2(b, a)))
            sds.append(float(sd[k]))
    return tuple(values), tuple(sds)


__all__ = ["DETERMINED", "OFFSET_PRIOR", "RADIUS_PRIOR", "Combination", "ObservableFit", "observable_fit"]
