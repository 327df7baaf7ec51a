"""base_driver's control cycle without ROS: safety rules, refused commands, run-time parameters."""

import math

import pytest
from base_test_helpers import EXAMPLE_ROBOTS, four_ws

from thorvald_base.bases.simulated import SimulatedBase
from thorvald_base.core import BaseDriverCore
from thorvald_base.kinematics import PltfClcStd
from thorvald_model import load_robot_config

DT = 0.02  # [s]: 50 Hz


def make_core(config=None, **kw):
    config = config or four_ws()
    calc = PltfClcStd()
    calc.initialize(config.drives, config.passive_wheels)
    return BaseDriverCore(config, calc, SimulatedBase(config), **kw)


def run(core, t0, seconds, command=None):
    """Steps the core from t0 for seconds, sending command (vx, vy, wz) every cycle; returns (t, last result)."""
    t, result = t0, None
    for _ in range(round(seconds / DT)):
        if command is not None:
            assert core.set_command(*command, t) is None
        result = core.step(t)
        t += DT
    return t, result


def test_commands_drive_the_simulated_robot_forward():
    core = make_core()
    _, r = run(core, 0.0, 2.0, (0.5, 0.0, 0.0))
    # 1.5 m/s^2 ramp: at 0.5 m/s after 0.33 s, so about 0.5 * (2.0 - 0.17) = 0.92 m in 2 s
    assert r.odometry.pose.x == pytest.approx(0.92, abs=0.05)
    assert all(c.speed == pytest.approx(0.5) and c.steering == pytest.approx(0.0) for c in r.commands)
    assert r.stopped_by is None


def test_old_command_stops_the_wheels_and_keeps_the_steering():
    core = make_core()
    t, r = run(core, 0.0, 1.5, (0.0, 0.4, 0.0))  # sideways: every wheel at +90 degrees
    assert all(c.steering == pytest.approx(math.pi / 2) for c in r.commands)
    t, r = run(core, t, 0.44)  # within the 0.5 s timeout: still driving
    assert r.stopped_by is None and r.commands[0].speed == pytest.approx(0.4)
    t, r = run(core, t, 0.1)
    assert r.stopped_by == "timeout"
    assert all(c.speed == 0.0 and c.steering == pytest.approx(math.pi / 2) for c in r.commands)


def test_a_command_from_before_time_moved_backwards_stops_the_wheels():
    core = make_core()
    _, r = run(core, 100.0, 1.0, (0.5, 0.0, 0.0))
    assert r.stopped_by is None
    _, r = run(core, 0.0, 0.1)  # a simulation reset to zero: the command is 100 s "ahead", nothing since
    assert r.stopped_by == "timeout" and all(c.speed == 0.0 for c in r.commands)
    _, r = run(core, 0.1, 0.5, (0.5, 0.0, 0.0))  # a command heard after the reset drives again
    assert r.stopped_by is None


@pytest.mark.parametrize("bad", [(math.nan, 0, 0), (0, math.inf, 0), (0, 0, -math.inf)])
def test_non_finite_command_is_refused_and_the_previous_one_stands(bad):
    core = make_core()
    core.set_command(0.3, 0.0, 0.0, 0.0)
    assert "non-finite" in core.set_command(*bad, 0.01)
    r = core.step(0.02)
    assert r.commands[0].speed == pytest.approx(0.3)


def test_absurd_command_is_refused():
    core = make_core()
    # fastest wheel 1.496 m/s: 10 times that is 14.96 m/s
    assert "absurd" in core.set_command(20.0, 0.0, 0.0, 0.0)
    assert core.set_command(14.0, 0.0, 0.0, 0.0) is None


def test_a_command_beyond_the_motors_is_scaled_down_not_passed_on():
    core = make_core()
    core.set_command(3.0, 0.0, 0.0, 0.0)
    r = core.step(0.0)
    assert r.speed_scale == pytest.approx(1.496 / 3.0, abs=1e-3)
    assert all(c.speed == pytest.approx(1.496, abs=1e-3) for c in r.commands)


def test_safety_stop_holds_the_wheels_until_released():
    core = make_core()
    assert core.safety_stop(True) == "safety stop enabled"
    t, r = run(core, 0.0, 0.5, (0.5, 0.0, 0.2))
    assert r.stopped_by == "safety stop" and all(c.speed == 0.0 for c in r.commands)
    assert r.odometry.pose.x == 0.0
    core.safety_stop(False)
    t, r = run(core, t, 0.5, (0.5, 0.0, 0.2))
    assert r.stopped_by is None and r.odometry.pose.x > 0.05


def test_reset_odometry():
    core = make_core()
    t, r = run(core, 0.0, 1.0, (0.5, 0.0, 0.0))
    assert r.odometry.pose.x > 0.2
    core.reset_odometry()
    _, r = run(core, t, 0.02)
    assert r.odometry.pose.x < 0.02


def test_wheel_radius_changed_at_run_time_changes_the_odometry():
    core = make_core()
    t, _ = run(core, 0.0, 1.0, (0.5, 0.0, 0.0))
    applied, problems = core.set_drive_params([(i, "r_wheel", 0.25) for i in range(4)])
    assert (applied, problems) == (4, [])
    assert all(d.r_wheel == 0.25 for d in core.config.drives)
    # the rim speed command is the same; the wheel turns slower: 0.5 / 0.25 = 2 rad/s, not 2.5
    before = core.handle.read_drive_states(t)[0].wheel_angle
    t2, _ = run(core, t, 1.0, (0.5, 0.0, 0.0))
    after = core.handle.read_drive_states(t2)[0].wheel_angle
    assert (after - before) == pytest.approx(2.0 * 1.0, abs=0.05)


def test_invalid_or_fixed_drive_parameters_are_refused_and_the_rest_applied():
    core = make_core()
    applied, problems = core.set_drive_params([(1, "r_wheel", -1.0), (1, "node", 9), (2, "prp_max_rpm", 1500)])
    assert applied == 1
    assert any("motor_drives.drive1.r_wheel" in p and "> 0" in p for p in problems)
    assert any("drive1.node: cannot be changed at run time" in p for p in problems)
    assert core.config.drives[1].r_wheel == 0.2 and core.config.drives[2].prp_max_rpm == 1500


def test_home_steering_slews_the_wheels_straight_until_the_next_command():
    core = make_core()
    t, _ = run(core, 0.0, 1.0, (0.0, 0.3, 0.0))
    assert core.home_steering() == "homing commands sent"
    t, r = run(core, t, 1.0)
    assert r.stopped_by == "homing"
    assert all(s.steering == pytest.approx(0.0) and s.speed == pytest.approx(0.0) for s in r.states)
    t, r = run(core, t, 0.1, (0.2, 0.0, 0.0))
    assert r.stopped_by is None


def test_simulated_base_reports_controllers_and_batteries():
    config = load_robot_config(next(p for p in EXAMPLE_ROBOTS if p.endswith("thorvald_ii_2wd_diff.yaml")))
    base = SimulatedBase(config)
    controllers = base.controllers(0.0)
    # two type-1 drives share one dual-channel controller: one entry, two propulsion channels
    assert len(controllers) == 1
    assert [v[0] for v in controllers[0].motor_vars] == ["propulsion", "propulsion"]
    std = SimulatedBase(load_robot_config(next(p for p in EXAMPLE_ROBOTS if p.endswith("4wd4ws_std.yaml"))))
    assert len(std.controllers(0.0)) == 4
    assert [b.id for b in std.batteries(0.0)] == [b.id for b in std.config.batteries if b.type == 1]
