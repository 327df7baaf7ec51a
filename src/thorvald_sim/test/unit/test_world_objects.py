"""Objects (boxes, cylinders, spheres, meshes; static or moving) and walls: keys, rules and pybullet."""

import math
import os
import struct

import pybullet as p
import pytest
import yaml
from sim_test_helpers import ray_down, world_problems

from thorvald_sim.physics.scene import build_scene
from thorvald_sim.world import ConfigError, load_world, parse_world, worlds_dir
from thorvald_sim.world.kinds.objects import WorldObject
from thorvald_sim.world.surfaces import Surface

CRATE = os.path.join(worlds_dir(), "meshes", "crate.obj")


def objects(**entries):
    return parse_world({"objects": entries}).objects


problems_of = world_problems


def write_cube_stl(path, size):
    """A binary STL of a cube of side size [m] with a corner at the origin."""
    corners = [(x, y, z) for x in (0, size) for y in (0, size) for z in (0, size)]
    faces = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    with open(path, "wb") as f:
        f.write(b"\0" * 80 + struct.pack("<I", 12))
        for a, b, c, d in faces:
            for tri in ((a, b, c), (a, c, d)):
                f.write(struct.pack("<3f", 0, 0, 0))
                for i in tri:
                    f.write(struct.pack("<3f", *corners[i]))
                f.write(b"\0\0")


# ---------------------------------------------------------------------------------------------
# Keys
# ---------------------------------------------------------------------------------------------
def test_each_shape_rests_on_the_ground_by_default():
    box, cylinder, sphere, mesh = objects(
        object0={"shape": "box", "x": 1, "y": 2, "size_x": 0.4, "size_y": 0.6, "size_z": 0.8},
        object1={"shape": "cylinder", "x": 0, "y": 0, "radius": 0.2, "length": 1.0},
        object2={"shape": "sphere", "x": 0, "y": 0, "radius": 0.3},
        object3={"shape": "mesh", "x": 0, "y": 0, "file": CRATE},
    )
    assert box == WorldObject(
        "object0", 0, "box", 1.0, 2.0, 0.4, 0.0, 0.0, 0.0, 0.4, 0.6, 0.8, 0.0, 0.0, "", 1.0, 0.0,
        (0.6, 0.45, 0.28, 1.0), Surface(0.8, 0.0, 0.0, 0.0),
    )  # fmt: skip
    assert (cylinder.z, cylinder.radius, cylinder.length, cylinder.size_x) == (0.5, 0.2, 1.0, 0.0)
    assert (sphere.z, sphere.radius) == (0.3, 0.3)
    assert (mesh.z, mesh.file, mesh.scale) == (0.0, CRATE, 1.0)


def test_z_is_above_the_ground_under_the_object():
    hill = {"x": 0, "y": 0, "width": 4, "angle": 0.3, "height": 0.5, "top_length": 2}
    (on_top,) = parse_world(
        {"slopes": {"slope0": hill}, "objects": {"object0": {"shape": "sphere", "x": 0, "y": 0, "z": 1, "radius": 0.1}}}
    ).objects
    assert on_top.z == pytest.approx(1.5)


def test_a_mesh_file_is_found_from_the_world_files_folder(tmp_path):
    os.makedirs(tmp_path / "things")
    write_cube_stl(str(tmp_path / "things" / "cube.STL"), 0.5)
    path = tmp_path / "world.yaml"
    path.write_text(
        yaml.safe_dump({"objects": {"object0": {"shape": "mesh", "file": "things/cube.STL", "x": 0, "y": 0}}})
    )
    (cube,) = load_world(str(path)).objects
    assert cube.file == str(tmp_path / "things" / "cube.STL")
    # parse_world: from the folder it is given, else the current one
    data = {"objects": {"object0": {"shape": "mesh", "file": "cube.STL", "x": 0, "y": 0}}}
    assert parse_world(data, base_dir=str(tmp_path / "things")).objects[0].file == cube.file


def test_a_missing_mesh_file_is_a_problem_with_its_key_path(tmp_path):
    path = tmp_path / "world.yaml"
    path.write_text(
        yaml.safe_dump(
            {
                "objects": {
                    "object0": {"shape": "mesh", "file": "meshes/nope.obj", "x": 0, "y": 0},
                    "object1": {"shape": "mesh", "file": "crate.dae", "x": 0, "y": 0},
                    "object2": {"shape": "mesh", "file": "", "x": 0, "y": 0},
                }
            }
        )
    )
    with pytest.raises(ConfigError) as e:
        load_world(str(path))
    lines = str(e.value).splitlines()
    missing = tmp_path / "meshes" / "nope.obj"
    assert lines[0] == f"{path}: invalid world (3 problems):"
    assert (
        f"  {path}: objects.object0.file: 'meshes/nope.obj': no such file: {missing} "
        "(a relative path is from the world file's folder)"
    ) in lines
    assert f"  {path}: objects.object1.file: 'crate.dae': must be an OBJ or STL file (.obj, .stl)" in lines
    assert f"  {path}: objects.object2.file: '': must not be empty" in lines


