"""The teleop rules without ROS: deadman, turbo, one zero on release, priority toggle, homing, joy timeout."""

import glob
import os

import pytest
import yaml

from thorvald_teleop.teleop import ZERO, TeleopConfig, TeleopConfigError, TeleopCore

CONFIGS = sorted(glob.glob(os.path.join(os.path.dirname(__file__), "..", "..", "config", "*.yaml")))
XBOX = {
    "enable_button": 4,
    "enable_turbo_button": 5,
    "axis_linear": {"x": 1, "y": 0},
    "scale_linear": {"x": 0.5, "y": 0.4},
    "scale_linear_turbo": {"x": 1.5, "y": 1.0},
    "axis_angular": {"yaw": 3},
    "scale_angular": {"yaw": 0.6},
    "scale_angular_turbo": {"yaw": 1.2},
    "priority_button": 3,
    "home_steering_button": 7,
}


def joy(buttons=(), **axes):
    a = [0.0] * 8
    for k, v in axes.items():
        a[int(k[1:])] = v
    b = [0] * 11
    for k in buttons:
        b[k] = 1
    return a, b


def test_every_controller_file_loads_and_names_distinct_buttons():
    assert [os.path.basename(p) for p in CONFIGS] == ["tiger_g2.yaml", "xbox.yaml", "xbox_one.yaml"]
    for path in CONFIGS:
        with open(path) as f:
            c = TeleopConfig.from_params(yaml.safe_load(f))
        buttons = [c.enable_button, c.enable_turbo_button, c.priority_button, c.home_steering_button]
        assert len(set(buttons)) == 4 and min(buttons) >= 0, path
        assert set(c.axis_linear) == {"x", "y"} and "yaw" in c.axis_angular


def test_deadman_turbo_release_and_silence():
    core = TeleopCore(TeleopConfig.from_params(XBOX))
    assert core.on_joy(*joy(a1=1.0, a3=0.5), now=0.0).twist is None  # no deadman: nothing
    assert core.on_joy(*joy([4], a1=1.0, a0=-0.5, a3=0.5), now=0.1).twist == pytest.approx((0.5, -0.2, 0.3))
    assert core.on_joy(*joy([5], a1=1.0, a0=-0.5, a3=0.5), now=0.2).twist == pytest.approx((1.5, -0.5, 0.6))
    assert core.on_joy(*joy(a1=1.0), now=0.3).twist == ZERO  # released: one zero
    assert core.on_joy(*joy(a1=1.0), now=0.4).twist is None  # then silence
    assert core.on_timer(10.0).twist is None


def test_priority_toggles_on_the_press_and_home_once():
    core = TeleopCore(TeleopConfig.from_params(XBOX))
    assert core.on_joy(*joy([3]), now=0.0).priority is True
    assert core.on_joy(*joy([3]), now=0.05).priority is None  # held: no new toggle
    assert core.on_joy(*joy(), now=0.1).priority is None
    assert core.on_joy(*joy([3]), now=0.15).priority is False
    assert core.on_joy(*joy([7]), now=0.2).home_steering
    assert not core.on_joy(*joy([7]), now=0.25).home_steering


def test_joystick_silent_with_the_deadman_held_stops_once():
    core = TeleopCore(TeleopConfig.from_params(XBOX))
    core.on_joy(*joy([4], a1=1.0), now=1.0)
    assert core.on_timer(1.4).twist is None
    assert core.on_timer(1.6).twist == ZERO
    assert core.on_timer(1.7).twist is None


def test_teleop_twist_joy_number_forms_and_short_messages():
    c = TeleopConfig.from_params({"axis_linear": 1, "scale_linear": 0.7, "axis_angular": 0, "enable_button": 0})
    assert c.axis_linear == {"x": 1} and c.scale_linear == {"x": 0.7} and c.scale_linear_turbo == {"x": 0.7}
    core = TeleopCore(c)
    # yaw on axis 0 at the default scale 0.5; axis 1 missing reads 0; a non-finite axis reads 0
    assert core.on_joy([0.3], [1], now=0.0).twist == pytest.approx((0.0, 0.0, 0.15))
    assert core.on_joy([0.3, 1.0], [1], now=0.1).twist == pytest.approx((0.7, 0.0, 0.15))
    assert core.on_joy([float("nan"), 1.0], [1], now=0.2).twist == pytest.approx((0.7, 0.0, 0.0))


@pytest.mark.parametrize(
    ("params", "message"),
    [
        ({"enable_button": "LB"}, r"~enable_button: 'LB': must be a button or axis index"),
        ({"axis_linear": {"z": 2}}, r"~axis_linear: \{'z': 2\}: unknown key\(s\) \['z'\]"),
        ({"scale_angular": {"yaw": "fast"}}, r"~scale_angular.yaw: 'fast': must be a number"),
        ({"joy_timeout": 0}, r"~joy_timeout: 0: must be > 0"),
        ({"axis_angular": {"yaw": 1.5}}, r"~axis_angular.yaw: 1.5: must be an axis index"),
    ],
)
def test_bad_parameters_are_named(params, message):
    with pytest.raises(TeleopConfigError, match=message):
        TeleopConfig.from_params(params)
