"""``simple_sim``: every drive is a SimulatedDrive that follows its commands (notes 3.5)."""

from typing import List

from ..kinematics import DriveCommand, SimulatedDrive
from ..modes import MODE_ONLINE
from .handle import BaseHandle, BatteryInfo, ControllerInfo, MeasuredDrive


class SimulatedBase(BaseHandle):
    """Drives that follow their commands with the configured ramps (``prp_sim_a``, ``str_sim_v``).

    Homing slews every steering to 0 with the wheels stopped until base_driver ends it. A KC
    battery reads as full and healthy at its nominal 48 V; each drive's controller is online.
    """

    NOMINAL_VOLTAGE = 48.0  # [V]

    def __init__(self, config):
        super().__init__(config)
        self.drives = [SimulatedDrive(d) for d in config.drives]
        self._measured = [MeasuredDrive(0.0, 0.0, 0.0, 0.0) for _ in config.drives]
        self._step_time = None

    def _send_drive_commands(self, commands, time):
        if self.homing:
            commands = [DriveCommand(0.0, 0.0) for _ in commands]
        dt = None if self._step_time is None else time - self._step_time
        self._step_time = time
        measured = []
        for sim, cmd, old in zip(self.drives, commands, self._measured):
            state = sim.step(cmd, time)
            rate = (state.steering - old.steering) / dt if dt and dt > 0 else 0.0
            measured.append(MeasuredDrive(state.steering, state.speed, state.wheel_angle, rate))
        self._measured = measured

    def _read_drive_states(self, time) -> List[MeasuredDrive]:
        return list(self._measured)

    def _home_steering(self):
        return "homing commands sent"

    def _set_params(self, config):
        for sim, drive in zip(self.drives, config.drives):
            sim.drive = drive

    def batteries(self, time):
        return [
            BatteryInfo(b.id, 0, 100.0, 100.0, self.NOMINAL_VOLTAGE, 0.0, temperatures=(20.0,))
            for b in self.config.present_batteries
        ]

    def controllers(self, time):
        # One controller per type-0 drive (propulsion + steering channels) and one per pair of
        # type-1 drives (two propulsion channels), as on the robot; channels in the drives' order.
        out = []
        for c in self.config.motor_controllers:
            motor_vars = []
            for k in c.indices:
                m = self._measured[k]
                motor_vars.append(("propulsion", m.speed, m.wheel_angle, 0.0, 0.0))
                if c.steered:
                    motor_vars.append(("steering", m.steering_speed, m.steering, 0.0, 0.0))
            out.append(
                ControllerInfo(
                    name=c.name,
                    type="simulated " + ("prop/steer" if c.steered else "prop/prop"),
                    version="simple_sim",
                    can_id=c.node,
                    mode=MODE_ONLINE,
                    battery_volts=self.NOMINAL_VOLTAGE,
                    motor_vars=tuple(motor_vars),
                )
            )
        return out
