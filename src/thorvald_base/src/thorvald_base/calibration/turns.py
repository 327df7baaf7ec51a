"""The yaw-rate multiplier from turns of the working radius: ground truth's turned angle over odometry's.

With every radius and steering offset right, a robot's odometry still reads a headland U turn a few
per mille short: its tyres slip sideways and creep in a turn, and the wheels' geometry no longer
says how fast the body turns (bench/turn_slip.py measured 0.35 to 1.18 % on the field route). A
heading error of half a degree per turn becomes an end-point error along every row that follows.
No drive parameter can correct it (the radii set the distance, the offsets the straight legs), so
the calibration gets one more, the calculator's ``yaw_rate_multiplier``, as diff_drive_controller's
``wheel_separation_multiplier`` corrects a skid-steered robot's turns.

:func:`turn_fit` finds the turns of a drive (odometry's yaw rate beyond TURNING for at least
MIN_TURN), compares the heading each turns by, from MARGIN before it to MARGIN after it (its
transitions included), in ground truth (the simulator's yaw or the IMU's) and in the odometry
replayed with the multiplier in effect, and fits their ratio by least squares through zero; its
uncertainty is the turns' scatter. Turns of the working radius, both ways, fit the turns a field
route drives (the ``turns`` manoeuvre); spins and tight corners slip differently.

Pure: numpy, no rospy.
"""

import math
from dataclasses import dataclass, replace
from typing import Callable, Tuple, Union

import numpy as np

from thorvald_model.values import RobotConfig

from ..errors import CalibrationError
from ..kinematics.calculator import NO_CORRECTION, YAW_RATE_MULTIPLIER_RANGE, OdometryCorrection
from ..plugins import load_calculator
from .odometry_error import replay
from .recording import DriveRecording, GnssTruth, PoseTruth
from .through_origin import through_origin

TURNING = 0.2  # [rad/s] of odometry's yaw rate: a turn (a field route's U turn: 1.3 rad/s)
MIN_TURN = 1.0  # [s]: a shorter swing is a correction on a straight leg, not a turn
MARGIN = 1.0  # [s] before and after a turn compared: the whole turn, its transitions included
MIN_TURNS = 2
MAX_GAIN_SD = 0.01  # the turns disagree by more: they slip each their own way, and no multiplier fits them


@dataclass(frozen=True)
class Turn:
    start: float  # [s] the window compared
    end: float  # [s]
    truth: float  # [rad] ground truth turned, signed
    odometry: float  # [rad] odometry turned, with the correction in effect

    @property
    def short_percent(self) -> float:
        """How much less than ground truth the odometry turned [%] (negative: more)."""
        return (1.0 - self.odometry / self.truth) * 100.0 if self.truth else math.nan


@dataclass(frozen=True)
class TurnFit:
    turns: Tuple[Turn, ...]
    in_effect: OdometryCorrection  # the correction the drive was replayed with
    gain: float  # truth over odometry, on top of in_effect's multiplier
    gain_sd: float

    @property
    def multiplier(self) -> float:
        return self.in_effect.yaw_rate_multiplier * self.gain

    @property
    def multiplier_sd(self) -> float:
        return self.in_effect.yaw_rate_multiplier * self.gain_sd

    @property
    def correction(self) -> OdometryCorrection:
        """The correction in effect with the fitted multiplier."""
        return replace(self.in_effect, yaw_rate_multiplier=self.multiplier)


def truth_yaw(truth: Union[PoseTruth, GnssTruth], t: np.ndarray) -> np.ndarray:
    """Ground truth's heading [rad] at times t, unwrapped (the IMU's: its bias does not matter here)."""
    if isinstance(truth, PoseTruth):
        return np.interp(t, truth.t, truth.yaw)
    return truth.yaw_at(t)


