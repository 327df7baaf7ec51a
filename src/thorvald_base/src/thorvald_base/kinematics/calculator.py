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
corrects for skid steering), and a frame driven straight can read a slow turn it does not make.
"""

import math
from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple

from thorvald_model.errors import Problem
from thorvald_model.layout import AxleLine, common_axle

from ..errors import KinematicsError
from .geometry import DEFAULT_PROJECTION, Layout, check_projection
from .odometry import DEFAULT_ESTIMATOR, ESTIMATORS, integrate_se2, make_estimator, wheel_velocities
from .types import CommandResult, DriveCommand, DriveState, OdometryResult, Pose, Twist

MAX_ODOMETRY_DT = 0.5  # [s]: a longer gap between states is a pause, not motion (the original's rule)
STOPPED_SPEED = 1e-9  # [m/s]: a wheel this slow has no direction of its own; it keeps its heading
YAW_RATE_MULTIPLIER_RANGE = (0.9, 1.1)  # a tyre slips a turn short by a few per mille, never 10 %
MAX_YAW_PER_METRE = 0.005  # [rad/m]: 0.3 degrees a metre is a bent frame or a broken module, not calibration
REALISABLE_TOLERANCE = 1e-9  # [m/s]: wheel-velocity change below which a twist counts as unchanged


@dataclass(frozen=True)
class OdometryCorrection:
    """What a calibration adds to the yaw rate the drive states give (``calibrate_odometry --fit turns``
    and ``--fit straight``): wz' = yaw_rate_multiplier wz + yaw_per_metre vx, the translation kept."""

    yaw_rate_multiplier: float = 1.0
    yaw_per_metre: float = 0.0  # [rad/m] of travel along base_link's x: a turn read on a straight line, undone

    def problems(self) -> List[str]:
        out = []
        low, high = YAW_RATE_MULTIPLIER_RANGE
        m, b = self.yaw_rate_multiplier, self.yaw_per_metre
        if isinstance(m, bool) or not (isinstance(m, (int, float)) and low <= m <= high):
            out.append(f"yaw_rate_multiplier must be in [{low:g}, {high:g}], not {m!r}")
        if isinstance(b, bool) or not (isinstance(b, (int, float)) and abs(b) <= MAX_YAW_PER_METRE):
            out.append(f"yaw_per_metre must be within +-{MAX_YAW_PER_METRE:g} rad/m, not {b!r}")
        return out

    def yaw_rate(self, vx: float, wz: float) -> float:
        """The corrected yaw rate [rad/s] of a body twist's vx [m/s] and wz [rad/s]."""
        return self.yaw_rate_multiplier * wz + self.yaw_per_metre * vx


NO_CORRECTION = OdometryCorrection()


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
        keep = self.layout is not None and len(self.layout.drives) == len(drives)
        self.layout = layout
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
        wz = self._correction.yaw_rate(vx, wz)
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
        return Twist(vx, vy, self._correction.yaw_rate(vx, wz))

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
