"""Odometry's heading model, fitted from a drive of every motion the robot makes.

Why. A single yaw-rate multiplier fitted on U turns of the working radius does not say how a steered
robot's heading drifts in spins, crab legs and the moments its wheels re-steer. Measured on an as-built
Figure 7 robot of the ``rigid`` profile (rigid tyres up to 1.7 % apart, homing within 0.3 degrees),
its calibration's radii, offsets and yaw per metre in effect, heading error (ground truth less odometry)
by what the robot did:

* steady spins, U turns and circles: 0.0 to 0.4 % of the turn (the tyres' slip: a multiplier's part);
* crab legs: 0.13 to 0.2 degrees per metre, left and right opposite (odometry read no turn);
* the first second after a command changes, while the wheels re-steer: up to -9 degrees at a square's
  corner spun from straight wheels, -1.7 and +3.0 degrees entering and leaving a left U turn, +1.6 and
  +0.8 a right one; 48 of the calibration drive's 50 degrees of error, and 6.8 of the field route's 8.1.

The last is where the wheels disagree: each wheel's velocity read right, but no rigid motion gives
them all. Odometry's least squares then weighs every wheel alike, while the frame moves as the wheels
that carry it push it. On rigid tyres of unequal radii a frame of six wheels stands on three (the
simulator measured 1291, 757 and 516 N on drives 1, 3 and 5 of ``rigid:1``, nothing on the other
three), and the three it does not stand on turn almost free. The model::

    wz' = m (wz + weighted) + b vx + c vy

``weighted``: how much the yaw rate of the least-squares fit that weights each drive's wheel by w_k
differs from the plain fit's (linear in the wheels' velocities: the calculator's weighted_change; 0
where the wheels agree); m, b: the multiplier and yaw per metre along x (slip in turns, a turn read
on a straight line); c: yaw per metre along y (a turn read crabbing). All of it is
:class:`OdometryCorrection`: odometry's alone, what base_driver commands unchanged.

The fit. The drive's states are replayed through base_driver's own calculator (no correction): each
sample's twist and each wheel's velocity. Over consecutive windows of WINDOW, ground truth's heading
change (the simulator's yaw, or the IMU's, averaged over IMU_AVERAGE either side of each window's ends:
its orientation carries white noise) less the model's integrated yaw rate is the residual; m, b and c
are fitted first with the weights as in effect, then with the log of each weight as well, by
Levenberg–Marquardt with priors at the values in effect: weak for m, b and c (a parameter the drive does
not excite, c on a robot that cannot crab, stays where it was), and on the weights all alike with
LOG_WEIGHT_SD. One of m, b and c that the drive moves by less than DETERMINED standard uncertainties from
its value in effect stays there too, and the rest are fitted again without it (the heading drive's 8 m
of crab legs gave c from 0.0011 +- 0.002 to -0.0015 +- 0.010 rad/m on seed 4's robots). An m the windows
leave so comes from the drives' whole turns instead (turns.py: each turn from a second before it to a
second after, read with the rest of the model in effect), where they tell it (scattered by at most
MAX_GAIN_SD, moved by DETERMINED of that): a frame that lags its wheels into a turn and catches up after it
scatters each window by a degree or more and leaves the whole turn alone (the differential robot's heading
drive: windows 1.0048 +- 0.0042, its 18 turns 1.0150 +- 0.0038). The weights are
used only where they take WEIGHTS_TOLD of the windows' squared error off (a differential robot's two
wheels never disagree; a frame on soft tyres may stand on all its wheels alike) and leave less heading
error in all over the windows where the wheels disagree than the fit without them (fitting each window's
shape better can still add up worse), and where the drive tells them twice: fitted on either half of its
windows (alternate blocks of HALF_BLOCK), they must leave less heading where the wheels disagree on the
other half than the weights in effect (two runs of one bench gave the Figure 7 robot on ``field:4`` the
weights 0.59 3.55 0.40 1.25 0.09 0.12 and 0.00 4.72 0.62 0.62 0.00 0.04, and its paper-like drive ended
0.49 and 1.67 m off: weights fitted to one drive's rocking); they are returned with the mean 1.
``keep_yaw_per_metre`` keeps b as in effect: straight legs at working speed between standstills (``--fit
straight``) tell it ten times as precisely (0.005 against 0.05 degrees a metre), and a drive of every
motion otherwise lets the re-steering windows pull it (on ``field:3`` from 0.0021 to 0.0032 rad/m, and
the field route's end point from 0.24 to 0.72 m). The weights' effect is bounded (the calculator's
MAX_WEIGHTED_GAIN), and so are m, b and c: a fit beyond them is refused.

What a drive cannot determine. On rigid tyres the frame does not always stand on the same wheels: in a
U turn at 1 m/s (1.3 m/s^2 across) ``rigid:2``'s frame rocks between drives {0, 2, 3}, {0, 2, 4},
{2, 5} and {2, 3, 5} within a second, and identical U turns of one drive end 1 to 2 degrees apart
(its field route: the exits of two right U turns read -0.04 and -3.05 degrees). Which wheels it lands
on is not in the drive states; no fixed weights, and nothing fitted from another drive, tell it.

Pure: numpy, no rospy.
"""

