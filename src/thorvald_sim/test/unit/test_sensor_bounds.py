"""What one reading may cost, bounded when the blocks are read (thorvald_sim.sensors.blocks): each bound
holds at its limit and refuses one past it, with the link, the element path, the value and the rule,
and the robot keeps its other sensors."""

import pytest

from thorvald_sim.sensors.blocks import MAX_IMAGE_PIXELS, MAX_IMAGE_SIDE, MAX_RAYS, read_sensor_blocks

IMU = """<gazebo reference="imu_link"><sensor type="imu" name="imu"><update_rate>100</update_rate>
  <plugin name="i" filename="libgazebo_ros_imu_sensor.so"><topicName>imu</topicName>
  <frameName>imu_link</frameName></plugin></sensor></gazebo>"""


def camera(width: int, height: int, kind: str = "camera") -> str:
    plugin = "libgazebo_ros_camera.so" if kind == "camera" else "libgazebo_ros_openni_kinect.so"
    return f"""<gazebo reference="camera_link"><sensor type="{kind}" name="cam"><update_rate>10</update_rate>
      <camera><image><width>{width}</width><height>{height}</height></image></camera>
      <plugin name="c" filename="{plugin}"><cameraName>cam</cameraName></plugin></sensor></gazebo>"""


def lidar(samples: int, vertical: int = 0, plugin: str = "libgazebo_ros_velodyne_laser.so") -> str:
    layers = f"<vertical><samples>{vertical}</samples><min_angle>-0.3</min_angle><max_angle>0.3</max_angle></vertical>"
    return f"""<gazebo reference="lidar_link"><sensor type="ray" name="lidar"><update_rate>10</update_rate>
      <ray><scan><horizontal><samples>{samples}</samples><min_angle>-3.1</min_angle><max_angle>3.1</max_angle>
      </horizontal>{layers if vertical else ""}</scan><range><min>0.3</min><max>100</max></range></ray>
      <plugin name="l" filename="{plugin}"><topicName>points</topicName></plugin></sensor></gazebo>"""


def robot(*blocks: str) -> str:
    return f"""<robot name="r">
  <link name="base_link"/><link name="camera_link"/><link name="lidar_link"/><link name="imu_link"/>
  <joint name="c" type="fixed"><parent link="base_link"/><child link="camera_link"/></joint>
  <joint name="l" type="fixed"><parent link="base_link"/><child link="lidar_link"/></joint>
  <joint name="i" type="fixed"><parent link="base_link"/><child link="imu_link"/></joint>
  {"".join(blocks)}
</robot>"""


def refusal(block: str):
    """The one refusal of a robot with block and an IMU; the IMU is kept."""
    blocks = read_sensor_blocks(robot(block, IMU))
    assert [s.name for s in blocks.sensors] == ["imu"]
    (refused,) = blocks.refused
    return refused


def test_the_limits_pass_the_real_sensors_they_are_chosen_for():
    # a 4K camera (UHD and DCI), a Kinect v2 (1920 x 1080, also as a depth camera), a 128-channel
    # lidar at 2048 and at 4096 columns (Ouster's densest mode), a planar lidar of 1081 beams
    sensors = [
        camera(3840, 2160),
        camera(4096, 2160).replace('name="cam"', 'name="dci"'),
        camera(1920, 1080, "depth").replace('name="cam"', 'name="kinect"'),
        lidar(2048, 128),
        lidar(4096, 128).replace('name="lidar"', 'name="os1"'),
        lidar(1081, 0, "libgazebo_ros_laser.so").replace('name="lidar"', 'name="hokuyo"'),
    ]
    blocks = read_sensor_blocks(robot(*sensors))
    assert not blocks.refused
    assert [s.name for s in blocks.sensors] == ["cam", "dci", "kinect", "lidar", "os1", "hokuyo"]


