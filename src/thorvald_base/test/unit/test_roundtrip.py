"""forward(inverse(twist)) == twist over every robot, with both estimators and through the drive layer."""

import math

import pytest
from base_test_helpers import ROBOT_IDS, make_realisable, robot_config
from hypothesis import given, settings
from hypothesis import strategies as st

from thorvald_base.kinematics import DriveLayer, DriveState, Twist
from thorvald_base.kinematics.calculator import STOPPED_SPEED
from thorvald_base.plugins import CalculatorLoader

SPEED = st.floats(-1.0, 1.0, allow_nan=False)
RATE = st.floats(-1.5, 1.5, allow_nan=False)
ANGLE = st.floats(-3.0, 3.0, allow_nan=False)

_CONFIGS = {}
_LOADER = CalculatorLoader()


def calculator(robot_id, estimator):
    if robot_id not in _CONFIGS:
        config = robot_config(robot_id)
        _CONFIGS[robot_id] = (config, _LOADER.class_for(config.base_calculator))
    config, cls = _CONFIGS[robot_id]
    calc = cls(estimator=estimator, seed=7)
    calc.initialize(config.drives, config.passive_wheels)
    return config, calc


def assert_twist(got, vx, vy, wz, tol, *, reach=1.0):
    # A wheel slower than STOPPED_SPEED is commanded to stand (it keeps its heading), so a twist that
    # slow reads back up to STOPPED_SPEED off at a wheel: [m/s], and over the nearest wheel's reach
    # [m] from base_link in wz (1.1e-9 rad/s at the standard robot's 0.9 m).
    scale = 1.0 + abs(vx) + abs(vy) + abs(wz)
    assert got.vx == pytest.approx(vx, abs=tol * scale + STOPPED_SPEED)
    assert got.vy == pytest.approx(vy, abs=tol * scale + STOPPED_SPEED)
    assert got.wz == pytest.approx(wz, abs=tol * scale + STOPPED_SPEED / reach)


@pytest.mark.slow  # hypothesis: 100 twists on every example robot
@pytest.mark.parametrize("estimator, tol", [("lsq", 1e-9), ("paper", 1e-6)])
@pytest.mark.parametrize("robot_id", ROBOT_IDS)
@settings(max_examples=100, deadline=None)
@given(vx=SPEED, vy=SPEED, wz=RATE)
def test_odometry_recovers_realisable_twist(robot_id, estimator, tol, vx, vy, wz):  # noqa: PLR0917
    config, calc = calculator(robot_id, estimator)
    vx, vy, wz = make_realisable(config, vx, vy, wz)
    result = calc.calculate_command(Twist(vx, vy, wz))
    assert not result.changed
    states = [DriveState(c.steering, c.speed) for c in result.commands]
    odom = calc.calculate_odometry(states, 0.0)
    assert odom.valid
    reach = min(r for r in (math.hypot(d.x, d.y) for d in config.drives) if r > 0)
    assert_twist(odom.twist, vx, vy, wz, tol, reach=reach)
    if estimator == "lsq":
        # Wheels that agree (noise-free) fit exactly, so the residual is rounding only.
        assert odom.residual < 1e-9 * (1 + abs(vx) + abs(vy) + abs(wz))


@pytest.mark.slow  # hypothesis: 100 twists on every example robot
@pytest.mark.parametrize("robot_id", ROBOT_IDS)
@settings(max_examples=60, deadline=None)
@given(vx=SPEED, vy=SPEED, wz=RATE, measured=st.lists(ANGLE, min_size=20, max_size=20))
def test_drive_layer_keeps_the_twist(robot_id, vx, vy, wz, measured):
    """Inversion turns a wheel 180 degrees and reverses it, which leaves its velocity vector as it
    was; the speed limit scales every wheel by one factor s, which scales the twist by s."""
    config, calc = calculator(robot_id, "lsq")
    vx, vy, wz = make_realisable(config, vx, vy, wz)
    result = calc.calculate_command(Twist(vx, vy, wz))
    layer = DriveLayer(config.drives)
    out = layer.apply(result.commands, measured[: len(config.drives)])
    for c, d in zip(out.commands, config.drives):
        assert abs(c.steering) <= d.str_lim
        assert abs(c.speed) <= d.max_wheel_speed * (1 + 1e-12)
    odom = calc.calculate_odometry([DriveState(c.steering, c.speed) for c in out.commands], 0.0)
    s = out.speed_scale
    assert 0.0 < s <= 1.0
    assert_twist(odom.twist, vx * s, vy * s, wz * s, 1e-9)


@pytest.mark.parametrize("robot_id", ROBOT_IDS)
def test_command_is_finite_and_unrealisable_twists_are_projected(robot_id):
    _config, calc = calculator(robot_id, "lsq")
    for twist in (Twist(0.3, 0.7, -0.4), Twist(0.0, 1.0, 0.0), Twist(0.0, 0.0, 1.0)):
        result = calc.calculate_command(twist)
        assert all(math.isfinite(c.steering) and math.isfinite(c.speed) for c in result.commands)
        # The commanded twist is realisable: odometry of the commands gives it back.
        odom = calc.calculate_odometry([DriveState(c.steering, c.speed) for c in result.commands], 0.0)
        t = result.twist
        assert_twist(odom.twist, t.vx, t.vy, t.wz, 1e-9)
        if not result.changed:
            assert t == twist
