"""Gazebo sensor blocks read as gazebo_ros's plugins read them (thorvald_sim.sensors.blocks): names,
defaults, topics, frames, and a broken block refusing that sensor only."""

import math
import os

import pytest

from thorvald_model.description import generate_urdf
from thorvald_sim.physics.description import parse_description
from thorvald_sim.sensors.blocks import (
    HECTOR_REFERENCE,
    Datum,
    gps_reference,
    read_sensor_blocks,
    resolve_frame,
    resolve_topic,
    tf_resolve,
)

LIDAR = """
  <gazebo reference="lidar_link">
    <sensor type="ray" name="front_lidar">
      <pose>0 0 0.05 0 0 0</pose>
      <update_rate>40</update_rate>
      <ray>
        <scan><horizontal><samples>1081</samples><resolution>1</resolution>
          <min_angle>-2.356194</min_angle><max_angle>2.356194</max_angle></horizontal></scan>
        <range><min>0.10</min><max>30.0</max><resolution>0.01</resolution></range>
        <noise><type>gaussian</type><mean>0.0</mean><stddev>0.01</stddev></noise>
      </ray>
      <plugin name="lidar_plugin" filename="libgazebo_ros_laser.so">
        <topicName>scan</topicName>
        <frameName>lidar_link</frameName>
      </plugin>
    </sensor>
  </gazebo>"""


def robot(*blocks: str) -> str:
    return f"""<robot name="r">
  <link name="base_link"/>
  <link name="lidar_link"/>
  <link name="imu_link"/>
  <joint name="lidar_joint" type="fixed"><parent link="base_link"/><child link="lidar_link"/></joint>
  <joint name="imu_joint" type="fixed"><parent link="base_link"/><child link="imu_link"/></joint>
  {"".join(blocks)}
</robot>"""


def test_a_laser_block_gives_its_values_topic_and_frame():
    blocks = read_sensor_blocks(robot(LIDAR))
    assert not blocks.refused and not blocks.unsupported
    (s,) = blocks.sensors
    assert (s.kind, s.name, s.link, s.rate, s.plugin) == (
        "laser",
        "front_lidar",
        "lidar_link",
        40.0,
        "libgazebo_ros_laser.so",
    )
    assert s.pose.xyz == (0.0, 0.0, 0.05)
    c = s.config
    assert (c.samples, c.vertical_samples, c.range_min, c.range_max, c.noise_stddev) == (1081, 1, 0.1, 30.0, 0.01)
    # 270 degrees in 1080 steps: 0.25 degrees
    assert math.degrees(c.angle_increment) == pytest.approx(0.25, abs=1e-5)
    assert resolve_topic(s, "scan", "/thorvald_001") == "/thorvald_001/scan"
    # gazebo_ros_laser resolves frameName with the robot's namespace as tf_prefix (tf::resolve)
    assert resolve_frame(s, "", "/thorvald_001") == "thorvald_001/lidar_link"
    assert resolve_frame(s, "", "/") == "lidar_link"
    assert resolve_frame(s, "robot_x", "/thorvald_001") == "robot_x/lidar_link"


def test_plugin_defaults_are_the_plugins_own():
    bare = LIDAR.replace("<topicName>scan</topicName>", "").replace("<frameName>lidar_link</frameName>", "")
    (s,) = read_sensor_blocks(robot(bare)).sensors
    # gazebo_ros_laser: both default to /world
    assert resolve_topic(s, "scan", "/thorvald_001") == "/world"
    assert resolve_frame(s, "", "/thorvald_001") == "world"


@pytest.mark.parametrize(
    "prefix, frame, resolved",
    [
        ("", "base_link", "base_link"),
        ("t1", "laser", "t1/laser"),
        ("/t1", "laser", "t1/laser"),
        ("t1", "/abs/laser", "abs/laser"),
    ],
)
def test_tf_resolve_as_ros1(prefix, frame, resolved):
    assert tf_resolve(prefix, frame) == resolved


