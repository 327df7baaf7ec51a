"""A drive's rail wheel in the simulator (paper 3.1: the greenhouse robot's double wheels): the tyres'
thin contact discs and as-built radii leave the rail wheel's tread and flanges as generated, and on a
greenhouse's heating pipes the robot rides its rail wheels, held on the pipes by the flanges."""

import math
import os
import xml.etree.ElementTree as ET
from typing import Dict, List, Tuple

import pybullet as p
import pytest

from thorvald_model import load_robot_config
from thorvald_model.description import generate_urdf
from thorvald_sim.physics.description import RAIL_WHEEL_COLLISIONS, narrow_tyres, set_wheel_radii, with_tyre_contact
from thorvald_sim.physics.robot import Pose2D
from thorvald_sim.physics.simulation import Simulation
from thorvald_sim.world import parse_world

HERE = os.path.dirname(os.path.abspath(__file__))
# the design studies' greenhouse robot (thorvald_design/studies/robots)
GREENHOUSE = os.path.abspath(
    os.path.join(HERE, "..", "..", "..", "thorvald_design", "studies", "robots", "greenhouse_rails.yaml")
)
CONFIG = load_robot_config(GREENHOUSE)
WHEELS = [d.wheel_name for d in CONFIG.drives]
PIPE_HEIGHT, PIPE_RADIUS = 0.1, 0.0255  # [m] worlds/greenhouse.yaml's pipes
# base_link over the floor with the rail wheels on the pipes: pipe top + rail wheel - tyre
STEP = PIPE_HEIGHT + PIPE_RADIUS + CONFIG.drives[0].rail_r_wheel - CONFIG.drives[0].r_wheel


@pytest.fixture(scope="module")
def urdf() -> str:
    return generate_urdf(GREENHOUSE)


def collisions(root: ET.Element, link: str) -> List[Tuple[str, Dict[str, str], Dict[str, str]]]:
    """Each collision of a link: its name, its cylinder's attributes and its origin's."""
    element = next(e for e in root.findall("link") if e.get("name") == link)
    return [
        (c.get("name"), dict(c.find("geometry/cylinder").attrib), dict(c.find("origin").attrib))
        for c in element.findall("collision")
    ]


def test_the_tyres_are_narrowed_and_the_rail_wheels_left_as_generated(urdf):
    before = ET.fromstring(urdf)
    after = ET.fromstring(urdf)
    narrow_tyres(after, WHEELS, 0.01)
    for n in range(len(CONFIG.drives)):
        was, now = collisions(before, f"wheel{n}_link"), collisions(after, f"wheel{n}_link")
        # tyre and hub: 1 cm discs, as every wheel's; the tread (6 cm) and its flanges untouched
        assert [float(c["length"]) for name, c, _ in now if name not in RAIL_WHEEL_COLLISIONS] == [0.01, 0.01]
        assert [c for c in now if c[0] in RAIL_WHEEL_COLLISIONS] == [c for c in was if c[0] in RAIL_WHEEL_COLLISIONS]
        assert [name for name, _, _ in now] == [None, None, "rail_tread", "rail_flange", "rail_flange"]
        assert float(now[2][1]["length"]) == 0.06
    # the text form does the same
    assert ET.tostring(after, encoding="unicode") == with_tyre_contact(urdf, WHEELS, 0.01)


def test_an_as_built_radius_is_the_tyres_not_the_rail_wheels(urdf):
    root = ET.fromstring(urdf)
    set_wheel_radii(root, {WHEELS[0]: 0.198})
    radii = [(name, float(c["radius"])) for name, c, _ in collisions(root, "wheel0_link")]
    assert radii == [(None, 0.198), (None, 0.198), ("rail_tread", 0.15), ("rail_flange", 0.17), ("rail_flange", 0.17)]
    # another drive's wheel is left alone
    assert [float(c["radius"]) for _, c, _ in collisions(root, "wheel1_link")] == pytest.approx(
        [0.2, 0.11, 0.15, 0.17, 0.17]
    )


@pytest.fixture
def pipes():
    """The greenhouse's pipes, 0.55 m apart along x from x = -2 to 8, on concrete."""
    world = parse_world(
        {
            "ground": {"surface": "concrete"},
            "rails": {"rail0": {"x": 3.0, "y": 0.0, "length": 10.0, "gauge": 0.55, "height": PIPE_HEIGHT}},
        },
        "pipes",
    )
    client = p.connect(p.DIRECT)
    yield Simulation(client, world)
    p.disconnect(client)


def run(sim, seconds):
    for _ in range(round(seconds / sim.dt)):
        sim.step()


def test_on_the_pipes_the_robot_rides_its_rail_wheels(pipes, urdf):
    """Set down on the pipes, base_link stands STEP above the floor, its tyres clear of it; driven at
    the rim speed v the tyres' radius gives, the wheels turn at v / r and the robot goes v r_rail / r:
    three quarters of the command for 0.2 m tyres on 0.15 m rail wheels. The flanges keep it on the
    pipes."""
    robot = pipes.spawn("r", urdf, Pose2D(0.0, 0.0, STEP + 0.005, 0.0))
    run(pipes, 1.0)
    (x0, y0, z0), _ = robot.world_pose()
    assert z0 == pytest.approx(STEP, abs=0.002)  # on the rail wheels, the tyres 7.5 cm over the floor
    v = 0.5
    robot.command([0.0] * 4, [v] * 4)
    run(pipes, 2.0)  # up to speed
    (x1, y1, _), _ = robot.world_pose()
    run(pipes, 4.0)
    (x2, y2, z2), _ = robot.world_pose()
    rail, tyre = CONFIG.drives[0].rail_r_wheel, CONFIG.drives[0].r_wheel
    assert (x2 - x1) / 4.0 == pytest.approx(v * rail / tyre, rel=0.01)
    assert abs(y2) < 0.005 and abs(y1) < 0.005 and z2 == pytest.approx(STEP, abs=0.002)
    assert math.isclose(x0, 0.0, abs_tol=0.01) and abs(y0) < 0.005
