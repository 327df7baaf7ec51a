"""Users' files of the original find its package names here, and run unchanged (issue 21).

thorvald_description, thorvald_twist_mux, thorvald_example_robots and xacro are thin packages over
ours: the files found through them are ours (links or includes, nothing copied). A lab's simulation
launch file composed as the original's users composed theirs (tests/data/lcas_composition.launch)
is brought up on a master of its own with both tf_prefix conventions, and the frames, odometry and
the simulated robot's motion are checked; the xacro command users' launch files run works on a
users' robot file.
"""

import os
import subprocess
import time
import xml.etree.ElementTree as ET

import pytest
import roslaunch.config
import roslaunch.xmlloader
import rospkg
import yaml

from thorvald_testing import Launch, poll

HERE = os.path.dirname(os.path.abspath(__file__))
SRC = os.path.join(HERE, "..", "src")
USERS_ROBOT = os.path.join(HERE, "data", "lcas_style_robot.yaml")
COMPOSITION = os.path.join(HERE, "data", "lcas_composition.launch")
ROBOTS = sorted(os.listdir(os.path.join(SRC, "thorvald_model", "config")))
STARTUP = 90.0  # [s] for the simulator and the robot's nodes on a busy machine


pytestmark = pytest.mark.long(35)  # [s] in all: the parallel run starts it early


def package(name):
    return rospkg.RosPack().get_path(name)


def load(path, args=()):
    config = roslaunch.config.ROSLaunchConfig()
    roslaunch.xmlloader.XmlLoader().load(path, config, argv=list(args), verbose=False)
    return config


@pytest.mark.parametrize(
    "name, path, ours",
    [
        ("thorvald_description", "urdf/thorvald_model.xacro", "thorvald_model/urdf/thorvald_model.xacro"),
        ("thorvald_description", "meshes/hokuyo/hokuyo.dae", "thorvald_model/meshes/hokuyo/hokuyo.dae"),
        ("thorvald_twist_mux", "config/twist_mux.yaml", "thorvald_bringup/config/twist_mux.yaml"),
        *(("thorvald_example_robots", f"config/{r}/{r}.yaml", f"thorvald_model/config/{r}/{r}.yaml") for r in ROBOTS),
    ],
)
def test_files_found_through_the_originals_names_are_ours(name, path, ours):
    assert os.path.samefile(os.path.join(package(name), path), os.path.join(SRC, ours))


def test_model_launch_of_thorvald_description_loads_the_description():
    config = load(
        os.path.join(package("thorvald_description"), "launch", "model.launch"),
        [f"robot_model:={USERS_ROBOT}", "tf_prefix:=thorvald_001", "robot_name:=thorvald_001"],
    )
    urdf = ET.fromstring(config.params["/robot_description"].value)
    names = {e.get("name") for e in urdf if e.tag in ("link", "joint")}
    assert {"thorvald_001/base_link", "thorvald_001/steering0", "thorvald_001/bat0"} <= names
    assert urdf.get("name") == "thorvald_001"


def test_twist_mux_launch_of_thorvald_twist_mux_runs_ours():
    config = load(os.path.join(package("thorvald_twist_mux"), "launch", "twist_mux.launch"))
    (node,) = config.nodes
    assert (node.package, node.type, node.name) == ("thorvald_base", "twist_mux", "twist_mux")
    assert dict(node.remap_args)["cmd_vel_out"] == "twist_mux/cmd_vel"
    topics = {t["topic"] for t in config.params["/twist_mux/topics"].value}
    assert {"teleop_joy/cmd_vel", "nav_vel"} <= topics


@pytest.mark.parametrize("robot", ROBOTS)
def test_example_robots_sim_launch_files(robot):
    config = load(os.path.join(package("thorvald_example_robots"), "launch", f"{robot}_sim.launch"))
    model = config.params["/thorvald_001/base_driver/robot_model"].value
    assert os.path.samefile(model, os.path.join(SRC, "thorvald_model", "config", robot, robot + ".yaml"))
    assert {"simulator", "base_driver", "spawn_robot"} <= {n.name for n in config.nodes}


