"""Each drive's effective rolling radius and steering offset from a recorded drive, by least squares.

The model. base_driver read drive i's steering θ and rim speed s with the configuration in effect
(radius r, offset δ0). If the wheel really rolls with radius k·r and stands δ further to the left
than it read, its contact point moves in base_link at k·s·(cos(θ+δ), sin(θ+δ)), which a rigid body
with twist (vx, vy, wz) gives a point at (x_i, y_i)::

    k·s·cos(θ+δ) = vx − wz·y_i,    k·s·sin(θ+δ) = vy + wz·x_i

In complex numbers, with q = s·e^{iθ} the wheel velocity read and m = k·e^{iδ}: m·q = the contact
point's velocity. The calibrated drive has r_wheel k·r and steering_offset δ0 + δ. A drive that does
not steer has δ fixed at 0 (the loader's rule); only k is estimated, from the along-wheel equation.

Ground truth (A), the simulator's body twist: the equations above at every sample time, the twist
interpolated to the drive states' times.

Ground truth (B), a GNSS fix and an IMU's yaw (a real robot's): differentiating positions that carry
2 cm of noise is poor, so the equations are integrated instead, exactly, over windows between fixes.
With the heading h = ψ_imu + ψ (the IMU's yaw has an unknown constant bias ψ against the fix's
east/north frame), contact point i moves over a window by e^{iψ}·m_i·U_i, U_i = ∫ e^{iψ_imu}·q_i dt
(each drive state held over the interval before it, as base_driver's odometry integrates it, with
the yaw linear in between); the same displacement is the antenna's Δp plus the lever arm's turn,
e^{iψ}·(e^{iψ_imu,b} − e^{iψ_imu,a})·(p_i − p_antenna). So, per window and drive::

    e^{iψ}·(m_i·U_i − (e^{iψ_imu,b} − e^{iψ_imu,a})·(p_i − p_antenna)) = Δp

with the fixes' noise on the right alone. ψ makes it nonlinear: Gauss–Newton in (k_i, δ_i, ψ). A
window runs from every fix to the fix WINDOW later, so each fix ends one window and starts another
(windows that shared no fix would throw away most of what the fixes tell: their number falls with
their length, and what each tells grows with its square). Without turning, δ_i + c and ψ − c fit
equally well for every c (the lever arm's term, which tells them apart, is zero): a straight line
cannot tell a steering offset common to all drives from a heading; that direction of the parameters
is not excited, and the offsets are refused (left at their values in effect).

Uncertainty: the standard uncertainty of each parameter is the square root of the diagonal of the
sandwich (JᵀJ)⁻¹·Var(Jᵀr)·(JᵀJ)⁻¹, Var(Jᵀr) from the residuals:

* (A): Σ_c J_cᵀ r_c r_cᵀ J_c over the sample times c, with the small-sample factor
  C/(C−1)·(n−1)/(n−p): the residuals' variance, as in σ²·(JᵀJ)⁻¹, but not assuming that the drives'
  residuals at one instant are independent, since they all share that instant's ground truth.
* (B): the fixes' noise, white, σ² per axis: a window's residuals hold ε_b − ε_a in every drive
  alike, and Jᵀr's noise is Σ_fix ε_fix·H_fix (H_fix: the Jacobian rows of the windows the fix ends
  less those it starts); σ² is half the variance of the residuals' mean over the drives.

Consecutive samples of a real drive share more than that (slip on one patch of ground, a GNSS
receiver's slowly wandering error), which is not modelled: on a real drive the uncertainty is a lower
bound. On synthetic drives (test_calibration) the stated uncertainties are within about 10 % of the
estimates' spread.

What ground truth sees of a wheel is its contact point's velocity, so k is the effective rolling
radius: wheels whose true radii differ push against each other and slip, and each then shows what
the rigid body lets it roll, not its geometric radius.

Excitation: with every parameter free, a parameter is not excited when a direction of the
parameters it moves in leaves the residuals unchanged (a singular value of the column-scaled Jacobian
below SINGULAR of the largest), or when its uncertainty exceeds MAX_RADIUS_SD (relative) or
MAX_OFFSET_SD. With GNSS the offsets are refused together: they share their common part with ψ, so
one left at its value in effect would pass its error on to the others. The refused parameters are
left at their values in effect and the others fitted again (from the start: the free fit may drift
along what the drive does not excite).

Pure: numpy, no rospy, no messages.
"""

