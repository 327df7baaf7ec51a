"""pybullet holds each example robot's mass where thorvald_model.mass_properties says: the total
mass, and the centre of mass in base_link's frame (every body's mass at its inertial frame, read
back from pybullet), to a micrometre; reading the description link by link, and as the simulator
spawns it, its fixed links merged (URDF_MERGE_FIXED_LINKS, which put the merged base's centre of
mass 1 to 4 cm too high until thorvald_sim.physics.description.centre_fixed_links)."""

import glob
import os
import tempfile

import numpy as np
import pybullet as p
import pytest

from thorvald_model.description import generate_urdf
from thorvald_model.mass_properties import mass_properties
from thorvald_sim.physics.description import parse_description
from thorvald_sim.physics.robot import Pose2D, SimRobot

HERE = os.path.dirname(os.path.abspath(__file__))
EXAMPLES = sorted(glob.glob(os.path.join(HERE, "..", "..", "..", "thorvald_model", "config", "*", "*.yaml")))


def pybullet_mass(client, urdf: str):
    """(mass, centre of mass in base_link's frame) of the description as pybullet loads it, unmerged."""
    with tempfile.NamedTemporaryFile("w", suffix=".urdf") as f:
        f.write(urdf)
        f.flush()
        body = p.loadURDF(f.name, flags=p.URDF_USE_INERTIA_FROM_FILE, physicsClientId=client)
    return body_mass(client, body)


def body_mass(client, body):
    """(mass, centre of mass in base_link's frame) of a body pybullet holds."""
    base_mass, _, _, inertial_xyz, inertial_quat = p.getDynamicsInfo(body, -1, physicsClientId=client)[:5]
    base_com = p.getBasePositionAndOrientation(body, physicsClientId=client)
    # base_link's frame in the world: the base's inertial frame, less its offset in base_link
    to_base_link = p.invertTransform(*p.multiplyTransforms(*base_com, *p.invertTransform(inertial_xyz, inertial_quat)))
    masses, centres = [base_mass], [base_com[0]]
    for j in range(p.getNumJoints(body, physicsClientId=client)):
        masses.append(p.getDynamicsInfo(body, j, physicsClientId=client)[0])
        centres.append(p.getLinkState(body, j, computeForwardKinematics=True, physicsClientId=client)[0])
    in_base_link = [p.multiplyTransforms(*to_base_link, c, (0, 0, 0, 1))[0] for c in centres]
    return sum(masses), np.average(np.array(in_base_link), axis=0, weights=masses)


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
@pytest.mark.parametrize("path", EXAMPLES, ids=lambda path: os.path.basename(path)[:-5])
def test_pybullet_holds_the_descriptions_mass_at_its_centre_of_mass(client, path):
    urdf = generate_urdf(path)
    mass, com = pybullet_mass(client, urdf)
    expected = mass_properties(urdf)
    assert mass == pytest.approx(expected.mass, rel=1e-9)
    assert com == pytest.approx(np.array(expected.com), abs=1e-6)


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
@pytest.mark.parametrize("path", EXAMPLES, ids=lambda path: os.path.basename(path)[:-5])
def test_the_simulator_holds_the_descriptions_mass_at_its_centre_of_mass(client, path):
    """As spawned: fixed links merged, the mass the root link keeps apart (ROOT_MASS) a micrometre's
    worth at most."""
    urdf = generate_urdf(path)
    robot = SimRobot(client, "r", parse_description(urdf), urdf, Pose2D(0.0, 0.0, 1.0, 0.0))
    mass, com = body_mass(client, robot.body)
    expected = mass_properties(urdf)
    assert mass == pytest.approx(expected.mass, rel=1e-7)
    assert com == pytest.approx(np.array(expected.com), abs=1e-6)
    assert p.getNumJoints(robot.body, physicsClientId=client) < len(expected.links)  # merged