@pytest.mark.parametrize(
    "broken, path, rule",
    [
        ("<samples>1081</samples>", "sensor[@name='front_lidar']/ray/scan/horizontal/samples", "missing"),
        ("<update_rate>40</update_rate>", "sensor[@name='front_lidar']/update_rate", "must be >= 0"),
        ("<max>30.0</max>", "sensor[@name='front_lidar']/ray/range/max", "must be > min"),
    ],
)
def test_a_broken_block_refuses_that_sensor_only(broken, path, rule):
    replacement = {
        "<samples>1081</samples>": "",
        "<update_rate>40</update_rate>": "<update_rate>-5</update_rate>",
        "<max>30.0</max>": "<max>0.05</max>",
    }[broken]
    bad = LIDAR.replace(broken, replacement)
    good = LIDAR.replace("front_lidar", "back_lidar")
    blocks = read_sensor_blocks(robot(bad, good))
    assert [s.name for s in blocks.sensors] == ["back_lidar"]
    (refused,) = blocks.refused
    assert refused.link == "lidar_link" and refused.path == path and rule in refused.rule
    assert "lidar_link" in str(refused) and path in str(refused)


def test_other_sensors_and_plugins_are_listed_by_name_and_link():
    contact = """<gazebo reference="imu_link"><sensor type="contact" name="bumper">
      <plugin name="b" filename="libContactPlugin.so"/></sensor></gazebo>"""
    model = """<gazebo><plugin name="mover" filename="libgazebo_ros_planar_move.so"/></gazebo>"""
    blocks = read_sensor_blocks(robot(contact, model))
    assert not blocks.sensors
    assert [(u.what, u.link) for u in blocks.unsupported] == [
        ("sensor contact 'bumper' (libContactPlugin.so)", "imu_link"),
        ("model plugin 'mover' (libgazebo_ros_planar_move.so)", ""),
    ]


def test_multilayer_lidars():
    vlp = LIDAR.replace(
        "</horizontal></scan>",
        "</horizontal><vertical><samples>16</samples><min_angle>-0.2618</min_angle>"
        "<max_angle>0.2618</max_angle></vertical></scan>",
    ).replace(
        '<plugin name="lidar_plugin" filename="libgazebo_ros_laser.so">',
        '<plugin name="v" filename="libgazebo_ros_velodyne_laser.so"><min_range>0.9</min_range>'
        "<max_range>100</max_range><gaussianNoise>0.008</gaussianNoise>",
    )
    (s,) = read_sensor_blocks(robot(vlp)).sensors
    assert s.kind == "multilayer"
    assert (s.config.vertical_samples, s.config.range_min, s.config.range_max) == (16, 0.9, 30.0)
    assert s.config.noise_stddev == 0.008
    assert resolve_topic(s, "points", "/r1") == "/r1/scan"
    # velodyne's plugin: tf::resolve with the namespace first, then the tf_prefix parameter
    assert resolve_frame(s, "other", "/r1") == "r1/lidar_link"
    assert resolve_frame(s, "other", "/") == "other/lidar_link"


def test_imu_sensor_and_imu_model_plugin():
    sensor = """<gazebo reference="imu_link"><sensor type="imu" name="imu"><update_rate>200</update_rate>
      <plugin name="i" filename="libgazebo_ros_imu_sensor.so"><topicName>imu/data</topicName>
      <frameName>imu_link</frameName><updateRateHZ>100</updateRateHZ><gaussianNoise>0.001</gaussianNoise>
      </plugin></sensor></gazebo>"""
    model = """<gazebo><plugin name="imu_plugin" filename="libgazebo_ros_imu.so"><bodyName>base_link</bodyName>
      <topicName>imu_base</topicName><updateRate>50</updateRate><gaussianNoise>0.0</gaussianNoise>
      </plugin></gazebo>"""
    a, b = read_sensor_blocks(robot(sensor, model)).sensors
    assert (a.kind, a.rate, a.config.noise, a.frame) == ("imu", 100.0, 0.001, "imu_link")
    assert resolve_topic(a, "imu", "/r1") == "/r1/imu/data"
    assert (b.kind, b.link, b.rate, b.frame) == ("imu", "base_link", 50.0, "base_link")
    no_frame = sensor.replace("<frameName>imu_link</frameName>", "")
    (refused,) = read_sensor_blocks(robot(no_frame)).refused
    assert refused.path.endswith("frameName") and "missing" in refused.rule


