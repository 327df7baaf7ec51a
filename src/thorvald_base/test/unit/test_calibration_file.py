"""The calibration file base_driver loads at start (``~calibration``): written from a calibration,
read back checked against the robot, every problem with the file, the key path, the value and the
rule; and the set_drive_params call that applies the same values to a running robot."""

import os

import pytest
import yaml
from base_test_helpers import diff, four_ws
from calibration_test_helpers import MIXED, STRAIGHT, synthetic_drive

from thorvald_base.calibration import (
    calibrate,
    calibration_dict,
    calibration_yaml,
    load_calibration,
    parse_calibration,
    set_drive_params_command,
)
from thorvald_model import ConfigError, with_drive_param

RADII = (0.2016, 0.1990, 0.2006, 0.1981)
OFFSETS = (0.004, -0.006, 0.002, 0.007)


def problems_of(data, config=None):
    with pytest.raises(ConfigError) as info:
        parse_calibration(data, config or four_ws(), "cal.yaml")
    assert "cal.yaml: invalid calibration file" in str(info.value) or str(info.value).startswith("cal.yaml: ")
    return [(p.path, p.value, p.rule) for p in info.value.problems]


@pytest.mark.slow  # a calibration file written and loaded as base_driver loads it
def test_written_and_read_back_as_base_driver_reads_it(tmp_path):
    config = four_ws()
    drive = synthetic_drive(config, MIXED, RADII, OFFSETS)
    calibration = calibrate(config, drive.recording, drive.pose_truth)
    path = tmp_path / "calibration.yaml"
    path.write_text(calibration_yaml(calibration, "odometry calibration\nfrom a drive"))
    text = path.read_text()
    assert text.startswith("# odometry calibration\n# from a drive\nmotor_drives:\n  drive0:\n    r_wheel: 0.2016\n")
    changes = load_calibration(str(path), config)
    assert [(i, key) for i, key, _ in changes] == [(i, key) for i in range(4) for key in ("r_wheel", "steering_offset")]
    expected = [v for i in range(4) for v in (RADII[i], OFFSETS[i])]
    assert [value for _, _, value in changes] == pytest.approx(expected, rel=1e-9)
    # applied as set_drive_params applies it: the calibrated robot
    for i, key, value in changes:
        config = with_drive_param(config, i, key, value)
    assert [d.r_wheel for d in config.drives] == pytest.approx(RADII, rel=1e-9)


def test_only_what_was_estimated_is_written():
    """A straight line with GNSS refuses the offsets: the file holds the radii alone."""
    config = four_ws()
    drive = synthetic_drive(config, STRAIGHT, RADII, OFFSETS, heading_bias=0.2)
    calibration = calibrate(config, drive.recording, drive.gnss_truth)
    data = calibration_dict(calibration)
    assert list(data) == ["motor_drives"]
    assert {name: list(values) for name, values in data["motor_drives"].items()} == {
        f"drive{i}": ["r_wheel"] for i in range(4)
    }
    # what an earlier calibration set and this one did not estimate again is kept beside it
    kept = calibration_dict(calibration, extra=[(1, "steering_offset", 0.01), (1, "r_wheel", 0.3)])
    assert kept["motor_drives"]["drive1"] == {"r_wheel": pytest.approx(RADII[1], rel=5e-5), "steering_offset": 0.01}


def test_a_partial_file_changes_only_what_it_names():
    changes = parse_calibration({"motor_drives": {"drive2": {"steering_offset": "-0.01"}}}, four_ws())
    assert changes == [(2, "steering_offset", -0.01)]  # a number written as a string reads as the robot file's
    assert parse_calibration(None, four_ws()) == []  # an empty file changes nothing
    # any key set_drive_params may change, aliases included
    assert parse_calibration({"motor_drives": {"drive0": {"prp_slm_e": 2.0}}}, four_ws()) == [(0, "prp_sim_a", 2.0)]


