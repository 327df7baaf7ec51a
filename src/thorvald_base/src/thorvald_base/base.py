"""The robot base behind base_driver (paper section 3.1, Figure 6), without ROS.

* :class:`BaseHandle`: the interface of the hardware side (the original's BaseCtrl): send drive
  commands, read drive states, motor controllers and batteries. Shared logic lives here; a
  handle implements the ``_``-prefixed methods (template method, as python-can's BusABC).
* :class:`SimulatedBase`: the ``simple_sim`` handle: every drive is a SimulatedDrive.
* :class:`BaseDriverCore`: one control cycle of base_driver: the latest command through the
  calculator and the drive layer, the safety rules (command timeout, e-stop, refused commands),
  the handle, and odometry from the measured states. The node only converts messages.

Times are seconds on whichever clock the node uses (ROS time, simulated time in simulation).
"""

import math
from dataclasses import dataclass, field
from typing import List, Optional, Sequence, Tuple

from thorvald_model.config import RobotConfig

from .errors import ThorvaldBaseError
from .kinematics import BaseCalculator, DriveCommand, DriveLayer, DriveState, OdometryResult, SimulatedDrive, Twist

# Mode codes of Controller.controller_mode (the MODE_* values of thorvald_msgs/BaseState).
MODE_ONLINE = 3

# A command is absurd, and refused, beyond this multiple of what the fastest wheel can do.
ABSURD_FACTOR = 10.0

# Keys of motor_drives/driveN that set_drive_params may change at run time: geometry and motor
# parameters. type, node and names define the hardware and need a restart.
RUNTIME_DRIVE_KEYS = (
    "x",
    "y",
    "r_wheel",
    "w_wheel",
    "prp_gr_rt",
    "prp_enc_ppr",
    "prp_max_rpm",
    "prp_sim_a",
    "str_gr_rt",
    "str_enc_ppr",
    "str_lim",
    "str_sim_v",
)


@dataclass(frozen=True)
class MeasuredDrive:
    """A drive's measured state with the rates a BaseState carries."""

    steering: float  # [rad]
    speed: float  # wheel rim speed [m/s]
    wheel_angle: float  # [rad]
    steering_speed: float  # [rad/s]

    def as_state(self) -> DriveState:
        return DriveState(self.steering, self.speed, self.wheel_angle)


@dataclass(frozen=True)
class BatteryInfo:
    """One battery as battery_data reports it (thorvald_msgs/BatteryData)."""

    id: int
    state: int  # 0 ok, 1 alarm, 2 lost connection
    state_of_charge: float  # [%]
    state_of_health: float  # [%]
    voltage: float  # [V]
    current: float  # [A]
    charge_fet_on: bool = True
    discharge_fet_on: bool = True
    cycle_count: int = 0
    capacity: float = 0.0  # [Ah]
    temperatures: Tuple[float, ...] = ()
    alarms: Tuple[str, ...] = ()  # names of the BatteryAlarms flags that are set


@dataclass(frozen=True)
class ControllerInfo:
    """One motor controller as motor_controller_data reports it (thorvald_msgs/Controller)."""

    name: str
    type: str
    version: str
    can_id: int
    mode: int
    battery_volts: float = 0.0
    battery_amps: float = 0.0
    temps: Tuple[float, ...] = ()
    status_flags: Tuple[Tuple[str, bool], ...] = ()
    motor_vars: Tuple[Tuple[str, float, float, float, float], ...] = ()  # (type, speed, position, amps, power)


class BaseHandle:
    """The hardware side of base_driver: drives, motor controllers, batteries."""

    def __init__(self, config: RobotConfig):
        self.config = config

    def send_drive_commands(self, commands: Sequence[DriveCommand], time: float) -> None:
        """Sends one command per drive (after the drive layer) for time [s]."""
        if len(commands) != len(self.config.drives):
            raise ThorvaldBaseError(f"expected {len(self.config.drives)} drive commands, got {len(commands)}")
        self._send_drive_commands(commands, time)

    def read_drive_states(self, time: float) -> List[MeasuredDrive]:
        """The latest measured state of every drive, in drive order."""
        return self._read_drive_states(time)

    def home_steering(self) -> str:
        """Starts homing the steering of every drive; returns a message for the caller."""
        return self._home_steering()

    def set_params(self, config: RobotConfig) -> None:
        """Takes changed drive parameters (set_drive_params) at once."""
        self.config = config
        self._set_params(config)

    def batteries(self, time: float) -> List[BatteryInfo]:
        return []

    def controllers(self, time: float) -> List[ControllerInfo]:
        return []

    def close(self) -> None:
        """Releases the hardware; the drives must be stopped before."""

    # implemented by each handle
    def _send_drive_commands(self, commands: Sequence[DriveCommand], time: float) -> None:
        raise NotImplementedError

    def _read_drive_states(self, time: float) -> List[MeasuredDrive]:
        raise NotImplementedError

    def _home_steering(self) -> str:
        raise NotImplementedError

    def _set_params(self, config: RobotConfig) -> None:
        raise NotImplementedError


