"""Sensors in the pybullet world (thorvald_sim.sensors.mounted), each checked against figures the geometry gives.

The test robot is a 0.4 m box (base_link on the ground) with a sensor mast: the lidar's and the
camera's links 1 m above the ground, fixed to base_link through an intermediate link (so pybullet
merges them into the base and the mount is found through two fixed joints).
"""

import math

import numpy as np
import pybullet as p
import pytest

import thorvald_sim.sensors.kinds.lidar as lidar_module
from thorvald_sim.physics.robot import Pose2D
from thorvald_sim.physics.simulation import Simulation
from thorvald_sim.sensors.blocks import Datum
from thorvald_sim.sensors.mounted import (
    OK,
    WARN,
    WGS84_A,
    WGS84_E2,
    InstantNoise,
    SensorUse,
    beams,
    depth_to_points,
    ranges_from_hits,
    sensor_report,
)
from thorvald_sim.world import parse_world

INERTIAL = '<inertial><mass value="{m}"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'

LIDAR = """<gazebo reference="lidar_link"><sensor type="ray" name="lidar"><update_rate>40</update_rate>
  <ray><scan><horizontal><samples>1081</samples><min_angle>-2.356194490</min_angle>
  <max_angle>2.356194490</max_angle></horizontal></scan>
  <range><min>0.1</min><max>30</max><resolution>0.01</resolution></range>
  <noise><type>gaussian</type><mean>0</mean><stddev>{stddev}</stddev></noise></ray>
  <plugin name="l" filename="libgazebo_ros_laser.so">
  <topicName>scan</topicName><frameName>lidar_link</frameName></plugin>
  </sensor></gazebo>"""

LAYERS = """<gazebo reference="lidar_link"><sensor type="ray" name="vlp"><update_rate>10</update_rate>
  <ray><scan><horizontal><samples>360</samples>
  <min_angle>-3.14159</min_angle><max_angle>3.14159</max_angle></horizontal>
  <vertical><samples>16</samples><min_angle>-0.261799</min_angle><max_angle>0.261799</max_angle></vertical></scan>
  <range><min>0.3</min><max>50</max></range></ray>
  <plugin name="v" filename="libgazebo_ros_velodyne_laser.so"><topicName>points</topicName></plugin>
  </sensor></gazebo>"""

IMU = """<gazebo reference="imu_link"><sensor type="imu" name="imu"><update_rate>100</update_rate>
  <plugin name="i" filename="libgazebo_ros_imu_sensor.so"><topicName>imu</topicName><frameName>imu_link</frameName>
  <updateRateHZ>100</updateRateHZ></plugin></sensor></gazebo>"""

GPS = """<gazebo><plugin name="gps" filename="libhector_gazebo_ros_gps.so"><updateRate>10</updateRate>
  <bodyName>base_link</bodyName><frameId>base_link</frameId></plugin></gazebo>"""

CAMERA = """<gazebo reference="camera_link"><sensor type="depth" name="rgbd"><update_rate>10</update_rate>
  <camera><horizontal_fov>1.0</horizontal_fov><image><width>80</width><height>60</height></image>
  <clip><near>0.05</near><far>20</far></clip></camera>
  <plugin name="k" filename="libgazebo_ros_openni_kinect.so"><cameraName>rgbd</cameraName>
  <frameName>camera_optical</frameName><pointCloudCutoffMax>10</pointCloudCutoffMax></plugin></sensor></gazebo>"""

P3D = """<gazebo><plugin name="truth" filename="libgazebo_ros_p3d.so"><bodyName>lidar_link</bodyName>
  <topicName>truth</topicName><updateRate>20</updateRate></plugin></gazebo>"""