def test_each_shape_requires_its_dimensions_and_refuses_the_others():
    found = problems_of(
        {
            "objects": {
                "object0": {"shape": "box", "x": 0, "y": 0, "size_x": 1, "size_y": 1, "radius": 0.5},
                "object1": {"shape": "cylinder", "x": 0, "y": 0, "radius": 0.5},
                "object2": {"shape": "sphere", "x": 0, "y": 0, "radius": -0.5, "scale": 2},
                "object3": {"shape": "mesh", "x": 0, "y": 0, "length": 1},
                "object4": {"shape": "cone", "x": 0, "y": 0},
            }
        }
    )
    assert {path: pr.rule for path, pr in found.items()} == {
        "objects.object0.radius": "is not a key of a box (it takes size_x, size_y, size_z)",
        "objects.object0.size_z": "is required for a box",
        "objects.object1.length": "is required for a cylinder",
        "objects.object2.radius": "must be in (0, 10000] [m]",  # reported once: not "is required" as well
        "objects.object2.scale": "is not a key of a sphere (it takes radius)",
        "objects.object3.length": "is not a key of a mesh (it takes file, scale)",
        "objects.object3.file": "is required for a mesh",
        "objects.object4.shape": "must be one of box, cylinder, sphere, mesh",
    }
    assert found["objects.object0.radius"].value == 0.5


@pytest.mark.parametrize(
    ("key", "value", "rule"),
    [
        ("mass", -1, "must be >= 0"),
        ("restitution", 2, "must be in [0, 1]"),
        ("rolling_friction", -0.1, "must be >= 0"),
        ("rgba", [1, 1, 1, 1, 1], "must be a list of 3 or 4 numbers in [0, 1] (red, green, blue, alpha)"),
        ("yaw", "left", "must be a finite number"),
    ],
)
def test_each_rule_of_an_object(key, value, rule):
    found = problems_of({"objects": {"object0": {"shape": "sphere", "x": 0, "y": 0, "radius": 1, key: value}}})
    assert {path: pr.rule for path, pr in found.items()} == {f"objects.object0.{key}": rule}


def test_walls_defaults_rules_and_their_foot_on_a_slope():
    (wall,) = parse_world({"walls": {"wall0": {"x": 1, "y": 2, "length": 5}}}).walls
    assert (wall.yaw, wall.height, wall.thickness, wall.z) == (0.0, 2.0, 0.2, 0.0)
    assert (wall.rgba, wall.surface) == ((0.75, 0.74, 0.7, 1.0), Surface(0.8, 0.0, 0.0))
    found = problems_of({"walls": {"wall0": {"x": 0, "y": 0, "length": 0, "thickness": -1, "rgba": [2, 0, 0]}}})
    assert {path: pr.rule for path, pr in found.items()} == {
        "walls.wall0.length": "must be in (0, 10000] [m]",
        "walls.wall0.thickness": "must be in (0, 10000] [m]",
        "walls.wall0.rgba": "must be a list of 3 or 4 numbers in [0, 1] (red, green, blue, alpha)",
    }
    # a wall across a hill's foot: its foot at the lowest ground along it, the plane's 0
    hill = {"x": 0, "y": 0, "width": 4, "angle": 0.3, "height": 0.5}
    world = parse_world({"slopes": {"slope0": hill}, "walls": {"wall0": {"x": 0, "y": 1, "yaw": 1.5708, "length": 6}}})
    assert world.walls[0].z == 0.0
    world = parse_world({"slopes": {"slope0": hill}, "walls": {"wall0": {"x": 0, "y": 0, "yaw": 1.5708, "length": 3}}})
    # along the ridge (yaw 1.5708 is 3.7e-6 off 90 degrees, and the hill has no flat top)
    assert world.walls[0].z == pytest.approx(0.5, abs=1e-5)


