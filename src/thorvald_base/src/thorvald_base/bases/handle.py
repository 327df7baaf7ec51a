"""The hardware side of base_driver (the original's BaseCtrl, paper Figure 6), without ROS.

A :class:`BaseHandle` sends drive commands, reads drive states, motor controllers and batteries,
homes the steering, and stops the wheels before it lets go of the hardware. The shared logic and
the contract live here; a handle implements the ``_``-prefixed methods (template method, as
python-can's BusABC with ``send``/``_send_internal``).

Times are seconds on whichever clock the node uses (ROS time, simulated time in simulation).
"""

from dataclasses import dataclass, replace
from typing import Callable, ClassVar, Dict, List, Optional, Sequence, Tuple

from thorvald_model.config import RobotConfig

from ..errors import ThorvaldBaseError
from ..kinematics import DriveCommand, DriveState


@dataclass(frozen=True)
class MeasuredDrive:
    """A drive's measured state with the rates a BaseState carries.

    heard: False when the drive's reports stopped (older than the handle's report timeout, or none
    came); the values are then the last ones heard, which odometry must not integrate.
    """

    steering: float  # [rad]
    speed: float  # wheel rim speed [m/s]
    wheel_angle: float  # [rad]
    steering_speed: float  # [rad/s]
    heard: bool = True

    def as_state(self) -> DriveState:
        return DriveState(self.steering, self.speed, self.wheel_angle, self.heard)


@dataclass(frozen=True)
class BatteryInfo:
    """One battery as battery_data reports it (thorvald_msgs/BatteryData)."""

    id: int
    state: int  # BATTERY_OK, BATTERY_ALARM, BATTERY_LOST
    state_of_charge: float  # [%]
    state_of_health: float  # [%]
    voltage: float  # [V]
    current: float  # [A]
    charge_fet_on: bool = True
    discharge_fet_on: bool = True
    cycle_count: int = 0
    capacity: float = 0.0  # [Ah]
    temperatures: Tuple[float, ...] = ()  # [degC]
    alarms: Tuple[str, ...] = ()  # names of the BatteryAlarms flags that are set


@dataclass(frozen=True)
class ControllerInfo:
    """One motor controller as motor_controller_data reports it (thorvald_msgs/Controller)."""

    name: str
    type: str
    version: str
    can_id: int
    mode: int
    battery_volts: float = 0.0  # [V]
    battery_amps: float = 0.0  # [A]
    temps: Tuple[float, ...] = ()  # [degC]
    status_flags: Tuple[Tuple[str, bool], ...] = ()
    motor_vars: Tuple[Tuple[str, float, float, float, float], ...] = ()  # (type, speed, position, amps, power)
    drive_direction: int = 0
    home_speed: int = 0
    home_count: int = 0


@dataclass(frozen=True)
class IoInfo:
    """One IO board as io_data reports it (thorvald_msgs/IOData)."""

    id: int
    type: int
    relays: Tuple[bool, ...]
    analog: Tuple[float, ...]  # [V]
    online: bool


class DriveTopics:
    """Drive commands out, measured drive states and motor currents in, over the node's topics (a
    simulator's).

    The node makes it (base_driver_node.RosPorts); a handle only calls it, so no handle imports
    rospy or a message type.
    """

    def send(self, commands: Sequence[DriveCommand], time: float, drives: Sequence) -> None:
        """One command per drive for time [s]; drives: the configuration's, for their steering
        speed limits and channels as they are now (set_drive_params may change them)."""
        raise NotImplementedError

    def listen(self, on_states: Callable[[List["MeasuredDrive"], float], None]) -> None:
        """on_states(states in drive order, their time [s]) for each measurement that arrives."""
        raise NotImplementedError

    def listen_currents(self, on_currents: Callable[[List[float], List[float], float], None]) -> None:
        """on_currents(propulsion amps, steering amps, their time [s]), the motor currents [A] in drive
        order, for each measurement that arrives (a simulator's that reports none: never)."""

    def close(self) -> None:
        """Stops sending and listening."""


