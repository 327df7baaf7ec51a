"""Crop rows: the keys, the plants a seed gives (pure), and the plants pybullet builds where they are."""

import math

import pybullet as p
import pytest
from sim_test_helpers import ray_down, world_problems

from thorvald_sim.physics.scene import build_scene
from thorvald_sim.world import ConfigError, load_world, parse_world, resolve_world
from thorvald_sim.world.bodies import MAX_MESH_VERTICES
from thorvald_sim.world.kinds.rows import Rows, plant_positions
from thorvald_sim.world.surfaces import Surface

ROW = {"x": 1.0, "y": 2.0, "length": 3.0}


def rows_of(**keys):
    return parse_world({"rows": {"row0": {**ROW, **keys}}}).rows[0]


def problems_of(**keys):
    return world_problems({"rows": {"row0": {**ROW, **keys}}})


# ---------------------------------------------------------------------------------------------
# Keys
# ---------------------------------------------------------------------------------------------
def test_defaults():
    rows = rows_of()
    assert rows == Rows(
        "row0", 0, 1.0, 2.0, 0.0, 1, 0.75, 3.0, "cylinder", 0.3, 0.1, 0.4, 0.0, 0.0, 0, (0.25, 0.55, 0.2, 1.0),
        Surface(0.5, 0.0, 0.0),
    )  # fmt: skip
    # 3 m at 0.3 m: 10 spacings, 11 places (both ends)
    assert rows.plants_per_row == 11


def test_gaps_is_another_name_of_gap_probability_and_colours_take_3_or_4_numbers():
    assert rows_of(gaps=0.25).gap_probability == 0.25
    assert rows_of(rgba=[0.1, 0.2, 0.3]).rgba == (0.1, 0.2, 0.3, 1.0)
    assert rows_of(rgba=[0, 1, 0, 0.5]).rgba == (0.0, 1.0, 0.0, 0.5)
    found = problems_of(gaps=0.1, gap_probability=0.2)
    assert (
        "already given as" in found["rows.row0.gap_probability"].rule
        or "already given as" in found["rows.row0.gaps"].rule
    )


@pytest.mark.parametrize(
    ("keys", "path", "rule"),
    [
        ({"count": 0}, "count", "must be > 0"),
        ({"count": 1.5}, "count", "must be an integer"),
        ({"spacing": -1}, "spacing", "must be in (0, 10000] [m]"),
        ({"plant": "tree"}, "plant", "must be one of cylinder, sphere"),
        ({"plant_spacing": 0}, "plant_spacing", "must be in (0, 10000] [m]"),
        ({"gap_probability": 1.5}, "gap_probability", "must be in [0, 1]"),
        ({"jitter": -0.1}, "jitter", "must be in [0, 10000] [m]"),
        ({"seed": "abc"}, "seed", "must be an integer"),
        ({"rgba": [1, 0]}, "rgba", "must be a list of 3 or 4 numbers in [0, 1] (red, green, blue, alpha)"),
        ({"rgba": [1, 0, 2]}, "rgba", "must be a list of 3 or 4 numbers in [0, 1] (red, green, blue, alpha)"),
        ({"rgba": "green"}, "rgba", "must be a list of 3 or 4 numbers in [0, 1] (red, green, blue, alpha)"),
        ({"lateral_friction": -1}, "lateral_friction", "must be >= 0"),
    ],
)
def test_each_rule(keys, path, rule):
    found = problems_of(**keys)
    assert list(found) == [f"rows.row0.{path}"]
    assert found[f"rows.row0.{path}"].rule == rule
    assert found[f"rows.row0.{path}"].value == next(iter(keys.values()))


def test_required_keys_and_a_mistyped_one():
    with pytest.raises(ConfigError) as e:
        parse_world({"rows": {"row0": {"plant_hieght": 1}}}, "test-world")
    found = {pr.path: pr.rule for pr in e.value.problems}
    assert found == {
        "rows.row0.plant_hieght": "unknown key (did you mean 'plant_height'?)",
        "rows.row0.x": "is required",
        "rows.row0.y": "is required",
        "rows.row0.length": "is required",
    }


def test_a_sphere_cannot_have_its_centre_below_the_ground():
    found = problems_of(plant="sphere", plant_radius=0.2, plant_height=0.1)
    assert list(found) == ["rows.row0.plant_height"]
    assert "must be >= plant_radius (0.2 m) for a sphere" in found["rows.row0.plant_height"].rule
    assert rows_of(plant="sphere", plant_radius=0.2, plant_height=0.2).plant_height == 0.2  # half a ball on the ground
    assert rows_of(plant="cylinder", plant_radius=0.2, plant_height=0.1).plant_height == 0.1


