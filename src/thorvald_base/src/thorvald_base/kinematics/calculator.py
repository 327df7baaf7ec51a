"""The calculator interface of the original base_calculator plugins (notes section 3).

A calculator turns a body twist into per-drive joint commands and measured drive states into
odometry. It is pure: time and states come in as numbers. The shared logic lives here (template
method, as python-can's ``recv``/``_recv_internal``); a calculator sets ``name`` (its plugin name),
declares the layouts it can serve in ``layout_rules`` (checked after the rules every calculator
shares, thorvald_model.layout), and, if it has a cheaper form, overrides ``_commands``. A calculator
of another package does the same and gets the same checks.

Lifecycle, as pluginlib's: construct with no arguments (or options), ``initialize(drives,
passive_wheels)`` once, ``set_params(drives, passive_wheels)`` when parameters change at run time
(the pose is kept), then ``calculate_command`` and ``calculate_odometry`` every cycle.

``odometry_correction`` (none unless a calibration sets it, :class:`OdometryCorrection`) corrects the
yaw rate odometry reads from the drive states, the translation kept: tyres that slip in turns make the
wheels' geometry read a turn a little short (as diff_drive_controller's ``wheel_separation_multiplier``
corrects for skid steering), a frame driven straight or crabbing can read a slow turn it does not make,
and where the wheels disagree (re-steering into a spin or a turn, a toe) the frame turns as the wheels
that carry it say, not as all of them alike: a frame on rigid tyres of unequal radii stands on three
wheels, and the others turn almost free (the correction's ``wheel_weights``).
"""

import math
from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple

from thorvald_model.errors import Problem
from thorvald_model.layout import AxleLine, common_axle

from ..errors import KinematicsError
from .geometry import DEFAULT_PROJECTION, Layout, check_projection, inverse, matmul, transpose
from .odometry import DEFAULT_ESTIMATOR, ESTIMATORS, integrate_se2, make_estimator, wheel_velocities
from .types import CommandResult, DriveCommand, DriveState, OdometryResult, Pose, Twist

MAX_ODOMETRY_DT = 0.5  # [s]: a longer gap between states is a pause, not motion (the original's rule)
STOPPED_SPEED = 1e-9  # [m/s]: a wheel this slow has no direction of its own; it keeps its heading
YAW_RATE_MULTIPLIER_RANGE = (0.9, 1.1)  # a tyre slips a turn short by a few per mille, never 10 %
MAX_YAW_PER_METRE = 0.005  # [rad/m]: 0.3 degrees a metre is a bent frame or a broken module, not calibration
# The weighted fit may read the wheels' disagreement as a turn at most this many times as strongly as the
# plain fit (the largest gain of any wheel's velocity on the yaw rate): a frame on three of six wheels reads
# it about twice as strongly (rigid:1: 1.9); beyond this the weights lean on wheels too close together
# to tell a turn, and a bad fit would turn odometry wherever the wheels disagree
MAX_WEIGHTED_GAIN = 4.0
REALISABLE_TOLERANCE = 1e-9  # [m/s]: wheel-velocity change below which a twist counts as unchanged