def xacro_names(*command):
    out = subprocess.run(list(command), capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    return out.stdout, sorted(e.get("name") for e in ET.fromstring(out.stdout) if e.tag in ("link", "joint"))


def test_rosrun_xacro_on_a_users_robot_file_in_both_conventions():
    model = os.path.join(package("thorvald_description"), "urdf", "thorvald_model.xacro")
    newer, names = xacro_names("rosrun", "xacro", "xacro", model, f"robot_config:={USERS_ROBOT}", "tf_prefix:=t1/")
    _, older_names = xacro_names("rosrun", "xacro", "xacro", model, f"robot_config:={USERS_ROBOT}", "tf_prefix:=t1")
    assert names == older_names and "t1/base_link" in names and all(n.startswith("t1/") for n in names)
    # the users' file: a battery by its deprecated node (345 is id 1), tubes at 0.65 -+ 0.075 m
    with open(USERS_ROBOT) as f:
        raw = yaml.safe_load(f)
    assert raw["batteries"]["bat0"]["node"] == 345 and "t1/bat0" in names
    tubes = {e.get("name"): e for e in ET.fromstring(newer).findall("joint")}
    assert tubes["t1/pipe0_1_joint"].find("origin").get("xyz").split()[2] in ("0.575", "0.5750000000000001")


def test_find_xacro_in_a_launch_files_param_command(tmp_path):
    """$(find xacro)/xacro, as users' launch files write it, is a file of the xacro package that runs."""
    launch = tmp_path / "users.launch"
    launch.write_text(
        "<launch>\n"
        '  <param name="robot_description" command="$(find xacro)/xacro '
        "'$(find thorvald_description)/urdf/thorvald_model.xacro' "
        f'robot_config:={USERS_ROBOT} tf_prefix:=thorvald_001 robot_name:=thorvald_001"/>\n'
        "</launch>\n"
    )
    assert os.access(os.path.join(package("xacro"), "xacro"), os.X_OK)
    urdf = ET.fromstring(load(str(launch)).params["/robot_description"].value)
    assert urdf.find("link").get("name") == "thorvald_001/base_link"


def echo(launch, topic, field=""):
    """One message of topic (or one field of it) as rostopic prints it, or "" after 15 s."""
    out = launch.run(["rostopic", "echo", "-n", "1", topic + field], timeout=20)
    return out.stdout if out.returncode == 0 else ""


@pytest.mark.ros
@pytest.mark.slow
@pytest.mark.parametrize(
    "tf_prefix, odom_frame_id",
    [("thorvald_001/", "thorvald_001/odom"), ("thorvald_001", "thorvald_001/odom")],
    ids=["newer_concatenated", "older_slash_inserted"],
)
def test_a_labs_composition_runs_unchanged(tmp_path, tf_prefix, odom_frame_id):
    args = [f"tf_prefix:={tf_prefix}", f"odom_frame_id:={odom_frame_id}", f"robot_model:={USERS_ROBOT}"]
    with Launch(tmp_path, COMPOSITION, args) as launch:

        def up(what, topic, field="", check=bool):
            def ready():
                assert launch.running(), "roslaunch ended:\n" + launch.tail()
                text = echo(launch, topic, field)
                return text if check(text) else None

            return poll(ready, STARTUP, what, interval=0.5)

        odom = up("odometry/base_raw", "/thorvald_001/odometry/base_raw")
        assert 'frame_id: "thorvald_001/odom"' in odom and 'child_frame_id: "thorvald_001/base_link"' in odom
        # robot_state_publisher's links: fixed ones on /tf_static, the steering legs on /tf
        static = up("/tf_static", "/tf_static", check=lambda t: "thorvald_001/top0" in t)
        assert 'frame_id: "thorvald_001/base_link"' in static and "thorvald_001//" not in static
        up("the legs on /tf", "/tf", check=lambda t: 'child_frame_id: "thorvald_001/leg0"' in t)
        # driven through thorvald_twist_mux's nav_vel input, the simulated robot moves
        pub = subprocess.Popen(
            ["rostopic", "pub", "-r", "10", "/thorvald_001/nav_vel", "geometry_msgs/Twist", "{linear: {x: 0.5}}"],
            env=launch.env,
            stdin=subprocess.DEVNULL,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        try:
            start = time.monotonic()
            moved = up(
                "the robot to drive 0.5 m",
                "/thorvald_001/odometry/base_raw",
                "/pose/pose/position/x",
                check=lambda t: bool(t) and float(t.split()[0]) > 0.5,
            )
            assert float(moved.split()[0]) > 0.5 and time.monotonic() - start < STARTUP
        finally:
            pub.terminate()
            pub.wait(timeout=10)
    assert launch.left == [], "processes left after roslaunch stopped (killed now):\n" + "\n".join(launch.left)