def robot_urdf(*blocks: str) -> str:
    return f"""<robot name="probe">
  <link name="base_link">{INERTIAL.format(m=20)}
    <collision><origin xyz="0 0 0.1"/><geometry><box size="0.4 0.4 0.2"/></geometry></collision></link>
  <link name="mast">{INERTIAL.format(m=0.5)}</link>
  <link name="lidar_link">{INERTIAL.format(m=0.2)}</link>
  <link name="camera_link">{INERTIAL.format(m=0.2)}</link>
  <link name="imu_link">{INERTIAL.format(m=0.1)}</link>
  <joint name="mast_joint" type="fixed"><origin xyz="0 0 0.5"/><parent link="base_link"/><child link="mast"/></joint>
  <joint name="lidar_joint" type="fixed"><origin xyz="0 0 0.5"/><parent link="mast"/><child link="lidar_link"/></joint>
  <joint name="camera_joint" type="fixed"><origin xyz="0.1 0 0.5"/>
    <parent link="mast"/><child link="camera_link"/></joint>
  <joint name="imu_joint" type="fixed"><origin xyz="0 0 0.1"/>
    <parent link="base_link"/><child link="imu_link"/></joint>
  {"".join(blocks)}
</robot>"""


@pytest.fixture
def world():
    client = p.connect(p.DIRECT)
    yield client
    p.disconnect(client)


def simulation(client, *blocks, datum=None, seed=0):
    sim = Simulation(client, parse_world({}), seed=seed, datum=datum)
    robot = sim.spawn("probe", robot_urdf(*blocks), Pose2D())
    for _ in range(480):  # settle on the ground
        sim.step()
    return sim, robot


def box(client, half, centre, rgba=(0.5, 0.5, 0.5, 1)):
    shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=client)
    visual = p.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=rgba, physicsClientId=client)
    return p.createMultiBody(0, shape, visual, centre, physicsClientId=client)


def readings(sim, sensor, n):
    """n readings of sensor as the simulator takes them (after physics steps, when due): {index on the
    sensor's schedule: reading}."""
    out = {}
    while len(out) < n:
        sim.step()
        if sensor.due(sim.time):
            out[sensor.reading] = sensor.read(sim.time)
    return out


def test_a_lidar_reads_the_geometry(world):
    sim, robot = simulation(world, LIDAR.format(stddev=0.01))
    (lidar,) = robot.sensors
    # a box whose face is 3 m ahead (centre 3.5 m, 1 m deep), 2 m wide, 3 m high
    box(world, (0.5, 1.0, 1.5), (3.5, 0.0, 1.5))
    # a post (radius 0.1 m) 2 m away at +30 degrees: its near side 1.9 m from the lidar
    post = p.createCollisionShape(p.GEOM_CYLINDER, radius=0.1, height=3.0, physicsClientId=world)
    p.createMultiBody(0, post, -1, (2 * math.cos(math.radians(30)), 2 * math.sin(math.radians(30)), 1.5),
                      physicsClientId=world)  # fmt: skip
    scans = [scan.ranges[0] for scan in readings(sim, lidar, 20).values()]
    ranges = np.mean(scans, axis=0)
    c = lidar.spec.config
    ahead = round((0.0 - c.min_angle) / c.angle_increment)  # beam 540 points straight ahead
    assert ahead == 540
    # 20 scans of noise 0.01: the mean within 3 standard deviations of it (0.01 / sqrt(20) each)
    assert ranges[ahead] == pytest.approx(3.0, abs=3 * 0.01 / math.sqrt(20) + 0.002)
    post_beam = round((math.radians(30) - c.min_angle) / c.angle_increment)
    assert ranges[post_beam] == pytest.approx(1.9, abs=0.01)
    # nothing behind to the left, 1 m above flat ground: no return
    assert np.isinf(scans[0][round((math.radians(120) - c.min_angle) / c.angle_increment)])
    # the noise: one scan's spread on the flat box face around the true value
    face = np.array([s[ahead - 3 : ahead + 4] for s in scans]).ravel()
    true = np.array([3.0 / math.cos(k * c.angle_increment) for k in range(-3, 4)] * 20)
    assert np.std(face - true) == pytest.approx(0.01, rel=0.3)


