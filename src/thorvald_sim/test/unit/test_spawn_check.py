"""Descriptions checked and normalised before pybullet loads them (Simulation.spawn): a joint naming a
link that does not exist is refused naming the joint, the link and the closest links; link names
written with a leading slash (older generators) or a doubled one are the robot's links, and a
sensor on them publishes frame ids without slashes in front."""

import os
import re
import xml.etree.ElementTree as ET

import pybullet as p
import pytest
import xacro

from thorvald_model.description import generate_urdf
from thorvald_sim.physics.robot import Pose2D
from thorvald_sim.physics.simulation import Simulation, SpawnError
from thorvald_sim.sensors.blocks import resolve_frame
from thorvald_sim.world import parse_world

HERE = os.path.dirname(os.path.abspath(__file__))
DATA = os.path.abspath(os.path.join(HERE, "..", "data"))
CONFIGS = os.path.abspath(os.path.join(HERE, "..", "..", "..", "thorvald_model", "config"))
STD = os.path.join(CONFIGS, "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
SLASH_LIDAR = os.path.join(DATA, "slash_lidar.xacro")
MISSING_LINK = os.path.join(DATA, "missing_link.urdf")
_URDF = {}


def std_urdf(tf_prefix=""):
    if tf_prefix not in _URDF:
        _URDF[tf_prefix] = generate_urdf(STD, tf_prefix=tf_prefix)
    return _URDF[tf_prefix]


def spliced(robot: str, extras: str) -> str:
    """The robot with the elements of another <robot> added, as another generator would write it."""
    root = ET.fromstring(robot)
    root.extend(list(ET.fromstring(extras)))
    return ET.tostring(root, encoding="unicode")


def plain_xacro(path: str, **args: str) -> str:
    """A xacro file made by xacro alone: nothing normalised, nothing checked."""
    try:
        return xacro.process_file(path, mappings=dict(args), in_order=True).toxml()
    finally:
        xacro.substitution_args_context["arg"] = {}


@pytest.fixture
def sim(client):
    return Simulation(client, parse_world({}))


def test_a_joint_naming_a_missing_link_is_refused_naming_the_joint_the_link_and_the_closest(sim, client):
    with open(MISSING_LINK) as f:
        broken = spliced(std_urdf(), f.read())
    bodies = p.getNumBodies(physicsClientId=client)
    with pytest.raises(SpawnError) as info:
        sim.spawn("thorvald_001", broken, Pose2D())
    message = str(info.value)
    assert message.startswith("thorvald_001: invalid robot description (1 problem):")
    # base_lnk / base_link: difflib's ratio 2*8/17 = 0.94
    assert "thorvald_001: joint lidar_joint/parent: 'base_lnk': link does not exist (closest: base_link" in message
    assert "Cannot load URDF" not in message
    # nothing was loaded: the world is as it was, and the robot spawns once repaired
    assert sim.robots == {} and p.getNumBodies(physicsClientId=client) == bodies
    sim.spawn("thorvald_001", broken.replace('"base_lnk"', '"base_link"'), Pose2D())
    assert list(sim.robots) == ["thorvald_001"]


@pytest.mark.parametrize(
    "tf_prefix, prefix",
    # the extras write /base_link, /thorvald_001/base_link and /thorvald_001//base_link
    [("", ""), ("thorvald_001", "thorvald_001/"), ("thorvald_001/", "thorvald_001/")],
)
@pytest.mark.parametrize("made_by", ["model_extras", "another generator"])
def test_sensors_on_links_written_with_slashes_spawn_and_publish_frames_without(sim, tf_prefix, prefix, made_by):
    if made_by == "model_extras":
        urdf = generate_urdf(STD, tf_prefix=tf_prefix, model_extras=SLASH_LIDAR)
    else:
        urdf = spliced(std_urdf(tf_prefix), plain_xacro(SLASH_LIDAR, tf_prefix=tf_prefix))
        assert 'link="/' in urdf and 'reference="/' in urdf  # as written: for the simulator to read
    robot = sim.spawn("thorvald_001", urdf, Pose2D())
    assert not robot.sensor_problems and not robot.sensor_blocks.refused
    sensors = {s.spec.name: s for s in robot.sensors}
    lidar, imu = sensors["slash_lidar"], sensors["slash_imu"]
    assert (lidar.spec.link, imu.spec.link) == (prefix + "lidar_link", prefix + "base_link")
    # the lidar's frame is 0.9 m ahead of base_link and 1 m above it (the extras' joint), yaw 0
    base, _ = robot.world_pose()
    assert lidar.pose()[0] == pytest.approx((base[0] + 0.9, base[1], base[2] + 1.0), abs=1e-6)
    # the simulator node resolves frames with the robot's namespace and its tf_prefix parameter
    for namespace in ("/thorvald_001", "/"):
        assert resolve_frame(lidar.spec, tf_prefix, namespace) == prefix + "lidar_link"  # tf::resolve: absolute
        assert resolve_frame(imu.spec, tf_prefix, namespace) == prefix + "base_link"  # as written, slash dropped
    assert robot.description.base_frame == prefix + "base_link"


def old_generator(urdf: str) -> str:
    """The description as an older generator wrote it: every link name and link reference, and the
    simulator block's frames, with a slash in front; joint names (and a joint's Gazebo block) not."""
    root = ET.fromstring(urdf)
    links = {link.get("name") for link in root.findall("link")}
    for link in root.findall("link"):
        link.set("name", "/" + link.get("name"))
    for end in root.findall("joint/parent") + root.findall("joint/child"):
        end.set("link", "/" + end.get("link"))
    for gazebo in root.findall("gazebo"):
        if gazebo.get("reference") in links:
            gazebo.set("reference", "/" + gazebo.get("reference"))
    for frame in root.findall("gazebo/plugin/odometryFrame") + root.findall("gazebo/plugin/robotBaseFrame"):
        frame.text = "/" + frame.text
    return ET.tostring(root, encoding="unicode")


def link_names(client, robot):
    return [p.getJointInfo(robot.body, j, physicsClientId=client)[12].decode() for j in range(len(robot.joint_index))]


def test_an_older_generators_description_spawns_as_the_same_robot(sim, client):
    urdf = std_urdf("thorvald_001/")
    old = old_generator(urdf)
    assert re.search(r'<parent link="/thorvald_001/base_link"', old)
    same = sim.spawn("old", old, Pose2D(0.0, 0.0))
    new = sim.spawn("new", urdf, Pose2D(0.0, 5.0))
    assert link_names(client, same) == link_names(client, new)
    assert all(name.startswith("thorvald_001/") for name in link_names(client, same))
    assert same.joint_index == new.joint_index
    assert (same.description.odometry_frame, same.description.base_frame) == (
        "thorvald_001/odom",
        "thorvald_001/base_link",
    )
    assert same.description.drives == new.description.drives
