"""Every launch file of thorvald_bringup loads in roslaunch (arguments, includes, the robot files
they name), and each example robot has its <robot>_sim.launch bringing up that robot's file."""

import glob
import os

import pytest
import roslaunch.config
import roslaunch.xmlloader

pytestmark = [pytest.mark.slow, pytest.mark.long(13)]  # a process per case: the commands as a user types them

HERE = os.path.dirname(os.path.abspath(__file__))
BRINGUP = os.path.join(HERE, "..", "src", "thorvald_bringup", "launch")
ROBOTS = sorted(
    os.path.basename(p) for p in glob.glob(os.path.join(HERE, "..", "src", "thorvald_model", "config", "*"))
)


def load(path, args=()):
    config = roslaunch.config.ROSLaunchConfig()
    loader = roslaunch.xmlloader.XmlLoader()
    loader.load(path, config, argv=list(args), verbose=False)
    return config


@pytest.mark.parametrize("robot", ROBOTS)
def test_each_example_robot_has_its_sim_launch(robot):
    config = load(os.path.join(BRINGUP, robot, f"{robot}_sim.launch"))
    model = config.params["/thorvald_001/base_driver/robot_model"].value
    assert model.endswith(os.path.join(robot, robot + ".yaml")) and os.path.isfile(model)
    names = {n.name for n in config.nodes}
    assert {"simulator", "base_driver", "twist_mux", "spawn_robot", "robot_state_publisher"} <= names


def test_sim_launch_options():
    config = load(
        os.path.join(BRINGUP, "sim.launch"), ["with_teleoperation:=true", "with_rviz:=true", "robot_name:=r7"]
    )
    names = {(n.namespace, n.name) for n in config.nodes}
    assert ("/r7/", "teleop_node") in names and ("/r7/", "joy_node") in names and ("/r7/", "rviz") in names
    assert config.params["/r7/teleop_node/enable_button"].value == 4  # the xbox controller file


def test_sim_launch_with_sensors_fits_the_example_sensors_and_your_extras_win():
    def description(*args):
        config = load(os.path.join(BRINGUP, "sim.launch"), list(args))
        return config.params["/thorvald_001/robot_description"].value

    plain = description()
    assert "<sensor" not in plain
    fitted = description("with_sensors:=true")
    for plugin in ("libgazebo_ros_laser.so", "libgazebo_ros_imu_sensor.so", "libhector_gazebo_ros_gps.so"):
        assert plugin in fitted
    assert "libgazebo_ros_openni_kinect.so" in fitted
    assert '<link name="thorvald_001/lidar_front_link"' in fitted
    # a model_extras of the user's replaces the example
    mine = os.path.join(HERE, "..", "src", "thorvald_sim", "test", "data", "row_lidar.xacro")
    theirs = description("with_sensors:=true", f"model_extras:={mine}")
    assert "thorvald_001/row_lidar_link" in theirs and "lidar_front_link" not in theirs


def test_as_built_reaches_the_spawn_and_never_base_driver():
    def spawn_args(launch, *args):
        config = load(os.path.join(BRINGUP, launch), list(args))
        return {n.namespace + n.name: n.args for n in config.nodes if n.type == "spawn_robot"}, config

    plain, _ = spawn_args("sim.launch")
    assert "-as_built" not in plain["/thorvald_001/spawn_robot"]
    built, config = spawn_args("sim.launch", "as_built:=field:3")
    args = built["/thorvald_001/spawn_robot"].split()
    model = config.params["/thorvald_001/base_driver/robot_model"].value
    assert args[args.index("-as_built") + 1] == "field:3" and args[args.index("-robot_model") + 1] == model
    assert not any("as_built" in name for name in config.params)  # base_driver runs on the configuration
    fleet, _ = spawn_args("multi_sim.launch", "as_built:=field:9")
    assert len(fleet) == 4 and all("-as_built field:9" in a for a in fleet.values())
    report, _ = spawn_args("odometry_report.launch", "as_built:=field:1")
    assert all("-as_built field:1" in a for a in report.values())


def test_multi_sim_launch_has_four_robots_each_placed_in_world():
    config = load(os.path.join(BRINGUP, "multi_sim.launch"))
    for k in range(1, 5):
        assert f"/robot_{k}/base_driver/robot_model" in config.params
        assert config.params[f"/world_to_robot_{k}_odom/child"].value == f"robot_{k}/odom"
    assert config.params["/simulator/world"].value == "tarmac_gravel"


def test_robot_launch_drives_the_real_base_over_can():
    std = os.path.join(
        HERE, "..", "src", "thorvald_model", "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml"
    )
    config = load(
        os.path.join(BRINGUP, "robot.launch"),
        [f"robot_model:={std}", "can_interface_type:=slcan", "can_interface_name:=/dev/ttyACM0", "robot_name:=t8"],
    )
    p = {k: v.value for k, v in config.params.items()}
    assert p["/t8/base_driver/simple_sim"] is False
    assert (p["/t8/base_driver/can_interface_type"], p["/t8/base_driver/can_interface_name"]) == (
        "slcan",
        "/dev/ttyACM0",
    )
    assert p["/t8/base_driver/tf_prefix"] == "t8/" and p["/t8/base_driver/odom_frame_id"] == "t8/odom"
    names = {n.name for n in config.nodes}
    assert {"base_driver", "twist_mux", "robot_state_publisher", "joy_node", "teleop_node"} <= names
    assert "simulator" not in names
