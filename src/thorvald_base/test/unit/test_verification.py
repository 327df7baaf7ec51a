"""The verification manoeuvre: about 80 m, ending at the start, realisable by every example robot; and the
calibration manoeuvre: within its area, realisable, determining all a drive can through the odometry."""

import math
import os

import numpy as np
import pytest
from base_test_helpers import EXAMPLE_ROBOTS, diff, four_wd_two_ws, four_ws
from calibration_test_helpers import synthetic_drive

from thorvald_base.calibration import observable_fit
from thorvald_base.calibration.toe_balance import toe_legs
from thorvald_base.kinematics import Pose, Twist, integrate_se2
from thorvald_base.plugins import load_calculator
from thorvald_base.verification import (
    BALANCE_AGAIN,
    BALANCE_LEGS,
    BALANCE_SETTLE,
    BALANCE_SPEED,
    SPEED,
    STRAIGHT_PAUSE,
    TOE_LEG_TIME,
    balance_legs,
    commanded_path,
    duration,
    plan_for,
    plan_named,
    report,
    twist_at,
)
from thorvald_model import load_robot_config
from thorvald_model.layout import common_axle


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


# ---- the calibration manoeuvre ---------------------------------------------------------------------
def poses(plan, step=0.01):
    """base_link's poses along the plan, followed exactly."""
    pose, out = Pose(), []
    for seg in plan:
        n = max(1, round(seg.duration / step))
        for _ in range(n):
            pose = integrate_se2(pose, seg.twist, seg.duration / n)
            out.append(pose)
    return out


@pytest.mark.slow  # a manoeuvre's plan, replayed or fitted, for every example robot
@pytest.mark.parametrize("path", EXAMPLE_ROBOTS, ids=lambda p: os.path.basename(p)[:-5])
def test_the_calibration_drive_ends_where_it_started_within_its_area_every_twist_realisable(path):
    config = load_robot_config(path)
    calc = load_calculator(config)
    _, plan = plan_named("calibration", config, side=4.0)
    track = poses(plan)
    assert math.hypot(track[-1].x, track[-1].y) < 1e-6 and abs(math.remainder(track[-1].yaw, 2 * math.pi)) < 1e-6
    assert max(max(abs(p.x), abs(p.y)) for p in track) <= 2 * 4.0 + 1e-6  # a square of twice the side
    for seg in plan:
        result = calc.calculate_command(seg.twist)
        assert not result.changed, (seg.label, result.twist)
        for cmd, d in zip(result.commands, config.drives):
            assert abs(cmd.speed) <= d.max_wheel_speed, (seg.label, d.name)
    # every way of moving it can, both ways: forward and back, turning left and right
    assert any(s.twist.vx > 0.5 for s in plan) or any(math.hypot(s.twist.vx, s.twist.vy) > 0.5 for s in plan)
    assert any(s.twist.wz > 0.1 for s in plan) and any(s.twist.wz < -0.1 for s in plan)
    if common_axle(config.drives, config.passive_wheels)[0] is None:  # every wheel steers
        assert any(s.twist.vy > 0.5 and s.twist.wz == 0 for s in plan)  # crab legs
        assert any(s.twist.vy < -0.5 and s.twist.wz == 0 for s in plan)
        assert any(s.twist.vx == s.twist.vy == 0 and s.twist.wz > 0 for s in plan)  # spins
        assert any(s.twist.vx == s.twist.vy == 0 and s.twist.wz < 0 for s in plan)


@pytest.mark.slow  # a manoeuvre's plan, replayed or fitted, for every example robot
@pytest.mark.parametrize("make", [four_ws, diff, four_wd_two_ws], ids=["4ws", "diff", "4wd2ws"])
def test_the_calibration_drive_determines_every_combination_any_drive_can(make):
    """What a long drive of random twists (every direction the robot can move in, for minutes)
    determines through the odometry is the most any drive can; the calibration drive, in under two
    minutes, determines as much."""
    config = make()
    calc = load_calculator(config)
    _, plan = plan_named("calibration", config)
    radii = [d.r_wheel * (1 + 0.01 * (-1) ** i) for i, d in enumerate(config.drives)]
    offsets = [0.005 * (i % 3 - 1) if d.steerable else 0.0 for i, d in enumerate(config.drives)]
    drive = synthetic_drive(config, [(s.duration, s.twist) for s in plan], radii, offsets)
    fit = observable_fit(config, drive.recording, drive.pose_truth)
    rng = np.random.default_rng(0)
    segments = [(2.0, calc.calculate_command(Twist(*rng.uniform(-0.8, 0.8, 3))).twist) for _ in range(150)]
    rich = observable_fit(config, *_truthful(synthetic_drive(config, segments, radii, offsets)))
    assert len(rich.determined) < len(rich.names) or make is diff  # some combinations no drive shows
    assert len(fit.determined) == len(rich.determined)