import math
from dataclasses import dataclass
from typing import List, Optional, Tuple, Union

import numpy as np

from thorvald_model import with_drive_params
from thorvald_model.values import RobotConfig

from ..errors import CalibrationError
from ..kinematics.calculator import MAX_ODOMETRY_DT
from .recording import DriveRecording, GnssTruth, PoseTruth

MOVING = 0.01  # [m/s]: samples where no wheel and not the robot moves faster say nothing
WINDOW = 2.0  # [s] from a GNSS fix to the one it is compared with
MAX_RADIUS_SD = 0.005  # relative: a radius known worse than 0.5 % is not estimated (the field profile's +-1 %)
MAX_OFFSET_SD = math.radians(0.25)  # [rad]: an offset known worse than 0.25 deg is not (the field's +-0.5 deg)
SINGULAR = 1e-9  # relative singular value below which a direction of the parameters is not excited
LOADING = 1e-6  # a parameter moves along such a direction when its (scaled) component exceeds this
MAX_ITERATIONS = 50
CONVERGED = 1e-14  # largest Gauss–Newton step [-], [rad] at which the estimate stands

SIMULATOR = "simulator"
GNSS = "gnss"


@dataclass(frozen=True)
class ParameterEstimate:
    """One drive parameter: the calibrated value, or the one in effect when the drive did not excite it."""

    drive: str  # "drive0"
    index: int
    key: str  # "r_wheel" [m] or "steering_offset" [rad]
    value: float
    sd: float  # standard uncertainty, in the value's unit (nan when not excited)
    in_effect: float
    excited: bool
    reason: str = ""  # why it was not excited


@dataclass(frozen=True)
class Calibration:
    ground_truth: str  # SIMULATOR or GNSS
    parameters: Tuple[ParameterEstimate, ...]  # per drive in order: r_wheel, then steering_offset if it steers
    heading_bias: Optional[Tuple[float, float]]  # GNSS: the IMU yaw's bias and its uncertainty [rad]
    residual_rms: float  # [m/s] (simulator: per equation) or [m] (GNSS: per window and axis)
    observations: int  # sample times (simulator) or windows (GNSS) used
    turned: float  # [rad] how far the robot turned in all (sum of |yaw changes|)

    def parameter(self, drive: str, key: str) -> ParameterEstimate:
        for p in self.parameters:
            if p.drive == drive and p.key == key:
                return p
        raise KeyError((drive, key))

    @property
    def estimated(self) -> Tuple[ParameterEstimate, ...]:
        return tuple(p for p in self.parameters if p.excited)

    @property
    def not_excited(self) -> Tuple[ParameterEstimate, ...]:
        return tuple(p for p in self.parameters if not p.excited)

    def changes(self) -> List[Tuple[int, str, float]]:
        """(drive index, key, value) of what was estimated: set_drive_params' and the file's."""
        return [(p.index, p.key, p.value) for p in self.estimated]

    def calibrated(self, config: RobotConfig) -> RobotConfig:
        """The configuration in effect with the estimates, validated as a robot file (ConfigError)."""
        return with_drive_params(config, self.changes())


