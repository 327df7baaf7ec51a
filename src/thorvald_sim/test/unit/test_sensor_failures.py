"""A sensor the robot goes without (thorvald_sim.node.sensor_io, thorvald_sim.sensors.mounted): a reading that fails
disables that sensor alone, logged once and reported as an error from then on, while the robot's other
sensors keep measuring; a block past a bound is refused at spawn and reported the same way; and a lidar
at the bound of rays reads every one of them (pybullet takes 16383 rays a call, and for 16384 it
silently returns nothing: the unwritten ranges were published as they were).

The robot is a 0.4 m box with a lidar 1 m above the ground and a camera beside it, in a pybullet DIRECT
client, measured through RobotSensors as the simulator node does; its publisher is a recorder that
every topic is subscribed to and that serialises each message as rospy would.
"""

import logging
import math
from dataclasses import replace

import numpy as np
import pybullet as p
import pytest
from sensor_msgs.msg import LaserScan
from sim_test_helpers import Recorder

from thorvald_sim.node.sensor_io import RobotSensors
from thorvald_sim.physics.robot import Pose2D
from thorvald_sim.physics.simulation import Simulation
from thorvald_sim.sensors.blocks import MAX_RAYS
from thorvald_sim.sensors.mounted import ERROR, RAY_BATCH, build_sensors, disabled_report, refused_sensors
from thorvald_sim.world import parse_world

INERTIAL = '<inertial><mass value="{m}"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'

LIDAR = """<gazebo reference="lidar_link"><sensor type="ray" name="lidar"><update_rate>40</update_rate>
  <ray><scan><horizontal><samples>181</samples><min_angle>-1.5707963</min_angle>
  <max_angle>1.5707963</max_angle></horizontal></scan><range><min>0.1</min><max>30</max></range></ray>
  <plugin name="l" filename="libgazebo_ros_laser.so"><topicName>scan</topicName>
  <frameName>lidar_link</frameName></plugin></sensor></gazebo>"""

CAMERA = """<gazebo reference="camera_link"><sensor type="camera" name="{name}"><update_rate>10</update_rate>
  <camera><image><width>{width}</width><height>{height}</height></image></camera>
  <plugin name="c" filename="libgazebo_ros_camera.so"><cameraName>{name}</cameraName>
  <frameName>camera_link</frameName></plugin></sensor></gazebo>"""

P3D_NOWHERE = """<gazebo><plugin name="truth" filename="libgazebo_ros_p3d.so"><bodyName>lidar_link</bodyName>
  <topicName>truth</topicName><frameName>nowhere</frameName></plugin></gazebo>"""

WALL_X = 3.0  # [m] the wall's face, ahead of the lidar at x = 0


def robot_urdf(*blocks: str) -> str:
    return f"""<robot name="probe">
  <link name="base_link">{INERTIAL.format(m=20)}
    <collision><origin xyz="0 0 0.1"/><geometry><box size="0.4 0.4 0.2"/></geometry></collision></link>
  <link name="lidar_link">{INERTIAL.format(m=0.2)}</link>
  <link name="camera_link">{INERTIAL.format(m=0.2)}</link>
  <joint name="lidar_joint" type="fixed"><origin xyz="0 0 1.0"/><parent link="base_link"/>
    <child link="lidar_link"/></joint>
  <joint name="camera_joint" type="fixed"><origin xyz="0 0.1 1.0"/><parent link="base_link"/>
    <child link="camera_link"/></joint>
  {"".join(blocks)}
</robot>"""


@pytest.fixture
def world():
    client = p.connect(p.DIRECT)
    yield client
    p.disconnect(client)


def spawn(client, *blocks):
    sim = Simulation(client, parse_world({}))
    urdf = robot_urdf(*blocks)
    robot = sim.spawn("probe", urdf, Pose2D())
    half = (0.1, 2.0, 1.5)
    shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=client)
    p.createMultiBody(0, shape, -1, (WALL_X + half[0], 0.0, half[2]), physicsClientId=client)
    for _ in range(480):  # 2 s: settled on the ground
        sim.step()
    return sim, robot, urdf