import math
from dataclasses import dataclass
from typing import Callable, List, Optional, Sequence, Tuple, Union

import numpy as np

from thorvald_model.values import RobotConfig

from ..errors import CalibrationError, KinematicsError
from ..kinematics.calculator import (
    MAX_ODOMETRY_DT,
    NO_CORRECTION,
    YAW_RATE_MULTIPLIER_RANGE,
    OdometryCorrection,
    weighted_yaw_gains,
)
from ..plugins import load_calculator
from .estimate import MOVING
from .recording import DriveRecording, GnssTruth, PoseTruth
from .through_origin import through_origin
from .turns import MAX_GAIN_SD, MIN_TURNS, Turn, drive_turns

WINDOW = 0.5  # [s]: short enough that a re-steering's second stands apart from the turn around it
IMU_AVERAGE = 0.05  # [s] either side: the IMU's yaw averaged over 11 samples at 100 Hz at each end
# Priors, in units of one window's heading residual [rad] per unit of the parameter: weak for m, b and c
# (only what no window moves stays put), on each weight's log as strong as 1 mrad of one window per
# LOG_WEIGHT_SD: weights the drive tells apart move freely, weights it cannot stay alike
PRIOR_ROW = 1e-3  # [rad]
LOG_WEIGHT_SD = 3.0  # a factor e^3 = 20 between two wheels' weights costs as much as 1 mrad in one window
LINEAR_SD = 10.0  # m, b [rad/m] and c [rad/m]: a prior so weak that only an unexcited one stays
KEPT_SD = 1e-9  # [rad/m]: b kept as in effect
MIN_WINDOWS = 20
DETERMINED = 2.0  # standard uncertainties a fitted m, b or c must move from the value in effect to be used
HALF_BLOCK = 10.0  # [s]: the drive's windows in alternate blocks of this make the two halves the weights must agree on
WEIGHTS_TOLD = 0.05  # of the windows' squared heading error the weights must take off to be used
MAX_ITERATIONS = 60
CONVERGED = 1e-10
DISAGREE = 0.02  # [m/s] of the plain fit's RMS residual: the wheels disagree (re-steering, a toe)
SPINNING = 0.1  # [rad/s] of odometry's mean |wz| over a window: the robot turns
TRANSLATING = 0.2  # [m/s]: a turn with less translation than this is a spin
MOTIONS = ("standing", "straight", "crab", "spin", "arc", "re-steering")


