"""The drive layer: inversion hysteresis, steering limit, speed limit, simulated drives."""

import math

import pytest
from base_test_helpers import four_ws
from hypothesis import given, settings
from hypothesis import strategies as st

from thorvald_base.kinematics import (
    DriveCommand,
    DriveLayer,
    PltfClcStd,
    SimulatedDrive,
    SteeringInverter,
    Twist,
    limit_wheel_speeds,
)


def test_backing_up_keeps_steering_straight_and_reverses_the_wheel():
    """The paper's example (3.2): alternating forward and backward."""
    config = four_ws()
    calc = PltfClcStd.from_config(config)
    layer = DriveLayer(config.drives)
    measured = [0.0] * 4
    for k in range(6):
        vx = 1.0 if k % 2 == 0 else -1.0
        raw = calc.calculate_command(Twist(vx, 0.0, 0.0)).commands
        # The calculator asks for 0 or pi with a positive speed ...
        assert all(abs(c.steering) in (0.0, math.pi) and c.speed == pytest.approx(1.0) for c in raw)
        out = layer.apply(raw, measured).commands
        # ... the drive layer leaves the wheel straight and reverses it when backing.
        assert all(c.steering == 0.0 for c in out)
        assert all(c.speed == pytest.approx(vx) for c in out)
        measured = [c.steering for c in out]


def test_hysteresis_of_the_original():
    inv = SteeringInverter(str_lim=3.078)
    # |p| < pi/8: never inverted.
    assert inv.apply(DriveCommand(0.3, 1.0), 2.0) == DriveCommand(0.3, 1.0)
    # p = 2.0 from a = 0: travel 2.0 > pi/2 -> inverted: 2.0 - pi, speed reversed.
    c = inv.apply(DriveCommand(2.0, 1.0), 0.0)
    assert (c.steering, c.speed) == pytest.approx((2.0 - math.pi, -1.0))
    # Stays inverted while |p - a| >= pi/4, even when the plain angle would now be nearer: a = 1.2,
    # |p - a| = 0.8 > pi/4 = 0.785.
    c = inv.apply(DriveCommand(2.0, 1.0), 1.2)
    assert c.speed == -1.0
    # Once the wheel is within pi/4 of the plain command, back to not inverted.
    c = inv.apply(DriveCommand(2.0, 1.0), 1.5)
    assert (c.steering, c.speed) == (2.0, 1.0)


@settings(max_examples=200, deadline=None)
@given(
    str_lim=st.floats(0.3, math.pi),
    steps=st.lists(
        st.tuples(st.floats(-math.pi, math.pi), st.floats(-2, 2, allow_nan=False), st.floats(-math.pi, math.pi)),
        min_size=1,
        max_size=10,
    ),
)
def test_never_commands_beyond_str_lim(str_lim, steps):
    inv = SteeringInverter(str_lim)
    for p, speed, a in steps:
        c = inv.apply(DriveCommand(p, speed), a)
        assert abs(c.steering) <= str_lim
        if str_lim >= math.pi / 2:
            # Some way round is always within the limit: the wheel velocity vector is kept.
            assert c.speed * math.cos(c.steering) == pytest.approx(speed * math.cos(p), abs=1e-9)
            assert c.speed * math.sin(c.steering) == pytest.approx(speed * math.sin(p), abs=1e-9)


@pytest.mark.parametrize("noise", [-1e-3, -1e-6, 0.0, 1e-6, 1e-3])
def test_a_crab_from_straight_ahead_turns_every_wheel_the_same_way_whatever_the_encoder_noise(noise):
    # 90 degrees from a wheel measured at +-noise: the original's strict |p - a| > pi/2 let the sign of
    # the noise choose between +90 forward and -90 reversed, wheel by wheel.
    for p in (math.pi / 2, -math.pi / 2):
        inv = SteeringInverter(3.078027759)
        assert inv.apply(DriveCommand(p, 1.0), noise) == DriveCommand(p, 1.0)
    # a real reversal still inverts: 92 degrees of travel
    inv = SteeringInverter(3.078027759)
    c = inv.apply(DriveCommand(math.radians(92), 1.0), 0.0)
    assert (c.steering, c.speed) == pytest.approx((math.radians(-88), -1.0))


def test_steering_near_the_stop_goes_the_other_way():
    # str_lim 176.4 degrees; the calculator asks for 179 degrees, measured 170 (travel 9 degrees,
    # not inverted by the hysteresis) -> beyond the stop, so the wheel points at -1 degree reversed.
    inv = SteeringInverter(3.078027759)
    c = inv.apply(DriveCommand(math.radians(179), 1.0), math.radians(170))
    assert c.steering == pytest.approx(math.radians(-1))
    assert c.speed == -1.0


def test_speed_limit_scales_all_wheels_together():
    # Default module: 3000 rpm / gear 42 * 2 pi / 60 * r 0.2 m = 1.49600 m/s at the rim.
    vmax = 3000 / 42 * 2 * math.pi / 60 * 0.2
    config = four_ws(x=0.5, y=0.4)
    assert config.drives[0].max_wheel_speed == pytest.approx(vmax)
    calc = PltfClcStd.from_config(config)
    raw = calc.calculate_command(Twist(2.0, 0.0, 1.0)).commands
    out = DriveLayer(config.drives).apply(raw, [c.steering for c in raw])
    # Right wheels (y = -0.4) move (2 + 0.4, +-0.5): fastest sqrt(2.4^2 + 0.5^2) = sqrt(6.01).
    scale = vmax / math.sqrt(6.01)
    assert out.speed_scale == pytest.approx(scale)
    for r, c in zip(raw, out.commands):
        assert c.steering == pytest.approx(r.steering)
        assert c.speed == pytest.approx(r.speed * scale)
    # Under the limit nothing changes.
    same, s = limit_wheel_speeds([DriveCommand(0.1, 1.0)], [1.5])
    assert s == 1.0 and same == [DriveCommand(0.1, 1.0)]


def test_simulated_drive_ramps_slews_and_integrates():
    drive = four_ws().drives[0]  # prp_sim_a 1.5 m/s^2, str_sim_v 4 rad/s, r_wheel 0.2 m
    sim = SimulatedDrive(drive)
    cmd = DriveCommand(1.0, 1.0)
    assert sim.step(cmd, 10.0).speed == 0.0  # first call: dt 0
    s = sim.step(cmd, 10.1)
    # 0.1 s: speed 1.5 * 0.1 = 0.15 m/s; steering 4 * 0.1 = 0.4 rad;
    # wheel 0.5 * 0.15 m/s * 0.1 s / 0.2 m = 0.0375 rad.
    assert (s.speed, s.steering, s.wheel_angle) == pytest.approx((0.15, 0.4, 0.0375))
    sim.step(cmd, 10.2)
    s = sim.step(cmd, 10.3)
    # 0.3 s: speed 0.45, steering reaches 1.0 and stops there (0.4, 0.8, then 1.0);
    # distance = 1.5 * 0.3^2 / 2 = 0.0675 m -> wheel 0.3375 rad.
    assert (s.speed, s.steering, s.wheel_angle) == pytest.approx((0.45, 1.0, 0.3375))
    # A gap over 0.5 s is a pause: nothing moves.
    assert sim.step(cmd, 11.0) == s
    # Steering never passes the stop (3.078 rad), even if commanded.
    for k in range(30):
        s = sim.step(DriveCommand(3.14, 0.45), 11.1 + 0.1 * k)
    assert s.steering == pytest.approx(drive.str_lim)