def _truthful(drive):
    return drive.recording, drive.pose_truth


def test_a_manoeuvre_of_another_name_or_a_bad_side_is_refused():
    config = four_ws()
    with pytest.raises(
        ValueError,
        match="one of verification, calibration, field, balance, straight, turns, heading, paper, not 'umbmark'",
    ):
        plan_named("umbmark", config)
    with pytest.raises(ValueError, match="side must be a positive length"):
        plan_named("calibration", config, side=0.0)
    with pytest.raises(ValueError, match="side must be a positive length"):
        plan_named("turns", config, side=float("nan"))
    assert plan_named("verification", config) == plan_for(config)


@pytest.mark.parametrize("path", EXAMPLE_ROBOTS, ids=lambda p: os.path.basename(p)[:-5])
def test_the_field_route_is_rows_and_headland_turns_of_about_the_papers_length(path):
    config = load_robot_config(path)
    calc = load_calculator(config)
    _, plan = plan_named("field", config)
    end, dist = commanded_path(plan)
    assert 80.0 < dist < 90.0  # the paper's 80 m
    # five rows along the robot's rolling direction, every second row of 0.75 m rows: it ends at the far
    # end of the fifth row, 4 x 1.5 m across, heading the way it started
    rows = [s for s in plan if s.label.startswith("row")]
    assert len(rows) == 5 and len([s for s in plan if "U turn" in s.label]) == 4
    assert math.hypot(end.x, end.y) == pytest.approx(math.hypot(15.0, 6.0), abs=1e-6)
    assert abs(math.remainder(end.yaw, 2 * math.pi)) < 1e-6
    for seg in plan:
        result = calc.calculate_command(seg.twist)
        assert not result.changed, (seg.label, result.twist)
        for cmd, d in zip(result.commands, config.drives):
            assert abs(cmd.speed) <= d.max_wheel_speed, (seg.label, d.name)