@dataclass(frozen=True)
class MotionHeading:
    """The heading error [rad] (ground truth less odometry) over the windows of one kind of motion."""

    motion: str  # one of MOTIONS
    windows: int
    seconds: float
    turned: float  # [rad] ground truth's sum of |heading change|
    before: float  # [rad] sum of the windows' errors with the correction in effect
    after: float  # [rad] with the fitted one
    rms_before: float  # [rad] per window
    rms_after: float


@dataclass(frozen=True)
class HeadingFit:
    correction: OdometryCorrection  # fitted: what the calibration file gets
    in_effect: OdometryCorrection  # the drive was replayed with it for "before"
    sd: Tuple[float, float, float]  # standard uncertainties of m, b [rad/m], c [rad/m]
    excited: Tuple[bool, bool, bool]  # m, b, c: whether the drive told them (else kept as in effect)
    weights_told: bool  # whether the drive told the wheels' weights apart (else kept as in effect)
    windows: int
    rms_before: float  # [rad] per window
    rms_after: float
    motions: Tuple[MotionHeading, ...]
    kept_yaw_per_metre: bool = False  # b kept as in effect (the straight legs'), not fitted
    weights_said: str = ""  # why the weights were kept as in effect, if they were
    undetermined: Tuple[bool, bool, bool] = (False, False, False)  # m, b, c: moved less than DETERMINED sd: kept
    turns: Tuple[Turn, ...] = ()  # the whole turns m came from where the windows left it undetermined (else ())


@dataclass(frozen=True)
class _Replayed:
    """A drive replayed without correction: per sample, the plain fit's twist, the wheels' velocities,
    the time each sample's rate holds, the plain fit's residual; and the windows."""

    t: np.ndarray
    twist: np.ndarray  # (T, 3) vx, vy, wz
    wheels: np.ndarray  # (T, 2N) vx_0, vy_0, vx_1, ...
    dt: np.ndarray  # (T,) [s] the interval before each sample base_driver integrates it over
    residual: np.ndarray  # (T,) [m/s] RMS over the wheels
    bounds: np.ndarray  # window edges: sample indices a < b, the window holds samples a+1..b
    truth: np.ndarray  # (W,) [rad] ground truth's heading change over each window


Drive = Tuple[DriveRecording, Union[PoseTruth, GnssTruth]]


