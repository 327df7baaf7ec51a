"""The sensor modules (urdf/sensor_modules) and the example extras (urdf/examples/sensors_example.xacro)
on the standard robot, without a ROS master: the links, joints and Gazebo blocks with the gazebo_ros
(ROS 1), hector and velodyne plugins' element names and values, the robot file's sensor keys, the
description's physical sanity, and pybullet loading it with every sensor seeing out.

Expected figures are the real sensors' (Hokuyo UTM-30LX, SICK LMS111, Velodyne VLP-16) and the
plugins' parameter names, never read back from the macros.
"""

import functools
import math
import os
import shutil
import subprocess
import xml.etree.ElementTree as ET
from typing import Dict, List, Tuple

import numpy as np
import pytest
import yaml
from urdf_helpers import EXAMPLE_ROBOTS, PKG, floats, inertia_problems, origin_of, robot_id

from thorvald_model.description import generate_urdf

STD = os.path.join(PKG, "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
EXAMPLE = os.path.join(PKG, "urdf", "examples", "sensors_example.xacro")
MODULES = os.path.join(PKG, "urdf", "sensor_modules", "sensor_modules.xacro")
SENSOR_KEYS = os.path.join(PKG, "test", "data", "sensor_keys.yaml")

PREFIXES = pytest.mark.parametrize("prefix", ["", "thorvald_001/"], ids=["no_prefix", "prefix"])

# The example's sensors: link -> (parent, kind)
EXAMPLE_LINKS = {
    "lidar_front_link": "base_link",
    "imu_link": "base_link",
    "gnss_link": "base_link",
    "camera_front_link": "base_link",
    "camera_front_optical_frame": "camera_front_link",
}


@functools.lru_cache(maxsize=None)
def urdf_text(robot: str = STD, prefix: str = "", extras: str = EXAMPLE) -> str:
    return generate_urdf(robot, tf_prefix=prefix, model_extras=extras)


def tree(robot: str = STD, prefix: str = "", extras: str = EXAMPLE) -> ET.Element:
    return ET.fromstring(urdf_text(robot, prefix, extras))


def by_name(root: ET.Element, tag: str) -> Dict[str, ET.Element]:
    return {e.get("name"): e for e in root.findall(tag)}


def sensor_block(root: ET.Element, link: str) -> ET.Element:
    blocks = [g for g in root.findall("gazebo") if g.get("reference") == link and g.find("sensor") is not None]
    assert len(blocks) == 1, f"one sensor block on {link}"
    return blocks[0].find("sensor")


def model_plugin(root: ET.Element, filename: str) -> List[ET.Element]:
    return [p for g in root.findall("gazebo") if g.get("reference") is None for p in g.findall("plugin")
            if p.get("filename") == filename]  # fmt: skip


def text(element: ET.Element, path: str) -> str:
    found = element.find(path)
    assert found is not None, f"<{path}> missing"
    return (found.text or "").strip()


def number(element: ET.Element, path: str) -> float:
    return float(text(element, path))


def robot_file_with_sensor_keys(tmp_path) -> str:
    """The standard robot's file with the sensor keys of test/data/sensor_keys.yaml added."""
    with open(STD) as f:
        data = yaml.safe_load(f)
    with open(SENSOR_KEYS) as f:
        data.update(yaml.safe_load(f))
    path = tmp_path / "thorvald_ii_4wd4ws_std.yaml"
    path.write_text(yaml.safe_dump(data))
    return str(path)


def extras_file(tmp_path, body: str) -> str:
    """An extras file including the sensor modules, with body inside its <robot>."""
    path = tmp_path / "extras.xacro"
    path.write_text(
        '<?xml version="1.0"?>\n<robot xmlns:xacro="http://www.ros.org/wiki/xacro">\n'
        f'  <xacro:include filename="{MODULES}"/>\n{body}\n</robot>\n'
    )
    return str(path)


# --- the example on the standard robot ------------------------------------------------------------
@pytest.mark.slow  # a description generated through xacro for every example robot
@PREFIXES
def test_the_example_fits_each_sensor_on_a_fixed_joint(prefix):
    root = tree(prefix=prefix)
    links, joints = by_name(root, "link"), by_name(root, "joint")
    for link, parent in EXAMPLE_LINKS.items():
        assert prefix + link in links
        joint = [j for j in joints.values() if j.find("child").get("link") == prefix + link]
        assert len(joint) == 1 and joint[0].get("type") == "fixed"
        assert joint[0].find("parent").get("link") == prefix + parent
    for name in ("lidar_front", "imu", "gnss", "camera_front"):
        assert joints[f"{prefix}{name}_joint"].find("child").get("link") == f"{prefix}{name}_link"
    # without the extras none of it
    assert not set(by_name(tree(prefix=prefix, extras=""), "link")) & {prefix + k for k in EXAMPLE_LINKS}


@PREFIXES
def test_the_front_lidar_is_a_utm30lx_on_gazebo_ros_laser(prefix):
    sensor = sensor_block(tree(prefix=prefix), prefix + "lidar_front_link")
    assert sensor.get("type") == "ray" and sensor.get("name") == "lidar_front"
    assert text(sensor, "pose") == "0 0 0 0 0 0" and text(sensor, "visualize") == "false"
    assert number(sensor, "update_rate") == 40
    horizontal = sensor.find("ray/scan/horizontal")
    assert number(horizontal, "samples") == 1081 and number(horizontal, "resolution") == 1
    lo, hi = number(horizontal, "min_angle"), number(horizontal, "max_angle")
    assert lo == pytest.approx(-math.radians(135)) and hi == pytest.approx(math.radians(135))
    assert (hi - lo) / (1081 - 1) == pytest.approx(math.radians(0.25))
    assert sensor.find("ray/scan/vertical") is None
    rng = sensor.find("ray/range")
    assert (number(rng, "min"), number(rng, "max"), number(rng, "resolution")) == (0.1, 30.0, 0.01)
    noise = sensor.find("ray/noise")
    assert text(noise, "type") == "gaussian" and number(noise, "mean") == 0 and number(noise, "stddev") == 0.01
    plugin = sensor.find("plugin")
    assert plugin.get("filename") == "libgazebo_ros_laser.so"
    assert text(plugin, "topicName") == "lidar_front/scan"
    # the prefixed link, absolute for tf::resolve (see test_frames_are_the_links_under_every_namespace)
    assert text(plugin, "frameName") == "/" + prefix + "lidar_front_link"
    # drawn with our Hokuyo mesh, colliding as its box
    link = by_name(tree(prefix=prefix), "link")[prefix + "lidar_front_link"]
    meshes = [m.get("filename") for m in link.iter("mesh")]
    assert meshes == ["package://thorvald_model/meshes/hokuyo/hokuyo.dae"]
    assert [floats(b.get("size")) for b in link.findall("collision/geometry/box")] == [[0.06, 0.06, 0.087]]


@PREFIXES
def test_the_imu_is_gazebo_ros_imu_sensor_at_100_hz(prefix):
    sensor = sensor_block(tree(prefix=prefix), prefix + "imu_link")
    assert sensor.get("type") == "imu" and text(sensor, "always_on") == "true"
    assert number(sensor, "update_rate") == 100
    plugin = sensor.find("plugin")
    assert plugin.get("filename") == "libgazebo_ros_imu_sensor.so"
    assert text(plugin, "topicName") == "imu/data"
    # this plugin publishes frameName as written: the prefixed link itself
    assert text(plugin, "frameName") == text(plugin, "bodyName") == prefix + "imu_link"
    assert number(plugin, "updateRateHZ") == 100 and number(plugin, "gaussianNoise") >= 0
    assert floats(text(plugin, "xyzOffset")) == [0, 0, 0] and floats(text(plugin, "rpyOffset")) == [0, 0, 0]


@PREFIXES
def test_the_gnss_is_hector_gps_with_rtk_noise_and_no_reference_of_its_own(prefix):
    root = tree(prefix=prefix)
    plugins = model_plugin(root, "libhector_gazebo_ros_gps.so")
    assert len(plugins) == 1
    plugin = plugins[0]
    assert number(plugin, "updateRate") == 10
    assert text(plugin, "bodyName") == text(plugin, "frameId") == prefix + "gnss_link"
    assert text(plugin, "topicName") == "gps/fix" and text(plugin, "velocityTopicName") == "gps/fix_velocity"
    assert floats(text(plugin, "gaussianNoise")) == [0.02, 0.02, 0.02]
    assert floats(text(plugin, "drift")) == [0, 0, 0] and floats(text(plugin, "velocityDrift")) == [0, 0, 0]
    assert len(floats(text(plugin, "velocityGaussianNoise"))) == 3
    assert int(text(plugin, "status")) == 2 and int(text(plugin, "service")) == 1  # RTK fix (GBAS), GPS
    # no reference: the datum file's applies (the simulator) or hector's default (Gazebo)
    assert not [e.tag for e in plugin if e.tag.startswith("reference")]
    # Gazebo keeps the antenna's link (bodyName) instead of merging it into base_link
    kept = [g for g in root.findall("gazebo") if g.get("reference") == prefix + "gnss_joint"]
    assert [text(g, "preserveFixedJoint") for g in kept] == ["true"]


@PREFIXES
def test_the_camera_is_an_openni_kinect_in_its_optical_frame(prefix):
    root = tree(prefix=prefix)
    sensor = sensor_block(root, prefix + "camera_front_link")
    assert sensor.get("type") == "depth" and number(sensor, "update_rate") == 10
    camera = sensor.find("camera")
    assert 0 < number(camera, "horizontal_fov") < math.pi
    assert (number(camera, "image/width"), number(camera, "image/height")) == (320, 240)
    assert text(camera, "image/format") == "R8G8B8"
    assert 0 < number(camera, "clip/near") < number(camera, "clip/far")
    plugin = sensor.find("plugin")
    assert plugin.get("filename") == "libgazebo_ros_openni_kinect.so"
    assert {tag: text(plugin, tag) for tag in (
        "cameraName", "imageTopicName", "cameraInfoTopicName", "depthImageTopicName",
        "depthImageCameraInfoTopicName", "pointCloudTopicName")} == {
        "cameraName": "camera_front", "imageTopicName": "rgb/image_raw", "cameraInfoTopicName": "rgb/camera_info",
        "depthImageTopicName": "depth/image_raw", "depthImageCameraInfoTopicName": "depth/camera_info",
        "pointCloudTopicName": "depth/points"}  # fmt: skip
    assert number(plugin, "updateRate") == 10 and number(plugin, "pointCloudCutoff") >= 0
    assert text(plugin, "frameName") == "/" + prefix + "camera_front_optical_frame"
    optical = by_name(root, "joint")[prefix + "camera_front_optical_joint"]
    assert optical.find("parent").get("link") == prefix + "camera_front_link"
    xyz, rpy = origin_of(optical)
    assert xyz == [0, 0, 0] and rpy == pytest.approx([-math.pi / 2, 0, -math.pi / 2])


@PREFIXES
def test_frames_are_the_links_under_every_namespace(prefix):
    """As the plugins resolve frameName (gazebo_ros: tf::resolve with the tf_prefix parameter or else
    the robot's namespace; imu_sensor and hector: as written), every sensor's frame_id is its link,
    whether or not the tf_prefix parameter is set, and the simulator reads every block."""
    sensor_blocks = pytest.importorskip("thorvald_sim.sensors.blocks")
    blocks = sensor_blocks.read_sensor_blocks(urdf_text(STD, prefix))
    assert not blocks.refused and not blocks.unsupported
    links = set(by_name(tree(prefix=prefix), "link"))
    specs = {s.kind: s for s in blocks.sensors}
    assert sorted(specs) == ["depth", "gps", "imu", "laser"]
    for param in ("", prefix.rstrip("/")):
        frames = {k: sensor_blocks.resolve_frame(s, param, "/thorvald_001/") for k, s in specs.items()}
        assert frames == {
            "laser": prefix + "lidar_front_link",
            "imu": prefix + "imu_link",
            "gps": prefix + "gnss_link",
            "depth": prefix + "camera_front_optical_frame",
        }
        assert set(frames.values()) <= links
    assert specs["gps"].config.reference is None  # takes the datum file's


# --- the robot file's sensor keys ------------------------------------------------------------------
def joint_to(root: ET.Element, child: str) -> ET.Element:
    found = [j for j in root.findall("joint") if j.find("child").get("link") == child]
    assert len(found) == 1, child
    return found[0]


@pytest.mark.slow  # a description generated through xacro for every example robot
@PREFIXES
def test_the_robot_files_sensor_keys_place_the_sensors(prefix, tmp_path):
    robot = robot_file_with_sensor_keys(tmp_path)
    root = tree(robot, prefix)
    with open(SENSOR_KEYS) as f:
        keys = yaml.safe_load(f)

    def placed(link, entry):
        joint = joint_to(root, prefix + link)
        assert joint.find("parent").get("link") == prefix + entry["parent_link"]
        xyz, rpy = origin_of(joint)
        assert xyz == pytest.approx([entry["x"], entry["y"], entry["z"]])
        assert rpy == pytest.approx([entry["roll"], entry["pitch"], entry["yaw"]])

    placed("lidar_front_link", keys["lidar_front"])
    placed("lidar_back_link", keys["lidar_back"])
    placed("imu_link", keys["imu"])
    placed("gnss_link", keys["gnss_antenna_main"])
    placed("gnss_aux_link", keys["gnss_antenna_aux"])
    for name, entry in keys["cameras"].items():
        placed(name + "_link", entry)
        assert text(sensor_block(root, prefix + name + "_link"), "plugin/cameraName") == name
    assert prefix + "camera_front_link" not in by_name(root, "link")  # the file's cameras replace the default
    # make "sick": the SICK LMS111, 270 deg at 0.5 deg, 0.5-20 m, 25 Hz
    back = sensor_block(root, prefix + "lidar_back_link")
    assert number(back, "update_rate") == 25 and number(back, "ray/scan/horizontal/samples") == 541
    assert (number(back, "ray/range/min"), number(back, "ray/range/max")) == (0.5, 20.0)
    assert text(back, "plugin/topicName") == "lidar_back/scan"
    assert text(back, "plugin/frameName") == "/" + prefix + "lidar_back_link"
    gnss = [text(p, "bodyName") for p in model_plugin(root, "libhector_gazebo_ros_gps.so")]
    assert sorted(gnss) == [prefix + "gnss_aux_link", prefix + "gnss_link"]


def test_a_lidar_of_make_velodyne_is_a_vlp16(tmp_path):
    with open(STD) as f:
        data = yaml.safe_load(f)
    data["lidar_front"] = {"make": "velodyne", "model": "vlp-16", "parent_link": "base_link", "x": 0.0, "y": 0.0,
                           "z": 1.1, "roll": 0, "pitch": 0, "yaw": 0}  # fmt: skip
    path = tmp_path / "robot.yaml"
    path.write_text(yaml.safe_dump(data))
    sensor = sensor_block(tree(str(path), "r/"), "r/lidar_front_link")
    assert sensor.find("plugin").get("filename") == "libgazebo_ros_velodyne_laser.so"
    assert text(sensor, "plugin/topicName") == "lidar_front/points"


# --- the macros, one by one -------------------------------------------------------------------------
def test_every_macro_alone_with_its_defaults(tmp_path):
    """Every macro in a robot of its own (no thorvald_model.xacro, so no tf_prefix property)."""
    import xacro  # noqa: PLC0415

    path = tmp_path / "robot.xacro"
    path.write_text(f"""<?xml version="1.0"?>
<robot name="bench" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="{MODULES}"/>
  <link name="base_link">
    <inertial><mass value="10"/><inertia ixx="1" ixy="0" ixz="0" iyy="1" iyz="0" izz="1"/></inertial>
  </link>
  <xacro:planar_lidar parent="base_link" name="generic" xyz="0 0 1" gpu="true" visualize="true"/>
  <xacro:hokuyo_utm30lx parent="base_link" name="hokuyo" xyz="0.2 0 1"/>
  <xacro:sick_lms111 parent="base_link" name="sick" xyz="0.4 0 1"/>
  <xacro:vlp16 parent="base_link" name="velodyne" xyz="0 0 1.5"/>
  <xacro:imu parent="base_link" name="imu" xyz="0 0 0.5"/>
  <xacro:gnss_antenna parent="base_link" name="gnss" xyz="0 0 1.8" mast="0.3"/>
  <xacro:rgbd_camera parent="base_link" name="camera" xyz="0.5 0 1"/>
</robot>
""")  # fmt: skip
    root = ET.fromstring(xacro.process_file(str(path), in_order=True).toprettyxml())
    links = by_name(root, "link")
    for name in ("generic", "hokuyo", "sick", "velodyne", "imu", "gnss", "camera"):
        assert joint_to(root, name + "_link").find("parent").get("link") == "base_link"
    assert "camera_optical_frame" in links

    generic = sensor_block(root, "generic_link")
    assert generic.get("type") == "gpu_ray" and text(generic, "visualize") == "true"
    assert generic.find("plugin").get("filename") == "libgazebo_ros_gpu_laser.so"

    sick = sensor_block(root, "sick_link")
    assert number(sick, "update_rate") == 25 and number(sick, "ray/scan/horizontal/samples") == 541
    assert links["sick_link"].find("visual/geometry/mesh") is None  # drawn as its box and window

    velodyne = sensor_block(root, "velodyne_link")
    assert velodyne.get("type") == "ray" and number(velodyne, "update_rate") == 10
    horizontal, vertical = velodyne.find("ray/scan/horizontal"), velodyne.find("ray/scan/vertical")
    assert number(horizontal, "samples") == 440
    assert number(horizontal, "min_angle") == pytest.approx(-math.pi)
    assert number(horizontal, "max_angle") == pytest.approx(math.pi)
    assert number(vertical, "samples") == 16
    assert number(vertical, "min_angle") == pytest.approx(math.radians(-15))
    assert number(vertical, "max_angle") == pytest.approx(math.radians(15))
    assert (number(velodyne, "ray/range/min"), number(velodyne, "ray/range/max")) == (0.3, 100.0)
    plugin = velodyne.find("plugin")
    assert plugin.get("filename") == "libgazebo_ros_velodyne_laser.so"
    assert text(plugin, "topicName") == "velodyne_points" and text(plugin, "frameName") == "/velodyne_link"
    assert (number(plugin, "min_range"), number(plugin, "max_range")) == (0.3, 100.0)
    assert number(plugin, "gaussianNoise") == 0.008 and text(plugin, "organize_cloud") == "false"

    gnss = model_plugin(root, "libhector_gazebo_ros_gps.so")[0]
    assert text(gnss, "topicName") == "fix" and text(gnss, "velocityTopicName") == "fix_velocity"
    assert not [e.tag for e in gnss if e.tag.startswith("reference")]
    assert len(links["gnss_link"].findall("collision")) == 2  # the antenna and its mast

    sensor_blocks = pytest.importorskip("thorvald_sim.sensors.blocks")
    blocks = sensor_blocks.read_sensor_blocks(ET.tostring(root, encoding="unicode"))
    assert not blocks.refused and not blocks.unsupported
    assert sorted(s.kind for s in blocks.sensors) == ["depth", "gps", "imu", "laser", "laser", "laser", "multilayer"]
    assert all(not inertia_problems(link) for link in links.values())


@pytest.mark.parametrize(
    "given, expected",
    [
        ("", {}),
        ('reference_latitude="52.2" reference_longitude="-0.55" reference_heading="90" reference_altitude="40"',
         {"referenceLatitude": 52.2, "referenceLongitude": -0.55, "referenceHeading": 90, "referenceAltitude": 40}),
        ('reference_latitude="0" reference_heading="0"', {"referenceLatitude": 0, "referenceHeading": 0}),
    ],
    ids=["none", "all", "some"],
)  # fmt: skip
@pytest.mark.slow  # a description generated through xacro for every example robot
def test_gnss_reference_elements_are_written_only_when_given(tmp_path, given, expected):
    extras = extras_file(tmp_path, f'<xacro:gnss_antenna parent="${{tf_prefix}}base_link" name="rtk" {given}/>')
    plugin = model_plugin(tree(STD, "r/", extras), "libhector_gazebo_ros_gps.so")[0]
    assert {e.tag: float(e.text) for e in plugin if e.tag.startswith("reference")} == expected
    assert text(plugin, "bodyName") == "r/rtk_link"


def test_a_macros_pose_and_topic_and_rate(tmp_path):
    extras = extras_file(
        tmp_path,
        '<xacro:imu parent="${tf_prefix}top1" name="imu2" xyz="0.01 0.02 0.2" rpy="0.1 0.2 0.3" topic="/abs/imu" '
        'rate="200"/>',
    )
    root = tree(STD, "r/", extras)
    joint = by_name(root, "joint")["r/imu2_joint"]
    assert joint.find("parent").get("link") == "r/top1" and joint.find("child").get("link") == "r/imu2_link"
    assert origin_of(joint) == ([0.01, 0.02, 0.2], [0.1, 0.2, 0.3])
    sensor = sensor_block(root, "r/imu2_link")
    assert number(sensor, "update_rate") == 200 and number(sensor, "plugin/updateRateHZ") == 200
    assert text(sensor, "plugin/topicName") == "/abs/imu"


# --- physical sanity --------------------------------------------------------------------------------
@PREFIXES
def test_the_description_is_one_tree_of_valid_links(prefix):
    root = tree(prefix=prefix)
    links = by_name(root, "link")
    children = [j.find("child").get("link") for j in root.findall("joint")]
    parents = {j.find("parent").get("link") for j in root.findall("joint")}
    assert len(children) == len(set(children)) and set(children) | parents <= set(links)
    assert set(links) - set(children) == {prefix + "base_link"}
    problems = [p for link in links.values() for p in inertia_problems(link)]
    assert not problems
    for link in (prefix + k for k in EXAMPLE_LINKS):
        assert float(links[link].find("inertial/mass").get("value")) > 0


@pytest.mark.skipif(shutil.which("check_urdf") is None, reason="check_urdf (liburdfdom-tools) not installed")
@PREFIXES
def test_check_urdf_accepts_it(prefix, tmp_path):
    path = tmp_path / "robot.urdf"
    path.write_text(urdf_text(STD, prefix))
    result = subprocess.run(["check_urdf", str(path)], capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "Successfully Parsed XML" in result.stdout


@pytest.mark.slow  # a description generated through xacro for every example robot
@pytest.mark.parametrize("robot", EXAMPLE_ROBOTS, ids=robot_id)
def test_the_example_gives_a_valid_description_for_every_example_robot(robot):
    root = tree(robot, "r/")
    links = by_name(root, "link")
    assert {"r/" + k for k in EXAMPLE_LINKS} <= set(links)
    assert all(j.find("parent").get("link") in links for j in root.findall("joint"))


# --- in pybullet --------------------------------------------------------------------------------------
class Loaded:
    """The description in a pybullet DIRECT client, fixed base, every link its own (no merging)."""

    def __init__(self, p, urdf: str, tmp_path):
        description = pytest.importorskip("thorvald_sim.physics.description")
        text_, missing = description.resolve_meshes(
            urdf, description.mesh_finder(lambda name: PKG if name == "thorvald_model" else None)
        )
        assert not missing
        path = tmp_path / "robot.urdf"
        path.write_text(text_)
        self.p = p
        self.client = p.connect(p.DIRECT)
        self.body = p.loadURDF(str(path), useFixedBase=True, physicsClientId=self.client)
        self.links = {
            p.getJointInfo(self.body, i, physicsClientId=self.client)[12].decode(): i
            for i in range(p.getNumJoints(self.body, physicsClientId=self.client))
        }
        self.names = {i: n for n, i in self.links.items()}

    def frame(self, link: str) -> Tuple[np.ndarray, np.ndarray]:
        state = self.p.getLinkState(self.body, self.links[link], computeForwardKinematics=True,
                                    physicsClientId=self.client)  # fmt: skip
        return np.array(state[4]), np.array(self.p.getMatrixFromQuaternion(state[5])).reshape(3, 3)

    def hits(self, link: str, directions: List[np.ndarray], start: float, length: float) -> List[Tuple[str, float]]:
        """What rays from link's origin along directions (in the link's frame) hit, from start to length [m]."""
        origin, rotation = self.frame(link)
        starts = [origin + rotation @ (start * d) for d in directions]
        ends = [origin + rotation @ (length * d) for d in directions]
        results = self.p.rayTestBatch(starts, ends, physicsClientId=self.client)
        return [(self.names.get(r[1], "base"), r[2]) for r in results if r[0] >= 0]

    def close(self):
        self.p.disconnect(self.client)


@pytest.fixture
def loaded(tmp_path):
    p = pytest.importorskip("pybullet")
    robot = Loaded(p, urdf_text(STD, "thorvald_001/"), tmp_path)
    yield robot
    robot.close()


def test_pybullet_loads_it_with_every_sensor_link(loaded):
    assert {"thorvald_001/" + k for k in EXAMPLE_LINKS} <= set(loaded.links)
    origin, _ = loaded.frame("thorvald_001/lidar_front_link")
    assert origin == pytest.approx([0.8, 0.0, 0.65], abs=1e-6)
    _, rotation = loaded.frame("thorvald_001/camera_front_optical_frame")
    _, body = loaded.frame("thorvald_001/camera_front_link")
    assert rotation[:, 2] == pytest.approx(body[:, 0], abs=1e-6)  # optical z is the camera's forward
    assert rotation[:, 0] == pytest.approx(-body[:, 1], abs=1e-6)  # optical x is its right


def test_the_sensors_see_out_clear_of_the_robot(loaded):
    lidar = [np.array([math.cos(a), math.sin(a), 0.0]) for a in np.radians(np.arange(-110, 110.5, 0.5))]
    assert loaded.hits("thorvald_001/lidar_front_link", lidar, 0.1, 10.0) == []
    # at the fan's edges it may see the front towers, nothing nearer than its minimum range
    edges = [np.array([math.cos(a), math.sin(a), 0.0]) for a in np.radians(np.arange(-135, 135.5, 0.5))]
    assert all(name.endswith(("top1", "top3")) for name, _ in loaded.hits("thorvald_001/lidar_front_link", edges,
                                                                          0.1, 10.0))  # fmt: skip
    hfov, aspect = 1.047, 240 / 320
    vfov = 2 * math.atan(math.tan(hfov / 2) * aspect)
    camera = [
        np.array([1.0, math.tan(a), math.tan(e)]) / np.linalg.norm([1.0, math.tan(a), math.tan(e)])
        for a in np.linspace(-hfov / 2, hfov / 2, 21)
        for e in np.linspace(-vfov / 2, vfov / 2, 15)
    ]
    assert loaded.hits("thorvald_001/camera_front_link", camera, 0.05, 10.0) == []
    sky = [
        np.array([math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el)])
        for az in np.radians(np.arange(0, 360, 10))
        for el in np.radians([10, 20, 40, 60, 80, 90])
    ]
    origin, _ = loaded.frame("thorvald_001/gnss_link")
    above = origin + np.array([0.0, 0.0, 0.07])  # over the antenna's top
    results = loaded.p.rayTestBatch([above] * len(sky), [above + 10 * d for d in sky], physicsClientId=loaded.client)
    assert [r for r in results if r[0] >= 0] == []


def test_no_sensor_overlaps_the_robot(loaded, tmp_path):
    p = loaded.p
    twin = p.loadURDF(str(tmp_path / "robot.urdf"), useFixedBase=True, physicsClientId=loaded.client)
    for sensor in ("lidar_front_link", "imu_link", "gnss_link", "camera_front_link"):
        a = loaded.links["thorvald_001/" + sensor]
        for name, b in loaded.links.items():
            if b != a:
                touching = p.getClosestPoints(loaded.body, twin, 0.0, a, b, physicsClientId=loaded.client)
                assert not touching, f"{sensor} overlaps {name}"
