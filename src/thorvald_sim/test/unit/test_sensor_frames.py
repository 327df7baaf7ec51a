"""Frame ids a sensor publishes, and the links model plugins name, as tf2 reads them: no leading
slash, no doubled slash (thorvald_sim.sensors.blocks, without pybullet)."""

import pytest

from thorvald_sim.sensors.blocks import read_sensor_blocks, resolve_frame


def robot(*blocks: str) -> str:
    return f"""<robot name="r">
  <link name="r1/base_link"/>
  <link name="r1/imu_link"/>
  <joint name="imu_joint" type="fixed"><parent link="r1/base_link"/><child link="r1/imu_link"/></joint>
  {"".join(blocks)}
</robot>"""


def model_plugins(body: str) -> str:
    return f"""<gazebo>
  <plugin name="truth" filename="libgazebo_ros_p3d.so"><bodyName>{body}</bodyName><topicName>truth</topicName>
    <frameName>world</frameName></plugin>
  <plugin name="gps" filename="libhector_gazebo_ros_gps.so"><bodyName>{body}</bodyName></plugin>
  <plugin name="imu" filename="libgazebo_ros_imu.so"><bodyName>{body}</bodyName><topicName>imu</topicName></plugin>
</gazebo>"""


@pytest.mark.parametrize("body", ["r1/base_link", "/r1/base_link", "r1//base_link", "/r1//base_link"])
def test_a_model_plugins_body_is_the_robots_link_however_slashed(body):
    blocks = read_sensor_blocks(robot(model_plugins(body)))
    assert not blocks.refused
    specs = {s.name: s for s in blocks.sensors}
    assert {s.link for s in specs.values()} == {"r1/base_link"}
    # nav_msgs/Odometry's child_frame_id is the body
    assert specs["truth"].child_frame == "r1/base_link"
    # gazebo_ros_imu's frameName defaults to the body, published as written: here without its slash
    assert resolve_frame(specs["imu"], "", "/r1") == "r1/base_link"
    # hector's frameId defaults to /world
    assert resolve_frame(specs["gps"], "", "/r1") == "world"


@pytest.mark.parametrize(
    "frame, tf_prefix, resolved",
    [
        ("/r1/imu_link", "", "r1/imu_link"),  # absolute: tf::resolve keeps it, without its slash
        ("imu_link", "r1/", "r1/imu_link"),  # a tf_prefix ending in a slash, joined with another
        ("imu_link", "/r1/", "r1/imu_link"),
        ("r1//imu_link", "", "r1/imu_link"),  # relative, no prefix: as written, the doubled slash collapsed
    ],
)
def test_a_laser_frame_resolved_has_no_leading_or_doubled_slash(frame, tf_prefix, resolved):
    laser = f"""<gazebo reference="r1/imu_link"><sensor type="ray" name="l"><ray><scan><horizontal>
      <samples>9</samples><min_angle>-1</min_angle><max_angle>1</max_angle></horizontal></scan>
      <range><min>0.1</min><max>10</max></range></ray>
      <plugin name="p" filename="libgazebo_ros_laser.so"><frameName>{frame}</frameName></plugin></sensor></gazebo>"""
    (spec,) = read_sensor_blocks(robot(laser)).sensors
    assert resolve_frame(spec, tf_prefix, "/") == resolved


def test_an_imu_sensor_frame_written_with_a_slash_is_published_without():
    imu = """<gazebo reference="r1/imu_link"><sensor type="imu" name="i">
      <plugin name="p" filename="libgazebo_ros_imu_sensor.so"><frameName>/r1/imu_link</frameName></plugin>
      </sensor></gazebo>"""
    (spec,) = read_sensor_blocks(robot(imu)).sensors
    assert spec.frame == "/r1/imu_link"  # the block as written
    assert resolve_frame(spec, "", "/r1") == "r1/imu_link"