def test_hector_gps_reference_from_itself_the_datum_or_hectors_default():
    plain = """<gazebo><plugin name="gps" filename="libhector_gazebo_ros_gps.so"><updateRate>10</updateRate>
      <bodyName>imu_link</bodyName><frameId>imu_link</frameId><topicName>gps/fix</topicName>
      <gaussianNoise>0.02 0.02 0.02</gaussianNoise></plugin></gazebo>"""
    (s,) = read_sensor_blocks(robot(plain)).sensors
    assert (s.kind, s.rate, s.link, s.config.position.gaussian_noise) == ("gps", 10.0, "imu_link", (0.02,) * 3)
    assert resolve_topic(s, "velocity", "/r1") == "/r1/fix_velocity"
    assert gps_reference(s, None) == HECTOR_REFERENCE
    datum = Datum(53.27, -0.52, 0.0)
    # robot_localization's heading is the ENU yaw of x (0: east); hector's the compass heading (90: east)
    assert gps_reference(s, datum) == (53.27, -0.52, 90.0, 0.0)
    own = plain.replace("<updateRate>", "<referenceLatitude>10</referenceLatitude><updateRate>")
    (s,) = read_sensor_blocks(robot(own)).sensors
    assert gps_reference(s, datum)[:3] == (10.0, HECTOR_REFERENCE[1], HECTOR_REFERENCE[2])


def test_cameras_and_depth_cameras():
    camera = """<gazebo reference="imu_link"><sensor type="depth" name="rgbd"><update_rate>10</update_rate>
      <camera><horizontal_fov>1.2</horizontal_fov><image><width>64</width><height>48</height>
      <format>B8G8R8</format></image><clip><near>0.05</near><far>20</far></clip></camera>
      <plugin name="k" filename="libgazebo_ros_openni_kinect.so"><cameraName>rgbd</cameraName>
      <imageTopicName>color/image_raw</imageTopicName><depthImageTopicName>depth/image_rect</depthImageTopicName>
      <pointCloudTopicName>depth/points</pointCloudTopicName><frameName>rgbd_optical</frameName>
      </plugin></sensor></gazebo>"""
    (s,) = read_sensor_blocks(robot(camera)).sensors
    c = s.config
    assert (s.kind, c.width, c.height, c.encoding, c.near, c.far, c.depth) == (
        "depth",
        64,
        48,
        "bgr8",
        0.05,
        20.0,
        True,
    )
    assert c.focal_length == pytest.approx(64 / (2 * math.tan(0.6)))
    topics = {role: resolve_topic(s, role, "/r1") for role in s.topics}
    assert topics == {
        "image": "/r1/rgbd/color/image_raw",
        "camera_info": "/r1/rgbd/camera_info",
        "depth": "/r1/rgbd/depth/image_rect",
        "depth_info": "/r1/rgbd/depth/camera_info",
        "points": "/r1/rgbd/depth/points",
    }
    bad = camera.replace("<format>B8G8R8</format>", "<format>YUV</format>")
    (refused,) = read_sensor_blocks(robot(bad)).refused
    assert refused.path.endswith("camera/image/format")


def test_p3d():
    p3d = """<gazebo><plugin name="truth" filename="libgazebo_ros_p3d.so"><bodyName>base_link</bodyName>
      <topicName>ground_truth</topicName><frameName>map</frameName><updateRate>50</updateRate>
      <xyzOffsets>1 2 3</xyzOffsets></plugin></gazebo>"""
    (s,) = read_sensor_blocks(robot(p3d)).sensors
    assert (s.kind, s.link, s.rate, s.config.reference_frame, s.config.xyz_offsets) == (
        "p3d", "base_link", 50.0, "world", (1.0, 2.0, 3.0),
    )  # fmt: skip
    no_link = p3d.replace("<bodyName>base_link</bodyName>", "<bodyName>nowhere</bodyName>")
    (refused,) = read_sensor_blocks(robot(no_link)).refused
    assert "nowhere" in refused.rule and refused.path.endswith("bodyName")


def test_a_sensor_on_a_link_the_description_lacks_is_refused():
    blocks = read_sensor_blocks(robot(LIDAR.replace('reference="lidar_link"', 'reference="elsewhere"')))
    assert not blocks.sensors
    assert blocks.refused[0].link == "elsewhere" and "not in the description" in blocks.refused[0].rule


def test_the_generators_datum_is_the_descriptions(tmp_path):
    here = os.path.dirname(os.path.abspath(__file__))
    std = os.path.join(here, "..", "..", "..", "thorvald_model", "config", "thorvald_ii_4wd4ws_std",
                       "thorvald_ii_4wd4ws_std.yaml")  # fmt: skip
    path = tmp_path / "datum.yaml"
    path.write_text("datum: [53.268642, -0.524509, 0.0]\naltitude: 12.5\n")
    assert parse_description(generate_urdf(std, datum_file=str(path))).datum == Datum(53.268642, -0.524509, 0.0, 12.5)
    assert parse_description(generate_urdf(std)).datum is None