TURRET = f"""<robot name="turret">
  <link name="base_link"><inertial><origin xyz="0.15 -0.1 0.05" rpy="0 0 0.3"/><mass value="20"/>
    <inertia ixx="0.5" iyy="0.5" izz="0.5" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><origin xyz="0 0 0.1"/><geometry><box size="0.4 0.4 0.2"/></geometry></collision></link>
  <link name="turret"><inertial><origin xyz="0.05 0.05 0.02" rpy="0.1 0 0"/><mass value="1"/>
    <inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial></link>
  <link name="lidar_link">{INERTIAL.format(m=0.2)}</link>
  <joint name="turret_joint" type="revolute"><origin xyz="0 0 0.5"/><axis xyz="0 0 1"/>
    <limit lower="-3" upper="3" effort="100" velocity="1"/><parent link="base_link"/><child link="turret"/></joint>
  <joint name="lidar_joint" type="fixed"><origin xyz="0 0 0.5"/>
    <parent link="turret"/><child link="lidar_link"/></joint>
  {LIDAR.format(stddev=0.0)}
</robot>"""


def test_a_lidar_on_a_moving_link_turns_with_it(world):
    # the lidar 1 m up on a turret turned to +90 degrees; both links' centres of mass off their
    # frames (pybullet casts the beams in a link's centre-of-mass frame): its straight-ahead beam
    # looks along world +y at a box face 3 m away, and along world +x it sees nothing
    sim = Simulation(world, parse_world({}))
    robot = sim.spawn("turret", TURRET, Pose2D())
    joint = robot.joint_index["turret_joint"]
    p.setJointMotorControl2(robot.body, joint, p.POSITION_CONTROL, targetPosition=math.pi / 2, force=500,
                            physicsClientId=world)  # fmt: skip
    for _ in range(480):
        sim.step()
    assert p.getJointState(robot.body, joint, physicsClientId=world)[0] == pytest.approx(math.pi / 2, abs=1e-3)
    box(world, (1.0, 0.5, 1.5), (0.0, 3.5, 1.5))
    (lidar,) = robot.sensors
    c = lidar.spec.config
    ranges = lidar.read(sim.time).ranges[0]
    ahead = round((0.0 - c.min_angle) / c.angle_increment)
    assert ranges[ahead] == pytest.approx(3.0, abs=0.01)
    assert np.isinf(ranges[round((math.radians(-90) - c.min_angle) / c.angle_increment)])  # world +x: nothing


def test_a_multilayer_lidar_ring_hits_a_wall_at_the_height_its_angle_gives(world):
    sim, robot = simulation(world, LAYERS)
    box(world, (0.1, 5.0, 3.0), (5.1, 0.0, 3.0))  # a wall whose face is 5 m ahead
    scan = robot.sensors[0].read(sim.time)
    c = robot.sensors[0].spec.config
    ahead = round((0.0 - c.min_angle) / c.angle_increment)
    top = scan.ranges[15, ahead]  # the top ring, +15 degrees
    height = 1.0 + top * math.sin(math.radians(15))
    # the ring's point on the wall: 5 m ahead, 1 m + 5 tan(15 deg) = 2.34 m up
    assert top * math.cos(math.radians(15)) == pytest.approx(5.0, abs=0.01)
    assert height == pytest.approx(1.0 + 5.0 * math.tan(math.radians(15)), abs=0.01)
    # the bottom ring (-15 degrees) hits the ground 1 / tan(15 deg) = 3.73 m ahead, before the wall
    assert scan.ranges[0, ahead] == pytest.approx(1.0 / math.sin(math.radians(15)), abs=0.02)


def test_a_low_lidar_sees_its_own_robot(world):
    # the lidar on imu_link (0.1 m up), and a 0.1 m block of the robot itself (a "wheel" on
    # camera_link, which is 0.1 m ahead and 1 m up) whose centre is 0.5 m ahead, 0.1 m up
    low = LIDAR.format(stddev=0).replace('reference="lidar_link"', 'reference="imu_link"')
    urdf = robot_urdf(low).replace(
        '<link name="camera_link">',
        '<link name="camera_link"><collision><origin xyz="0.4 0 -0.9"/><geometry><box size="0.1 0.1 0.1"/>'
        "</geometry></collision>",
    )
    sim = Simulation(world, parse_world({}))
    robot = sim.spawn("probe", urdf, Pose2D())
    sim.step()
    (lidar,) = robot.sensors
    ranges = lidar.read(sim.time).ranges[0]
    c = lidar.spec.config
    ahead = round((0.0 - c.min_angle) / c.angle_increment)
    assert ranges[ahead] == pytest.approx(0.45, abs=0.01)  # the block's near face