@dataclass(frozen=True)
class OdometryCorrection:
    """What a calibration adds to the yaw rate the drive states give (``calibrate_odometry --fit heading``,
    ``--fit turns`` and ``--fit straight``), the translation kept::

        wz' = yaw_rate_multiplier (wz + weighted) + yaw_per_metre vx + yaw_per_metre_sideways vy

    where ``weighted`` is how much the yaw rate of the least-squares fit that weights each drive's wheel
    by ``wheel_weights`` (in drive order; empty: all alike, weighted 0) differs from the estimator's.
    Where the wheels agree it is 0; where they disagree (a wheel re-steering, a toe) the frame turns as
    the wheels that carry it say."""

    yaw_rate_multiplier: float = 1.0
    yaw_per_metre: float = 0.0  # [rad/m] of travel along base_link's x: a turn read on a straight line, undone
    yaw_per_metre_sideways: float = 0.0  # [rad/m] of travel along base_link's y: a turn read crabbing, undone
    wheel_weights: Tuple[float, ...] = ()  # each drive's weight in the yaw rate's fit (mean 1); (): all alike

    def problems(self) -> List[str]:
        """What is wrong with the values alone (calculator.odometry_correction also checks the weights
        against the robot's wheels)."""
        out = []
        low, high = YAW_RATE_MULTIPLIER_RANGE
        m, b, c = self.yaw_rate_multiplier, self.yaw_per_metre, self.yaw_per_metre_sideways
        if not _number_in(m, low, high):
            out.append(f"yaw_rate_multiplier must be in [{low:g}, {high:g}], not {m!r}")
        if not _number_in(b, -MAX_YAW_PER_METRE, MAX_YAW_PER_METRE):
            out.append(f"yaw_per_metre must be within +-{MAX_YAW_PER_METRE:g} rad/m, not {b!r}")
        if not _number_in(c, -MAX_YAW_PER_METRE, MAX_YAW_PER_METRE):
            out.append(f"yaw_per_metre_sideways must be within +-{MAX_YAW_PER_METRE:g} rad/m, not {c!r}")
        out += weight_problems(self.wheel_weights)
        return out

    def yaw_rate(self, vx: float, wz: float, vy: float = 0.0, weighted: float = 0.0) -> float:
        """The corrected yaw rate [rad/s] of a body twist's vx, vy [m/s] and wz [rad/s], weighted [rad/s]
        the weights' change of wz (:meth:`BaseCalculator.weighted_change`)."""
        return self.yaw_rate_multiplier * (wz + weighted) + self.yaw_per_metre * vx + self.yaw_per_metre_sideways * vy


NO_CORRECTION = OdometryCorrection()


def _number_in(value, low: float, high: float) -> bool:
    return not isinstance(value, bool) and isinstance(value, (int, float)) and low <= value <= high


def weight_problems(weights: Sequence[float]) -> List[str]:
    """What is wrong with wheel weights alone: each a number >= 0 and their mean 1 (to 1e-6: a file holds
    9 digits). What they do is bounded with the robot's wheels (MAX_WEIGHTED_GAIN)."""
    if not weights:
        return []
    if not all(_number_in(w, 0.0, math.inf) for w in weights):
        return [f"wheel_weights must each be a number >= 0, not {list(weights)!r}"]
    mean = sum(weights) / len(weights)
    if abs(mean - 1.0) > 1e-6:
        return [f"wheel_weights must have the mean 1, not {mean:.9g}"]
    return []


def weighted_yaw_gains(layout: Layout, weights: Sequence[float]) -> Optional[Tuple[Tuple[float, float], ...]]:
    """Per drive, (gx, gy) [1/m] such that sum gx vx_k + gy vy_k over the wheels' velocities is how much the
    yaw rate of the least-squares fit weighting drive k by weights[k] differs from the plain fit's (the
    layout's constraints kept); None when the weighted wheels do not determine the robot's motion.

    The weighted fit minimises sum w_k |J_k t - v_k|^2 over realisable twists t = B^T z: t = P_W b_W with
    P_W = B^T (B M_W B^T)^-1 B, M_W = sum w_k J_k^T J_k and b_W = sum w_k J_k^T v_k (geometry.py); its wz is
    linear in the wheels' velocities, and so is its difference from the plain fit's."""
    basis = layout.basis
    bt = transpose(basis)
    m = [[0.0] * 3 for _ in range(3)]
    for w, x, y in zip(weights, layout.x, layout.y):
        for i, row in enumerate(((1.0, 0.0, -y), (0.0, 1.0, x), (-y, x, x * x + y * y))):
            for j in range(3):
                m[i][j] += w * row[j]
    try:
        reduced = inverse(matmul(matmul(basis, m), bt))
    except KinematicsError:
        return None
    p_w = matmul(matmul(bt, reduced), basis)[2]
    p_1 = layout.lsq[2]
    gains = []
    for w, x, y in zip(weights, layout.x, layout.y):
        # wz = P[2] . (vx, vy, x vy - y vx) summed with each wheel's weight (1 for the plain fit)
        gx = w * (p_w[0] - y * p_w[2]) - (p_1[0] - y * p_1[2])
        gy = w * (p_w[1] + x * p_w[2]) - (p_1[1] + x * p_1[2])
        gains.append((gx, gy))
    return tuple(gains)