class _Problem:
    """The residuals z (complex, observations x drives) = e^{iψ}·(m·Q − C) − P and which parts count.

    Written so that ground truth's noise (in C for A, in P for B) stays out of the Jacobian: it is
    on the observations' side alone, and the Jacobian says what the drive excites, not what noise
    happens to look like (the common part of the offsets against ψ is seen through the lever arm's
    turn C alone, zero on a straight line, whatever the fixes' noise).
    """

    Q: np.ndarray  # (n, D) complex: wheel velocities read (A) or their rotated integrals U (B)
    C: np.ndarray  # (n, D) complex: what the contact points did (A) or the lever arm's turn (B)
    P: np.ndarray  # (n,) complex: the antenna's displacement (B), zero for A
    imaginary: np.ndarray  # (D,) bool: the cross-wheel part counts (steered drives; every drive for B)
    estimates_heading: bool

    def evaluate(self, k: np.ndarray, delta: np.ndarray, psi: float):
        """(residuals, Jacobian, (observation, part) of each residual); Jacobian columns k_0.., δ_0.., ψ;
        part 0 the real (x, east), 1 the imaginary (y, north) part."""
        m = k * np.exp(1j * delta)
        rot = np.exp(1j * psi)
        wheels = m * self.Q - self.C
        z = rot * wheels - self.P[:, None]
        d_k = rot * np.exp(1j * delta) * self.Q
        d_delta = 1j * rot * m * self.Q
        d_psi = 1j * rot * wheels
        n, drives = z.shape
        rows, jac, obs, parts = [], [], [], []
        for index, (part, used) in enumerate(((np.real, np.ones(drives, bool)), (np.imag, self.imaginary))):
            for i in np.flatnonzero(used):
                block = np.zeros((n, 2 * drives + 1))
                block[:, i] = part(d_k[:, i])
                block[:, drives + i] = part(d_delta[:, i])
                block[:, -1] = part(d_psi[:, i])
                rows.append(part(z[:, i]))
                jac.append(block)
                obs.append(np.arange(n))
                parts.append(np.full(n, index))
        return np.concatenate(rows), np.vstack(jac), (np.concatenate(obs), np.concatenate(parts))

    def meat(self, r: np.ndarray, jac: np.ndarray, rows, rank: int) -> np.ndarray:
        """Var(Jᵀr): the middle of the sandwich (see the module's notes)."""
        raise NotImplementedError


class _TwistProblem(_Problem):
    """Ground truth (A): the body twist at every drive state's time."""

    def __init__(self, config: RobotConfig, recording: DriveRecording, truth: PoseTruth):
        if len(truth) < 2:
            raise CalibrationError("the ground truth holds fewer than 2 samples")
        t = recording.t
        inside = (t >= truth.t[0]) & (t <= truth.t[-1])
        vx, vy, wz = (np.interp(t[inside], truth.t, v) for v in (truth.vx, truth.vy, truth.wz))
        q = recording.speed[inside] * np.exp(1j * recording.steering[inside])
        moving = (np.max(np.abs(recording.speed[inside]), axis=1, initial=0.0) > MOVING) | (
            np.hypot(vx, vy) + np.abs(wz) > MOVING
        )
        x, y = _positions(config)
        self.Q = q[moving]
        self.C = (vx[moving, None] - wz[moving, None] * y) + 1j * (vy[moving, None] + wz[moving, None] * x)
        self.P = np.zeros(len(self.Q), complex)
        self.imaginary = np.array([d.steerable for d in config.drives])
        self.estimates_heading = False
        self.turned = float(np.sum(np.abs(np.diff(truth.yaw))))

    def meat(self, r, jac, rows, rank):
        # every drive's residuals at one instant share that instant's ground truth: summed per instant
        obs, _ = rows
        scores = np.zeros((len(self.Q), jac.shape[1]))
        np.add.at(scores, obs, jac * r[:, None])
        instants, n = len(np.unique(obs)), len(r)
        if instants < 2 or n <= rank:
            raise CalibrationError(f"too few samples ({instants}) for {rank} parameters")
        return instants / (instants - 1.0) * (n - 1.0) / (n - rank) * scores.T @ scores


