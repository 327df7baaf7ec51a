"""model.launch's robot_state_publisher shim: the joint states it reads, resolved in the robot's namespace."""

import os
import subprocess
import sys

import pytest

from thorvald_model.errors import StatePublisherError
from thorvald_model.state_publisher import command, joint_states_topic, robot_namespace

RSP = "/usr/lib/robot_state_publisher/robot_state_publisher"


@pytest.mark.parametrize(
    "ns, robot",
    [("/thorvald_001/rsp/", "/thorvald_001/"), ("/thorvald_001/rsp", "/thorvald_001/"), ("/a/b/rsp/", "/a/b/"),
     ("/rsp/", "/"), ("/", "/")],
)  # fmt: skip
def test_the_robot_namespace_is_the_one_around_the_nodes(ns, robot):
    assert robot_namespace(ns) == robot


def test_joint_states_resolve_in_the_robot_namespace_a_global_topic_stays():
    assert joint_states_topic("/thorvald_001/rsp/") == "/thorvald_001/base_driver/joint_states"
    assert joint_states_topic("/thorvald_001/rsp/", "joint_states") == "/thorvald_001/joint_states"
    assert joint_states_topic("/rsp/") == "/base_driver/joint_states"  # model.launch at the root
    assert joint_states_topic("/r/rsp/", "/elsewhere/js") == "/elsewhere/js"
    for bad in ("", "~joint_states", "bad topic", "1abc"):
        with pytest.raises(StatePublisherError):
            joint_states_topic("/r/rsp/", bad)


def test_the_command_line_passes_roslaunchs_arguments_and_adds_the_remap():
    argv = ["--joint-states", "joint_states", "__name:=robot_state_publisher", "__log:=/tmp/x.log"]
    cmd = command(argv, environ={"ROS_NAMESPACE": "/robot_1/rsp"}, executable=RSP)
    assert cmd == [RSP, "__name:=robot_state_publisher", "__log:=/tmp/x.log", "joint_states:=/robot_1/joint_states"]
    # __ns:= wins over the environment, as in every ROS node; the default topic is base_driver's
    assert command(["__ns:=/r2/rsp"], environ={"ROS_NAMESPACE": "/r1/rsp"}, executable=RSP)[-1] == (
        "joint_states:=/r2/base_driver/joint_states"
    )


def test_a_users_own_remap_of_joint_states_wins():
    cmd = command(["joint_states:=/mine"], environ={"ROS_NAMESPACE": "/r/rsp"}, executable=RSP)
    assert cmd == [RSP, "joint_states:=/mine"]


def test_the_real_robot_state_publisher_is_found():
    cmd = command([], environ={"ROS_NAMESPACE": "/r/rsp"})
    assert os.access(cmd[0], os.X_OK) and os.path.basename(cmd[0]) == "robot_state_publisher"


def test_a_bad_topic_is_one_line_and_exit_2():
    out = subprocess.run(
        [sys.executable, "-c", "import sys; from thorvald_model.state_publisher import main; sys.exit(main())",
         "--joint-states", "bad topic"],
        capture_output=True, text=True,
    )  # fmt: skip
    assert out.returncode == 2 and out.stderr.startswith("state_publisher: --joint-states 'bad topic'")
    assert "Traceback" not in out.stderr