def heading_fit(
    config: RobotConfig,
    drives: Sequence[Drive],
    in_effect: OdometryCorrection = NO_CORRECTION,
    calculator_for: Callable = load_calculator,
    *,
    keep_yaw_per_metre: bool = False,
) -> HeadingFit:
    """The heading model (the module's docstring) that makes the drives' heading read as ground truth's:
    drives, (recording, ground truth) pairs, each recorded with the configuration in effect; keep_yaw_per_metre:
    b stays as in effect (straight legs at working speed told it, ten times as precisely as a drive of every
    motion does). CalibrationError when they are too short, or the fit asks for more than a calibration
    explains."""
    calc = calculator_for(config)
    layout = calc.layout
    drive = _joined([_replay(calc, recording, truth) for recording, truth in drives])
    n = len(config.drives)
    if len(drive.truth) < MIN_WINDOWS:
        raise CalibrationError(
            f"--fit heading: the drives hold {len(drive.truth)} windows of {WINDOW:g} s with ground truth, at "
            f"least {MIN_WINDOWS} are needed: drive the heading manoeuvre"
        )
    prior = _params_of(in_effect, n)
    prior[3:] = np.maximum(prior[3:], math.log(1e-6))  # a weight of 0 in effect: drawn back from far below
    prior[3:] -= np.mean(prior[3:])

    def windows_of(p: np.ndarray) -> np.ndarray:
        return _window_rates(drive, layout, p, n)

    windows = len(drive.truth)
    resteering = np.array([motion_of(drive, a, z) == "re-steering" for a, z in drive.bounds], dtype=bool)

    def fit_with(scale: np.ndarray, pick: Optional[np.ndarray] = None):
        """(p, weights_told, said, sd of m, b and c, told) with the priors' scale, over the windows picked
        (default: all)."""
        pick = np.ones(windows, dtype=bool) if pick is None else pick
        count = int(np.sum(pick))

        def residuals(p: np.ndarray) -> np.ndarray:
            return np.concatenate([(drive.truth - windows_of(p))[pick], PRIOR_ROW * (p - prior) / scale])

        # the weights kept as in effect first (m, b and c enter linearly), then free: the weights are told
        # where they take WEIGHTS_TOLD of the windows' squared error off (a frame that stands on all its
        # wheels alike, or wheels that never disagree, leave them as they were)
        kept = prior[3:]
        linear = _solve(lambda q: residuals(np.concatenate([q, kept])), prior[:3].copy())
        p = _solve(residuals, np.concatenate([linear, kept]))
        cost_kept = _cost(residuals(np.concatenate([linear, kept]))[:count])
        weights_told = cost_kept - _cost(residuals(p)[:count]) > WEIGHTS_TOLD * cost_kept
        # the weights act where the wheels disagree: they must also leave less heading there in all, not
        # only fit each window's shape better (on field:3 the windows' squared error fell by half while
        # the re-steering windows' sum went from +4 to +8 degrees)
        sum_kept = abs(float(np.sum((drive.truth - windows_of(np.concatenate([linear, kept])))[resteering & pick])))
        sum_free = abs(float(np.sum((drive.truth - windows_of(p))[resteering & pick])))
        said = "" if weights_told else "not told apart: the wheels never disagreed, or alike fit as well"
        if weights_told and sum_free > sum_kept:
            weights_told = False
            said = (
                f"refused: they fit each window where the wheels disagree better, but leave more heading there "
                f"in all ({math.degrees(sum_free):.1f} against {math.degrees(sum_kept):.1f} degrees without them)"
            )
        if not weights_told:
            p = np.concatenate([linear, kept])
        r = residuals(p)
        jac = _jacobian(residuals, p, r)[:, :3]
        data = jac[:count]
        sigma2 = float(r[:count] @ r[:count]) / max(1, count - 3)
        try:
            cov = sigma2 * np.linalg.inv(jac.T @ jac)
            sd = np.array([math.sqrt(max(cov[k, k], 0.0)) for k in range(3)])
        except np.linalg.LinAlgError:
            sd = np.full(3, math.nan)
        # excited: the windows alone pin m, b or c far better than its prior (a tenth of the prior's sd)
        told = np.sqrt(np.sum(data * data, axis=0)) * scale[:3] / PRIOR_ROW > 10.0
        return p, weights_told, said, sd, told

    scale = np.array([LINEAR_SD, KEPT_SD if keep_yaw_per_metre else LINEAR_SD, LINEAR_SD] + [LOG_WEIGHT_SD] * n)
    p, weights_told, said, sd, told = fit_with(scale)
    refused = (
        _told_twice(fit_with, scale, p, prior[3:], windows_of=windows_of, truth=drive.truth, resteering=resteering)
        if weights_told
        else ""
    )
    if refused:  # the weights stay as in effect from here on
        scale[3:] = KEPT_SD
        p, weights_told, said, sd, told = fit_with(scale)
        weights_told, said = False, refused
    told[1] = told[1] and not keep_yaw_per_metre
    # determined: the drive moves m, b or c from the value in effect by more than DETERMINED of its
    # standard uncertainty; one it does not (c from the heading drive's 8 m of crab legs: 0.0011 +- 0.002
    # to 0.0015 +- 0.01 rad/m) stays as in effect, and the rest are fitted again without it
    undetermined = told & (np.abs(p[:3] - prior[:3]) < DETERMINED * sd)
    if np.any(undetermined):
        scale[:3][undetermined] = KEPT_SD
        p, weights_told, said_again, sd_again, _ = fit_with(scale)
        said = refused or said_again
        sd = np.where(undetermined, sd, sd_again)
        told &= ~undetermined
    in_effect_linear = (in_effect.yaw_rate_multiplier, in_effect.yaw_per_metre, in_effect.yaw_per_metre_sideways)
    linear = [float(p[k]) if told[k] else in_effect_linear[k] for k in range(3)]
    weights = np.exp(p[3:] - np.max(p[3:]))
    correction = OdometryCorrection(*linear, _mean_one(weights) if weights_told else in_effect.wheel_weights)
    turns: Tuple[Turn, ...] = ()
    if not told[0]:
        # the windows leave m as in effect: the drives' whole turns, the rest of the model in effect, may tell it
        turns, gain, gain_sd = _whole_turns(config, drives, correction, calculator_for)
        if turns:
            linear[0] *= gain
            sd[0] = correction.yaw_rate_multiplier * gain_sd
            told[0], undetermined[0] = True, False
            correction = OdometryCorrection(*linear, correction.wheel_weights)
    sd = tuple(float(v) for v in sd)
    problems = correction.problems()
    if problems:
        raise CalibrationError(
            "--fit heading: the drive asks for more than a calibration explains (" + "; ".join(problems) + ")"
        )
    try:
        calc.odometry_correction = correction
    except KinematicsError as e:
        raise CalibrationError(f"--fit heading: the drive asks for wheel weights no frame carries ({e})") from None
    before = drive.truth - windows_of(_params_of(in_effect, n))
    after = drive.truth - windows_of(_params_of(correction, n))
    return HeadingFit(
        correction,
        in_effect,
        sd,
        (bool(told[0]), bool(told[1]), bool(told[2])),
        bool(weights_told),
        windows,
        _rms(before),
        _rms(after),
        _by_motion(drive, before, after),
        keep_yaw_per_metre,
        said,
        (bool(undetermined[0]), bool(undetermined[1]), bool(undetermined[2])),
        turns,
    )


