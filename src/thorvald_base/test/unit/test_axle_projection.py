"""Robots with a fixed axle follow the yaw rate a navigation stack commands (the default projection).

A wheel that cannot steer cannot slide, so the centre of rotation (ICR) lies on its axle line. Every
fixed axle of the example robots rolls along base_link x, so its axle line is x = x_axle, and a
twist (vx, wz) turns about the ICR (x_axle, vx / wz): the realisable twist keeps vx and wz and has
vy = -wz x_axle (ICR = (-vy / wz, vx / wz)). Each wheel then moves as the rigid body turning about
that point: v_i = wz x (p_i - ICR) = (-wz (y_i - icr_y), wz (x_i - icr_x)).

The axle is read from the robot file here (its fixed passive wheels and type-1 drives), not from
the calculator.
"""

import math
import os

import numpy as np
import pytest
from base_test_helpers import EXAMPLE_ROBOTS

from thorvald_base.kinematics import Twist
from thorvald_base.plugins import CalculatorLoader
from thorvald_model import load_robot_config

FIXED_AXLE_ROBOTS = [
    "thorvald_ii_1wd1ws_rwd",
    "thorvald_ii_1wd1ws_fwd",
    "thorvald_ii_4wd2ws_tall",
    "thorvald_ii_2wd_diff",
]
LOADER = CalculatorLoader()

# (vx [m/s], vy [m/s], wz [rad/s]) requested: both directions of turn, reversing, a sideways part
# that the axle cannot take, and straight lines.
REQUESTS = [
    (0.5, 0.0, 0.4),
    (0.5, 0.0, -0.4),
    (-0.5, 0.0, 0.4),
    (-0.5, 0.0, -0.4),
    (0.5, 0.3, 0.4),
    (0.8, -0.2, -1.1),
    (0.5, 0.0, 0.0),
    (-0.5, 0.2, 0.0),
]


def robot(name, **options):
    config = load_robot_config(next(p for p in EXAMPLE_ROBOTS if os.path.basename(p) == name + ".yaml"))
    calc = LOADER.create(config.base_calculator, **options)
    calc.initialize(config.drives, config.passive_wheels)
    return config, calc


def axle_x(config):
    """x of the axle line, from the wheels that cannot steer (all roll along x in the examples)."""
    xs = [d.x for d in config.drives if d.type == 1] + [w.x for w in config.passive_wheels if w.type == "fixed"]
    assert xs and all(w.yaw == 0.0 for w in config.passive_wheels if w.type == "fixed")
    assert max(xs) - min(xs) < 1e-9
    return xs[0]


def wheel_velocity(command):
    return command.speed * math.cos(command.steering), command.speed * math.sin(command.steering)


@pytest.mark.parametrize("request_", REQUESTS, ids=lambda r: "vx{}_vy{}_wz{}".format(*r))
@pytest.mark.parametrize("name", FIXED_AXLE_ROBOTS)
def test_the_axle_keeps_vx_and_wz_and_turns_about_a_point_of_the_axle(name, request_):
    config, calc = robot(name)
    vx, vy, wz = request_
    xa = axle_x(config)
    result = calc.calculate_command(Twist(vx, vy, wz))
    t = result.twist
    assert t.vx == vx and t.wz == wz  # exactly: nothing is traded
    assert t.vy == pytest.approx(-wz * xa, abs=1e-12)
    assert result.changed == (abs(vy + wz * xa) > 1e-9)
    for d, c in zip(config.drives, result.commands):
        got = wheel_velocity(c)
        if wz == 0.0:
            expected = (vx, 0.0)  # straight along the rolling direction; the sideways part dropped
        else:
            icr_x, icr_y = xa, vx / wz  # on the axle line, vx / wz to the left of the x axis
            expected = (-wz * (d.y - icr_y), wz * (d.x - icr_x))
        assert got == pytest.approx(expected, abs=1e-12), d.name
    for w in config.passive_wheels:
        if w.type == "fixed":
            # the fixed wheel's contact moves along x only: vy + wz x = 0 there
            assert t.vy + t.wz * w.x == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize(
    "name, request_",
    [
        ("thorvald_ii_1wd1ws_rwd", (0.5, 0.0, 0.4)),
        ("thorvald_ii_1wd1ws_fwd", (0.5, 0.0, 0.3)),
        ("thorvald_ii_4wd2ws_tall", (0.5, 0.0, 0.3)),
        ("thorvald_ii_1wd1ws_rwd", (0.5, 0.3, 0.4)),
    ],
)
def test_the_navigation_commands_of_the_issue_keep_their_yaw_rate(name, request_):
    # The rows that the least-squares projection cut (to 0.246, 0.185, 0.216 and -0.009 rad/s).
    _config, calc = robot(name)
    t = calc.calculate_command(Twist(*request_)).twist
    assert (t.vx, t.wz) == (request_[0], request_[2])


def test_a_differential_drive_on_base_link_drops_vy_only():
    config, calc = robot("thorvald_ii_2wd_diff")
    assert axle_x(config) == 0.0
    r = calc.calculate_command(Twist(0.5, 0.3, 0.4))
    assert r.changed
    assert (r.twist.vx, r.twist.vy, r.twist.wz) == (0.5, 0.0, 0.4)
    # v = vx - wz y for each wheel
    assert [c.speed for c in r.commands] == pytest.approx([0.5 - 0.4 * d.y for d in config.drives])


@pytest.mark.parametrize("name", FIXED_AXLE_ROBOTS)
@pytest.mark.parametrize("request_", [(0.5, 0.0, 0.4), (0.5, 0.3, 0.4), (-0.3, 0.5, -0.2)])
def test_the_lsq_projection_gives_the_closest_wheel_velocities(name, request_):
    """The option keeps the former behaviour: minimise, over the realisable twists (vx, -wz x_axle, wz),
    the squared differences of the velocities of the drives and fixed wheels from the requested ones."""
    config, calc = robot(name, projection="lsq")
    vxr, vyr, wzr = request_
    xa = axle_x(config)
    points = [(d.x, d.y) for d in config.drives] + [(w.x, w.y) for w in config.passive_wheels if w.type == "fixed"]
    # unknowns (vx, wz); per wheel, x: vx - wz y = vxr - wzr y, y: wz (x - xa) = vyr + wzr x
    rows, rhs = [], []
    for x, y in points:
        rows += [[1.0, -y], [0.0, x - xa]]
        rhs += [vxr - wzr * y, vyr + wzr * x]
    (vx, wz), *_ = np.linalg.lstsq(np.array(rows), np.array(rhs), rcond=None)
    t = calc.calculate_command(Twist(*request_)).twist
    assert (t.vx, t.vy, t.wz) == pytest.approx((vx, -wz * xa, wz), abs=1e-12)


def test_the_lsq_projection_reproduces_the_figures_that_cut_the_yaw_rate():
    # The issue's measurement of the former default: (0.5, 0, 0.4) became (0.5, -0.111, 0.246).
    _config, calc = robot("thorvald_ii_1wd1ws_rwd", projection="lsq")
    t = calc.calculate_command(Twist(0.5, 0.0, 0.4)).twist
    assert (round(t.vx, 3), round(t.vy, 3), round(t.wz, 3)) == (0.5, -0.111, 0.246)
