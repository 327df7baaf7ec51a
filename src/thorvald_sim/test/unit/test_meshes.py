"""Meshes in robot descriptions: found through their packages for pybullet, and those of packages
that are not installed left out, the link drawn from its other geometry (thorvald_sim.physics.description)."""

import os
import xml.etree.ElementTree as ET

import pybullet as p
import pytest

from thorvald_model.description import generate_urdf
from thorvald_sim.physics.description import mesh_finder, resolve_meshes
from thorvald_sim.physics.robot import Pose2D
from thorvald_sim.physics.simulation import Simulation, installed_package_path
from thorvald_sim.world import parse_world

HERE = os.path.dirname(os.path.abspath(__file__))
MODEL = os.path.abspath(os.path.join(HERE, "..", "..", "..", "thorvald_model"))
STD = os.path.join(MODEL, "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
EXTRAS = os.path.join(HERE, "..", "data", "extras_meshes.xacro")
HOKUYO = os.path.join(MODEL, "meshes", "hokuyo", "hokuyo.dae")

URDF = """<robot name="r">
  <link name="a">
    <visual><geometry><mesh filename="package://here/m/a.stl" scale="2 2 2"/></geometry></visual>
    <visual><geometry><box size="1 1 1"/></geometry></visual>
    <collision><geometry><mesh filename="package://gone/m/b.dae"/></geometry></collision>
  </link>
  <link name="b">
    <visual><geometry><mesh filename="package://here/m/missing.stl"/></geometry></visual>
    <collision><geometry><mesh filename="package://here/m/a.stl"/></geometry></collision>
    <inertial><mass value="1"/></inertial>
  </link>
</robot>"""


@pytest.fixture
def package(tmp_path):
    (tmp_path / "m").mkdir()
    (tmp_path / "m" / "a.stl").write_text("solid a\nendsolid a\n")
    return str(tmp_path)


def test_found_meshes_become_absolute_paths_and_lost_ones_are_dropped(package):
    find = mesh_finder(lambda name: package if name == "here" else None)
    text, missing = resolve_meshes(URDF, find)
    root = ET.fromstring(text)
    a, b = root.findall("link")
    assert [m.get("filename") for m in a.iter("mesh")] == [os.path.join(package, "m", "a.stl")]
    assert a.find("visual/geometry/mesh").get("scale") == "2 2 2"  # the rest of the element as it was
    assert a.find("visual/geometry/box") is not None and a.find("collision") is None
    assert b.find("visual") is None and b.find("collision/geometry/mesh") is not None
    assert b.find("inertial/mass").get("value") == "1"
    assert [(m.link, m.element, m.uri, m.reason) for m in missing] == [
        ("a", "collision", "package://gone/m/b.dae", "package gone is not installed"),
        ("b", "visual", "package://here/m/missing.stl", "package here has no m/missing.stl"),
    ]


@pytest.mark.parametrize(
    "uri, found",
    [("file://{h}", True), ("{h}", True), ("model://hokuyo/meshes/hokuyo.dae", False), ("meshes/x.dae", False)],
)
def test_file_and_absolute_paths_are_found_other_schemes_are_not(uri, found):
    path, reason = mesh_finder(lambda name: None)(uri.format(h=HOKUYO))
    assert (path == HOKUYO) if found else (path is None and reason)


def test_the_hokuyo_mesh_is_ours_and_reproducible(tmp_path):
    """thorvald_model/meshes/hokuyo/hokuyo.dae is what scripts/make_hokuyo_mesh writes."""
    import subprocess  # noqa: PLC0415
    import sys  # noqa: PLC0415

    out = tmp_path / "hokuyo.dae"
    subprocess.run([sys.executable, os.path.join(MODEL, "scripts", "make_hokuyo_mesh"), str(out)], check=True)
    with open(HOKUYO) as f:
        assert out.read_text() == f.read()
    assert installed_package_path("thorvald_description") is not None
    assert os.path.samefile(
        os.path.join(installed_package_path("thorvald_description"), "meshes", "hokuyo", "hokuyo.dae"), HOKUYO
    )


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_a_robot_with_users_extras_spawns_without_the_meshes_it_cannot_find():
    client = p.connect(p.DIRECT)
    try:
        sim = Simulation(client, parse_world({}, "flat"))
        urdf = generate_urdf(STD, tf_prefix="r/", model_extras=EXTRAS)
        robot = sim.spawn("r", urdf, Pose2D(0.0, 0.0))
        assert [(m.link, m.element, m.uri) for m in robot.missing_meshes] == [
            ("r/velodyne_base_link", "visual", "package://velodyne_description/meshes/VLP16_base_1.dae"),
            ("r/velodyne_base_link", "collision", "package://velodyne_description/meshes/VLP16_base_1.dae"),
        ]
        # fixed links are merged into the base when pybullet loads a robot: look at every shape
        shapes = [
            shape
            for link in range(-1, p.getNumJoints(robot.body, physicsClientId=client))
            for shape in p.getCollisionShapeData(robot.body, link, physicsClientId=client)
        ]
        files = [s[4].decode() for s in shapes if s[2] == p.GEOM_MESH]
        hokuyo = [f for f in files if f.endswith("hokuyo.dae")]  # through thorvald_description's meshes/
        assert len(hokuyo) == 1 and os.path.samefile(hokuyo[0], HOKUYO)
        assert not any("VLP16" in f for f in files)
        # the robot stands on its wheels, upright, with the extras on it
        for _ in range(240):
            sim.step()
        _, orientation = p.getBasePositionAndOrientation(robot.body, physicsClientId=client)
        roll, pitch, _ = p.getEulerFromQuaternion(orientation)
        assert abs(roll) < 0.01 and abs(pitch) < 0.01
    finally:
        p.disconnect(client)