def _told_twice(fit_with, scale, p, kept, *, windows_of, truth, resteering) -> str:
    """Why the weights the whole drive told are not told twice, or "" when they are: fitted on each half of
    its windows (alternate blocks of HALF_BLOCK), they leave less heading where the wheels disagree on the
    other half than the weights in effect do, the rest of the model as the whole drive fitted it."""
    block = np.arange(len(truth)) // max(1, round(HALF_BLOCK / WINDOW)) % 2 == 0
    for half in (block, ~block):
        fitted, told, said, _, _ = fit_with(scale, half)
        if not told:
            return f"not told twice: on half the drive (alternate {HALF_BLOCK:g} s) {said}"
        other = resteering & ~half
        with_them = abs(float(np.sum((truth - windows_of(np.concatenate([p[:3], fitted[3:]])))[other])))
        without = abs(float(np.sum((truth - windows_of(np.concatenate([p[:3], kept])))[other])))
        if with_them > without:
            return (
                f"not told twice: fitted on half the drive (alternate {HALF_BLOCK:g} s), they leave more heading "
                f"where the wheels disagree on the other half ({math.degrees(with_them):.1f} against "
                f"{math.degrees(without):.1f} degrees without them)"
            )
    return ""


def _whole_turns(config: RobotConfig, drives: Sequence[Drive], correction: OdometryCorrection, calculator_for):
    """(turns, gain, its sd): the drives' whole turns (turns.py) replayed with correction, and the gain on
    its multiplier that makes them read as ground truth turned them; () when they do not determine one
    (fewer than MIN_TURNS, scattered beyond MAX_GAIN_SD, within DETERMINED sd of 1, or the multiplier out
    of range)."""
    if correction.problems():  # heading_fit says so
        return (), 1.0, math.nan
    turns: Tuple[Turn, ...] = ()
    for recording, truth in drives:
        turns += drive_turns(config, recording, truth, correction, calculator_for)
    if len(turns) < MIN_TURNS:
        return (), 1.0, math.nan
    gain, gain_sd = through_origin([turn.odometry for turn in turns], [turn.truth for turn in turns])
    low, high = YAW_RATE_MULTIPLIER_RANGE
    if not gain_sd <= MAX_GAIN_SD or abs(gain - 1.0) < DETERMINED * gain_sd:
        return (), 1.0, math.nan
    if not low <= correction.yaw_rate_multiplier * gain <= high:
        return (), 1.0, math.nan
    return turns, gain, gain_sd