def test_an_imu_at_rest_reads_gravity_up_and_no_rotation(world):
    sim, robot = simulation(world, IMU)
    (imu,) = robot.sensors
    imu.read(sim.time)
    for _ in range(3):
        sim.step()
    r = imu.read(sim.time)
    assert r.linear_acceleration == pytest.approx((0.0, 0.0, 9.81), abs=0.02)
    assert r.angular_velocity == pytest.approx((0.0, 0.0, 0.0), abs=2e-3)
    assert r.orientation == pytest.approx((0.0, 0.0, 0.0, 1.0), abs=1e-3)


def test_an_imu_spinning_reads_its_rate_and_follows_the_yaw(world):
    sim, robot = simulation(world, IMU)
    (imu,) = robot.sensors
    com, _ = p.getBasePositionAndOrientation(robot.body, physicsClientId=world)
    p.resetBasePositionAndOrientation(robot.body, (com[0], com[1], com[2] + 1.0), (0, 0, 0, 1), physicsClientId=world)
    p.setGravity(0, 0, 0, physicsClientId=world)  # floating, spinning freely at 0.5 rad/s
    p.resetBaseVelocity(robot.body, (0, 0, 0), (0, 0, 0.5), physicsClientId=world)
    for _ in range(240):
        sim.step()
    r = imu.read(sim.time)
    assert r.angular_velocity[2] == pytest.approx(0.5, abs=1e-3)
    _, truth = robot.world_pose()
    yaw = math.atan2(2 * (r.orientation[3] * r.orientation[2]), 1 - 2 * r.orientation[2] ** 2)
    assert yaw == pytest.approx(math.atan2(2 * truth[3] * truth[2], 1 - 2 * truth[2] ** 2), abs=1e-3)
    assert yaw == pytest.approx(0.5, abs=0.01)  # one second at 0.5 rad/s


def test_a_gnss_moves_with_the_robot_in_hectors_axes(world):
    # robot_localization's datum: heading 0 = the world's x points east (hector heading 90)
    sim, robot = simulation(world, GPS, datum=Datum(53.0, -1.0, 0.0))
    (gps,) = robot.sensors
    start = gps.read(sim.time)
    com, orn = p.getBasePositionAndOrientation(robot.body, physicsClientId=world)
    p.resetBasePositionAndOrientation(robot.body, (com[0] + 10.0, com[1], com[2]), orn, physicsClientId=world)
    moved = gps.read(sim.time + 0.1)
    lat = math.radians(53.0)
    radius_east = WGS84_A / math.sqrt(1 - WGS84_E2 * math.sin(lat) ** 2) * math.cos(lat)
    assert moved.longitude - start.longitude == pytest.approx(math.degrees(10.0 / radius_east), rel=1e-6)
    assert moved.latitude == pytest.approx(start.latitude, abs=1e-9)
    assert (start.latitude, start.longitude) == pytest.approx((53.0, -1.0), abs=1e-7)
    # with the datum's heading at 90 degrees (x north), the same move goes north
    sim2 = Simulation(world, parse_world({}), datum=Datum(53.0, -1.0, math.pi / 2))
    north = sim2.spawn("north", robot_urdf(GPS), Pose2D(x=10.0))
    assert north.sensors[0].read(0.0).latitude > 53.0 + math.degrees(9.9 / 6.4e6)