class _GnssProblem(_Problem):
    """Ground truth (B): windows between two fixes, with the IMU's yaw and its unknown bias."""

    def __init__(self, config: RobotConfig, recording: DriveRecording, truth: GnssTruth, window: float):
        if len(truth) < 2 or len(truth.t_yaw) < 2:
            raise CalibrationError(f"the ground truth holds {len(truth)} GNSS fixes and {len(truth.t_yaw)} IMU yaws")
        t = recording.t
        if len(t) < 2:
            raise CalibrationError(f"the recording holds {len(t)} drive states")
        yaw = truth.yaw_at(t)
        dt = np.diff(t)
        gap = dt > MAX_ODOMETRY_DT  # base_driver's odometry takes a longer gap for a pause
        dyaw = np.diff(yaw)
        small = np.abs(dyaw) < 1e-4
        safe = np.where(small, 1.0, dyaw)
        # (e^{iΔ} − 1)/(iΔ): the mean of e^{i yaw} over an interval where the yaw turns by Δ linearly
        mean_turn = np.where(
            small, 1.0 + 0.5j * dyaw - dyaw**2 / 6.0 - 1j * dyaw**3 / 24.0, (np.exp(1j * dyaw) - 1.0) / (1j * safe)
        )
        weight = np.where(gap, 0.0, dt) * np.exp(1j * yaw[:-1]) * mean_turn
        q = recording.speed * np.exp(1j * recording.steering)
        integral = np.vstack([np.zeros((1, recording.drives), complex), np.cumsum(weight[:, None] * q[1:], axis=0)])
        gaps_before = np.concatenate([[0], np.cumsum(gap)])

        inside = np.flatnonzero((truth.t_fix >= t[0]) & (truth.t_fix <= t[-1]))
        if len(inside) < 2:
            raise CalibrationError("no two GNSS fixes fall within the recorded drive states' time")
        spacing = float(np.median(np.diff(truth.t_fix[inside])))
        n_fix = max(1, round(window / spacing)) if spacing > 0 else 1
        # a window from every fix to the fix n_fix later: each fix ends one window and starts another,
        # so windows n_fix apart share a fix's noise (and overlapping ones the slip between)
        start = np.arange(len(inside) - n_fix)
        a, b = inside[start], inside[start + n_fix]
        ta, tb = truth.t_fix[a], truth.t_fix[b]
        ja, jb = np.searchsorted(t, ta, side="right") - 1, np.searchsorted(t, tb, side="right") - 1
        keep = (gaps_before[np.minimum(jb + 1, len(t) - 1)] == gaps_before[ja]) & (tb - ta <= 2.0 * n_fix * spacing)
        a, b, ta, tb, start = a[keep], b[keep], ta[keep], tb[keep], start[keep]
        if not len(a):
            raise CalibrationError(f"no window of {window:g} s between two GNSS fixes within the drive states")

        def integral_at(times):
            j = np.clip(np.searchsorted(t, times, side="right") - 1, 0, len(t) - 2)
            w = ((times - t[j]) / (t[j + 1] - t[j]))[:, None]
            return integral[j] * (1.0 - w) + integral[j + 1] * w

        yaw_a, yaw_b = truth.yaw_at(ta), truth.yaw_at(tb)
        x, y = _positions(config)
        lever = (x - truth.antenna[0]) + 1j * (y - truth.antenna[1])
        self.Q = integral_at(tb) - integral_at(ta)
        self.C = (np.exp(1j * yaw_b) - np.exp(1j * yaw_a))[:, None] * lever
        self.P = (truth.east[b] - truth.east[a]) + 1j * (truth.north[b] - truth.north[a])
        self.imaginary = np.ones(recording.drives, bool)
        self.estimates_heading = True
        self.fix_a, self.fix_b = start, start + n_fix  # each window's fixes, numbered from 0
        self.turned = float(np.sum(np.abs(np.diff(truth.yaw_at(truth.t_fix[inside])))))

    def meat(self, r, jac, rows, rank):
        # A window's residuals share its two fixes' noise, ε_b − ε_a, in every drive alike, and a fix
        # is in two windows: Jᵀr's noise is Σ_fix ε_fix·H_fix, with H_fix the Jacobian rows of the
        # windows it ends less those it starts. Its variance σ² per axis comes from the residuals'
        # mean over the drives (whose variance is 2σ², the wheels' part averaged down).
        obs, part = rows
        windows = len(self.Q)
        summed = np.zeros((windows, 2, jac.shape[1]))
        np.add.at(summed, (obs, part), jac)
        mean = np.zeros((windows, 2))
        np.add.at(mean, (obs, part), r)
        mean /= np.maximum(np.bincount(obs * 2 + part, minlength=2 * windows).reshape(windows, 2), 1)
        fixes = int(self.fix_b.max()) + 1
        h = np.zeros((fixes, 2, jac.shape[1]))
        np.add.at(h, self.fix_b, summed)
        np.add.at(h, self.fix_a, -summed)
        used = 2 * len(np.union1d(self.fix_a, self.fix_b))  # independent noise values: two axes a fix
        if used <= rank:
            raise CalibrationError(f"too few GNSS fixes ({used // 2}) for {rank} parameters")
        variance = np.sum(mean**2) / (2.0 * mean.size) * used / (used - rank)
        flat = h.reshape(-1, jac.shape[1])
        return variance * flat.T @ flat