def weighted_gain_ratio(layout: Layout, weights: Sequence[float]) -> float:
    """How much more strongly the weighted fit's yaw rate follows a wheel's velocity than the plain fit's:
    the largest gain of a wheel's velocity on it over the plain fit's largest (inf where the weighted
    wheels do not determine the motion)."""
    gains = weighted_yaw_gains(layout, weights)
    if gains is None:
        return math.inf
    p_1 = layout.lsq[2]
    plain = [(p_1[0] - y * p_1[2], p_1[1] + x * p_1[2]) for x, y in zip(layout.x, layout.y)]
    largest = max(math.hypot(px, py) for px, py in plain)
    full = max(math.hypot(gx + px, gy + py) for (gx, gy), (px, py) in zip(gains, plain))
    return full / largest if largest > 0 else math.inf


def _weighted_gains(layout: Optional[Layout], correction: OdometryCorrection):
    """The correction's weighted_yaw_gains for the layout (None without weights or layout);
    KinematicsError when its weights do not fit the robot's wheels."""
    weights = correction.wheel_weights
    if not weights or layout is None:
        return None
    if len(weights) != len(layout.drives):
        raise KinematicsError(
            f"wheel_weights must give one weight per drive ({len(layout.drives)}), not {len(weights)}"
        )
    ratio = weighted_gain_ratio(layout, weights)
    if ratio > MAX_WEIGHTED_GAIN:
        said = "do not determine the robot's motion" if math.isinf(ratio) else f"read it {ratio:.1f} times as strongly"
        raise KinematicsError(
            f"wheel_weights {list(weights)!r}: the weighted wheels {said} as the plain fit (at most "
            f"{MAX_WEIGHTED_GAIN:g}): weights that lean on too few wheels"
        )
    return weighted_yaw_gains(layout, weights)


def unheard_drives(states: Sequence[DriveState]) -> Tuple[int, ...]:
    """The drives (indices) odometry must leave out: their reports stopped, or hold no number."""
    return tuple(
        k for k, s in enumerate(states) if not (s.heard and math.isfinite(s.steering) and math.isfinite(s.speed))
    )