def test_a_sensor_whose_reading_fails_is_disabled_alone_and_the_others_keep_measuring(world, caplog):
    sim, robot, urdf = spawn(world, LIDAR, CAMERA.format(name="cam", width=64, height=48))
    lidar, camera = robot.sensors
    # a camera past the reader's bounds, made here from its spec: pybullet itself refuses to read it
    # (its argument parser takes the width as a C int and raises OverflowError past 2^31 - 1)
    huge = replace(camera.spec, config=replace(camera.spec.config, width=2**31))
    (broken,), _ = build_sensors([huge], robot, urdf, dt=sim.dt)
    sensors = RobotSensors([lidar, broken], "/probe", publisher=Recorder)
    scan_io, camera_io = sensors.ios
    with caplog.at_level(logging.DEBUG, logger="rosout"):
        for _ in range(240):  # 1 s of simulated time, from 2 s on
            sim.step()
            sensors.step(sim.time)

    # the camera's first reading is due at 2.1 s (its 10 Hz grid's next instant): it failed then, once
    failure = camera_io.failure
    assert failure is not None and failure.since == pytest.approx(2.1, abs=1e-9)
    assert failure.name == "cam" and "OverflowError" in failure.what
    assert failure.topics == ("/probe/cam/image_raw", "/probe/cam/camera_info")
    assert all(not pub.messages for pub in camera_io.pubs.values())
    errors = [r for r in caplog.records if r.levelno == logging.ERROR]
    assert len(errors) == 1
    said = errors[0].getMessage()
    assert "probe" in said and "cam" in said and "/probe/cam/image_raw" in said and "OverflowError" in said

    # the lidar kept measuring: 40 Hz for 1 s, each scan the wall straight ahead at 3 m
    scans = scan_io.pubs["scan"].messages
    assert 39 <= len(scans) <= 41
    middle = len(scans[-1].ranges) // 2  # the beam at 0 rad (181 beams from -90 to 90 degrees)
    assert all(s.ranges[middle] == pytest.approx(WALL_X, abs=1e-3) for s in scans)
    # 30 degrees off axis the beam meets the wall's face at 3 / cos(30 degrees) = 3.464 m
    assert scans[-1].ranges[middle + 30] == pytest.approx(WALL_X / math.cos(math.radians(30)), abs=1e-3)
    assert isinstance(scans[-1], LaserScan) and np.isfinite(scans[-1].ranges[middle])

    # /diagnostics: the camera an error naming the robot, the sensor and its topics; its cost no more
    assert sensors.disabled() == [failure]
    level, message, values = disabled_report("probe", failure)
    assert level == ERROR == 2
    assert message.startswith("probe: sensor cam (/probe/cam/image_raw, /probe/cam/camera_info) disabled at 2.100 s")
    assert values["robot"] == "probe" and values["sensor"] == "cam" and "OverflowError" in values["why"]
    assert [use.name for use in sensors.uses()] == ["laser lidar (/probe/scan)"]

    # and it stays disabled: nothing is read or logged again
    for _ in range(48):
        sim.step()
        sensors.step(sim.time)
    assert camera_io.failure is failure and camera_io.readings == 0
    assert len([r for r in caplog.records if r.levelno == logging.ERROR]) == 1


def test_a_block_past_a_bound_is_refused_at_spawn_and_reported_while_the_robot_has_its_other_sensors(world):
    big = CAMERA.format(name="big", width=100000, height=100000)
    _, robot, _ = spawn(world, LIDAR, big, P3D_NOWHERE)
    assert [s.spec.name for s in robot.sensors] == ["lidar"]
    (refused,) = robot.sensor_blocks.refused
    assert refused.path == "sensor[@name='big']/camera/image/width"
    (problem,) = robot.sensor_problems  # a sensor whose link cannot be mounted: logged as it always was
    assert str(problem) == (
        "p3d 'truth' on link lidar_link (libgazebo_ros_p3d.so): frameName 'nowhere' is neither world nor a link"
        " of the robot"
    )

    disabled = refused_sensors(robot.sensor_blocks, robot.sensor_problems)
    assert [(d.name, d.topics, d.since) for d in disabled] == [("big", (), None), ("truth", (), None)]
    sensors = RobotSensors(robot.sensors, "/probe", disabled, publisher=Recorder)
    assert sensors.disabled() == list(disabled)
    level, message, values = disabled_report("probe", disabled[0])
    assert level == ERROR
    assert message == (
        "probe: sensor big refused at spawn: link camera_link: sensor[@name='big']/camera/image/width:"
        " 100000 must be <= 8192 pixels (no camera is wider)"
    )
    assert values == {"robot": "probe", "sensor": "big", "topics": "none", "why": disabled[0].what}


@pytest.mark.slow  # half a million rays
def test_a_lidar_at_the_bound_of_rays_reads_every_ray(world):
    # 4096 columns over +-30 degrees x 128 channels over +-15 degrees: MAX_RAYS = 524288 rays, 33 calls
    # of at most 16383. Every beam meets the wall's face x = 3 m (|y| = 3 tan h <= 1.73 m, z = 1 m +
    # 3 tan v / cos h within 0.07..1.93 m), at the range 3 / (cos v cos h)
    block = LIDAR.replace("<samples>181</samples>", "<samples>4096</samples>")
    block = block.replace("-1.5707963", "-0.5235988").replace("1.5707963", "0.5235988")
    block = block.replace(
        "</horizontal>",
        "</horizontal><vertical><samples>128</samples><min_angle>-0.2617994</min_angle>"
        "<max_angle>0.2617994</max_angle></vertical>",
    ).replace("libgazebo_ros_laser.so", "libgazebo_ros_velodyne_laser.so")
    sim, robot, _ = spawn(world, block)
    (lidar,) = robot.sensors
    c = lidar.spec.config
    assert c.samples * c.vertical_samples == MAX_RAYS and RAY_BATCH == 16383
    scan = lidar.read(sim.time)
    h = np.linspace(c.min_angle, c.max_angle, c.samples)[None, :]
    v = np.linspace(c.vertical_min_angle, c.vertical_max_angle, c.vertical_samples)[:, None]
    expected = WALL_X / (np.cos(v) * np.cos(h))
    assert scan.ranges.shape == (128, 4096)
    assert np.abs(scan.ranges - expected).max() < 1e-3