@pytest.mark.parametrize(
    "data, path, value, rule",
    [
        ({"motor_drives": {"drive1": {"r_wheel": -0.2}}}, "motor_drives.drive1.r_wheel", -0.2, "must be > 0"),
        ({"motor_drives": {"drive1": {"r_wheel": "big"}}}, "motor_drives.drive1.r_wheel", "big", "a finite number"),
        (
            {"motor_drives": {"drive0": {"steering_offset": 0.3}}},
            "motor_drives.drive0.steering_offset",
            0.3,
            "must be within +-0.2 rad",
        ),
        ({"motor_drives": {"drive0": {"r_wheeel": 0.2}}}, "motor_drives.drive0.r_wheeel", 0.2, "did you mean"),
        ({"motor_drives": {"drive0": {"node": 5}}}, "motor_drives.drive0.node", 5, "cannot be calibrated"),
        ({"motor_drives": {"drive7": {"r_wheel": 0.2}}}, "motor_drives.drive7", None, "is not a drive of the robot"),
        ({"motor_drives": [0.2]}, "motor_drives", [0.2], "must be a mapping of the robot's drives"),
        ({"motor_drive": {}}, "motor_drive", {}, "did you mean 'motor_drives'"),
    ],
)
def test_a_bad_value_names_the_key_path_the_value_and_the_rule(data, path, value, rule):
    problems = problems_of(data)
    matching = [p for p in problems if p[0] == path]
    assert matching, problems
    assert rule in matching[0][2]
    if value is not None:
        assert matching[0][1] == value


def test_a_rule_across_keys_is_checked_against_the_robot():
    """A drive that does not steer has no steering offset: the robot file's rule, in the calibration
    file's name; and every problem is reported at once."""
    problems = problems_of(
        {"motor_drives": {"drive0": {"steering_offset": 0.01}, "drive1": {"r_wheel": 0.0}}}, config=diff()
    )
    assert problems == [
        ("motor_drives.drive1.r_wheel", 0.0, "must be > 0"),
        ("motor_drives.drive0.steering_offset", 0.01, "must be 0: this drive does not steer"),
    ]


def test_an_unreadable_file_is_one_line(tmp_path):
    missing = str(tmp_path / "nowhere.yaml")
    with pytest.raises(ConfigError) as info:
        load_calibration(missing, four_ws())
    assert str(info.value) == f"{missing}: cannot read the calibration file: No such file or directory"
    not_yaml = tmp_path / "bad.yaml"
    not_yaml.write_text("motor_drives: {drive0: [\n")
    with pytest.raises(ConfigError, match=r"bad.yaml: not valid YAML at line 2"):
        load_calibration(str(not_yaml), four_ws())
    a_list = tmp_path / "list.yaml"
    a_list.write_text("- 0.2\n")
    with pytest.raises(ConfigError, match=r"list.yaml: <top level>: \[0.2\]: the file must hold a mapping of keys"):
        load_calibration(str(a_list), four_ws())


def test_the_set_drive_params_call_for_a_running_robot():
    command = set_drive_params_command([(0, "r_wheel", 0.2016), (2, "steering_offset", -0.003)], "/robot_1")
    assert command == (
        "rosservice call /robot_1/base_driver/set_drive_params \"params: [{index: 0, type: 'r_wheel', "
        "value: 0.2016}, {index: 2, type: 'steering_offset', value: -0.003}]\""
    )
    assert set_drive_params_command([(1, "r_wheel", 0.2)]).startswith("rosservice call /base_driver/set_drive_params ")
    # its argument is the DriveParams request as YAML, as rosservice reads it
    argument = command.split(" ", 3)[3].strip('"')
    assert yaml.safe_load(argument) == {
        "params": [
            {"index": 0, "type": "r_wheel", "value": 0.2016},
            {"index": 2, "type": "steering_offset", "value": -0.003},
        ]
    }


def test_the_example_file_of_the_tests_loads(tmp_path):
    """The rostest's calibration file is a valid calibration of the standard robot."""
    from base_test_helpers import EXAMPLE_ROBOTS  # noqa: PLC0415

    from thorvald_model import load_robot_config  # noqa: PLC0415

    std = next(p for p in EXAMPLE_ROBOTS if p.endswith("thorvald_ii_4wd4ws_std.yaml"))
    data = os.path.join(os.path.dirname(__file__), "..", "data", "calibration_std.yaml")
    assert load_calibration(data, load_robot_config(std)) == [
        (0, "r_wheel", 0.21),
        (0, "steering_offset", 0.05),
        (2, "steering_offset", -0.03),
    ]