def calibrate(
    config: RobotConfig,
    recording: DriveRecording,
    truth: Union[PoseTruth, GnssTruth],
    window: float = WINDOW,
) -> Calibration:
    """Each drive's r_wheel and steering_offset from a recorded drive; config: the one in effect
    when it was recorded. CalibrationError if the drive excites no parameter at all."""
    drives = len(config.drives)
    if recording.drives != drives:
        raise CalibrationError(f"the recording holds {recording.drives} drives, the robot file {drives}")
    if isinstance(truth, GnssTruth):
        problem = _GnssProblem(config, recording, truth, window)
    else:
        problem = _TwistProblem(config, recording, truth)
    if not len(problem.Q):
        raise CalibrationError(
            "the recorded drive excites nothing: the robot never moved within the ground truth's time"
        )
    steered = np.array([d.steerable for d in config.drives])
    rolled = np.sum(np.abs(recording.speed[1:]) * np.diff(recording.t)[:, None], axis=0)

    # parameters: k_0.., δ_0.., ψ; a drive that does not steer never has δ, ψ only with GNSS
    free = np.concatenate([np.ones(drives, bool), steered, [problem.estimates_heading]])
    k, delta, psi = np.ones(drives), np.zeros(drives), _initial_heading_bias(problem)
    # Whether the drive excites a parameter is decided with every parameter free: its uncertainty
    # then holds what the others leave unknown, and a direction of the parameters the residuals do
    # not see is left where it started (Gauss–Newton's minimum-norm steps).
    k, delta, psi = _gauss_newton(problem, k, delta, psi, free)
    r, jac, rows = problem.evaluate(k, delta, psi)
    columns = np.flatnonzero(free)
    sd, unexcited = _uncertainty(problem, r, jac[:, free], rows)
    sd_of = dict(zip(columns, sd))
    # the bounds in each parameter's own unit: k is relative, sd(r)/r = sd(k)/k
    bound_of = {c: MAX_OFFSET_SD if c >= drives else MAX_RADIUS_SD * abs(k[c]) for c in columns[columns < 2 * drives]}
    refused = {}  # parameter column -> reason
    for c, not_moved in zip(columns, unexcited):
        if c in bound_of and (not_moved or not sd_of[c] <= bound_of[c]):
            refused[c] = _reason(problem, c, drives, k, not_moved=not_moved, spread=sd_of[c], rolled=rolled)
    if problem.estimates_heading and any(c >= drives for c in refused):
        # the offsets share their common part with ψ: one left at its value in effect would pass its
        # error on to the others through ψ, so they are refused together
        first = min(c for c in refused if c >= drives)
        for c in columns[(columns >= drives) & (columns < 2 * drives)]:
            refused.setdefault(
                c,
                f"refused with {_parameter_name(first, drives)}: the offsets share their common part with the "
                "heading (the IMU yaw's bias), so one left at its value in effect would bias the others",
            )
    if len(refused) == len(bound_of):
        reasons = "; ".join(f"{_parameter_name(c, drives)}: {reason}" for c, reason in sorted(refused.items()))
        raise CalibrationError(f"the recorded drive excites nothing: {reasons}")
    if refused:
        # fitted again from the start, with the refused ones at their values in effect: the fit above
        # may have drifted far along what the drive does not excite
        free[list(refused)] = False
        k, delta, psi = _gauss_newton(problem, np.ones(drives), np.zeros(drives), _initial_heading_bias(problem), free)
        r, jac, rows = problem.evaluate(k, delta, psi)
        sd_of = dict(zip(np.flatnonzero(free), _uncertainty(problem, r, jac[:, free], rows)[0]))

    parameters = []
    for i, d in enumerate(config.drives):
        for c, key, in_effect, value, scale in (
            (i, "r_wheel", d.r_wheel, d.r_wheel * k[i], d.r_wheel),
            (drives + i, "steering_offset", d.steering_offset, d.steering_offset + delta[i], 1.0),
        ):
            if key == "steering_offset" and not d.steerable:
                continue
            if c in refused:
                parameters.append(ParameterEstimate(d.name, i, key, in_effect, math.nan, in_effect, False, refused[c]))
            else:
                parameters.append(
                    ParameterEstimate(d.name, i, key, float(value), float(sd_of[c] * scale), in_effect, True)
                )
    heading = None
    if problem.estimates_heading:
        heading = (float(math.remainder(psi, 2 * math.pi)), float(sd_of.get(2 * drives, math.nan)))
    rms = float(np.sqrt(np.mean(r**2))) if len(r) else 0.0
    return Calibration(
        SIMULATOR if not problem.estimates_heading else GNSS,
        tuple(parameters),
        heading,
        rms,
        len(problem.Q),
        problem.turned,
    )


