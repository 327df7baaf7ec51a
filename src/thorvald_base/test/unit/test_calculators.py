"""Focused checks of the three calculators with hand-derived numbers."""

import math

import pytest
from base_test_helpers import diff, drive, four_wd_two_ws, four_ws, one_wheel

from thorvald_base.errors import KinematicsError
from thorvald_base.kinematics import DriveState, PltfClc1WD, PltfClc2WDiff, PltfClcStd, Twist
from thorvald_model import parse_robot_config


def std(config=None):
    return PltfClcStd.from_config(config or four_ws(x=0.5, y=0.4))


def test_pure_translation_points_every_wheel_the_same_way():
    # vx = vy = 0.3: every wheel at atan2(0.3, 0.3) = 45 degrees, speed 0.3 * sqrt(2).
    r = std().calculate_command(Twist(0.3, 0.3, 0.0))
    for c in r.commands:
        assert c.steering == pytest.approx(math.pi / 4)
        assert c.speed == pytest.approx(0.3 * math.sqrt(2))


def test_spin_in_place_puts_wheels_on_the_circle():
    # wz = 1 about base_link; drive1 at (0.5, -0.4) moves (0.4, 0.5): angle atan2(0.5, 0.4),
    # speed = distance to the centre = sqrt(0.41).
    r = std().calculate_command(Twist(0.0, 0.0, 1.0))
    c = r.commands[1]
    assert c.steering == pytest.approx(math.atan2(0.5, 0.4))
    assert c.speed == pytest.approx(math.sqrt(0.41))


def test_rotation_about_the_icr():
    # vx = 1, wz = 0.5: ICR (-vy/wz, vx/wz) = (0, 2). drive2 at (0.5, 0.4) is (0.5, -1.6) from it:
    # speed |wz| * sqrt(0.25 + 2.56) = 0.5 * sqrt(2.81); its velocity (1 - 0.5*0.4, 0.5*0.5) = (0.8, 0.25).
    r = std().calculate_command(Twist(1.0, 0.0, 0.5))
    c = r.commands[2]
    assert c.speed == pytest.approx(0.5 * math.sqrt(2.81))
    assert c.steering == pytest.approx(math.atan2(0.25, 0.8))
    # The wheel rolls perpendicular to the line to the ICR.
    assert math.cos(c.steering) * 0.5 + math.sin(c.steering) * -1.6 == pytest.approx(0.0)


def test_zero_command_keeps_the_heading():
    calc = std()
    first = calc.calculate_command(Twist(0.0, 0.0, 1.0))
    zero = calc.calculate_command(Twist(0.0, 0.0, 0.0))
    assert [c.steering for c in zero.commands] == [c.steering for c in first.commands]
    assert all(c.speed == 0.0 for c in zero.commands)
    # Before any command, straight ahead.
    assert all(c.steering == 0.0 for c in std().calculate_command(Twist()).commands)


def test_set_zero_speed_keeps_steering():
    calc = std()
    r = calc.calculate_command(Twist(0.2, 0.5, 0.1))
    zeroed = calc.set_zero_speed(r.commands)
    assert [c.steering for c in zeroed] == [c.steering for c in r.commands]
    assert all(c.speed == 0.0 for c in zeroed)


def test_diff_drive_wheel_speeds_and_sideways_command():
    calc = PltfClc2WDiff.from_config(diff(b=0.3))
    # v = vx - wz y: right wheel (y = -0.3): 1 + 0.5*0.3 = 1.15, left: 1 - 0.15 = 0.85.
    r = calc.calculate_command(Twist(1.0, 0.0, 0.5))
    assert [c.speed for c in r.commands] == pytest.approx([1.15, 0.85])
    assert [c.steering for c in r.commands] == [0.0, 0.0]
    assert not r.changed
    # Sideways: the axle is on base_link's y axis, so vy must be 0; the wheel velocities closest to
    # the requested (0.5, 1) everywhere are those of (0.5, 0, 0) (the wheels' lateral parts cancel).
    r = calc.calculate_command(Twist(0.5, 1.0, 0.0))
    assert r.changed
    assert r.requested == Twist(0.5, 1.0, 0.0)
    assert (r.twist.vx, r.twist.vy, r.twist.wz) == pytest.approx((0.5, 0.0, 0.0))
    assert [c.speed for c in r.commands] == pytest.approx([0.5, 0.5])