@pytest.mark.parametrize("kind", ["camera", "depth"])
@pytest.mark.parametrize("side", ["width", "height"])
def test_a_cameras_side_at_the_limit_passes_and_one_pixel_more_is_refused(kind, side):
    size = {"width": 1, "height": 1}
    size[side] = MAX_IMAGE_SIDE  # 8192 x 1: its pixels are far within MAX_IMAGE_PIXELS
    (spec,) = read_sensor_blocks(robot(camera(size["width"], size["height"], kind))).sensors
    assert getattr(spec.config, side) == 8192
    size[side] = MAX_IMAGE_SIDE + 1
    refused = refusal(camera(size["width"], size["height"], kind))
    assert refused.link == "camera_link"
    assert refused.path == f"sensor[@name='cam']/camera/image/{side}"
    assert refused.rule.startswith("8193 must be <= 8192 pixels")
    assert str(refused) == f"link camera_link: sensor[@name='cam']/camera/image/{side}: {refused.rule}"


@pytest.mark.parametrize("kind", ["camera", "depth"])
def test_a_cameras_pixels_at_the_limit_pass_and_one_row_more_is_refused(kind):
    # 4096 x 4096 = 2^24 = MAX_IMAGE_PIXELS; 4096 x 4097 = 16781312, each side within 8192
    (spec,) = read_sensor_blocks(robot(camera(4096, 4096, kind))).sensors
    assert spec.config.width * spec.config.height == MAX_IMAGE_PIXELS == 16777216
    refused = refusal(camera(4096, 4097, kind))
    assert (refused.link, refused.path) == ("camera_link", "sensor[@name='cam']/camera/image")
    assert refused.rule.startswith("width x height = 4096 x 4097 = 16781312 pixels must be <= 16777216")


def test_the_camera_that_crashed_pybullet_is_refused_at_its_width():
    # 100000 x 100000 = 10^10 pixels: pybullet's byte counts in C int overflow past 2^29 pixels
    refused = refusal(camera(100000, 100000))
    assert refused.path.endswith("camera/image/width") and refused.rule.startswith("100000 must be <= 8192")


@pytest.mark.parametrize("plugin", ["libgazebo_ros_velodyne_laser.so", "libgazebo_ros_laser.so"])
def test_a_lidars_samples_at_the_limit_pass_and_one_more_is_refused(plugin):
    # one row of 2^19 = 524288 beams is MAX_RAYS rays
    (spec,) = read_sensor_blocks(robot(lidar(MAX_RAYS, 0, plugin))).sensors
    assert spec.config.samples * spec.config.vertical_samples == 524288
    refused = refusal(lidar(MAX_RAYS + 1, 0, plugin))
    assert (refused.link, refused.path) == ("lidar_link", "sensor[@name='lidar']/ray/scan/horizontal/samples")
    assert refused.rule.startswith("524289 must be <= 524288 rays a reading")


def test_a_lidars_vertical_samples_alone_past_the_limit_are_refused_at_their_element():
    refused = refusal(lidar(1, MAX_RAYS + 1))
    assert refused.path == "sensor[@name='lidar']/ray/scan/vertical/samples"
    assert refused.rule.startswith("524289 must be <= 524288")


@pytest.mark.parametrize("plugin", ["libgazebo_ros_velodyne_laser.so", "libgazebo_ros_block_laser.so"])
def test_a_lidars_rays_at_the_limit_pass_and_one_column_more_is_refused(plugin):
    # 4096 columns x 128 channels = 524288 = MAX_RAYS; 4097 x 128 = 524416
    (spec,) = read_sensor_blocks(robot(lidar(4096, 128, plugin))).sensors
    assert (spec.kind, spec.config.samples, spec.config.vertical_samples) == ("multilayer", 4096, 128)
    refused = refusal(lidar(4097, 128, plugin))
    assert (refused.link, refused.path) == ("lidar_link", "sensor[@name='lidar']/ray/scan")
    assert refused.rule.startswith("samples x vertical samples = 4097 x 128 = 524416 must be <= 524288")


def test_the_lidar_that_stalled_the_clock_is_refused():
    # 10^7 rays a reading (10000 x 1000), each side within MAX_RAYS
    refused = refusal(lidar(10000, 1000))
    assert refused.path.endswith("ray/scan") and "= 10000000 must be <= 524288" in refused.rule


def test_the_bounds_are_what_the_docs_say():
    assert (MAX_IMAGE_SIDE, MAX_IMAGE_PIXELS, MAX_RAYS) == (8192, 4096 * 4096, 4096 * 128)
