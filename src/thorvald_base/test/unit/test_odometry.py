"""Odometry: exact SE(2) integration, dt rules, the paper estimator's seed and translation test, slip."""

import math
import random

import pytest
from base_test_helpers import four_ws, ring

from thorvald_base.kinematics import DriveState, PltfClcStd, Pose, Twist, integrate_se2


def test_quarter_circle():
    # vx 1 m/s, wz 1 rad/s: a circle of radius 1 about (0, 1); after pi/2 s the robot is at (1, 1)
    # heading +y.
    p = integrate_se2(Pose(), Twist(1.0, 0.0, 1.0), math.pi / 2)
    assert (p.x, p.y, p.yaw) == pytest.approx((1.0, 1.0, math.pi / 2))


def test_full_circle_returns_to_start_through_the_calculator():
    # A twist with vy: period 2 pi / 0.5 = 4 pi s, in 200 steps of 2 pi / 50 = 0.1257 s (< 0.5 s).
    config = four_ws()
    calc = PltfClcStd.from_config(config)
    states = [DriveState(c.steering, c.speed) for c in calc.calculate_command(Twist(0.3, 0.4, 0.5)).commands]
    dt = 4 * math.pi / 200
    # Centre of the circle in odom: the ICR (-vy/wz, vx/wz) = (-0.8, 0.6); radius |v|/wz = 0.5/0.5 = 1.
    for k in range(201):
        odom = calc.calculate_odometry(states, k * dt)
        assert math.hypot(odom.pose.x + 0.8, odom.pose.y - 0.6) == pytest.approx(1.0, abs=1e-9)
    assert (odom.pose.x, odom.pose.y, odom.pose.yaw) == pytest.approx((0.0, 0.0, 0.0), abs=1e-9)


def test_pure_translation_integrates_exactly():
    p = integrate_se2(Pose(1.0, 2.0, math.pi / 2), Twist(0.5, -0.2, 0.0), 0.4)
    # Body (0.2, -0.08) rotated by 90 degrees: (0.08, 0.2).
    assert (p.x, p.y, p.yaw) == pytest.approx((1.08, 2.2, math.pi / 2))


def test_dt_rules_and_zero_pose():
    calc = PltfClcStd.from_config(four_ws())
    states = [DriveState(0.0, 1.0)] * 4
    assert calc.calculate_odometry(states, 5.0).dt == 0.0  # first call
    assert calc.calculate_odometry(states, 5.1).dt == pytest.approx(0.1)
    assert calc.calculate_odometry(states, 5.7).dt == 0.0  # gap > 0.5 s
    assert calc.calculate_odometry(states, 5.6).dt == 0.0  # time went back
    r = calc.calculate_odometry(states, 5.8)
    assert r.pose.x == pytest.approx(0.1 + 0.2)
    calc.zero_odometry_pose()
    assert calc.pose == Pose()
    # drives whose states hold no number are unheard: with none heard, no motion and no pose change
    bad = calc.calculate_odometry([DriveState(float("nan"), 1.0)] * 4, 5.9)
    assert bad.valid and bad.blind and bad.unheard == (0, 1, 2, 3)
    assert bad.pose == Pose() and bad.twist == Twist()


def test_paper_estimator_is_reproducible_with_a_seed_and_detects_translation():
    config = four_ws()
    rng = random.Random(3)
    noisy = [DriveState(0.3 + rng.gauss(0, 0.02), 1.0 + rng.gauss(0, 0.02)) for _ in range(4)]
    a = PltfClcStd.from_config(config, estimator="paper", seed=42).calculate_odometry(noisy, 0.0)
    b = PltfClcStd.from_config(config, estimator="paper", seed=42).calculate_odometry(noisy, 0.0)
    assert a.twist == b.twist
    straight = [DriveState(0.3, 1.0)] * 4
    r = PltfClcStd.from_config(config, estimator="paper", seed=1).calculate_odometry(straight, 0.0)
    assert r.translating
    assert (r.twist.vx, r.twist.vy, r.twist.wz) == pytest.approx((math.cos(0.3), math.sin(0.3), 0.0))
    stopped = PltfClcStd.from_config(config, estimator="paper").calculate_odometry([DriveState(0.5, 0.0)] * 4, 0.0)
    assert stopped.twist == Twist(0.0, 0.0, 0.0)


def test_residual_measures_slip():
    # 6 drives on a ring driving straight at 1 m/s; one wheel slips 10 % (reports 1.1 m/s).
    # Least squares: the twist that best fits gives every wheel 1 + 0.1/6 (mean) plus a small
    # rotation; the residual is positive and far below the slip itself.
    config = ring(6)
    calc = PltfClcStd.from_config(config)
    states = [DriveState(0.0, 1.0)] * 5 + [DriveState(0.0, 1.1)]
    r = calc.calculate_odometry(states, 0.0)
    assert 0.0 < r.residual < 0.1
    assert r.twist.vx == pytest.approx(1.0 + 0.1 / 6)
