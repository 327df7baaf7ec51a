"""``simulated_joints``: drives measured from a physics simulator's joints (ours, beyond the original).

base_driver sends its drive commands on ``drive_commands`` (thorvald_msgs/BaseState: steering,
rim speed, steering speed limit per drive) and reads what the simulator's joints measure on
``drive_states`` (steering angle and rate, wheel angle and rim speed), as it would read encoders
over CAN. Odometry then sees what a real robot's encoders see: torque limits, slew, stalls and
slip. The simulator knows nothing of base_driver beyond these two topics (thorvald_sim follows
``drive_commands`` when a robot is spawned with ``-command_topic drive_commands``).

The class is pure: it gets a function that sends commands, and the node's subscribers hand it the
measured states (:meth:`update`) and motor currents (:meth:`update_currents`, from ``drive_currents``);
:meth:`from_params` wires them to the topics the node offers (:class:`~thorvald_base.bases.handle.Ports`),
so no ROS module is imported here.

The motor controllers (``motor_controller_data``) report what a real robot's would: per drive the
propulsion channel (rim speed, wheel angle, motor amps, relative power) and, for a drive that steers,
the steering channel (steering speed, angle, amps, relative power), channels in drive order per
controller, from the newest measurement at or before the instant asked. The relative power is the
output torque the current carries (:func:`thorvald_model.motors.output_torque`, the drive's motors)
over the drive's torque limit, within [-1, 1]; before any currents came, amps and power read 0.

A cycle at instant t reads the newest measurement taken at or before t: in lockstep the simulator
steps on as soon as the cycle's commands reach it, and the next instant's states may arrive while
the cycle still reads (base_driver reads once more after sending): they belong to the next cycle.

Homing points every wheel straight with zero speed until base_driver ends it. Measurements older
than ``stale_after`` [s] mean the simulator lost the robot: the wheels are sent zero speeds, the
controllers read as lost and every drive as unheard. A drive whose measurement holds no number (NaN:
the simulator's silenced drive, an encoder that gave no reading) is unheard at once and keeps the
values last heard; unheard for longer than ``stale_after`` it is lost, as a CAN controller that went
quiet is: every wheel is sent zero speed and its controller reads as lost until it is heard again.

Rim speeds cross the topics as the simulator converts them: with the radius of the robot it spawned,
the configuration's ``r_wheel`` when this handle was made (the spawn radius). When set_drive_params
(or ``~calibration``) changes a drive's ``r_wheel``, the wheel must turn as the new radius says, as a
CAN controller's would: a rim speed v is sent as v * r_spawn / r_now (the joint turns at v / r_now)
and a measured one read as v * r_now / r_spawn. Angles (steering, wheel) and currents cross unchanged.
"""

import math
import threading
from collections import deque
from dataclasses import replace
from typing import Callable, List, Optional, Sequence, Tuple

from thorvald_model.motors import Motor, output_torque, propulsion_motor, steering_motor

from ..errors import ParameterError
from ..kinematics import DriveCommand
from ..modes import MODE_LOST_CONNECTION, MODE_ONLINE
from .handle import BaseHandle, ControllerInfo, MeasuredDrive

SendCommands = Callable[[Tuple[DriveCommand, ...], float], None]
HISTORY = 8  # measurements kept: a cycle reads the newest taken at or before its instant
SAME_INSTANT = 1e-9  # [s]