# ---------------------------------------------------------------------------------------------
# In pybullet
# ---------------------------------------------------------------------------------------------
def test_objects_are_where_the_file_says(client, tmp_path):
    write_cube_stl(str(tmp_path / "cube.stl"), 1.0)
    world = parse_world(
        {
            "objects": {
                "object0": {"shape": "box", "x": 2, "y": 0, "size_x": 0.4, "size_y": 0.6, "size_z": 0.8, "yaw": 0.5},
                "object1": {"shape": "cylinder", "x": -2, "y": 0, "radius": 0.3, "length": 1.2},
                "object2": {"shape": "sphere", "x": 0, "y": 2, "z": 1.0, "radius": 0.25},
                "object3": {"shape": "mesh", "x": 0, "y": -2, "file": CRATE, "rgba": [1, 0, 0]},
                "object4": {"shape": "mesh", "x": 4, "y": 4, "file": "cube.stl", "scale": 0.5},
            }
        },
        base_dir=str(tmp_path),
    )
    scene = build_scene(client, world)
    assert list(scene.bodies) == ["ground"] + [f"objects.object{i}" for i in range(5)]
    top = {"object0": 0.8, "object1": 1.2, "object2": 1.25}
    for name, z in top.items():
        thing = next(o for o in world.objects if o.name == name)
        assert ray_down(client, thing.x, thing.y) == (scene.bodies[f"objects.{name}"], pytest.approx(z, abs=1e-4))
    # the turned box: 0.3 m along its own y is inside it, 0.35 m outside (its half width is 0.3)
    for v, inside in ((0.28, True), (0.32, False)):
        x, y = 2 - math.sin(0.5) * v, math.cos(0.5) * v
        assert (ray_down(client, x, y)[0] == scene.bodies["objects.object0"]) == inside
    # the crate is open: a ray down its middle hits its bottom, 2 cm thick; one down a wall its rim
    crate = scene.bodies["objects.object3"]
    assert ray_down(client, 0.0, -2.0) == (crate, pytest.approx(0.02, abs=1e-4))
    assert ray_down(client, 0.29, -2.0) == (crate, pytest.approx(0.3, abs=1e-4))
    assert p.getVisualShapeData(crate, physicsClientId=client)[0][7] == (1.0, 0.0, 0.0, 1.0)
    # the STL cube, scaled to 0.5 m, its corner at (4, 4)
    assert ray_down(client, 4.25, 4.25) == (scene.bodies["objects.object4"], pytest.approx(0.5, abs=1e-4))
    assert ray_down(client, 4.55, 4.25)[0] == scene.bodies["ground"]


def test_objects_with_a_mass_fall_and_static_ones_stay(client):
    world = parse_world(
        {
            "objects": {
                "object0": {"shape": "box", "x": 0, "y": 0, "z": 2.0, "size_x": 0.2, "size_y": 0.2, "size_z": 0.2},
                "object1": {
                    "shape": "box",
                    "x": 1,
                    "y": 0,
                    "z": 2.0,
                    "size_x": 0.2,
                    "size_y": 0.2,
                    "size_z": 0.2,
                    "mass": 3,
                },
                "object2": {"shape": "mesh", "x": 2, "y": 0, "z": 1.0, "file": CRATE, "mass": 2},
                "object3": {"shape": "sphere", "x": 3, "y": 0, "z": 1.0, "radius": 0.1, "mass": 0.5},
            }
        }
    )
    scene = build_scene(client, world)
    body = {name.split(".")[1]: b for name, b in scene.bodies.items() if name != "ground"}
    assert p.getDynamicsInfo(body["object1"], -1, physicsClientId=client)[0] == 3.0
    assert p.getDynamicsInfo(body["object2"], -1, physicsClientId=client)[0] == 2.0

    def z(name):
        return p.getBasePositionAndOrientation(body[name], physicsClientId=client)[0][2]

    # free fall from 2 m: 0.5 g t^2 = 1.9 m takes 0.62 s; after 0.25 s the box has fallen 0.31 m
    for _ in range(60):
        p.stepSimulation(physicsClientId=client)
    assert z("object0") == 2.0
    assert z("object1") == pytest.approx(2.0 - 0.5 * 9.81 * 0.25**2, abs=0.01), "no drag"
    for _ in range(480):
        p.stepSimulation(physicsClientId=client)
    assert z("object0") == 2.0, "static: hangs in the air"
    assert z("object1") == pytest.approx(0.1, abs=0.003), "resting on the ground"
    assert z("object2") == pytest.approx(0.0, abs=0.003)
    assert z("object3") == pytest.approx(0.1, abs=0.003)
    # a resting object may sleep; a hit wakes it: a ball dropped on the box moves it down a little
    ball = p.createMultiBody(
        1.0,
        p.createCollisionShape(p.GEOM_SPHERE, radius=0.05, physicsClientId=client),
        basePosition=(1.05, 0.0, 0.5),
        physicsClientId=client,
    )
    moved = 0.0
    for _ in range(240):
        p.stepSimulation(physicsClientId=client)
        moved = max(moved, abs(p.getBaseVelocity(body["object1"], physicsClientId=client)[1][1]))
    assert moved > 0.01, "the box tipped under the ball"
    assert p.getBasePositionAndOrientation(ball, physicsClientId=client)[0][2] < 0.5


def test_walls_stand_where_the_file_says(client):
    world = parse_world(
        {"walls": {"wall0": {"x": 1, "y": 2, "yaw": 0.5, "length": 4, "height": 1.5, "thickness": 0.3}}}
    )
    scene = build_scene(client, world)
    wall, ground = scene.bodies["walls.wall0"], scene.bodies["ground"]
    c, s = math.cos(0.5), math.sin(0.5)
    for u, v, hit in ((0, 0, wall), (1.9, 0.1, wall), (-1.9, -0.1, wall), (2.1, 0, ground), (0, 0.2, ground)):
        x, y = 1 + c * u - s * v, 2 + s * u + c * v
        assert ray_down(client, x, y) == (hit, pytest.approx(1.5 if hit == wall else 0.0, abs=1e-4))
