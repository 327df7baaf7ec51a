"""thorvald_teleop's errors: one hierarchy in errors.py (every exception class of the package there:
tests/test_errors.py), the old names importable where they were, and the nodes refusing a parameter
they cannot use with one fatal line and a non-zero exit."""

import subprocess

import pytest

from thorvald_teleop import errors
from thorvald_teleop.keyboard import KeyboardTeleop
from thorvald_teleop.teleop import TeleopConfig, parameter_number
from thorvald_testing import poll, stop_group


def test_one_base_class_and_the_old_names_where_they_were():
    from thorvald_teleop.joystick import DeviceUnavailable  # noqa: PLC0415
    from thorvald_teleop.teleop import TeleopConfigError  # noqa: PLC0415

    assert TeleopConfigError is errors.TeleopConfigError and DeviceUnavailable is errors.DeviceUnavailable
    for cls in (TeleopConfigError, DeviceUnavailable):
        assert issubclass(cls, errors.ThorvaldTeleopError)
    assert issubclass(TeleopConfigError, ValueError)  # as before: code catching ValueError still does
    e = DeviceUnavailable("/dev/input/js0", "no such device")
    assert (str(e), e.path, e.reason) == ("/dev/input/js0: no such device", "/dev/input/js0", "no such device")


def test_parameter_errors_are_the_packages():
    with pytest.raises(errors.TeleopConfigError, match=r"^~joy_timeout: 0: must be > 0 \[s\]$"):
        TeleopConfig.from_params({"joy_timeout": 0})
    with pytest.raises(errors.TeleopConfigError, match=r"^speed must be a positive number, not -1$"):
        KeyboardTeleop(speed=-1)
    with pytest.raises(errors.TeleopConfigError, match=r"^~deadzone: 'abc': must be a number$"):
        parameter_number("deadzone", "abc")
    with pytest.raises(errors.TeleopConfigError, match=r"^~rate: True: must be a number$"):
        parameter_number("rate", True)
    assert parameter_number("rate", 20) == 20.0 and parameter_number("deadzone", "0.1") == 0.1


@pytest.mark.parametrize(
    "node, param, line",
    [
        ("joy_node", "_deadzone:=abc", "joy_node: refusing to start: ~deadzone: 'abc': must be a number"),
        ("teleop_node", "_joy_timeout:=-1", "teleop_node: refusing to start: ~joy_timeout: -1: must be > 0 [s]"),
    ],
)
def test_a_node_refuses_a_parameter_it_cannot_use(ros_env, tmp_path, node, param, line):
    log = tmp_path / f"{node}.log"
    with open(log, "w") as out:
        proc = subprocess.Popen(
            ["rosrun", "thorvald_teleop", node, param],
            env=ros_env,
            stdout=out,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
    try:
        poll(lambda: proc.poll() is not None, 60, f"{node} to exit")
    finally:
        stop_group(proc)
    text = log.read_text()
    assert proc.returncode == 1, text
    assert line in text and "Traceback" not in text, text