@pytest.mark.slow  # a manoeuvre's plan, replayed or fitted, for every example robot
@pytest.mark.parametrize("path", EXAMPLE_ROBOTS, ids=lambda p: os.path.basename(p)[:-5])
def test_the_balancing_drive_is_straight_legs_both_ways_every_wheel_straight_at_one_speed(path):
    config = load_robot_config(path)
    calc = load_calculator(config)
    _, plan = plan_named("balance", config, side=3.0)
    track = poses(plan)
    assert math.hypot(track[-1].x, track[-1].y) < 1e-6  # back where it started, on one line of the side
    assert max(math.hypot(p.x, p.y) for p in track) <= 3.0 + 1e-6
    windows = balance_legs(plan)
    toe = toe_legs(config)  # a robot with a toe to search: its legs, then the radii's again
    kinds = ["radii"] * BALANCE_LEGS + (["toe"] * toe + ["radii"] * BALANCE_AGAIN if toe else [])
    assert [w.kind for w in windows] == kinds
    # a differential robot steers nothing, a one-wheeled one has no toe the frame does not follow
    assert (toe == 0) == (sum(d.steerable for d in config.drives) < 2)
    assert [math.copysign(1, w.speed) for w in windows] == [1, -1] * (len(windows) // 2)
    for w in windows:
        begin, end, speed = w.begin, w.end, w.speed
        length = 3.0 if w.kind == "radii" else BALANCE_SPEED * TOE_LEG_TIME
        assert abs(abs(speed) - BALANCE_SPEED) < 1e-12
        assert end - begin == pytest.approx(length / BALANCE_SPEED - BALANCE_SETTLE)
        twist = twist_at(plan, (begin + end) / 2)
        result = calc.calculate_command(twist)
        assert not result.changed
        for cmd in result.commands:  # every wheel rolls straight at the leg's rim speed, the same for all
            assert abs(math.remainder(cmd.steering, math.pi)) < 1e-9
            assert abs(cmd.speed) == pytest.approx(BALANCE_SPEED)
            # a wheel rolling backwards on a forward leg would read its torque with the wrong sign
            assert math.copysign(1, cmd.speed * math.cos(cmd.steering)) == math.copysign(1, speed)
        assert twist_at(plan, end + 0.5) == twist_at(plan, end + 2.5)  # standing: the pause


@pytest.mark.slow  # a manoeuvre's plan, replayed or fitted, for every example robot
@pytest.mark.parametrize("path", EXAMPLE_ROBOTS, ids=lambda p: os.path.basename(p)[:-5])
def test_the_straight_drive_is_legs_on_one_line_with_stops_every_wheel_straight(path):
    config = load_robot_config(path)
    calc = load_calculator(config)
    _, plan = plan_named("straight", config, side=3.0)
    track = poses(plan)
    assert math.hypot(track[-1].x, track[-1].y) < 1e-6  # back at the start, within the side of it
    assert max(math.hypot(p.x, p.y) for p in track) <= 3.0 + 1e-6
    assert max(abs(p.yaw) for p in track) < 1e-12  # never turns
    assert commanded_path(plan)[1] == pytest.approx(8 * 3.0)
    moving = [s for s in plan if s.twist != Twist()]
    assert len(moving) == 5 and [s.label for s in plan[::2]] == ["stop"] * 6  # a stop before and after each leg
    assert all(s.duration == STRAIGHT_PAUSE for s in plan[::2])
    for seg in moving:
        result = calc.calculate_command(seg.twist)
        assert not result.changed
        for cmd in result.commands:  # every wheel straight, at the working speed
            assert abs(math.remainder(cmd.steering, math.pi)) < 1e-9
            assert abs(cmd.speed) == pytest.approx(SPEED)


@pytest.mark.parametrize("path", EXAMPLE_ROBOTS, ids=lambda p: os.path.basename(p)[:-5])
def test_the_paper_like_manoeuvre_spins_on_the_spot_crabs_where_it_can_and_ends_at_the_start(path):
    """The bench's second validation drive (bench/calibration_heading.py): the paper's 80 m of translation,
    with spins on the spot between the legs; a robot that cannot crab spins about its axle line."""
    config = load_robot_config(path)
    calc = load_calculator(config)
    description, plan = plan_named("paper", config)
    end, dist = commanded_path(plan)
    assert math.hypot(end.x, end.y) < 1e-6 and abs(math.remainder(end.yaw, 2 * math.pi)) < 1e-6
    for seg in plan:
        result = calc.calculate_command(seg.twist)
        assert not result.changed, (seg.label, result.twist)
        for cmd, d in zip(result.commands, config.drives):
            assert abs(cmd.speed) <= d.max_wheel_speed, (seg.label, d.name)
    spins = [s for s in plan if s.label.startswith("spin")]
    turned = sum(abs(s.twist.wz) * s.duration for s in spins)
    axle, _ = common_axle(config.drives, config.passive_wheels)
    if axle is None:
        # forward, crab left, backward, crab left again (half turned): 40 m, and two 20 m circles
        assert dist == pytest.approx(80.0, abs=0.01) and description.startswith("paper-like: translation in x and y")
        assert any(s.twist.vy and not s.twist.vx and not s.twist.wz for s in plan)  # crab legs
        assert turned == pytest.approx(3 * 2 * math.pi)  # two full turns and two half turns on the spot
        assert all(s.twist.vx == 0.0 and s.twist.vy == 0.0 for s in spins)
    else:
        # the spins turn about the axle line's point nearest base_link: no wheel of the axle rolls sideways
        assert description.startswith("paper-like for a robot that cannot crab")
        assert turned == pytest.approx(4 * math.pi) and 75.0 < dist < 90.0
        assert not any(s.twist.vy and not s.twist.vx and not s.twist.wz for s in plan)
