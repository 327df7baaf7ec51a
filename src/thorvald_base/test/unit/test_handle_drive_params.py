"""Drive parameters a base handle applies itself: ``steering_offset`` (once, in BaseHandle, for every
kind of base) and, for ``simulated_joints``, a changed ``r_wheel`` against the simulator's spawn radius."""

import pytest
from base_test_helpers import diff, four_ws

from thorvald_base.bases import BaseHandle, MeasuredDrive
from thorvald_base.bases.simulated import SimulatedBase
from thorvald_base.bases.simulated_joints import SimulatedJointsBase
from thorvald_base.core import BaseDriverCore
from thorvald_base.kinematics import DriveCommand, PltfClcStd
from thorvald_model import with_drive_param

OFFSETS = (0.05, 0.0, -0.03, 0.0)  # [rad] drive0 and drive2 homed off


def with_offsets(config, offsets=OFFSETS):
    for k, offset in enumerate(offsets):
        config = with_drive_param(config, k, "steering_offset", offset)
    return config


class ControllerBase(BaseHandle):
    """A handle whose controllers read back exactly the angle they were last sent."""

    def __init__(self, config):
        super().__init__(config)
        self.sent = []
        self.readings = [MeasuredDrive(0.0, 0.0, 0.0, 0.0) for _ in config.drives]

    def _send_drive_commands(self, commands, time):
        self.sent.append(commands)
        self.readings = [MeasuredDrive(c.steering, c.speed, 0.0, 0.0) for c in commands]

    def _read_drive_states(self, time):
        return list(self.readings)

    def _home_steering(self):
        return "homing"

    def _set_params(self, config):
        pass


def test_commands_reach_the_controllers_minus_the_offset_and_readings_come_back_plus_it():
    handle = ControllerBase(with_offsets(four_ws()))
    # before any command every controller reads 0: the wheels really stand at their offsets
    assert [s.steering for s in handle.read_drive_states(0.0)] == list(OFFSETS)
    handle.send_drive_commands([DriveCommand(0.3, 0.5)] * 4, 0.0)
    # true 0.3 rad: controller 0 is told 0.3 - 0.05 = 0.25, controller 2 0.3 + 0.03 = 0.33
    assert [c.steering for c in handle.sent[-1]] == pytest.approx([0.25, 0.3, 0.33, 0.3], abs=1e-15)
    assert [c.speed for c in handle.sent[-1]] == [0.5] * 4  # speeds untouched
    # and read back as the true angle, once: 0.25 + 0.05 = 0.3
    assert [s.steering for s in handle.read_drive_states(0.0)] == pytest.approx([0.3] * 4, abs=1e-15)
    # the stop before closing re-sends the true angles through the same path: subtracted once, not twice
    handle.close(0.1)
    assert [c.steering for c in handle.sent[-1]] == pytest.approx([0.25, 0.3, 0.33, 0.3], abs=1e-15)
    assert [c.speed for c in handle.sent[-1]] == [0.0] * 4


def test_a_robot_homed_exactly_passes_commands_and_states_through_unchanged():
    handle = ControllerBase(four_ws())
    commands = tuple(DriveCommand(0.1 * k, 0.2) for k in range(4))
    handle.send_drive_commands(commands, 0.0)
    assert handle.sent[-1] == commands
    assert [s.steering for s in handle.read_drive_states(0.0)] == [0.1 * k for k in range(4)]


def test_set_drive_params_changes_the_offset_at_once_through_the_core():
    handle = ControllerBase(four_ws())
    core = BaseDriverCore(handle.config, PltfClcStd.from_config(handle.config), handle)
    applied, problems = core.set_drive_params([(1, "steering_offset", 0.04)])
    assert (applied, problems) == (1, [])
    core.set_command(0.0, 0.4, 0.0, 0.0)  # sideways: every wheel at +pi/2
    result = core.step(0.0)
    assert [c.steering for c in handle.sent[-1]] == pytest.approx([1.5707963267948966 - o for o in (0, 0.04, 0, 0)])
    # what base_driver publishes (commands, measured states) is in true angles
    assert [c.steering for c in result.commands] == pytest.approx([1.5707963267948966] * 4)
    assert [s.steering for s in result.states] == pytest.approx([1.5707963267948966] * 4)
    applied, problems = core.set_drive_params([(1, "steering_offset", 0.3)])
    assert applied == 0 and "motor_drives.drive1.steering_offset" in problems[0] and "0.2 rad" in problems[0]


