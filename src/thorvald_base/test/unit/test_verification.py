"""The verification manoeuvre: about 80 m, ending at the start, realisable by every example robot."""

import math
import os

import pytest
from base_test_helpers import EXAMPLE_ROBOTS

from thorvald_base.plugins import load_calculator
from thorvald_base.verification import commanded_path, duration, plan_for, report
from thorvald_model import load_robot_config


@pytest.mark.parametrize("path", EXAMPLE_ROBOTS, ids=lambda p: os.path.basename(p)[:-5])
def test_plan_ends_at_the_start_after_about_80_m(path):
    config = load_robot_config(path)
    _, plan = plan_for(config)
    end, dist = commanded_path(plan)
    assert math.hypot(end.x, end.y) < 1e-6
    assert 75.0 < dist < 85.0
    assert 75.0 < duration(plan) < 90.0


@pytest.mark.parametrize("path", EXAMPLE_ROBOTS, ids=lambda p: os.path.basename(p)[:-5])
def test_every_planned_twist_is_realisable_within_the_motors(path):
    config = load_robot_config(path)
    calc = load_calculator(config)
    _, plan = plan_for(config)
    for seg in plan:
        result = calc.calculate_command(seg.twist)
        assert not result.changed, (seg.label, result.twist)
        for cmd, d in zip(result.commands, config.drives):
            assert abs(cmd.speed) <= d.max_wheel_speed, (seg.label, d.name)


def test_omnidirectional_robots_translate_sideways_and_fixed_axles_do_not():
    std = load_robot_config(next(p for p in EXAMPLE_ROBOTS if p.endswith("4wd4ws_std.yaml")))
    diff = load_robot_config(next(p for p in EXAMPLE_ROBOTS if p.endswith("2wd_diff.yaml")))
    assert any(abs(s.twist.vy) > 0.5 and s.twist.wz == 0 for s in plan_for(std)[1])
    assert all(abs(s.twist.vy) < 1e-9 for s in plan_for(diff)[1])  # axle at x = 0: no sideways part


def test_report_compares_command_and_odometry():
    std = load_robot_config(next(p for p in EXAMPLE_ROBOTS if p.endswith("4wd4ws_std.yaml")))
    description, plan = plan_for(std)
    text = report("std", std, description, plan, [(0.0, 0.0), (3.0, 4.0), (0.3, 0.4)], sim_time=80.0, wall=10.0)
    assert "distance by odometry       9.50 m" in text  # 5 m out, hypot(2.7, 3.6) = 4.5 m back
    assert "end-point difference      0.500 m" in text