def test_a_typing_mistake_cannot_make_millions_of_plants():
    # 10 rows of 1000 m every 1 mm: 10 million plants
    found = problems_of(count=10, length=1000, plant_spacing=0.001)
    assert list(found) == ["rows.row0.plant_spacing"]
    # (the world's budget over every entry: test_world_limits.py)
    assert found["rows.row0.plant_spacing"].rule == (
        "makes 10000010 plants over the world's rows and polytunnels; at most 50000"
    )


# ---------------------------------------------------------------------------------------------
# The plants a seed gives
# ---------------------------------------------------------------------------------------------
def test_without_gaps_or_jitter_the_plants_are_a_grid_turned_by_yaw():
    rows = rows_of(count=3, spacing=0.5, plant_spacing=1.0, yaw=math.pi / 2)
    lines = plant_positions(rows)
    # yaw 90 degrees: the rows run along +y, each next one 0.5 m to the left (-x); 3 m: 4 places
    assert len(lines) == 3
    for k, line in enumerate(lines):
        assert [c for point in line for c in point] == pytest.approx(
            [c for i in range(4) for c in (1.0 - 0.5 * k, 2.0 + i)]
        )
        assert rows.row_start(k) == pytest.approx((1.0 - 0.5 * k, 2.0))


def test_a_row_of_a_whole_number_of_spacings_ends_with_a_plant():
    # 0.3 / 0.1 is 2.9999999999999996 in floating point; the row still has 4 places
    assert rows_of(length=0.3, plant_spacing=0.1).plants_per_row == 4
    assert len(plant_positions(rows_of(length=0.3, plant_spacing=0.1))[0]) == 4


def test_the_same_seed_gives_the_same_plants_and_another_seed_others():
    keys = dict(count=4, length=20.0, gap_probability=0.2, jitter=0.05)
    a = plant_positions(rows_of(seed=7, **keys))
    assert plant_positions(rows_of(seed=7, **keys)) == a
    assert plant_positions(rows_of(seed=8, **keys)) != a


def test_jitter_moves_each_plant_by_at_most_its_bound_along_and_across():
    rows = rows_of(count=5, spacing=0.6, length=30.0, plant_spacing=0.25, jitter=0.04, yaw=0.3, seed=3)
    moved = []
    for k, line in enumerate(plant_positions(rows)):
        for i, (x, y) in enumerate(line):
            # back into the rows' frame: u along, v across from the first row's start
            c, s = math.cos(rows.yaw), math.sin(rows.yaw)
            u, v = c * (x - rows.x) + s * (y - rows.y), -s * (x - rows.x) + c * (y - rows.y)
            du, dv = u - i * rows.plant_spacing, v - k * rows.spacing
            assert abs(du) <= 0.04 + 1e-9 and abs(dv) <= 0.04 + 1e-9
            moved += [abs(du), abs(dv)]
    # uniform in [-0.04, 0.04]: the moves fill the range (mean 0.02), not a few fixed offsets
    assert max(moved) > 0.039 and 0.018 < sum(moved) / len(moved) < 0.022


def test_gaps_leave_out_about_their_share_and_move_no_other_plant():
    keys = dict(count=10, length=60.0, plant_spacing=0.3, jitter=0.03, seed=5)
    full = plant_positions(rows_of(**keys))
    assert [len(line) for line in full] == [201] * 10
    gappy = plant_positions(rows_of(gap_probability=0.1, **keys))
    kept = sum(len(line) for line in gappy)
    # 2010 places, 10 % missing: binomial, standard deviation sqrt(2010 * 0.1 * 0.9) = 13.4
    assert abs(kept - 1809) < 4 * 13.4
    for line, line_full in zip(gappy, full):
        assert set(line) <= set(line_full), "the plants left are where they were without gaps"
    assert plant_positions(rows_of(gap_probability=1.0, **keys)) == ((),) * 10