def turn_windows(t: np.ndarray, yaw: np.ndarray) -> Tuple[Tuple[float, float], ...]:
    """(start, end) [s] of each turn of a heading series, MARGIN wider either side (within the series)."""
    if len(t) < 3:
        return ()
    rate = np.gradient(yaw, t)
    turning = np.abs(rate) > TURNING
    edges = np.flatnonzero(np.diff(np.concatenate([[0], turning.astype(int), [0]])))
    windows = []
    for a, b in zip(edges[::2], edges[1::2]):  # turning from index a to b - 1
        if t[b - 1] - t[a] >= MIN_TURN:
            windows.append((max(t[0], t[a] - MARGIN), min(t[-1], t[b - 1] + MARGIN)))
    return tuple(windows)


def drive_turns(
    config: RobotConfig,
    recording: DriveRecording,
    truth: Union[PoseTruth, GnssTruth],
    in_effect: OdometryCorrection = NO_CORRECTION,
    calculator_for: Callable = load_calculator,
) -> Tuple[Turn, ...]:
    """The drive's turns (:func:`turn_windows` of odometry replayed with in_effect, within ground truth),
    each with the heading ground truth and odometry turned by."""
    t, _, _, yaw = replay(config, recording, calculator_for, correction=in_effect)
    lo, hi = (truth.t[0], truth.t[-1]) if isinstance(truth, PoseTruth) else (truth.t_yaw[0], truth.t_yaw[-1])
    inside = (t >= lo) & (t <= hi)
    t, yaw = t[inside], yaw[inside]
    turns = []
    for start, end in turn_windows(t, yaw):
        ends = np.array([start, end])
        odometry = float(np.diff(np.interp(ends, t, yaw))[0])
        turns.append(Turn(float(start), float(end), float(np.diff(truth_yaw(truth, ends))[0]), odometry))
    return tuple(turns)


def turn_fit(
    config: RobotConfig,
    recording: DriveRecording,
    truth: Union[PoseTruth, GnssTruth],
    in_effect: OdometryCorrection = NO_CORRECTION,
    calculator_for: Callable = load_calculator,
) -> TurnFit:
    """The yaw-rate multiplier that makes the drive's turns read as ground truth turned them.
    CalibrationError if the drive holds fewer than MIN_TURNS turns, or the multiplier comes out
    beyond what slip explains."""
    turns = drive_turns(config, recording, truth, in_effect, calculator_for)
    if len(turns) < MIN_TURNS:
        raise CalibrationError(
            f"--fit turns: the drive holds {len(turns)} turns (the odometry turning faster than {TURNING:g} rad/s for "
            f"{MIN_TURN:g} s or more), at least {MIN_TURNS} are needed: drive the turns manoeuvre"
        )
    a = np.array([turn.truth for turn in turns])
    b = np.array([turn.odometry for turn in turns])
    gain, sd = through_origin(b, a)
    fit = TurnFit(tuple(turns), in_effect, gain, sd)
    if sd > MAX_GAIN_SD:
        worst = max(turns, key=lambda turn: abs(turn.short_percent))
        raise CalibrationError(
            f"--fit turns: the turns disagree (the multiplier {fit.multiplier:.4f} ± {fit.multiplier_sd:.4f}; the turn "
            f"at {worst.start:.1f} s read {worst.short_percent:+.1f} % short): they slip each their own way, and no "
            "multiplier fits them"
        )
    low, high = YAW_RATE_MULTIPLIER_RANGE
    if not low <= fit.multiplier <= high:
        raise CalibrationError(
            f"--fit turns: the turns ask for a yaw-rate multiplier of {fit.multiplier:.4f}, beyond "
            f"[{low:g}, {high:g}]: more than tyre slip (a wrong robot file, or ground truth that is not this drive's)"
        )
    return fit


__all__ = [
    "MARGIN",
    "MAX_GAIN_SD",
    "MIN_TURN",
    "MIN_TURNS",
    "TURNING",
    "Turn",
    "TurnFit",
    "drive_turns",
    "truth_yaw",
    "turn_fit",
    "turn_windows",
]
