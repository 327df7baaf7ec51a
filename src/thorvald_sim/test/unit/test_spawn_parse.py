"""A spawn reads its description once: one parse of the XML that the robot, its tyres, its link tree
and its sensor blocks all read (thorvald_sim.physics.description.SpawnedDescription)."""

import xml.etree.ElementTree as ET

import pybullet as p
import pytest

from thorvald_model.description import generate_urdf, package_file
from thorvald_sim.physics.robot import Pose2D
from thorvald_sim.physics.simulation import Simulation
from thorvald_sim.world import load_world, resolve_world

STD = package_file("config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
SENSORS = package_file("urdf", "examples", "sensors_example.xacro")


@pytest.fixture
def sim():
    client = p.connect(p.DIRECT)
    yield Simulation(client, load_world(resolve_world("flat")))
    p.disconnect(client)


def test_a_spawn_parses_its_description_once(sim, monkeypatch):
    urdf = generate_urdf(STD, tf_prefix="r1/", model_extras=SENSORS)
    parsed = []
    original = ET.fromstring

    def counting(text, *args, **kwargs):
        if "<robot" in (text if isinstance(text, str) else text.decode("utf-8", "replace")):
            parsed.append(len(text))
        return original(text, *args, **kwargs)

    monkeypatch.setattr(ET, "fromstring", counting)
    robot = sim.spawn("r1", urdf, Pose2D(0.0, 0.0, 0.0, 0.0))
    assert parsed == [len(urdf)]  # the description itself, once; nothing parses a text made from it
    # and every reader got what it needs from that one parse
    assert len(robot.wheels) == 4 and {s.spec.kind for s in robot.sensors} >= {"laser", "imu", "depth"}
    assert robot.sensor_blocks is not None and not robot.sensor_problems