def test_a_camera_sees_a_red_box_where_its_field_of_view_puts_it_and_the_depth_reads_its_distance(world):
    sim, robot = simulation(world, CAMERA)
    (camera,) = robot.sensors
    # a red box whose face is 2 m ahead of the camera (camera 0.1 m ahead of base_link, 1 m up),
    # 0.6 m wide: 0.3 / 2 = tan(8.5 deg) either side, of a horizontal field of view of 1 rad
    box(world, (0.25, 0.3, 0.3), (2.35, 0.0, 1.0), rgba=(1, 0, 0, 1))
    frame = camera.read(sim.time)
    h, w, _ = frame.image.shape
    assert (h, w) == (60, 80)
    centre = frame.image[h // 2, w // 2]
    assert centre[0] > 150 and centre[1] < 60 and centre[2] < 60
    f = camera.spec.config.focal_length
    half_width_px = 0.3 / 2.0 * f  # the box's half width on the image
    inside = int(w / 2 + 0.7 * half_width_px)
    outside = int(w / 2 + 1.5 * half_width_px)
    assert frame.image[h // 2, inside][0] > 150
    assert not (frame.image[h // 2, outside][0] > 150 and frame.image[h // 2, outside][1] < 60)
    assert frame.depth[h // 2, w // 2] == pytest.approx(2.0, abs=0.02)
    points = depth_to_points(frame.depth, camera.spec.config)
    assert points[h // 2, w // 2, 2] == pytest.approx(2.0, abs=0.02)
    assert points[h // 2, inside, 0] == pytest.approx(0.7 * 0.3, abs=0.03)  # right of the axis: +x
    # written into a point cloud's fields instead: the same figures
    fields = np.zeros((h, w, 8), dtype=np.float32)
    xyz = (fields[..., 0], fields[..., 1], fields[..., 4])
    assert depth_to_points(frame.depth, camera.spec.config, out=xyz) is None
    assert np.array_equal(fields[..., [0, 1, 4]], points, equal_nan=True)
    assert np.array_equal(frame.rgba[..., :3], frame.image)  # rgb8: the renderer's RGBA without its alpha


def test_a_bgr8_camera_orders_its_image_blue_green_red(world):
    bgr = CAMERA.replace("<height>60</height>", "<height>60</height><format>B8G8R8</format>")
    sim, robot = simulation(world, bgr)
    (camera,) = robot.sensors
    assert camera.spec.config.encoding == "bgr8"
    box(world, (0.25, 0.3, 0.3), (2.35, 0.0, 1.0), rgba=(1, 0, 0, 1))  # red, 2 m ahead
    frame = camera.read(sim.time)
    h, w, _ = frame.image.shape
    blue, green, red = frame.image[h // 2, w // 2]
    assert red > 150 and green < 60 and blue < 60
    assert np.array_equal(frame.image, frame.rgba[..., 2::-1])  # the renderer's RGBA stays RGBA (the cloud's colours)


def test_p3d_reports_its_link_in_the_world(world):
    sim, robot = simulation(world, P3D)
    truth = robot.sensors[0].read(sim.time)
    assert truth.position == pytest.approx((0.0, 0.0, 1.0), abs=0.01)


def test_noise_is_seeded():
    a = InstantNoise(7, "r1", "lidar").at(3).normal(size=5)
    assert np.array_equal(a, InstantNoise(7, "r1", "lidar").at(3).normal(size=5))
    assert not np.array_equal(a, InstantNoise(8, "r1", "lidar").at(3).normal(size=5))
    assert not np.array_equal(a, InstantNoise(7, "r2", "lidar").at(3).normal(size=5))
    assert not np.array_equal(a, InstantNoise(7, "r1", "lidar").at(4).normal(size=5))


def test_an_instants_noise_does_not_depend_on_what_was_drawn_before():
    # a run whose recorder subscribed later drew less before: the same instant still draws the same
    late, early = InstantNoise(7, "r1", "gps"), InstantNoise(7, "r1", "gps")
    for k in range(50):
        early.at(k).normal(size=720)
    assert np.array_equal(late.at(50).normal(size=3), early.at(50).normal(size=3))
    # and consecutive instants' streams do not overlap: many draws at one instant never reach the next's
    many = InstantNoise(7, "r1", "gps").at(50).standard_normal(100000)
    following = InstantNoise(7, "r1", "gps").at(51).standard_normal(4)
    assert not any(np.array_equal(following, many[i : i + 4]) for i in range(len(many) - 3))


def test_a_readings_normals_depend_on_the_reading_alone():
    # drawn in blocks of readings, but a reading's draws are its own: the same whatever was drawn
    # before or in which order, different for the next reading and for another sensor
    n = 720
    per_block = InstantNoise.BLOCK // n
    noise = InstantNoise(7, "r1", "lidar")
    forward = [noise.normals(k, n).copy() for k in range(2 * per_block + 3)]
    backward = InstantNoise(7, "r1", "lidar")
    for k in reversed(range(len(forward))):
        assert np.array_equal(backward.normals(k, n), forward[k])
    assert not any(np.array_equal(forward[k], forward[k + 1]) for k in range(len(forward) - 1))
    assert not np.array_equal(InstantNoise(7, "r1", "lidar2").normals(0, n), forward[0])
    assert not np.array_equal(InstantNoise(8, "r1", "lidar").normals(0, n), forward[0])
    # they are standard normals, and not the draws at() gives the same instant
    everything = np.concatenate(forward)
    assert abs(everything.mean()) < 4 / math.sqrt(everything.size) and everything.std() == pytest.approx(1, abs=0.01)
    assert not np.array_equal(InstantNoise(7, "r1", "lidar").at(0).standard_normal(n), forward[0])


def test_a_scan_is_the_same_whenever_the_lidar_began_to_be_read(world):
    # two runs of one seed: one reads the lidar from the start, the other only after 0.25 s; the
    # scans they share (the same readings on the schedule) are the same, noise included
    sim, robot = simulation(world, LIDAR.format(stddev=0.05), seed=3)
    box(world, (0.5, 1.0, 1.5), (3.5, 0.0, 1.5))  # something to see, 3 m ahead
    (lidar,) = robot.sensors
    early = {k: scan.ranges for k, scan in readings(sim, lidar, 20).items()}
    client2 = p.connect(p.DIRECT)
    try:
        sim2, robot2 = simulation(client2, LIDAR.format(stddev=0.05), seed=3)
        box(client2, (0.5, 1.0, 1.5), (3.5, 0.0, 1.5))
        (lidar2,) = robot2.sensors
        for _ in range(60):
            sim2.step()
        late = {k: scan.ranges for k, scan in readings(sim2, lidar2, 5).items()}
    finally:
        p.disconnect(client2)
    assert set(late) < set(early) and np.isfinite(late[min(late)]).sum() > 100
    for k, ranges in late.items():
        assert np.array_equal(ranges, early[k], equal_nan=True)
    assert not np.array_equal(early[min(early)], early[min(early) + 1])  # consecutive scans' noise differs


def test_the_same_seed_gives_the_same_scan(world):
    sim, robot = simulation(world, LIDAR.format(stddev=0.05), seed=3)
    box(world, (0.5, 1.0, 1.5), (3.5, 0.0, 1.5))
    first = robot.sensors[0].read(sim.time).ranges
    client2 = p.connect(p.DIRECT)
    try:
        sim2, robot2 = simulation(client2, LIDAR.format(stddev=0.05), seed=3)
        box(client2, (0.5, 1.0, 1.5), (3.5, 0.0, 1.5))
        again = robot2.sensors[0].read(sim2.time).ranges
    finally:
        p.disconnect(client2)
    assert np.array_equal(first, again)


def test_sensor_blocks_do_not_stop_a_robot_from_spawning(world):
    broken = LIDAR.format(stddev=0).replace("<samples>1081</samples>", "")
    sim = Simulation(world, parse_world({}))
    robot = sim.spawn("probe", robot_urdf(broken, IMU), Pose2D())
    assert [s.spec.kind for s in robot.sensors] == ["imu"]
    assert robot.sensor_blocks.refused[0].path.endswith("samples")


def test_the_sensor_report_names_a_sensor_that_cannot_hold_its_rate():
    level, message, values = sensor_report([SensorUse("laser a (/scan)", 40.0, 0.02, 80)], 2.0, 240.0, 1.0)
    assert level == OK and "1 sensor read" in message
    assert values["laser a (/scan): rate [Hz]"] == "40.0 of 40"
    assert values["laser a (/scan): CPU per simulated second [s]"] == "0.01000"
    # a camera costing 1.5 s of CPU per simulated second cannot run at real time
    level, message, _ = sensor_report([SensorUse("camera c (/img)", 30.0, 3.0, 60)], 2.0, 240.0, 1.0)
    assert level == WARN and "camera c (/img) costs 1.50 s" in message
    # ... but can at a real-time factor of 0.5, and at "as fast as possible" nothing is late
    assert sensor_report([SensorUse("camera c (/img)", 30.0, 3.0, 60)], 2.0, 240.0, 0.5)[0] == OK
    assert sensor_report([SensorUse("camera c (/img)", 30.0, 3.0, 60)], 2.0, 240.0, 0.0)[0] == OK
    # a rate above the physics rate is measured once a step at most
    level, message, _ = sensor_report([SensorUse("imu i (/imu)", 1000.0, 0.01, 480)], 2.0, 240.0, 0.0)
    assert level == WARN and "above the physics rate" in message


def test_the_lidar_arithmetic_is_built_in_c():
    # catkin_make builds csrc/scan.c (tools/setup installs Python's headers); numpy is only the fallback
    assert lidar_module._scan is not None


def test_the_compiled_beams_and_ranges_are_numpys():
    rng = np.random.default_rng(11)
    directions = rng.normal(size=(721, 3))
    directions /= np.linalg.norm(directions, axis=1, keepdims=True)
    for _ in range(20):
        q = rng.normal(size=4)
        quat, origin = tuple(q / np.linalg.norm(q)), tuple(rng.uniform(-50.0, 50.0, 3))
        out = [np.empty_like(directions) for _ in range(4)]
        beams((origin, quat), directions, (0.1, 30.0), out[:2])
        beams((origin, quat), directions, (0.1, 30.0), out[2:], compiled=False)
        assert np.allclose(out[0], out[2], rtol=0, atol=1e-12) and np.allclose(out[1], out[3], rtol=0, atol=1e-12)
        # the geometry itself: each beam starts 0.1 m and ends 30 m from the origin, along the turned direction
        assert np.allclose(np.linalg.norm(out[1] - origin, axis=1), 30.0)
        assert np.allclose(out[1] - origin, 300.0 * (out[0] - origin))
    fractions = [0.0, 0.25, 0.5, 0.999999, 1.0, 1.0, 0.0125]
    hits = tuple((3, -1, f, (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)) for f in fractions)  # rayTestBatch's shape
    compiled, numpy = np.full(9, -1.0), np.full(9, -1.0)
    ranges_from_hits(hits, compiled[1:8], (0.1, 30.0))
    ranges_from_hits(hits, numpy[1:8], (0.1, 30.0), compiled=False)
    assert np.array_equal(compiled, numpy)
    assert compiled[0] == -1.0 and compiled[8] == -1.0  # only the slice written
    assert compiled[3] == 0.1 + 0.5 * 29.9 and math.isinf(compiled[5]) and math.isinf(compiled[6])
    # with noise: stddev z added to every range, inf stays inf
    z = rng.normal(size=7)
    ranges_from_hits(hits, compiled[1:8], (0.1, 30.0), (0.05, z))
    ranges_from_hits(hits, numpy[1:8], (0.1, 30.0), (0.05, z), compiled=False)
    assert np.array_equal(compiled, numpy)
    assert compiled[3] == (0.1 + 0.5 * 29.9) + 0.05 * z[2] and math.isinf(compiled[5])


def test_the_compiled_loops_refuse_what_they_cannot_read():
    hits = ((3, -1, 0.5, (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)),) * 4
    with pytest.raises(ValueError, match="out must be C-contiguous float64 with room for 4"):
        ranges_from_hits(hits, np.empty(3), (0.1, 30.0))
    with pytest.raises(ValueError, match="float64"):
        ranges_from_hits(hits, np.empty(4, dtype=np.float32), (0.1, 30.0))
    with pytest.raises(ValueError, match="noise must be C-contiguous float64 with room for 4"):
        ranges_from_hits(hits, np.empty(4), (0.1, 30.0), (0.05, np.zeros(3)))
    with pytest.raises(TypeError, match="result 1 is not a rayTestBatch result"):
        ranges_from_hits((hits[0], (1, 2)), np.empty(2), (0.1, 30.0))
    directions = np.ones((5, 3))
    with pytest.raises(ValueError, match="ends must be"):
        beams(((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0)), directions, (0.1, 30.0), (np.empty((5, 3)), np.empty((4, 3))))