def test_one_wheel_drive_sideways_with_the_lsq_projection_becomes_rotation_about_the_axle():
    # Drive at (L, 0) = (0.8, 0), fixed wheels at (0, +-0.4): realisable twists have vy = 0.
    # Requested (0, 1, 0): minimise over (vx, wz) the squared differences of wheel velocities
    # (drive: (vx, 0.8 wz) vs (0, 1); fixed: (vx -+ 0.4 wz, 0) vs (0, 1)): vx = 0 and
    # wz = L / (L^2 + 2 b^2) = 0.8 / (0.64 + 0.32) = 5/6; the drive points sideways at 0.8 * 5/6.
    calc = PltfClc1WD(projection="lsq")
    config = one_wheel(0.8, 0.4)
    calc.initialize(config.drives, config.passive_wheels)
    r = calc.calculate_command(Twist(0.0, 1.0, 0.0))
    assert r.changed
    assert (r.twist.vx, r.twist.vy, r.twist.wz) == pytest.approx((0.0, 0.0, 5.0 / 6.0))
    assert r.commands[0].steering == pytest.approx(math.pi / 2)
    assert r.commands[0].speed == pytest.approx(0.8 * 5.0 / 6.0)
    # A realisable arc: vx = 0.5, wz = 0.5 -> ICR (0, 1) on the axle; the drive at (0.8, 0) moves
    # (0.5, 0.4): steering atan2(0.4, 0.5), as a tricycle's front wheel.
    r = calc.calculate_command(Twist(0.5, 0.0, 0.5))
    assert not r.changed
    assert r.commands[0].steering == pytest.approx(math.atan2(0.4, 0.5))


def test_4wd2ws_confines_the_icr_to_the_rear_axle():
    # Rear type-1 drives on x = -0.5: the rear wheels may not slide, so vy + wz * (-0.5) = 0.
    calc = PltfClcStd.from_config(four_wd_two_ws())
    ok = calc.calculate_command(Twist(1.0, 0.25, 0.5))  # 0.25 - 0.5*0.5 = 0: realisable
    assert not ok.changed
    assert [c.steering for c in ok.commands[2:]] == [0.0, 0.0]
    # Rear right (y = -0.4): speed vx - wz y = 1 + 0.2 = 1.2; rear left 0.8.
    assert [c.speed for c in ok.commands[2:]] == pytest.approx([1.2, 0.8])
    bad = calc.calculate_command(Twist(1.0, 0.0, 0.5))
    assert bad.changed
    assert bad.twist.vy - 0.5 * bad.twist.wz == pytest.approx(0.0, abs=1e-12)


def test_calculators_refuse_layouts_they_cannot_serve():
    four = four_ws()
    with pytest.raises(KinematicsError, match="two type-1 drives"):
        PltfClc2WDiff().initialize(four.drives)
    with pytest.raises(KinematicsError, match="exactly one type-0"):
        PltfClc1WD().initialize(four.drives)
    with pytest.raises(KinematicsError, match="needs fixed passive wheels"):
        PltfClc1WD().initialize(four.drives[:1])
    with pytest.raises(KinematicsError, match="single steered drive"):
        PltfClcStd().initialize(four.drives[:1])
    with pytest.raises(KinematicsError, match="before initialize"):
        PltfClcStd().calculate_command(Twist(1, 0, 0))
    with pytest.raises(KinematicsError, match="estimator"):
        PltfClcStd(estimator="kalman")
    with pytest.raises(KinematicsError, match="projection must be one of axle, lsq"):
        PltfClcStd(projection="nearest")
    with pytest.raises(KinematicsError, match="finite"):
        std().calculate_command(Twist(float("nan"), 0, 0))


def test_set_params_at_run_time_keeps_the_pose_and_uses_the_new_geometry():
    calc = std()
    r = calc.calculate_command(Twist(0.5, 0.0, 0.0))
    states = [DriveState(c.steering, c.speed) for c in r.commands]
    calc.calculate_odometry(states, 0.0)
    calc.calculate_odometry(states, 0.2)  # 0.5 m/s * 0.2 s = 0.1 m
    wide = four_ws(x=0.5, y=0.6)
    calc.set_params(wide.drives)
    assert calc.pose.x == pytest.approx(0.1)
    # New geometry: spin in place now puts drive1 at (0.5, -0.6) moving (0.6, 0.5).
    c = calc.calculate_command(Twist(0.0, 0.0, 1.0)).commands[1]
    assert c.steering == pytest.approx(math.atan2(0.5, 0.6))


def test_standard_calculator_serves_a_differential_layout():
    config = parse_robot_config({"motor_drives": {"drive0": drive(1, 0, -0.3, 1), "drive1": drive(1, 0, 0.3, 1)}})
    # The standard calculator serves a diff layout too (paper 3.1): v = vx - wz y, steering 0.
    r = PltfClcStd.from_config(config).calculate_command(Twist(1.0, 0.0, 1.0))
    assert [c.speed for c in r.commands] == pytest.approx([1.3, 0.7])
