"""One control cycle of base_driver (paper section 3.1, Figure 6), without ROS.

:class:`BaseDriverCore` takes the latest velocity command through the calculator and the drive
layer, applies the safety rules (command timeout, e-stop, refused commands), drives the base
handle and computes odometry from the measured states; :class:`PoseCovariance` is the odometry
message's covariance. The node only converts messages.

Times are seconds on whichever clock the node uses (ROS time, simulated time in simulation).
"""

import math
from dataclasses import dataclass, field
from typing import List, Optional, Sequence, Tuple

from thorvald_model import with_drive_param
from thorvald_model.config import RUNTIME_DRIVE_KEYS, RobotConfig

from .bases import BaseHandle, MeasuredDrive
from .errors import ParameterError
from .kinematics import BaseCalculator, DriveCommand, DriveLayer, OdometryResult, Twist
from .kinematics.calculator import unheard_drives

# A command is absurd, and refused, beyond this multiple of what the fastest wheel can do.
ABSURD_FACTOR = 10.0

# The original's twist covariance: 0.001 on the diagonal, 0.03 for the yaw rate (row-major 6 x 6).
DEFAULT_TWIST_COVARIANCE = tuple((0.03 if i == 5 else 0.001) if i == j else 0.0 for i in range(6) for j in range(6))
MOVING = 0.005  # [m/s], [rad/s]: faster than this, the pose covariance grows (the original's rule)
# The stop reason while the drives heard cannot determine the motion (OdometryResult.blind).
BLIND = "odometry blind"
# [(m/s)^2], [(rad/s)^2]: the twist's variance while odometry is blind: anything up to about 1 m/s
# and 1 rad/s, which is what a Thorvald can do.
BLIND_VARIANCE = 1.0
BLIND_DIAGONAL = (0, 7, 35)  # vx, vy and wz's places in the row-major 6 x 6 twist covariance


@dataclass(frozen=True)
class CycleResult:
    """What one control cycle produced, for the node to publish."""

    time: float
    commands: Tuple[DriveCommand, ...]  # sent to the drives (joint_commands)
    states: Tuple[MeasuredDrive, ...]  # measured after sending (base_state, joint_states)
    odometry: OdometryResult
    stopped_by: Optional[str]  # "timeout", "safety stop", "homing", BLIND or None
    twist_changed: bool  # the command was not realisable; the projection's twist was used
    speed_scale: float  # wheel speeds were scaled by this factor to stay within the motors' limits


@dataclass
class _Command:
    twist: Twist = field(default_factory=Twist)
    time: Optional[float] = None


class BaseDriverCore:
    """One control cycle of base_driver.

    command_timeout [s]: a command older than this stops the wheels (the steering is kept).
    """

    def __init__(
        self,
        config: RobotConfig,
        calculator: BaseCalculator,
        handle: BaseHandle,
        command_timeout: float = 0.5,
        invert_steering: bool = True,
    ):
        if not command_timeout > 0:
            raise ParameterError(f"~command_timeout: {command_timeout!r}: must be > 0 [s]")
        self.config = config
        self.calculator = calculator
        self.handle = handle
        self.command_timeout = command_timeout
        self.layer = DriveLayer(config.drives, invert=invert_steering)
        self._command = _Command()
        self._safety_stop = False
        self._last_commands: Tuple[DriveCommand, ...] = tuple(DriveCommand(0.0, 0.0) for _ in config.drives)
        self._limits = _command_limits(config)

    # ---- inputs ---------------------------------------------------------------------------
    def set_command(self, vx: float, vy: float, wz: float, time: float) -> Optional[str]:
        """Takes a velocity command; returns why it was refused, or None.

        A refused command (NaN, infinite, absurdly large) is dropped: the previous one stands until
        it times out, so a source sending only garbage stops the wheels. An accepted one ends homing.
        """
        values = (vx, vy, wz)
        if not all(math.isfinite(v) for v in values):
            return f"refused velocity command with a non-finite value (vx {vx}, vy {vy}, wz {wz})"
        linear_limit, angular_limit = self._limits
        if math.hypot(vx, vy) > linear_limit or abs(wz) > angular_limit:
            return (
                f"refused absurd velocity command (vx {vx:g} m/s, vy {vy:g} m/s, wz {wz:g} rad/s): beyond "
                f"{ABSURD_FACTOR:g} times what the wheels can do ({linear_limit:.1f} m/s, {angular_limit:.1f} rad/s)"
            )
        self._command = _Command(Twist(vx, vy, wz), time)
        self.handle.end_homing()
        return None

    def safety_stop(self, enabled: bool) -> str:
        self._safety_stop = bool(enabled)
        return "safety stop enabled" if enabled else "safety stop disabled"

    @property
    def safety_stopped(self) -> bool:
        return self._safety_stop

    def reset_odometry(self) -> None:
        self.calculator.zero_odometry_pose()

    def home_steering(self) -> str:
        self._command = _Command()
        return self.handle.home_steering()

    def set_drive_params(self, changes: Sequence[Tuple[int, str, float]]) -> Tuple[int, List[str]]:
        """Changes drive parameters at run time; returns how many were applied and the problems.

        Each change is validated like the configuration file; one that breaks a rule is not applied
        and the others still are. Commands and odometry use the new values from the next cycle.
        """
        config, applied, problems = self.config, 0, []
        for index, key, value in changes:
            if key not in RUNTIME_DRIVE_KEYS:
                problems.append(
                    f"motor_drives.drive{index}.{key}: cannot be changed at run time "
                    f"(changeable: {', '.join(RUNTIME_DRIVE_KEYS)})"
                )
                continue
            try:
                candidate = with_drive_param(config, index, key, value)
                self.calculator.set_params(candidate.drives, candidate.passive_wheels)
            except Exception as e:  # ConfigError or KinematicsError: both say what is wrong
                problems.append(str(e).replace("\n", " "))
                continue
            config, applied = candidate, applied + 1
        self.calculator.set_params(config.drives, config.passive_wheels)
        self.config = config
        self.layer.set_params(config.drives)
        self.handle.set_params(config)
        self._limits = _command_limits(config)
        return applied, problems

    # ---- the cycle ------------------------------------------------------------------------
    def step(self, time: float) -> CycleResult:
        measured = self.handle.read_drive_states(time)
        stopped_by = "homing" if self.handle.homing else None
        changed, scale = False, 1.0
        cmd = self._command
        # a command more than a timeout ahead of time: time moved backwards (a simulation reset), and
        # no command has come since
        if cmd.time is None or abs(time - cmd.time) > self.command_timeout:
            stopped_by = stopped_by or "timeout"
            commands = self.calculator.set_zero_speed(self._last_commands)
        else:
            result = self.calculator.calculate_command(cmd.twist)
            out = self.layer.apply(result.commands, [m.steering for m in measured])
            commands, changed, scale = out.commands, result.changed, out.speed_scale
            if self._safety_stop:
                stopped_by = "safety stop"
            elif not self.calculator.determines_motion(unheard_drives([m.as_state() for m in measured])):
                # Nothing heard can tell how the robot moves: it stops at once, not at the device's
                # lost timeout (the differential robot's one controller, two seconds of unseen travel).
                stopped_by = BLIND
            if stopped_by:
                commands = self.calculator.set_zero_speed(commands)
        commands = tuple(commands)
        self._last_commands = commands
        self.handle.send_drive_commands(commands, time)
        states = tuple(self.handle.read_drive_states(time))
        odom = self.calculator.calculate_odometry([s.as_state() for s in states], time)
        return CycleResult(time, commands, states, odom, stopped_by, changed, scale)

    def shutdown(self, time: Optional[float] = None) -> None:
        """Stops the wheels (the handle sends zero speeds, steering kept) and releases the handle."""
        self._command = _Command()
        self.handle.close(time)

    @property
    def closed(self) -> bool:
        return self.handle.closed