def _cost(r: np.ndarray) -> float:
    return float(r @ r)


def _solve(residuals: Callable, p: np.ndarray) -> np.ndarray:
    """Levenberg–Marquardt from p."""
    r = residuals(p)
    damping = 1e-3
    for _ in range(MAX_ITERATIONS):
        jac = _jacobian(residuals, p, r)
        h, g = jac.T @ jac, jac.T @ r
        step = np.linalg.solve(h + damping * np.diag(np.diag(h) + 1e-18), -g)
        trial = p + step
        r_trial = residuals(trial)
        if r_trial @ r_trial <= r @ r:
            converged = r @ r - r_trial @ r_trial <= CONVERGED * max(r @ r, 1e-30)
            p, r = trial, r_trial
            damping = max(damping / 3.0, 1e-9)
            if converged:
                break
        else:
            damping *= 5.0
            if damping > 1e9:
                break
    return p


def _mean_one(weights: np.ndarray) -> Tuple[float, ...]:
    """The weights scaled to the mean 1, in the file's 9 digits."""
    return tuple(float(f"{w:.9g}") for w in weights * (len(weights) / np.sum(weights)))


def _params_of(correction: OdometryCorrection, n: int) -> np.ndarray:
    weights = np.asarray(correction.wheel_weights or (1.0,) * n, dtype=float)
    return np.concatenate(
        [
            [correction.yaw_rate_multiplier, correction.yaw_per_metre, correction.yaw_per_metre_sideways],
            np.log(np.maximum(weights, 1e-300)),
        ]
    )