class BaseCalculator:
    """Base class of every kinematics calculator plugin.

    estimator: odometry, "lsq" (least-squares rigid-body fit, the default) or "paper" (random pairs);
    seed: seed of the paper estimator's random pairs, for reproducible odometry;
    projection: how a twist the wheels cannot realise is changed, "axle" (keep wz and the speed
    along the fixed wheels, the default) or "lsq" (closest wheel velocities); see geometry.py.
    """

    name: Optional[str] = None  # the plugin name, e.g. "pltf_clc_std::PltfClcStd"

    def __init__(
        self, estimator: str = DEFAULT_ESTIMATOR, seed: Optional[int] = None, projection: str = DEFAULT_PROJECTION
    ):
        if estimator not in ESTIMATORS:
            raise KinematicsError("estimator must be one of {}, not {!r}".format(", ".join(ESTIMATORS), estimator))
        self.estimator_name = estimator
        self.projection = check_projection(projection)
        self.seed = seed
        self.layout: Optional[Layout] = None
        self._estimator = None
        self._last_steering: List[float] = []
        self._pose = Pose()
        self._last_time: Optional[float] = None
        self._correction = NO_CORRECTION
        self._gains: Optional[Tuple[Tuple[float, float], ...]] = None  # the correction's weighted_yaw_gains
        self._partial: Dict[Tuple[int, ...], Optional[tuple]] = {}  # unheard drives -> lsq_for, or None
        self._last_motion = Twist()  # the last twist commanded that moves the robot

    # ---- the original's interface ---------------------------------------------------------
    def initialize(self, drives: Sequence, passive_wheels: Sequence = ()) -> None:
        """Sets the drives (thorvald_model Drive) and passive wheels, and zeroes the pose."""
        self.set_params(drives, passive_wheels)
        self.zero_odometry_pose()
        self._last_time = None

    def set_params(self, drives: Sequence, passive_wheels: Optional[Sequence] = None) -> None:
        """Replaces the drive parameters at run time (paper 3.1: e.g. a new wheel radius); keeps the pose.

        passive_wheels None keeps the current ones. Raises KinematicsError if this calculator
        cannot serve the layout, leaving the previous parameters in place.
        """
        if passive_wheels is None:
            passive_wheels = self.layout.fixed_wheels if self.layout is not None else ()
        drives = tuple(drives)
        self._check_layout(drives, tuple(passive_wheels))
        layout = Layout(drives, passive_wheels, self.projection)
        gains = _weighted_gains(layout, self._correction)  # drives moved: the weights must still hold
        keep = self.layout is not None and len(self.layout.drives) == len(drives)
        self.layout = layout
        self._gains = gains
        self._estimator = make_estimator(self.estimator_name, layout, self.seed)
        self._partial = {}
        if not keep:
            self._last_steering = [0.0] * len(drives)

    def calculate_command(self, twist: Twist) -> CommandResult:
        """Joint commands for a body twist; a realisable twist (the projection's) if this one is not."""
        layout = self._require()
        vals = (float(twist.vx), float(twist.vy), float(twist.wz))
        if not all(math.isfinite(v) for v in vals):
            raise KinematicsError(f"twist must be finite, not {twist}")
        vx, vy, wz = layout.project(*vals)
        realised = Twist(vx, vy, wz)
        changed = False
        if layout.constrained:
            # Compare by the largest change of a wheel's velocity, so the test has units [m/s].
            for x, y in zip(layout.x, layout.y):
                ex = (vals[0] - vx) - (vals[2] - wz) * y
                ey = (vals[1] - vy) + (vals[2] - wz) * x
                if math.hypot(ex, ey) > REALISABLE_TOLERANCE:
                    changed = True
                    break
            if not changed:
                realised = Twist(*vals)
        commands = self._commands(realised)
        self._last_steering = [c.steering for c in commands]
        if any(abs(v) > STOPPED_SPEED for v in (realised.vx, realised.vy, realised.wz)):
            self._last_motion = realised
        return CommandResult(tuple(commands), realised if changed else twist, twist, changed)

    def set_zero_speed(self, commands: Sequence[DriveCommand]) -> List[DriveCommand]:
        """The commands with every wheel speed 0 and the steering kept (command timeout, e-stop)."""
        return [DriveCommand(c.steering, 0.0) for c in commands]

    def calculate_odometry(self, states: Sequence[DriveState], time: float) -> OdometryResult:
        """Body velocity from measured drive states, and the pose integrated since the last call.

        time [s] is the time of the states. The first call, a step back in time and a gap longer than
        MAX_ODOMETRY_DT integrate nothing (dt = 0), as in the original.
        """
        layout = self._require()
        if len(states) != len(layout.drives):
            raise KinematicsError(f"expected {len(layout.drives)} drive states, got {len(states)}")
        dt = 0.0 if self._last_time is None else time - self._last_time
        if not 0.0 < dt <= MAX_ODOMETRY_DT:
            dt = 0.0
        self._last_time = time
        steering = [s.steering for s in states]
        speed = [s.speed for s in states]
        unheard = unheard_drives(states)
        blind = False
        if not unheard:
            vx, vy, wz, res, translating = self._estimator.estimate(steering, speed)
        else:
            vx, vy, wz, res, blind = self._estimate_heard(unheard, steering, speed)
            translating = None
        # the weights are every wheel's: with a drive unheard the heard ones' fit stands as it is
        wz = self._correction.yaw_rate(vx, wz, vy, 0.0 if unheard else self.weighted_change(steering, speed))
        twist = Twist(vx, vy, wz)
        if not all(math.isfinite(v) for v in (vx, vy, wz)):
            return OdometryResult(twist, self._pose, res, dt, False, translating, unheard, blind)
        self._pose = integrate_se2(self._pose, twist, dt)
        return OdometryResult(twist, self._pose, res, dt, True, translating, unheard, blind)

    def determines_motion(self, unheard: Sequence[int]) -> bool:
        """Whether the drives heard (every drive but those indices) determine the robot's motion by
        themselves: two steered drives do, one with a fixed axle does, one wheel of a differential
        robot does not."""
        return not unheard or self._heard_lsq(tuple(unheard)) is not None

    def _heard_lsq(self, unheard: Tuple[int, ...]):
        if unheard not in self._partial:
            layout = self._require()
            self._partial[unheard] = layout.lsq_for([k not in unheard for k in range(len(layout.drives))])
        return self._partial[unheard]

    def _estimate_heard(self, unheard: Tuple[int, ...], steering: Sequence[float], speed: Sequence[float]):
        """(vx, vy, wz, residual, blind) from the drives heard alone, whichever estimator: the least-squares
        fit over them where they determine the motion; else (blind) the motion last commanded, scaled to
        what they measure (both wheels of a differential robot follow one command, so its shape holds
        while the base stops), or none with no drive heard or no motion commanded yet."""
        layout = self.layout
        heard = [k for k in range(len(layout.drives)) if k not in unheard]
        xs, ys = [layout.x[k] for k in heard], [layout.y[k] for k in heard]
        wvx, wvy = wheel_velocities([steering[k] for k in heard], [speed[k] for k in heard])
        p = self._heard_lsq(unheard)
        if p is not None:
            b = (sum(wvx), sum(wvy), sum(x * my - y * mx for x, y, mx, my in zip(xs, ys, wvx, wvy)))
            vx, vy, wz = (sum(p[i][j] * b[j] for j in range(3)) for i in range(3))
            blind = False
        else:
            shape, blind = self._last_motion, True
            num = den = 0.0
            for x, y, mx, my in zip(xs, ys, wvx, wvy):
                ux, uy = shape.vx - shape.wz * y, shape.vy + shape.wz * x
                num += ux * mx + uy * my
                den += ux * ux + uy * uy
            scale = num / den if den > STOPPED_SPEED * STOPPED_SPEED else 0.0
            vx, vy, wz = shape.vx * scale, shape.vy * scale, shape.wz * scale
        errors = [(vx - wz * y - mx) ** 2 + (vy + wz * x - my) ** 2 for x, y, mx, my in zip(xs, ys, wvx, wvy)]
        res = math.sqrt(sum(errors) / len(errors)) if errors else 0.0
        return vx, vy, wz, res, blind

    def zero_odometry_pose(self) -> None:
        self._pose = Pose()

    def body_twist(self, steering: Sequence[float], speed: Sequence[float]) -> Twist:
        """The body velocity odometry takes from these drive states (its estimator's), integrating
        nothing: what a calibration compares with ground truth."""
        self._require()
        vx, vy, wz, _, _ = self._estimator.estimate(list(steering), list(speed))
        return Twist(vx, vy, self._correction.yaw_rate(vx, wz, vy, self.weighted_change(steering, speed)))

    def weighted_change(self, steering: Sequence[float], speed: Sequence[float]) -> float:
        """[rad/s] how much the yaw rate of the fit weighting the wheels by the correction's wheel_weights
        differs from the plain least-squares fit's, for these drive states (0 without weights)."""
        if self._gains is None:
            return 0.0
        wvx, wvy = wheel_velocities(steering, speed)
        return sum(gx * mx + gy * my for (gx, gy), mx, my in zip(self._gains, wvx, wvy))

    # ---- conveniences ---------------------------------------------------------------------
    @classmethod
    def from_config(cls, config, **options) -> "BaseCalculator":
        """A calculator initialised with a thorvald_model RobotConfig's drives and passive wheels."""
        calc = cls(**options)
        calc.initialize(config.drives, config.passive_wheels)
        return calc

    @property
    def pose(self) -> Pose:
        return self._pose

    def set_pose(self, pose: Pose) -> None:
        self._pose = pose

    @property
    def odometry_correction(self) -> OdometryCorrection:
        return self._correction

    @odometry_correction.setter
    def odometry_correction(self, correction: OdometryCorrection) -> None:
        """The correction of odometry's yaw rate, from the next odometry on; KinematicsError for values
        beyond what a calibration explains (the previous correction stays)."""
        problems = correction.problems()
        if problems:
            raise KinematicsError("; ".join(problems))
        self._gains = _weighted_gains(self.layout, correction)
        self._correction = correction

    def wheel_velocity(self, twist: Twist, index: int):
        """Velocity (vx, vy) [m/s] the twist gives drive index's wheel contact."""
        layout = self._require()
        return twist.vx - twist.wz * layout.y[index], twist.vy + twist.wz * layout.x[index]

    # ---- what a calculator specialises ----------------------------------------------------
    @classmethod
    def layout_problems(cls, drives: Sequence, passive_wheels: Sequence = ()) -> List[Problem]:
        """Every rule of the layout these wheels break for this calculator: the rules every
        calculator shares (thorvald_model.layout), then, if they hold, the calculator's own."""
        axle, problems = common_axle(drives, passive_wheels)
        return problems or cls.layout_rules(drives, passive_wheels, axle)

    @classmethod
    def layout_rules(cls, drives: Sequence, passive_wheels: Sequence, axle: Optional[AxleLine]) -> List[Problem]:
        """The layouts this calculator can serve: the problems of these wheels, given the axle line
        every wheel that cannot steer shares (None if there is none). Each problem names the key
        path (``base_calculator`` for the choice of calculator), the value and the rule."""
        return []

    def _check_layout(self, drives: Sequence, passive_wheels: Sequence) -> None:
        """Raises KinematicsError naming the problems if this calculator cannot serve the layout."""
        problems = self.layout_problems(drives, passive_wheels)
        if problems:
            raise KinematicsError("; ".join(p.rule for p in problems))

    def _commands(self, twist: Twist) -> List[DriveCommand]:
        """Commands realising a realisable twist: each wheel points along its contact's velocity."""
        layout = self.layout
        out = []
        for k, (x, y) in enumerate(zip(layout.x, layout.y)):
            wvx = twist.vx - twist.wz * y
            wvy = twist.vy + twist.wz * x
            if not layout.steerable[k]:
                out.append(DriveCommand(0.0, wvx))  # rolls along x; the lateral part is 0 by projection
                continue
            speed = math.hypot(wvx, wvy)
            if speed <= STOPPED_SPEED:
                # A zero command (or a wheel at the centre of rotation) keeps the wheel's heading
                # instead of snapping it straight ahead as the original did.
                out.append(DriveCommand(self._last_steering[k], 0.0))
            else:
                out.append(DriveCommand(math.atan2(wvy, wvx), speed))
        return out

    def _require(self) -> Layout:
        if self.layout is None:
            raise KinematicsError(f"{type(self).__name__} used before initialize()")
        return self.layout