class PoseCovariance:
    """Covariances of the odometry message: the twist's, and the pose's, growing while moving.

    twist: 36 numbers, row-major 6 x 6 (ParameterError otherwise), the covariance of an estimate from
    every one of the robot's drives (drives of them). From fewer drives (some unheard) it is scaled
    by drives / heard, as the variance of a mean over fewer wheels; blind (OdometryResult.blind), the
    linear and yaw rates' variances are BLIND_VARIANCE. ``current_twist`` is the last estimate's.
    The pose covariance starts equal to twist and grows by the current twist covariance per second
    of motion (the original added it per cycle, so its growth depended on the loop rate) while any
    of |vx|, |vy|, |wz| exceeds MOVING, and for every second odometry is blind (the motion is unknown).
    """

    def __init__(self, twist: Sequence[float] = DEFAULT_TWIST_COVARIANCE, drives: int = 1):
        if (
            isinstance(twist, (str, bytes))
            or not hasattr(twist, "__len__")
            or len(twist) != 36
            or not all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in twist)
        ):
            raise ParameterError(f"~twist_covariance: {twist!r}: must be a list of 36 finite numbers (row-major 6x6)")
        self.twist = tuple(float(v) for v in twist)
        self.drives = max(1, int(drives))
        self.pose = self.twist
        self.current_twist = self.twist

    def twist_for(self, odometry: OdometryResult) -> Tuple[float, ...]:
        """The twist covariance of this estimate (see the class)."""
        if odometry.blind:
            return tuple(BLIND_VARIANCE if k in BLIND_DIAGONAL else v for k, v in enumerate(self.twist))
        heard = self.drives - len(odometry.unheard)
        if odometry.unheard and heard > 0:
            return tuple(v * self.drives / heard for v in self.twist)
        return self.twist

    def update(self, odometry: OdometryResult) -> None:
        self.current_twist = self.twist_for(odometry)
        t = odometry.twist
        if odometry.blind or abs(t.vx) > MOVING or abs(t.vy) > MOVING or abs(t.wz) > MOVING:
            self.pose = tuple(a + b * odometry.dt for a, b in zip(self.pose, self.current_twist))

    def reset(self) -> None:
        self.pose = self.twist


def _command_limits(config: RobotConfig) -> Tuple[float, float]:
    """(linear [m/s], angular [rad/s]) beyond which a command is absurd for this robot."""
    fastest = max(d.max_wheel_speed for d in config.drives)
    reach = max(math.hypot(x, y) for x, y in config.wheel_contacts()) or 1.0
    return ABSURD_FACTOR * fastest, ABSURD_FACTOR * fastest / reach


__all__ = [
    "ABSURD_FACTOR",
    "BLIND",
    "BLIND_VARIANCE",
    "DEFAULT_TWIST_COVARIANCE",
    "MOVING",
    "RUNTIME_DRIVE_KEYS",
    "BaseDriverCore",
    "CycleResult",
    "PoseCovariance",
]