def _jacobian(residuals: Callable, p: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Forward differences: m, b and c enter linearly, the weights through a 3x3 solve."""
    jac = np.empty((len(r), len(p)))
    for k in range(len(p)):
        step = 1e-7 * max(1.0, abs(p[k]))
        q = p.copy()
        q[k] += step
        jac[:, k] = (residuals(q) - r) / step
    return jac


def _window_rates(drive: _Replayed, layout, p: np.ndarray, n: int) -> np.ndarray:
    """[rad] the model's heading change over each window for the parameters p = (m, b, c, log weights)."""
    m, b, c = p[:3]
    logs = np.clip(p[3:], -700.0, 700.0)
    weights = np.exp(logs - np.max(logs))
    gains = weighted_yaw_gains(layout, list(weights))
    weighted = drive.wheels @ np.asarray(gains).reshape(2 * n) if gains is not None else 0.0
    vx, vy, wz = drive.twist.T
    rate = m * (wz + weighted) + b * vx + c * vy
    total = np.concatenate([[0.0], np.cumsum(rate * drive.dt)])
    a, z = drive.bounds[:, 0], drive.bounds[:, 1]
    return total[z + 1] - total[a + 1]


def _replay(calc, recording: DriveRecording, truth) -> _Replayed:
    """The drive through the calculator without correction, cut into windows of WINDOW with ground truth."""
    calc.odometry_correction = NO_CORRECTION
    t = recording.t
    twists = [calc.body_twist(list(a), list(s)) for a, s in zip(recording.steering, recording.speed)]
    twist = np.array([(w.vx, w.vy, w.wz) for w in twists], dtype=float).reshape(len(t), 3)
    wheels = np.empty((len(t), 2 * recording.drives))
    wheels[:, 0::2] = recording.speed * np.cos(recording.steering)
    wheels[:, 1::2] = recording.speed * np.sin(recording.steering)
    layout = calc.layout
    xs, ys = np.asarray(layout.x), np.asarray(layout.y)
    ex = twist[:, :1] - twist[:, 2:3] * ys - wheels[:, 0::2]
    ey = twist[:, 1:2] + twist[:, 2:3] * xs - wheels[:, 1::2]
    residual = np.sqrt(np.mean(ex * ex + ey * ey, axis=1))
    dt = np.diff(t, prepend=t[0] if len(t) else 0.0)
    dt[(dt <= 0.0) | (dt > MAX_ODOMETRY_DT)] = 0.0  # as base_driver: a pause integrates nothing
    if isinstance(truth, PoseTruth):
        lo, hi = truth.t[0], truth.t[-1]
    else:
        lo, hi = truth.t_yaw[0] + IMU_AVERAGE, truth.t_yaw[-1] - IMU_AVERAGE
    inside = np.flatnonzero((t >= lo) & (t <= hi))
    bounds: List[Tuple[int, int]] = []
    if len(inside):
        start = inside[0]
        for k in inside[1:]:
            if t[k] - t[start] >= WINDOW - 1e-9:
                bounds.append((start, k))
                start = k
    edges = np.array(bounds, dtype=int).reshape(-1, 2)
    moving = [np.any(np.abs(recording.speed[a + 1 : z + 1]) > MOVING) for a, z in edges]
    edges = edges[np.asarray(moving, dtype=bool)] if len(edges) else edges
    heading = _truth_heading(truth, t[edges.reshape(-1)]).reshape(-1, 2) if len(edges) else np.zeros((0, 2))
    return _Replayed(t, twist, wheels, dt, residual, edges, heading[:, 1] - heading[:, 0])


def _joined(parts: Sequence[_Replayed]) -> _Replayed:
    """Drives one after the other: each one's windows over its own samples."""
    offsets = np.cumsum([0] + [len(part.t) for part in parts[:-1]])
    return _Replayed(
        np.concatenate([part.t for part in parts]),
        np.concatenate([part.twist for part in parts]),
        np.concatenate([part.wheels for part in parts]),
        np.concatenate([part.dt for part in parts]),
        np.concatenate([part.residual for part in parts]),
        np.concatenate([part.bounds + offset for part, offset in zip(parts, offsets)]),
        np.concatenate([part.truth for part in parts]),
    )


def _truth_heading(truth: Union[PoseTruth, GnssTruth], times: np.ndarray) -> np.ndarray:
    """Ground truth's heading [rad] at the times: the simulator's, or the IMU's yaw averaged over
    IMU_AVERAGE either side (its white noise: 0.23 degrees a sample at 0.002 per quaternion component)."""
    if isinstance(truth, PoseTruth):
        return np.interp(times, truth.t, truth.yaw)
    lo = np.searchsorted(truth.t_yaw, times - IMU_AVERAGE, side="left")
    hi = np.searchsorted(truth.t_yaw, times + IMU_AVERAGE, side="right")
    total = np.concatenate([[0.0], np.cumsum(truth.yaw)])
    count = hi - lo
    mean = np.where(count > 0, (total[hi] - total[lo]) / np.maximum(count, 1), 0.0)
    return np.where(count > 0, mean, truth.yaw_at(times))


def _by_motion(drive: _Replayed, before: np.ndarray, after: np.ndarray) -> Tuple[MotionHeading, ...]:
    kinds = [motion_of(drive, a, z) for a, z in drive.bounds]
    out = []
    for motion in MOTIONS:
        pick = np.array([k == motion for k in kinds], dtype=bool)
        if not np.any(pick):
            continue
        seconds = float(sum(drive.t[z] - drive.t[a] for (a, z), p in zip(drive.bounds, pick) if p))
        out.append(
            MotionHeading(
                motion,
                int(np.sum(pick)),
                seconds,
                float(np.sum(np.abs(drive.truth[pick]))),
                float(np.sum(before[pick])),
                float(np.sum(after[pick])),
                _rms(before[pick]),
                _rms(after[pick]),
            )
        )
    return tuple(out)


def motion_of(drive: _Replayed, a: int, z: int) -> str:
    """What the robot did over samples a+1..z, by odometry: MOTIONS."""
    part = slice(a + 1, z + 1)
    twist = drive.twist[part]
    if not len(twist) or not np.any(np.abs(drive.wheels[part]) > MOVING):
        return "standing"
    if np.mean(drive.residual[part]) > DISAGREE:
        return "re-steering"
    vx, vy, wz = np.mean(np.abs(twist), axis=0)
    if wz > SPINNING:
        return "spin" if math.hypot(vx, vy) < TRANSLATING else "arc"
    return "crab" if vy > vx else "straight"


def _rms(values: np.ndarray) -> float:
    return float(math.sqrt(np.mean(values * values))) if len(values) else math.nan


def describe(fit: HeadingFit) -> List[str]:
    """The fit in lines of text: what drives the heading error, by motion, and the model."""
    c = fit.correction
    lines = [
        f"heading error (ground truth less odometry) by motion, over {fit.windows} windows of {WINDOW:g} s:",
        f"  {'motion':<12} {'windows':>7} {'s':>6} {'turned [deg]':>12} {'before [deg]':>12} {'after [deg]':>11}"
        f" {'rms before':>10} {'rms after':>9}",
    ]
    for m in fit.motions:
        lines.append(
            f"  {m.motion:<12} {m.windows:>7} {m.seconds:>6.1f} {math.degrees(m.turned):>12.1f} "
            f"{math.degrees(m.before):>+12.2f} {math.degrees(m.after):>+11.2f} {math.degrees(m.rms_before):>10.3f} "
            f"{math.degrees(m.rms_after):>9.3f}"
        )
    total_before = sum(m.before for m in fit.motions)
    total_after = sum(m.after for m in fit.motions)
    lines.append(f"  {'all':<12} {fit.windows:>7} {'':>6} {'':>12} {math.degrees(total_before):>+12.2f} "
                 f"{math.degrees(total_after):>+11.2f} {math.degrees(fit.rms_before):>10.3f} "
                 f"{math.degrees(fit.rms_after):>9.3f}")  # fmt: skip

    def told(k: int) -> str:
        if k == 1 and fit.kept_yaw_per_metre:
            return "(kept: the straight legs')"
        if k == 0 and fit.turns:
            return (
                f"± {fit.sd[0]:.2g} (from {len(fit.turns)} whole turns: the windows' scatter left it within "
                f"{DETERMINED:g} sd of the value in effect)"
            )
        if fit.undetermined[k]:
            return f"(not determined: within {DETERMINED:g} of its ± {fit.sd[k]:.2g} of the value in effect, kept)"
        return f"± {fit.sd[k]:.2g}" if fit.excited[k] else "(not excited: kept)"

    weights = ", ".join(f"drive{k} {w:.3f}" for k, w in enumerate(c.wheel_weights)) or "all alike"
    lines += [
        "odometry's heading model: wz' = m (wz + weighted) + b vx + c vy",
        f"  m (yaw-rate multiplier)      {c.yaw_rate_multiplier:.5f} {told(0)} "
        f"(was {fit.in_effect.yaw_rate_multiplier:g})",
        f"  b (yaw per metre along x)    {c.yaw_per_metre:+.6f} rad/m {told(1)} (was {fit.in_effect.yaw_per_metre:g})",
        f"  c (yaw per metre along y)    {c.yaw_per_metre_sideways:+.6f} rad/m {told(2)} "
        f"(was {fit.in_effect.yaw_per_metre_sideways:g})",
        f"  wheel weights (mean 1)       {weights}" + ("" if fit.weights_told else f" (kept: {fit.weights_said})"),
    ]
    return lines


__all__ = [
    "DISAGREE",
    "IMU_AVERAGE",
    "MOTIONS",
    "WINDOW",
    "HeadingFit",
    "MotionHeading",
    "describe",
    "heading_fit",
    "motion_of",
]