class SimulatedJointsBase(BaseHandle):
    COMMAND_TOPIC = "drive_commands"
    STATE_TOPIC = "drive_states"
    CURRENT_TOPIC = "drive_currents"
    supports_lockstep = True  # wait_for_states and answer: the simulator's instants, one by one

    def __init__(self, config, send: Optional[SendCommands] = None, stale_after: float = 0.5):
        super().__init__(config)
        self._send = send
        self.stale_after = stale_after
        self._lock = threading.Lock()
        self._unmeasured = [MeasuredDrive(0.0, 0.0, 0.0, 0.0, heard=False) for _ in config.drives]  # before any came
        self._history = deque(maxlen=HISTORY)  # (time, states) of the last measurements, oldest first
        self._heard_at: List[Optional[float]] = [None] * len(config.drives)  # [s] each drive's last reading
        self._currents = deque(maxlen=HISTORY)  # (time, (prop amps, steer amps)) likewise
        self._topics = None
        self._arrived = threading.Condition(self._lock)  # lockstep: new drive states
        self._last_sent: Optional[Tuple[DriveCommand, ...]] = None  # what went to the simulator last
        self._spawn_radii: Tuple[float, ...] = tuple(d.r_wheel for d in config.drives)  # [m]
        self._scales: Tuple[float, ...] = tuple(1.0 for _ in config.drives)  # r_now / r_spawn

    @classmethod
    def from_params(cls, config, params, ports=None) -> "SimulatedJointsBase":
        """Wired to the simulator through the node's drive topics (``drive_commands`` out,
        ``drive_states`` and ``drive_currents`` in); ``params.measured_timeout`` [s] is when
        measurements are stale."""
        if ports is None:
            raise ParameterError("~base_handle: 'simulated_joints': needs base_driver's topics (run it in the node)")
        topics = ports.drive_topics(cls.COMMAND_TOPIC, cls.STATE_TOPIC, cls.CURRENT_TOPIC)
        handle = cls(
            config, lambda commands, time: topics.send(commands, time, handle.config.drives), params.measured_timeout
        )
        topics.listen(handle.update)
        topics.listen_currents(handle.update_currents)
        handle._topics = topics
        return handle

    def update(self, states: Sequence[MeasuredDrive], time: float) -> None:
        """The simulator's latest measurement of every drive, in drive order, taken at time [s]."""
        if len(states) != len(self.config.drives):
            raise ValueError(f"{len(states)} drive states for {len(self.config.drives)} drives")
        with self._lock:
            if self._history and time < self._history[-1][0]:
                self._history.clear()  # simulated time went back (a reset)
                self._heard_at = [None] * len(self._heard_at)
            last = self._history[-1][1] if self._history else self._unmeasured
            states = [s if _a_reading(s) else replace(held, heard=False) for s, held in zip(states, last)]
            self._heard_at = [time if s.heard else t for s, t in zip(states, self._heard_at)]
            self._history.append((time, states))
            self._arrived.notify_all()

    def update_currents(self, prop_amps: Sequence[float], steer_amps: Sequence[float], time: float) -> None:
        """The simulator's latest motor currents [A] of every drive, in drive order, taken at time [s]:
        propulsion and steering (0 for a drive that does not steer)."""
        n = len(self.config.drives)
        if len(prop_amps) != n or len(steer_amps) != n:
            raise ValueError(f"{len(prop_amps)} propulsion and {len(steer_amps)} steering currents for {n} drives")
        with self._lock:
            if self._currents and time < self._currents[-1][0]:
                self._currents.clear()  # simulated time went back (a reset)
            self._currents.append((time, (tuple(prop_amps), tuple(steer_amps))))

    @staticmethod
    def _at(history, time: float, default):
        """The newest of history's (time, value) taken at or before time [s]; the newest of all if every
        one is newer (the clock lags); default if there is none. Under the lock."""
        return next(
            (value for t, value in reversed(history) if t <= time + SAME_INSTANT),
            history[-1][1] if history else default,
        )

    @property
    def _measured_time(self) -> Optional[float]:
        """When the newest measurement was taken [s] (None before any); under the lock."""
        return self._history[-1][0] if self._history else None

    def wait_for_states(self, after: Optional[float], timeout: float) -> Optional[float]:
        """Lockstep: the time [s] of drive states newer than after (None: any), waiting up to timeout
        [s] of wall time for them; None if none came."""

        def newer() -> bool:
            t = self._measured_time
            return t is not None and (after is None or t > after + SAME_INSTANT)

        with self._arrived:
            return self._measured_time if self._arrived.wait_for(newer, timeout) else None

    def answer(self, time: float) -> None:
        """Lockstep: answers drive states of an instant that is not a cycle of base_driver's with the
        last commands sent, stamped with that instant (the simulator steps on only when answered)."""
        if self._send is not None and self._last_sent is not None:
            self._send(self._last_sent, time)

    def lost_drives(self, time: float) -> List[int]:
        """The drives (indices) not heard for longer than stale_after [s] at time [s], or never."""
        with self._lock:
            return [k for k, t in enumerate(self._heard_at) if t is None or time - t > self.stale_after]

    def online(self, time: float) -> bool:
        with self._lock:
            return self._measured_time is not None and time - self._measured_time <= self.stale_after

    def _send_drive_commands(self, commands, time):
        if self.homing:
            commands = tuple(DriveCommand(0.0, 0.0) for _ in commands)
        elif self.lost_drives(time):
            commands = tuple(DriveCommand(c.steering, 0.0) for c in commands)
        if self._send is not None:
            self._last_sent = tuple(DriveCommand(c.steering, c.speed / k) for c, k in zip(commands, self._scales))
            self._send(self._last_sent, time)

    def _read_drive_states(self, time):
        with self._lock:
            measured = list(self._at(self._history, time, self._unmeasured))
        if not self.online(time):
            measured = [replace(m, heard=False) for m in measured]
        return [replace(m, speed=m.speed * k) if k != 1.0 else m for m, k in zip(measured, self._scales)]

    def _home_steering(self):
        return "homing commands sent"

    def _set_params(self, config):
        # the simulator's joints are the physics; only the rim speeds' radius follows r_wheel
        self._scales = tuple(d.r_wheel / r for d, r in zip(config.drives, self._spawn_radii))

    def controllers(self, time):
        # One controller per type-0 drive (propulsion + steering channels) and one per pair of type-1
        # drives (two propulsion channels), as on the robot; channels in the drives' order.
        lost = set(self.lost_drives(time))
        drives = self.config.drives
        states = self._read_drive_states(time)  # the controllers' own angles: no steering offset
        with self._lock:  # None: no currents came yet
            prop_amps, steer_amps = self._at(self._currents, time, ((None,) * len(drives),) * 2)
        out = []
        for c in self.config.motor_controllers:
            motor_vars = []
            for k in c.indices:
                d, m = drives[k], states[k]
                # the wheel's turning rate [rad/s]: the rim speed with the radius it was scaled to
                prop = _channel(prop_amps[k], propulsion_motor(d), m.speed / d.r_wheel, d.max_wheel_torque)
                motor_vars.append(("propulsion", m.speed, m.wheel_angle, *prop))
                if c.steered:
                    steer = _channel(steer_amps[k], steering_motor(d), m.steering_speed, d.max_steering_torque)
                    motor_vars.append(("steering", m.steering_speed, m.steering, *steer))
            out.append(
                ControllerInfo(
                    name=c.name,
                    type="simulated joints",
                    version="thorvald_sim",
                    can_id=c.node,
                    mode=MODE_LOST_CONNECTION if lost.intersection(c.indices) else MODE_ONLINE,
                    motor_vars=tuple(motor_vars),
                )
            )
        return out

    def _close(self):
        if self._topics is not None:
            self._topics.close()


def _a_reading(state: MeasuredDrive) -> bool:
    return all(math.isfinite(v) for v in (state.steering, state.speed, state.wheel_angle, state.steering_speed))


def _channel(amps: Optional[float], motor: Motor, rate: float, limit: float) -> Tuple[float, float]:
    """(amps, relative power) of a motor channel: its current [A] (None: none came yet, both 0), and
    the output torque it carries at the output's rate [rad/s] over its limit [N m], within [-1, 1]."""
    if amps is None:
        return 0.0, 0.0
    return amps, max(-1.0, min(1.0, output_torque(motor, amps, rate) / limit))
