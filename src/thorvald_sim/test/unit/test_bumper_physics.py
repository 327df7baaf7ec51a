"""The bumper in pybullet (thorvald_sim.sensors.kinds.bumper), no ROS master: a robot driven into a wall.

The standard robot (thorvald_model's example, the real xacro) gets a bumper: ``bumper_link``, a box
0.1 x 0.8 x 0.15 m fixed 0.8 m ahead of base_link and 0.55 m up, so its front face is 0.85 m ahead
of base_link, ahead of the wheels (0.75 m) and the frame (0.63 m), and clear of the ground (0.475 m
up). Gazebo lumps it into base_link behind the batteries (its joint, ``bumper_joint``, comes after
``bat0_joint`` and ``bat1_joint``, three collisions each), so its collision is
``base_link_fixed_joint_lump__bumper_link_collision_6``. A wall 0.2 m thick stands across the way,
its face at x = 2.9 m; the robot starts at x = 0 and drives at 0.5 m/s.

The sensor is built twice: as the simulator spawns it from the description (through the block
reader), and from the block read with the description's collisions, which places the collision's
box and keeps only the contact points on it.
"""

import math
import os
import xml.etree.ElementTree as ET

import pybullet as p
import pytest
from sim_test_helpers import Recorder

from thorvald_model.description import generate_urdf
from thorvald_sim.node.sensor_io import SensorIO
from thorvald_sim.physics.description import link_tree
from thorvald_sim.physics.robot import Pose2D
from thorvald_sim.physics.simulation import Simulation
from thorvald_sim.sensors.kinds.block import Element, Found
from thorvald_sim.sensors.kinds.bumper import GROUND, read_bumper
from thorvald_sim.sensors.mounted import build_sensors
from thorvald_sim.world import parse_world

pytestmark = pytest.mark.slow  # pybullet: simulations of several seconds

CONFIGS = os.path.join(os.path.dirname(os.path.abspath(__file__)), *[".."] * 3, "thorvald_model", "config")
STANDARD = "thorvald_ii_4wd4ws_std"
WALL_FACE = 2.9  # [m] x of the wall's face: a wall of 0.2 m centred at x = 3
FRONT = 0.85  # [m] the bumper's front face ahead of base_link
COLLISION = "base_link_fixed_joint_lump__bumper_link_collision_6"
INERTIAL = '<inertial><mass value="{m}"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
BUMPER = f"""<link name="bumper_link">{INERTIAL.format(m=1)}
  <collision><geometry><box size="0.1 0.8 0.15"/></geometry></collision></link>
<joint name="bumper_joint" type="fixed"><origin xyz="0.8 0 0.55"/><parent link="base_link"/>
  <child link="bumper_link"/></joint>
<gazebo reference="bumper_link"><sensor name="bumper" type="contact"><update_rate>50</update_rate>
  <contact><collision>{COLLISION}</collision></contact>
  <plugin name="bumper_plugin" filename="libgazebo_ros_bumper.so"><bumperTopicName>bumper_states</bumperTopicName>
  <frameName>bumper_link</frameName></plugin></sensor></gazebo>"""


def world(face: float):
    return parse_world({"walls": {"wall0": {"x": face + 0.1, "y": 0.0, "yaw": math.pi / 2, "length": 4.0}}}, "wall")


def found(root: ET.Element, link: str) -> Found:
    """The block as the block reader hands it to the kind."""
    sensor = root.find(f"gazebo[@reference='{link}']/sensor")
    path = f"sensor[@name='{sensor.get('name')}']"
    plugin = Element(sensor.find("plugin"), f"{path}/plugin")
    return Found(Element(sensor, path), plugin, link, sensor.get("name"), "libgazebo_ros_bumper.so", 50.0)


def checked_sensor(sim, robot, urdf: str, link: str):
    """The bumper built from its block read with the description's collisions."""
    root = ET.fromstring(urdf)
    spec = read_bumper(found(root, link), root)
    (sensor,), problems = build_sensors([spec], robot, link_tree(urdf), dt=sim.dt)
    assert not problems
    return sensor


@pytest.fixture(scope="module")
def drive():
    """(readings, messages): the checked sensor's readings as (base_link x, reading), and what the
    simulator's own bumper published on its topic, driving at 0.5 m/s for 8 simulated seconds."""
    urdf = generate_urdf(os.path.join(CONFIGS, STANDARD, STANDARD + ".yaml")).replace("</robot>", BUMPER + "</robot>")
    client = p.connect(p.DIRECT)
    try:
        sim = Simulation(client, world(WALL_FACE))
        robot = sim.spawn("thorvald_001", urdf, Pose2D())
        assert not robot.sensor_problems and not robot.sensor_blocks.refused
        (spawned,) = robot.sensors
        io = SensorIO(spawned, "/thorvald_001", "", publisher=Recorder)
        sensor = checked_sensor(sim, robot, urdf, "bumper_link")
        readings = []
        for _ in range(round(8.0 / sim.dt)):
            robot.command([0.0] * 4, [0.5] * 4)
            sim.step()
            io.step(sim.time, {"bumper": True})
            if sensor.due(sim.time):
                readings.append((robot.world_pose()[0][0], sensor.read(sim.time)))
        assert io.failure is None, io.failure
        return readings, io.pubs["bumper"].messages, io.topics["bumper"]
    finally:
        p.disconnect(client)