def test_the_simulated_base_stands_at_its_offset_and_follows_true_angles():
    base = SimulatedBase(with_offsets(four_ws()))
    assert [s.steering for s in base.read_drive_states(0.0)] == list(OFFSETS)
    for k in range(100):  # 2 s at 50 Hz: the steering (4 rad/s) and speed (1.5 m/s^2) ramps are done
        base.send_drive_commands([DriveCommand(0.2, 0.5)] * 4, 0.02 * k)
    assert [s.steering for s in base.read_drive_states(2.0)] == pytest.approx([0.2] * 4, abs=1e-12)
    # the simulated controllers themselves stand at 0.2 - offset
    assert [d.state.steering for d in base.drives] == pytest.approx([0.15, 0.2, 0.23, 0.2], abs=1e-12)


def test_simulated_joints_scale_rim_speeds_by_the_spawn_radius_over_the_radius_now():
    sent = []
    config = four_ws()  # spawned with r_wheel 0.2 m
    base = SimulatedJointsBase(config, lambda commands, time: sent.append(commands))
    base.update([MeasuredDrive(0.1, 0.4, 2.0, 0.3)] * 4, 1.0)
    base.send_drive_commands([DriveCommand(0.1, 0.5)] * 4, 1.0)
    assert [c.speed for c in sent[-1]] == [0.5] * 4  # the radius it spawned with: unchanged
    assert base.read_drive_states(1.0)[0].speed == 0.4

    # drive1 now 0.25 m: the simulator (0.2 m) must turn that wheel at 0.5 / 0.25 = 2 rad/s, which it
    # does for a rim speed of 2 * 0.2 = 0.4 m/s; what it measures at 0.2 m reads 0.25/0.2 larger
    base.set_params(with_drive_param(config, 1, "r_wheel", 0.25))
    base.send_drive_commands([DriveCommand(0.1, 0.5)] * 4, 1.02)
    assert [c.speed for c in sent[-1]] == pytest.approx([0.5, 0.4, 0.5, 0.5], abs=1e-15)
    assert [c.steering for c in sent[-1]] == [0.1] * 4
    states = base.read_drive_states(1.02)
    assert [s.speed for s in states] == pytest.approx([0.4, 0.5, 0.4, 0.4], abs=1e-15)
    # angles are angles: steering, wheel angle and steering rate cross unchanged
    assert {(s.steering, s.wheel_angle, s.steering_speed) for s in states} == {(0.1, 2.0, 0.3)}

    # back to the spawn radius: no scaling left over
    base.set_params(config)
    base.send_drive_commands([DriveCommand(0.1, 0.5)] * 4, 1.04)
    assert [c.speed for c in sent[-1]] == [0.5] * 4


def test_simulated_joints_apply_radius_and_offset_together_on_a_differential_robot():
    sent = []
    config = diff()  # two type-1 drives: no offset allowed, radius only
    base = SimulatedJointsBase(config, lambda commands, time: sent.append(commands))
    base.set_params(with_drive_param(config, 0, "r_wheel", 0.21))
    base.update([MeasuredDrive(0.0, 0.3, 0.0, 0.0)] * 2, 0.0)
    base.send_drive_commands([DriveCommand(0.0, 0.42), DriveCommand(0.0, 0.42)], 0.0)
    assert [c.speed for c in sent[-1]] == pytest.approx([0.4, 0.42], abs=1e-15)  # 0.42 * 0.2 / 0.21
    assert [s.speed for s in base.read_drive_states(0.0)] == pytest.approx([0.315, 0.3], abs=1e-15)
