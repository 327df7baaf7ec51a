"""``simulated_joints``: drives measured from a physics simulator's joints (ours, beyond the original).

base_driver sends its drive commands on ``drive_commands`` (thorvald_msgs/BaseState: steering,
rim speed, steering speed limit per drive) and reads what the simulator's joints measure on
``drive_states`` (steering angle and rate, wheel angle and rim speed), as it would read encoders
over CAN. Odometry then sees what a real robot's encoders see: torque limits, slew, stalls and
slip. The simulator knows nothing of base_driver beyond these two topics (thorvald_sim follows
``drive_commands`` when a robot is spawned with ``-command_topic drive_commands``).

The class is pure: it gets a function that sends commands, and the node's subscriber hands it the
measured states (:meth:`update`). Only :meth:`from_params` talks to ROS, to wire them.

Homing points every wheel straight with zero speed until base_driver ends it. Measurements older
than ``stale_after`` [s] mean the simulator lost the robot: the wheels are sent zero speeds and the
controllers read as lost.
"""

import threading
from typing import Callable, List, Optional, Sequence, Tuple

from ..errors import ParameterError
from ..kinematics import DriveCommand
from .handle import MODE_LOST_CONNECTION, MODE_ONLINE, BaseHandle, ControllerInfo, MeasuredDrive

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
        self._ros = ()

    @classmethod
    def from_params(cls, config, params: dict) -> "SimulatedJointsBase":
        import rospy  # noqa: PLC0415  (the node's side: only when base_driver creates this handle)

        from thorvald_msgs.msg import BaseState  # noqa: PLC0415

        from .. import conversions  # noqa: PLC0415

        stale_after = float(params.get("measured_timeout", 0.5))
        if not stale_after > 0:
            raise ParameterError(f"~measured_timeout: {stale_after!r}: must be > 0 [s]")
        pub = rospy.Publisher(cls.COMMAND_TOPIC, BaseState, queue_size=1)

        def send(commands, time):
            drives = handle.config.drives
            pub.publish(
                conversions.command_msg(
                    rospy.Time.from_sec(time),
                    commands,
                    [d.max_steering_speed for d in drives],
                    [d.channel for d in drives],
                )
            )

        def on_states(msg):
            try:
                handle.update(conversions.measured_drives(msg), msg.header.stamp.to_sec())
            except ValueError as e:
                rospy.logwarn_throttle(5.0, "base_driver: drive_states ignored: %s", e)

        handle = cls(config, send, stale_after)
        handle._ros = (pub, rospy.Subscriber(cls.STATE_TOPIC, BaseState, on_states, queue_size=1))
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
        seen = {}
        for d in self.config.drives:
            seen.setdefault(d.node, d)
        return [
            ControllerInfo(name=d.name, type="simulated joints", version="thorvald_sim", can_id=node, mode=mode)
            for node, d in seen.items()
        ]

    def _close(self):
        for endpoint in self._ros:
            endpoint.unregister()