class SimulatedBase(BaseHandle):
    """``simple_sim``: drives follow their commands with the configured ramps (notes 3.5).

    Homing slews every steering to 0 with the wheels stopped until the next drive command.
    A KC battery reads as full and healthy at its nominal 48 V; each drive's controller is online.
    """

    NOMINAL_VOLTAGE = 48.0  # [V]

    def __init__(self, config: RobotConfig):
        super().__init__(config)
        self.drives = [SimulatedDrive(d) for d in config.drives]
        self._measured = [MeasuredDrive(0.0, 0.0, 0.0, 0.0) for _ in config.drives]
        self._last_time: Optional[float] = None
        self._homing = False

    def _send_drive_commands(self, commands, time):
        if self._homing:
            commands = [DriveCommand(0.0, 0.0) for _ in commands]
        dt = None if self._last_time is None else time - self._last_time
        self._last_time = time
        measured = []
        for sim, cmd, old in zip(self.drives, commands, self._measured):
            state = sim.step(cmd, time)
            rate = (state.steering - old.steering) / dt if dt and dt > 0 else 0.0
            measured.append(MeasuredDrive(state.steering, state.speed, state.wheel_angle, rate))
        self._measured = measured

    def _read_drive_states(self, time):
        return list(self._measured)

    def _home_steering(self):
        self._homing = True
        return "homing commands sent"

    def end_homing(self):
        self._homing = False

    @property
    def homing(self) -> bool:
        return self._homing

    def _set_params(self, config):
        for sim, drive in zip(self.drives, config.drives):
            sim.drive = drive

    def batteries(self, time):
        return [
            BatteryInfo(b.id, 0, 100.0, 100.0, self.NOMINAL_VOLTAGE, 0.0, temperatures=(20.0,))
            for b in self.config.batteries
            if b.type == 1 and b.with_battery
        ]

    def controllers(self, time):
        # One controller per type-0 drive (propulsion + steering channels) and one per pair of
        # type-1 drives (two propulsion channels), as on the robot.
        channels, first = {}, {}
        for d, m in zip(self.config.drives, self._measured):
            first.setdefault(d.node, d)
            channels.setdefault(d.node, []).append(("propulsion", m.speed, m.wheel_angle, 0.0, 0.0))
            if d.steerable:
                channels[d.node].append(("steering", m.steering_speed, m.steering, 0.0, 0.0))
        return [
            ControllerInfo(
                name=d.name,
                type="simulated " + ("prop/steer" if d.steerable else "prop/prop"),
                version="simple_sim",
                can_id=node,
                mode=MODE_ONLINE,
                battery_volts=self.NOMINAL_VOLTAGE,
                motor_vars=tuple(channels[node]),
            )
            for node, d in first.items()
        ]


@dataclass(frozen=True)
class CycleResult:
    """What one control cycle produced, for the node to publish."""

    time: float
    commands: Tuple[DriveCommand, ...]  # sent to the drives (joint_commands)
    states: Tuple[MeasuredDrive, ...]  # measured after sending (base_state, joint_states)
    odometry: OdometryResult
    stopped_by: Optional[str]  # "timeout", "safety stop", "homing" or None
    twist_changed: bool  # the command was not realisable; the closest one was used
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
            raise ThorvaldBaseError(f"~command_timeout: {command_timeout!r}: must be > 0 [s]")
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
        it times out, so a source sending only garbage stops the wheels.
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
        if isinstance(self.handle, SimulatedBase):
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
                candidate = config.with_drive_param(index, key, value)
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
        stopped_by = None
        changed, scale = False, 1.0
        cmd = self._command
        if isinstance(self.handle, SimulatedBase) and self.handle.homing:
            stopped_by = "homing"
        if cmd.time is None or time - cmd.time > self.command_timeout:
            stopped_by = stopped_by or "timeout"
            commands = self.calculator.set_zero_speed(self._last_commands)
        else:
            result = self.calculator.calculate_command(cmd.twist)
            out = self.layer.apply(result.commands, [m.steering for m in measured])
            commands, changed, scale = out.commands, result.changed, out.speed_scale
            if self._safety_stop:
                stopped_by = "safety stop"
                commands = self.calculator.set_zero_speed(commands)
        commands = tuple(commands)
        self._last_commands = commands
        self.handle.send_drive_commands(commands, time)
        states = tuple(self.handle.read_drive_states(time))
        odom = self.calculator.calculate_odometry([s.as_state() for s in states], time)
        return CycleResult(time, commands, states, odom, stopped_by, changed, scale)


def _command_limits(config: RobotConfig) -> Tuple[float, float]:
    """(linear [m/s], angular [rad/s]) beyond which a command is absurd for this robot."""
    fastest = max(d.max_wheel_speed for d in config.drives)
    reach = max(math.hypot(x, y) for x, y in config.wheel_contacts()) or 1.0
    return ABSURD_FACTOR * fastest, ABSURD_FACTOR * fastest / reach