class Ports:
    """What base_driver's node offers a handle besides the configuration and parameters."""

    def drive_topics(self, command_topic: str, state_topic: str, current_topic: str = "drive_currents") -> DriveTopics:
        """The drives' commands out, their states and motor currents in, on these topics (names the
        node resolves as its own)."""
        raise NotImplementedError


@dataclass
class Frame:
    """A CAN frame, independent of python-can and of ROS messages (the relay for implements)."""

    id: int
    data: bytes
    is_extended: bool = False
    is_remote: bool = False


class BaseHandle:
    """The hardware side of base_driver: drives, motor controllers, batteries.

    Contract, for every handle:

    * ``send_drive_commands`` once per cycle, one command per drive after the drive layer;
      ``read_drive_states`` the latest measured state of every drive, in drive order, each marked
      unheard (``MeasuredDrive.heard``) when its reports stopped: a held value is no measurement.
    * ``home_steering`` starts homing; ``homing`` is true until the handle ends it (the homing is
      done) or base_driver calls ``end_homing`` because a new velocity command arrived. What the
      drives do meanwhile is the handle's business.
    * ``close`` stops the wheels (zero speed, the steering where it was commanded) before the
      hardware is released; after it, nothing is sent.
    * Each drive's ``steering_offset`` [rad] (the angle the wheel really stands at when its
      controller reads 0) is applied here, once, for every kind of base: a handle's
      ``_send_drive_commands`` gets steering - offset and its ``_read_drive_states`` returns what
      the controller reads; ``read_drive_states`` gives reading + offset, the wheel's true angle.
      Everything above the handle (drive layer, odometry, joint_states) sees true angles only.
      Homing is the handle's: it drives the controllers' own 0, wherever that stands.
    """

    # Whether base_driver can run in lockstep with a simulator on this handle: the handle then waits
    # for each instant's measured states (wait_for_states) and answers an instant without a cycle
    # (answer); see SimulatedJointsBase.
    supports_lockstep: ClassVar[bool] = False

    def __init__(self, config: RobotConfig):
        self.config = config
        self._homing = False
        self._closed = False
        self._last_commands: Optional[Tuple[DriveCommand, ...]] = None
        self._last_time: Optional[float] = None

    @classmethod
    def from_params(cls, config: RobotConfig, params, ports: Optional["Ports"] = None) -> "BaseHandle":
        """The handle for base_driver's parameters (DriverParams; the factory's entry point).

        A handle that needs more than the configuration (a CAN bus opened from
        ``can_interface_type``, the node's topics) takes it here, so that tests can construct
        it directly.
        """
        return cls(config)

    def send_drive_commands(self, commands: Sequence[DriveCommand], time: float) -> None:
        """Sends one command per drive (after the drive layer) for time [s]."""
        if self._closed:
            raise ThorvaldBaseError("the base handle is closed")
        if len(commands) != len(self.config.drives):
            raise ThorvaldBaseError(f"expected {len(self.config.drives)} drive commands, got {len(commands)}")
        commands = tuple(commands)
        # the true angles are kept for stop(), which sends them through here again
        self._send_drive_commands(self._to_controllers(commands), time)
        self._last_commands, self._last_time = commands, time

    def read_drive_states(self, time: float) -> List["MeasuredDrive"]:
        """The latest measured state of every drive, in drive order (true steering angles)."""
        states = self._read_drive_states(time)
        offsets = self._steering_offsets()
        if not any(offsets):
            return states
        return [replace(s, steering=s.steering + offset) if offset else s for s, offset in zip(states, offsets)]

    def _steering_offsets(self) -> Tuple[float, ...]:
        return tuple(d.steering_offset for d in self.config.drives)

    def _to_controllers(self, commands: Tuple[DriveCommand, ...]) -> Tuple[DriveCommand, ...]:
        """The commands in the controllers' angles: true steering - steering_offset."""
        offsets = self._steering_offsets()
        if not any(offsets):
            return commands
        return tuple(DriveCommand(c.steering - offset, c.speed) for c, offset in zip(commands, offsets))

    def home_steering(self) -> str:
        """Starts homing the steering of every drive; returns a message for the caller."""
        self._homing = True
        return self._home_steering()

    @property
    def homing(self) -> bool:
        return self._homing

    def end_homing(self) -> None:
        """Ends homing (a new velocity command arrived, or the handle found the homing done)."""
        if self._homing:
            self._homing = False
            self._end_homing()

    def set_params(self, config: RobotConfig) -> None:
        """Takes changed drive parameters (set_drive_params) at once."""
        self.config = config
        self._set_params(config)

    @property
    def io_config(self):
        """The IO boards of this base (thorvald_model IOBoard): the relay services base_driver offers."""
        return self.config.io

    def batteries(self, time: float) -> List[BatteryInfo]:
        return []

    def controllers(self, time: float) -> List[ControllerInfo]:
        return []

    def io_boards(self, time: float) -> List[IoInfo]:
        return []

    def diagnostics(self, time: float) -> Dict[str, str]:
        """Key/values about the hardware link for /diagnostics (bus errors, counters); none by default."""
        return {}

    # ---- a CAN bus's services; a base without one answers that it has none ----------------------
    NO_BUS = "this base has no CAN bus (base handle {name})"

    def _no_bus(self) -> str:
        return self.NO_BUS.format(name=type(self).__name__)

    def relay(self, frame: Frame) -> Optional[str]:
        """Queues a frame from can_frames_device_t for the bus; the reason if it is refused or dropped."""
        return self._no_bus()

    def take_received(self) -> Tuple[List[Frame], List[Frame]]:
        """(frames base devices claimed, frames none claimed) received since the last call."""
        return [], []

    def mute(self, muted: bool) -> str:
        """Stops (or resumes) relaying frames from can_frames_device_t; the queue is cleared."""
        return self._no_bus()

    def setup_motor_controller(self, node: int, setup_id: int, value: int) -> Tuple[int, str]:
        return -1, self._no_bus()

    def set_home_count_current_pos_zero(self, node: int) -> Tuple[int, str]:
        return -1, self._no_bus()

    def set_relay(self, io_id: int, relay: int, on: bool) -> str:
        raise ThorvaldBaseError(self._no_bus())

    @property
    def closed(self) -> bool:
        return self._closed

    def stop(self, time: Optional[float] = None) -> None:
        """Sends zero wheel speeds with the steering of the last command (or straight ahead)."""
        last = self._last_commands or tuple(DriveCommand(0.0, 0.0) for _ in self.config.drives)
        when = time if time is not None else (self._last_time if self._last_time is not None else 0.0)
        self.send_drive_commands([DriveCommand(c.steering, 0.0) for c in last], when)

    def close(self, time: Optional[float] = None) -> None:
        """Stops the wheels, then releases the hardware. Closing twice does nothing."""
        if self._closed:
            return
        try:
            self.stop(time)
        finally:
            self._closed = True
            self._close()

    # ---- implemented by each handle -------------------------------------------------------
    def _send_drive_commands(self, commands: Tuple[DriveCommand, ...], time: float) -> None:
        raise NotImplementedError

    def _read_drive_states(self, time: float) -> List[MeasuredDrive]:
        raise NotImplementedError

    def _home_steering(self) -> str:
        raise NotImplementedError

    def _end_homing(self) -> None:
        """What ending the homing takes on this hardware (nothing by default)."""

    def _set_params(self, config: RobotConfig) -> None:
        raise NotImplementedError

    def _close(self) -> None:
        """Releases the hardware (nothing by default)."""