def _positions(config: RobotConfig) -> Tuple[np.ndarray, np.ndarray]:
    """Each drive's steering axis (its wheel contact) in base_link [m], in drive order."""
    contacts = np.array(config.wheel_contacts()[: len(config.drives)], dtype=float)
    return contacts[:, 0], contacts[:, 1]


def _initial_heading_bias(problem: _Problem) -> float:
    """ψ that turns the fixes' displacements onto the wheels' mean (every k 1, every δ 0)."""
    if not problem.estimates_heading:
        return 0.0
    wheels = np.mean(problem.Q - problem.C, axis=1)
    alignment = np.sum(wheels * np.conj(problem.P))
    return float(-np.angle(alignment)) if abs(alignment) > 0 else 0.0


def _gauss_newton(problem: _Problem, k, delta, psi, free):
    k, delta = k.copy(), delta.copy()
    drives = len(k)
    for _ in range(MAX_ITERATIONS):
        r, jac, _ = problem.evaluate(k, delta, psi)
        j = jac[:, free]
        scale = np.linalg.norm(j, axis=0)
        scale[scale == 0] = 1.0
        # minimum-norm step: a direction the drive does not excite is left where it stands
        step = np.linalg.lstsq(j / scale, -r, rcond=SINGULAR)[0] / scale
        full = np.zeros(2 * drives + 1)
        full[free] = step
        k, delta, psi = k + full[:drives], delta + full[drives:-1], psi + full[-1]
        if np.max(np.abs(step), initial=0.0) < CONVERGED:
            break
    return k, delta, psi


def _uncertainty(problem: _Problem, r: np.ndarray, jac: np.ndarray, rows) -> Tuple[np.ndarray, np.ndarray]:
    """(standard uncertainty of each column's parameter, whether it moves along a direction the
    residuals do not see); see the module's notes for the formula."""
    p = jac.shape[1]
    scale = np.linalg.norm(jac, axis=0)
    scale[scale == 0] = 1.0
    _, s, vt = np.linalg.svd(jac / scale, full_matrices=False)
    seen = s > SINGULAR * (s[0] if len(s) else 0.0)
    blind = vt[~seen]
    unexcited = np.any(np.abs(blind) > LOADING, axis=0) if len(blind) else np.zeros(p, bool)
    bread = (vt[seen].T / s[seen] ** 2) @ vt[seen] / np.outer(scale, scale)
    cov = bread @ problem.meat(r, jac, rows, int(np.sum(seen))) @ bread
    sd = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    sd[unexcited] = math.inf
    return sd, unexcited


def _amount(column: int, drives: int, k: np.ndarray, value: float) -> str:
    """A parameter's spread in words: degrees for an offset, per cent for a radius."""
    if column >= drives:
        return f"{math.degrees(value):.3g} deg"
    return f"{100 * value / max(abs(k[column]), 1e-12):.3g} %"


def _reason(
    problem: _Problem, column: int, drives: int, k: np.ndarray, *, not_moved: bool, spread: float, rolled
) -> str:
    """Why the drive did not excite a parameter: what it cannot tell it from, and its uncertainty."""
    if column >= drives and problem.estimates_heading:
        why = (
            "a straight line cannot tell a steering offset from a heading (the IMU yaw's bias, estimated "
            f"with it): the drive turned {math.degrees(problem.turned):.1f} deg in all"
        )
    else:
        why = f"the drive does not move this wheel enough to tell it: it rolled {rolled[column % drives]:.2f} m"
    if not_moved:
        return why
    bound = MAX_OFFSET_SD if column >= drives else MAX_RADIUS_SD * abs(k[column])
    spread_text, bound_text = _amount(column, drives, k, spread), _amount(column, drives, k, bound)
    return f"its standard uncertainty {spread_text} exceeds {bound_text}: {why}"


def _parameter_name(column: int, drives: int) -> str:
    return f"drive{column % drives} {'steering_offset' if column >= drives else 'r_wheel'}"


__all__ = [
    "GNSS",
    "MAX_OFFSET_SD",
    "MAX_RADIUS_SD",
    "SIMULATOR",
    "WINDOW",
    "Calibration",
    "ParameterEstimate",
    "calibrate",
]