def touching(readings):
    """The readings from the first that has a contact on, and the readings before it."""
    first = next(k for k, (_, r) in enumerate(readings) if r.states)
    return readings[:first], readings[first:]


def test_the_bumper_reports_nothing_until_it_touches_the_wall(drive):
    readings, _, _ = drive
    before, after = touching(readings)
    # 0.5 m/s from 0.85 m to 2.9 m: about 4 s of the 8 before, at 50 Hz
    assert len(before) > 150 and len(after) > 150
    # nothing while the bumper is short of the wall; its first contact where the wall's face is
    assert max(x + FRONT for x, _ in before) < WALL_FACE + 0.002
    assert abs(after[0][0] + FRONT - WALL_FACE) < 0.005
    # and it stays in contact, pushing
    assert all(r.states for _, r in after)


def test_the_wall_pushes_the_bumper_back_along_its_normal(drive):
    _, after = touching(drive[0])
    for _, reading in after:
        (state,) = reading.states  # the bumper and the wall, nothing else of the robot's frame
        assert state.collision1 == f"thorvald_001::base_link::{COLLISION}"
        assert state.collision2 == GROUND  # the world's static scene, as the /gazebo API names it
        for (x, y, z), normal, depth in zip(state.positions, state.normals, state.depths):
            # on the wall's face, within the bumper's 0.8 m width and its 0.475 to 0.625 m height
            assert abs(x - WALL_FACE) < 0.01 and abs(y) < 0.41 and 0.465 < z < 0.635
            # from the wall into the bumper: -x
            assert normal[0] < -0.99 and 0.0 <= depth < 0.01
        # the force on the bumper's link (base_link, heading along the world's x) points back
        force, _ = state.total
        assert force[0] < -10.0 and abs(force[1]) < abs(force[0])


def test_the_simulator_publishes_gazebo_ros_bumpers_message(drive):
    _, messages, topic = drive
    assert topic == "/thorvald_001/bumper_states"
    assert len(messages) == 8 * 50  # every reading, touching or not, at the sensor's 50 Hz
    assert {m.header.frame_id for m in messages} == {"thorvald_001/bumper_link"}
    assert not messages[0].states and messages[-1].states
    assert messages[-1].header.stamp.to_sec() == pytest.approx(8.0)
    (state,) = messages[-1].states
    assert state.collision1_name == f"thorvald_001::base_link::{COLLISION}"
    assert state.contact_normals and all(n.x < -0.99 for n in state.contact_normals)
    assert state.total_wrench.force.x < 0.0


CART = f"""<robot name="cart">
  <link name="body">{INERTIAL.format(m=20)}
    <collision><origin xyz="0 0 0.1"/><geometry><box size="0.6 0.4 0.2"/></geometry></collision></link>
  <link name="bumper_link">{INERTIAL.format(m=0.5)}
    <collision><geometry><box size="0.05 0.4 0.1"/></geometry></collision></link>
  <joint name="bumper_joint" type="fixed"><origin xyz="0.325 0 0.15"/><parent link="body"/>
    <child link="bumper_link"/></joint>
  <gazebo reference="bumper_link"><sensor name="bumper" type="contact"><update_rate>50</update_rate>
    <contact><collision>body_fixed_joint_lump__bumper_link_collision_1</collision></contact>
    <plugin name="b" filename="libgazebo_ros_bumper.so"/></sensor></gazebo>
</robot>"""


def test_a_bumper_on_a_body_resting_on_the_ground_reports_the_wall_and_not_the_ground():
    # a cart on the ground, a bumper box on its front face 0.1 to 0.2 m up: the cart's rigid body
    # touches the ground all along, its bumper only the wall. Pushed with 230 N (its weight 201 N at
    # friction 1) from 0.15 m before the wall.
    client = p.connect(p.DIRECT)
    try:
        face = 0.5
        sim = Simulation(client, world(face))
        robot = sim.spawn("cart", CART, Pose2D())
        sensor = checked_sensor(sim, robot, CART, "bumper_link")
        readings = []
        for _ in range(round(3.0 / sim.dt)):
            com, _ = p.getBasePositionAndOrientation(robot.body, physicsClientId=client)
            p.applyExternalForce(robot.body, -1, (230.0, 0.0, 0.0), com, p.WORLD_FRAME, physicsClientId=client)
            sim.step()
            if sensor.due(sim.time):
                readings.append((robot.world_pose()[0][0], sensor.read(sim.time)))
        assert p.getContactPoints(robot.body, physicsClientId=client), "the cart stands on the ground"
        before, after = touching(readings)
        assert len(before) > 10 and len(after) > 100
        assert max(x + 0.35 for x, _ in before) < face + 0.002
        # it bounces off the wall at first, then rests against it, pushed (the last second: 50 readings)
        assert all(r.states for _, r in after[-50:])
        for _, reading in after:
            for state in reading.states:  # the wall alone: the ground under the cart is not the bumper's
                assert state.collision1 == "cart::body::body_fixed_joint_lump__bumper_link_collision_1"
                # the bumper is 0.1 to 0.2 m up (the cart rocks a few millimetres as it hits the wall)
                assert all(0.08 < z < 0.22 and n[0] < -0.99 for (_, _, z), n in zip(state.positions, state.normals))
            assert len(reading.states) <= 1
    finally:
        p.disconnect(client)