# ---------------------------------------------------------------------------------------------
# In pybullet
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("plant", ["cylinder", "sphere"])
def test_the_plants_stand_where_the_file_says_and_the_furrows_are_free(client, plant):
    rows = {"x": -2.0, "y": 1.0, "yaw": 0.4, "count": 3, "spacing": 0.8, "length": 6.0, "plant": plant}
    rows.update(plant_radius=0.1, plant_height=0.35, jitter=0.03, gap_probability=0.2, seed=9)
    world = parse_world({"rows": {"row0": rows}})
    scene = build_scene(client, world)
    r = world.rows[0]
    assert [name for name in scene.bodies if name.startswith("rows.")] == ["rows.row0.0", "rows.row0.1", "rows.row0.2"]
    for k, line in enumerate(plant_positions(r)):
        body = scene.bodies[f"rows.row0.{k}"]
        assert p.getDynamicsInfo(body, -1, physicsClientId=client)[0] == 0.0, "static"
        for x, y in line:
            # the plant's top (a cylinder's cap; a sphere's pole) over its centre
            assert ray_down(client, x, y) == (body, pytest.approx(0.35, abs=1e-4))
        # half-way between two rows, and beyond the row's ends: the ground
        for u, v in ((1.0, (k + 0.5) * r.spacing), (-0.3, k * r.spacing), (r.length + 0.3, k * r.spacing)):
            x, y = r.x + math.cos(r.yaw) * u - math.sin(r.yaw) * v, r.y + math.sin(r.yaw) * u + math.cos(r.yaw) * v
            assert ray_down(client, x, y) == (scene.bodies["ground"], pytest.approx(0.0, abs=1e-9))


def test_a_plant_is_as_wide_as_its_radius(client):
    world = parse_world({"rows": {"row0": {"x": 0, "y": 0, "length": 0.0001, "plant_radius": 0.2, "plant_height": 1}}})
    scene = build_scene(client, world)
    body = scene.bodies["rows.row0.0"]
    # an octagonal prism: its corners 0.2 m from the centre every 45 degrees from +x, the middles of
    # its faces 0.2 cos(22.5 deg) = 0.185 m, half-way between
    for degrees, reach in ((0, 0.2), (90, 0.2), (225, 0.2), (22.5, 0.2 * math.cos(math.pi / 8)), (112.5, 0.1848)):
        a = math.radians(degrees)
        hit = p.rayTest((math.cos(a), math.sin(a), 0.5), (0.0, 0.0, 0.5), physicsClientId=client)[0]
        assert hit[0] == body and math.hypot(*hit[3][:2]) == pytest.approx(reach, abs=1e-4), degrees


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_a_row_too_big_for_one_mesh_goes_on_in_parts(client):
    # spheres on stems: 26 + 16 vertices a plant (65536 // 42 = 1560 a body); 2000 of them in two bodies
    world = parse_world({"rows": {"row0": {"x": 0, "y": 0, "length": 199.9, "plant_spacing": 0.1, "plant": "sphere"}}})
    scene = build_scene(client, world)
    assert [n for n in scene.bodies if n.startswith("rows.")] == ["rows.row0.0", "rows.row0.0.part1"]
    assert MAX_MESH_VERTICES == 65536
    # the first 1560 plants in the first body, the rest in the second
    assert ray_down(client, 0.0, 0.0)[0] == scene.bodies["rows.row0.0"]
    assert ray_down(client, 155.9, 0.0)[0] == scene.bodies["rows.row0.0"]
    assert ray_down(client, 156.0, 0.0)[0] == scene.bodies["rows.row0.0.part1"]
    assert ray_down(client, 199.9, 0.0)[0] == scene.bodies["rows.row0.0.part1"]


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_the_shipped_crop_rows_are_where_the_file_says(client):
    world = load_world(resolve_world("crop_rows"))
    scene = build_scene(client, world)
    lettuce, maize = world.rows
    # the lettuce row the robot straddles driving +x from the origin: the 6th of 11, at y = 0
    assert lettuce.row_start(5) == pytest.approx((4.0, 0.0))
    for k, (rows, top) in enumerate(((lettuce, 0.25), (maize, 1.5))):
        for line, positions in enumerate(plant_positions(rows)):
            body = scene.bodies[f"rows.row{k}.{line}"]
            for x, y in positions[::10]:
                assert ray_down(client, x, y) == (body, pytest.approx(top, abs=1e-4))
    # the furrows either side of the straddled row, where the wheels go: free from x = 4 to 44
    for x in (4.0 + 0.05 * i for i in range(801)):
        for y in (-0.3, 0.3):
            assert ray_down(client, x, y, top=1.0)[0] == scene.bodies["ground"], (x, y)
    counts = [sum(len(line) for line in plant_positions(rows)) for rows in world.rows]
    assert 1150 < counts[0] < 1260 and 1050 < counts[1] < 1170  # 1202 and 1110 expected (5 and 8 % gaps)
