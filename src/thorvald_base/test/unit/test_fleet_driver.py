"""fleet_driver's robot list and the names each of its robots' nodes get (no ROS master)."""

import pytest

from thorvald_base.errors import ParameterError
from thorvald_base.node_names import Names
from thorvald_base.params import robot_namespaces


@pytest.mark.parametrize(
    "value, expected",
    [
        ("robot_1 robot_2", ["/robot_1/", "/robot_2/"]),
        ("r0,r1, r2", ["/r0/", "/r1/", "/r2/"]),
        (["/field/r0", "field/r1/"], ["/field/r0/", "/field/r1/"]),
        ("r0", ["/r0/"]),
    ],
)
def test_robots_are_namespaces(value, expected):
    assert robot_namespaces(value) == expected


@pytest.mark.parametrize(
    "value, words",
    [
        ("", "<missing>"),
        ([], "<missing>"),
        ("r0 r0", "given twice"),
        ("r0 1abc", "not a ROS namespace"),
        ("r0 a-b", "not a ROS namespace"),
        (3, "a list or a string"),
    ],
)
def test_a_bad_robot_list_is_refused_with_its_value(value, words):
    with pytest.raises(ParameterError, match="~robots") as e:
        robot_namespaces(value)
    assert words in str(e.value)


def test_a_fleet_robot_gets_its_own_names_and_the_launch_files_remappings():
    names = Names("/r3/", "/r3/base_driver/", {"cmd_vel": "twist_mux/cmd_vel"})
    assert names.topic("cmd_vel") == "/r3/twist_mux/cmd_vel"
    assert names.topic("odometry/base_raw") == "/r3/odometry/base_raw"
    assert names.topic("/diagnostics") == "/diagnostics"
    assert names.param("home_steering") == "/r3/base_driver/home_steering"
    assert names.param() == "/r3/base_driver/"
    assert names.robot == "r3"
    assert names.node == "/r3/base_driver"


def test_a_node_of_its_own_keeps_rospys_relative_names():
    names = Names()
    assert names.topic("cmd_vel") == "cmd_vel"  # rospy resolves it and applies roslaunch's remappings
    assert names.param("rate") == "~rate"
