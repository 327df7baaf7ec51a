"""``simulated_joints``: drives measured from a physics simulator's joints (ours, beyond the original).

base_driver sends its drive commands on ``drive_commands`` (thorvald_msgs/BaseState: steering,
rim speed, steering speed limit per drive) and reads what the simulator's joints measure on
``drive_states`` (steering angle and rate, wheel angle and rim speed), as it would read encoders
over CAN. Odometry then sees what a real robot's encoders see: torque limits, slew, stalls and
slip. The simulator knows nothing of base_driver beyond these two topics (thorvald_sim follows
``drive_commands`` when a robot is spawned with ``-command_topic drive_commands``).

The class is pure: it gets a function that sends commands, and the node's subscriber hands it the
measured states (:meth:`update`); :meth:`from_params` wires both to the topics the node offers
(:class:`~thorvald_base.bases.handle.Ports`), so no ROS module is imported here.

Homing points every wheel straight with zero speed until base_driver ends it. Measurements older
than ``stale_after`` [s] mean the simulator lost the robot: the wheels are sent zero speeds and the
controllers read as lost.
"""

import threading
from typing import Callable, List, Optional, Sequence, Tuple

from ..errors import ParameterError
from ..kinematics import DriveCommand
from ..modes import MODE_LOST_CONNECTION, MODE_ONLINE
from .handle import BaseHandle, ControllerInfo, MeasuredDrive

SendCommands = Callable[[Tuple[DriveCommand, ...], float], None]


class SimulatedJointsBase(BaseHandle):
    COMMAND_TOPIC = "drive_commands"
    STATE_TOPIC = "drive_states"

    def __init__(self, config, send: Optional[SendCommands] = None, stale_after: float = 0.5):
        super().__init__(config)
        self._send = send
        self.stale_after = stale_after
        self._lock = threading.Lock()
        self._measured: List[MeasuredDrive] = [MeasuredDrive(0.0, 0.0, 0.0, 0.0) for _ in config.drives]
        self._measured_time: Optional[float] = None
        self._topics = None

    @classmethod
    def from_params(cls, config, params, ports=None) -> "SimulatedJointsBase":
        """Wired to the simulator through the node's drive topics (``drive_commands`` out,
        ``drive_states`` in); ``params.measured_timeout`` [s] is when measurements are stale."""
        if ports is None:
            raise ParameterError("~base_handle: 'simulated_joints': needs base_driver's topics (run it in the node)")
        topics = ports.drive_topics(cls.COMMAND_TOPIC, cls.STATE_TOPIC)
        handle = cls(
            config, lambda commands, time: topics.send(commands, time, handle.config.drives), params.measured_timeout
        )
        topics.listen(handle.update)
        handle._topics = topics
        return handle

    def update(self, states: Sequence[MeasuredDrive], time: float) -> None:
        """The simulator's latest measurement of every drive, in drive order, taken at time [s]."""
        if len(states) != len(self.config.drives):
            raise ValueError(f"{len(states)} drive states for {len(self.config.drives)} drives")
        with self._lock:
            self._measured = list(states)
            self._measured_time = time

    def online(self, time: float) -> bool:
        with self._lock:
            return self._measured_time is not None and time - self._measured_time <= self.stale_after

    def _send_drive_commands(self, commands, time):
        if self.homing:
            commands = tuple(DriveCommand(0.0, 0.0) for _ in commands)
        elif not self.online(time):
            commands = tuple(DriveCommand(c.steering, 0.0) for c in commands)
        if self._send is not None:
            self._send(commands, time)

    def _read_drive_states(self, time):
        with self._lock:
            return list(self._measured)

    def _home_steering(self):
        return "homing commands sent"

    def _set_params(self, config):
        pass  # the simulator's joints are the physics; base_driver's parameters do not change them

    def controllers(self, time):
        mode = MODE_ONLINE if self.online(time) else MODE_LOST_CONNECTION
        return [
            ControllerInfo(name=c.name, type="simulated joints", version="thorvald_sim", can_id=c.node, mode=mode)
            for c in self.config.motor_controllers
        ]

    def _close(self):
        if self._topics is not None:
            self._topics.close()
