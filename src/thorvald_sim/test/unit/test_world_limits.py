"""A world file can never exhaust the memory or hang the loader: every length and position is
bounded, and every budget of the world (plants, hoops, table legs, bodies, holes, ground look-ups,
grid points, image pixels and bytes, noise lattice, mesh bytes) is checked at load, before anything
it counts is made. Each is tried at its limit (loads) and just past it (refused at once, naming the
key, the value and the rule). Nothing here builds a scene of that size: a world at a limit is
parsed only, which makes none of its plants or meshes."""

import os
import random
import struct
import time
import zlib

import numpy as np
import pytest
import yaml
from PIL import Image
from sim_test_helpers import world_problems

from thorvald_sim.physics.scene import build_scene
from thorvald_sim.world import LIMITS, ConfigError, Limits, limits, load_world, loader, parse_world, worlds_dir
from thorvald_sim.world.kinds.height_field import HEIGHT_FIELD_KEYS
from thorvald_sim.world.kinds.objects import OBJECT_KEYS
from thorvald_sim.world.kinds.patches import PATCH_KEYS, soft_patches
from thorvald_sim.world.kinds.polytunnels import POLYTUNNEL_KEYS
from thorvald_sim.world.kinds.rails import RAIL_KEYS
from thorvald_sim.world.kinds.rows import ROWS_KEYS, plant_positions
from thorvald_sim.world.kinds.slopes import SLOPE_KEYS
from thorvald_sim.world.kinds.walls import WALL_KEYS
from thorvald_sim.world.rules import MAX_LENGTH, MAX_REACH

CRATE = os.path.join(worlds_dir(), "meshes", "crate.obj")
LENGTH_RULE = "must be in (0, 10000] [m]"
LENGTH_OR_ZERO_RULE = "must be in [0, 10000] [m]"
COORDINATE_RULE = "must be in [-10000, 10000] [m]"
JUST_PAST = 10_000.001  # [m] a millimetre past MAX_LENGTH and MAX_REACH


def test_the_limits_are_the_documented_ones():
    assert (MAX_REACH, MAX_LENGTH) == (10_000.0, 10_000.0)
    d = LIMITS
    assert (d.plants, d.hoops, d.table_legs, d.bodies, d.holes) == (50_000, 2_000, 10_000, 2_000, 50)
    assert (d.ground_lookups, d.field_points, d.noise_points) == (2_000_000, 1_000_000, 1_000_000)
    assert (d.image_bytes, d.mesh_bytes) == (32_000_000, 32_000_000)
    assert Limits() == LIMITS
    for figure in ("50 000", "2000 over every polytunnel", "10 000 over every polytunnel", "2 000 000", "32 MB"):
        assert figure in limits.__doc__


# ---------------------------------------------------------------------------------------------
# Lengths and positions
# ---------------------------------------------------------------------------------------------
# a valid entry of each section, and its keys
ENTRIES = {
    "patches": ({"x": 0, "y": 0, "size_x": 1, "size_y": 1, "lateral_friction": 0.5}, PATCH_KEYS),
    "slopes": ({"x": 0, "y": 0, "width": 1, "angle": 0.3, "height": 0.5}, SLOPE_KEYS),
    "rails": ({"x": 0, "y": 0, "length": 5}, RAIL_KEYS),
    "objects": ({"shape": "box", "x": 0, "y": 0, "size_x": 1, "size_y": 1, "size_z": 1}, OBJECT_KEYS),
    "rows": ({"x": 0, "y": 0, "length": 3}, ROWS_KEYS),
    "polytunnels": ({"x": 0, "y": 0, "length": 50}, POLYTUNNEL_KEYS),
    "walls": ({"x": 0, "y": 0, "length": 5}, WALL_KEYS),
    "height_field": ({"size_x": 10, "size_y": 6}, HEIGHT_FIELD_KEYS),
}
PREFIX = {"patches": "patch", "slopes": "slope", "rails": "rail", "objects": "object", "rows": "row"}
PREFIX.update(polytunnels="polytunnel", walls="wall")
# a cylinder's and a sphere's dimensions are tried on a cylinder, a mesh's scale on a mesh
OTHER_SHAPES = {
    "radius": {"shape": "cylinder", "x": 0, "y": 0, "radius": 1, "length": 1},
    "length": {"shape": "cylinder", "x": 0, "y": 0, "radius": 1, "length": 1},
}


def _world(section, entry):
    if section == "height_field":
        return {"height_field": entry}, "height_field"
    return {section: {PREFIX[section] + "0": entry}}, f"{section}.{PREFIX[section]}0"


def _bounded_keys():
    """(section, key, rule) of every key with a bound of the module's Limits."""
    cases = []
    for section, (_, keys) in ENTRIES.items():
        for key in keys:
            if key.rule in (LENGTH_RULE, LENGTH_OR_ZERO_RULE, COORDINATE_RULE) or key.name == "table_height":
                cases.append((section, key.name, key.rule))
    return cases


def test_every_length_and_position_key_is_bounded():
    bounded = {(section, key) for section, key, _ in _bounded_keys()}
    # every float key but the angles, frictions, sinkage, restitution, mass, probability and scale,
    # which have bounds of their own or scale nothing (a mesh's scale: below)
    unbounded = {
        (section, key.name)
        for section, (_, keys) in ENTRIES.items()
        for key in keys
        if key.kind is float and (section, key.name) not in bounded
    }
    assert {key for _, key in unbounded} == {
        "yaw", "roll", "pitch", "angle", "lateral_friction", "rolling_friction", "spinning_friction", "sinkage",
        "restitution", "mass", "gap_probability", "scale",
    }  # fmt: skip
    # patches 4, slopes 5, rails 6, objects 8, rows 8, polytunnels 14, walls 5, height field 13
    assert len(bounded) == 63


@pytest.mark.parametrize(("section", "key", "rule"), _bounded_keys())
def test_a_length_or_position_at_its_bound_passes_and_just_past_it_is_refused(section, key, rule):
    entry = dict(OTHER_SHAPES.get(key, ENTRIES[section][0])) if section == "objects" else dict(ENTRIES[section][0])
    data, path = _world(section, {**entry, key: JUST_PAST})
    found = world_problems(data)
    assert found[f"{path}.{key}"].rule == rule and found[f"{path}.{key}"].value == JUST_PAST
    # at the bound the key keeps to its rule (a cross-field rule or a budget may still refuse the
    # world: a rail's radius of 10 km is above its height)
    bound = -MAX_REACH if rule == COORDINATE_RULE else MAX_LENGTH
    data, path = _world(section, {**entry, key: bound})
    try:
        parse_world(data)
    except ConfigError as e:
        assert all(pr.rule != rule for pr in e.problems if pr.path == f"{path}.{key}")


def test_a_mesh_scale_is_bounded():
    mesh = {"shape": "mesh", "x": 0, "y": 0, "file": CRATE}
    assert parse_world({"objects": {"object0": {**mesh, "scale": 1000}}}).objects[0].scale == 1000.0
    found = world_problems({"objects": {"object0": {**mesh, "scale": 1000.001}}})
    assert found["objects.object0.scale"].rule == "must be in (0, 1000]"


# ---------------------------------------------------------------------------------------------
# What the file says it wants, tried as a careless or hostile user would
# ---------------------------------------------------------------------------------------------
def _png_header(path, width, height):
    """A PNG that says it is width x height pixels, with a few bytes of pixels: decoded, it would
    fail or exhaust the memory; refused from its header, it never is."""

    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)  # 8-bit grey
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"IDAT", zlib.compress(b"\0" * 100)))
        f.write(chunk(b"IEND", b""))


HOSTILE = {
    "100 rows entries": (
        {"rows": {f"row{i}": {"x": 0, "y": i, "length": 999, "plant_spacing": 1} for i in range(100)}},
        "rows.row0.plant_spacing",
        # 1000 places a row (0, 1, ..., 999 m) in each of 100 entries
        "makes 100000 plants over the world's rows and polytunnels, 1000 of them here; at most 50000",
    ),
    "an image of 10^10 pixels": (
        {"height_field": {"size_x": 10, "size_y": 10, "image": "bomb.png"}},
        "height_field.image",
        "makes 100000 x 100000 grid points (its pixels); at most 1000000",
    ),
    "size_x 1e308": ({"height_field": {"size_x": 1e308, "size_y": 10}}, "height_field.size_x", LENGTH_RULE),
    "length 1e308": ({"walls": {"wall0": {"x": 0, "y": 0, "length": 1e308}}}, "walls.wall0.length", LENGTH_RULE),
    "a wall 10^9 m long": ({"walls": {"wall0": {"x": 0, "y": 0, "length": 1e9}}}, "walls.wall0.length", LENGTH_RULE),
    "a polytunnel 10^7 m long with hoops every millimetre": (
        {"polytunnels": {"polytunnel0": {"x": 0, "y": 0, "length": 1e7, "hoop_spacing": 0.001}}},
        "polytunnels.polytunnel0.length",
        LENGTH_RULE,
    ),
    "a polytunnel 10 km long with hoops every millimetre": (
        {"polytunnels": {"polytunnel0": {"x": 0, "y": 0, "length": 1e4, "hoop_spacing": 0.001, "crop": "none"}}},
        "polytunnels.polytunnel0.hoop_spacing",
        # 10 000 m / 1 mm = 10^7 spacings, a hoop at each end of each
        "makes 10000001 hoops over the world's polytunnels; at most 2000",
    ),
    "a noise lattice at feature_length 1e-4": (
        {"height_field": {"size_x": 100, "size_y": 100, "resolution": 1, "amplitude": 0.1, "feature_length": 1e-4}},
        "height_field.feature_length",
        # 50 m / 0.1 mm = 500 000 lattice cells either side of the centre, and 2 more points
        "makes 1000002 x 1000002 noise lattice points (size / feature_length); at most 1000000",
    ),
    "a grid at the smallest resolution a float has": (
        {"height_field": {"size_x": 100, "size_y": 100, "resolution": 5e-324}},
        "height_field.resolution",
        "makes more than 1e308 x more than 1e308 grid points; at most 1000000",
    ),
    "a billion tables a micrometre wide": (
        {"polytunnels": {"polytunnel0": {"x": 0, "y": 0, "length": 3.5, "width": 10_000, "tables": 10**9}}},
        "polytunnels.polytunnel0.tables",
        # three bodies a table and three of the tunnel; the ground's is the one more
        "makes 3000000004 pybullet bodies over the world's entries and the ground, 3000000003 of them here; "
        "at most 2000",
    ),
}


@pytest.mark.parametrize("case", sorted(HOSTILE))
def test_a_hostile_world_is_refused_at_once_naming_the_key(tmp_path, case):
    _png_header(tmp_path / "bomb.png", 100_000, 100_000)
    data, path, rule = HOSTILE[case]
    if case == "a billion tables a micrometre wide":
        data["polytunnels"]["polytunnel0"]["table_width"] = 1e-6
    start = time.perf_counter()
    found = world_problems(data, base_dir=str(tmp_path))
    # milliseconds here; a loader that made what the file asks for would take hours or all the memory
    assert time.perf_counter() - start < 2.0
    assert found[path].rule == rule


def test_a_hostile_world_file_is_one_clean_error_naming_the_file(tmp_path):
    path = tmp_path / "world.yaml"
    path.write_text(yaml.safe_dump({"walls": {"wall0": {"x": 0, "y": 0, "length": 1e9}}}))
    with pytest.raises(ConfigError) as e:
        load_world(str(path))
    assert str(e.value).splitlines() == [
        f"{path}: invalid world (1 problem):",
        f"  {path}: walls.wall0.length: 1000000000.0: must be in (0, 10000] [m]",
    ]


# ---------------------------------------------------------------------------------------------
# Plants, hoops, table legs
# ---------------------------------------------------------------------------------------------
def rows_entry(count, length, spacing=1.0, **keys):
    return {"x": 0, "y": 0, "count": count, "length": length, "plant_spacing": spacing, **keys}


def test_plants_over_every_rows_entry_and_polytunnel_at_and_past_the_limit():
    # 49 rows of 1000 places (0 .. 999 m every 1 m) and a tunnel of 4 tables of 250 plants (its
    # tables 65.5 - 2 * 1.5 = 62.5 m long, a plant every 0.25 m from half a spacing in): 50 000
    tunnel = {"x": 0, "y": 500, "length": 65.5}
    world = {"rows": {"row0": rows_entry(49, 999)}, "polytunnels": {"polytunnel0": tunnel}}
    parsed = parse_world(world)
    assert len(parsed.polytunnels[0].plant_stations()) * 4 == 1000
    assert sum(r.count * r.plants_per_row for r in parsed.rows) == 49_000
    world["rows"]["row1"] = rows_entry(1, 0.5)  # one more place
    found = world_problems(world)
    assert list(found) == ["rows.row0.plant_spacing"]
    assert found["rows.row0.plant_spacing"].rule == (
        "makes 50001 plants over the world's rows and polytunnels, 49000 of them here; at most 50000"
    )
    assert found["rows.row0.plant_spacing"].value == 1.0


def test_gaps_count_as_plants_they_draw_their_random_numbers_too():
    # every place a gap: no plant is made, but each place draws its three random numbers
    world = parse_world({"rows": {"row0": rows_entry(50, 999, gap_probability=1.0)}})
    assert plant_positions(world.rows[0]) == ((),) * 50
    found = world_problems({"rows": {"row0": rows_entry(51, 999, gap_probability=1.0)}})
    assert found["rows.row0.plant_spacing"].rule.startswith("makes 51000 plants")


def test_hoops_at_and_past_the_limit():
    # 1999 m every 1 m: 1999 spacings, 2000 hoops
    tunnel = {"x": 0, "y": 0, "length": 1999, "hoop_spacing": 1, "crop": "none"}
    (parsed,) = parse_world({"polytunnels": {"polytunnel0": tunnel}}).polytunnels
    assert len(parsed.hoop_stations()) == LIMITS.hoops
    found = world_problems({"polytunnels": {"polytunnel0": {**tunnel, "length": 2000}}})
    assert found["polytunnels.polytunnel0.hoop_spacing"].rule == (
        "makes 2001 hoops over the world's polytunnels; at most 2000"
    )


def test_table_legs_at_and_past_the_limit():
    # one table from end to end (no end gaps) of 9999 m with legs every 1 m: 10 000 pairs; hoops
    # every 10 m (1001) and a plant every 0.25 m (39 996) stay inside their budgets
    tunnel = {"x": 0, "y": 0, "length": 9999, "hoop_spacing": 10, "tables": 1, "end_gap": 0, "leg_spacing": 1}
    (parsed,) = parse_world({"polytunnels": {"polytunnel0": tunnel}}).polytunnels
    assert len(parsed.table_leg_stations()) * len(parsed.table_offsets()) == LIMITS.table_legs
    found = world_problems({"polytunnels": {"polytunnel0": {**tunnel, "length": 10_000}}})
    assert list(found) == ["polytunnels.polytunnel0.leg_spacing"]
    assert found["polytunnels.polytunnel0.leg_spacing"].rule == (
        "makes 10001 pairs of table legs over the world's polytunnels; at most 10000"
    )


@pytest.mark.parametrize("budget", ["plants", "hoops", "table_legs"])
def test_the_budgets_count_what_the_world_makes(budget):
    # a world of every kind of plant and tunnel part, its counts from the value types themselves;
    # with the budget one below them, the refusal says exactly that count
    data = {
        "rows": {
            "row0": {"x": 0, "y": 0, "count": 3, "length": 3.0, "plant_spacing": 0.3, "gap_probability": 0.5},
            "row1": {"x": 0, "y": 5, "count": 2, "length": 0.31, "plant_spacing": 0.1, "plant": "sphere"},
        },
        "polytunnels": {
            "polytunnel0": {"x": 0, "y": 20, "length": 20.5, "tables": 3, "leg_spacing": 1.7},
            "polytunnel1": {"x": 0, "y": 40, "length": 11, "crop": "ground_beds", "hoop_spacing": 3},
            "polytunnel2": {"x": 0, "y": 60, "length": 7, "crop": "none"},
        },
    }
    world = parse_world(data)
    tunnels = world.polytunnels
    counts = {
        # places, gaps included (plant_positions leaves the gaps out)
        "plants": sum(r.count * r.plants_per_row for r in world.rows)
        + sum(len(t.plant_stations()) * len(t.table_offsets()) for t in tunnels),
        "hoops": sum(len(t.hoop_stations()) for t in tunnels),
        "table_legs": sum(len(t.table_leg_stations()) * len(t.table_offsets()) for t in tunnels),
    }
    # row0: 3 x 11; row1: 2 x 4 (0.31 m every 0.1 m); tunnel0: 3 tables of 70 (17.5 m every 0.25 m),
    # tunnel1: 4 beds of 32 (8 m)
    assert counts["plants"] == 33 + 8 + 210 + 128
    assert sum(len(line) for r in world.rows for line in plant_positions(r)) < 41, "the gaps are left out"
    with pytest.raises(ConfigError) as e:
        parse_world(data, limits=Limits(**{budget: counts[budget] - 1}))
    assert any(f"makes {counts[budget]} " in pr.rule for pr in e.value.problems)
    parse_world(data, limits=Limits(**{budget: counts[budget]}))


# ---------------------------------------------------------------------------------------------
# Bodies, holes, ground look-ups
# ---------------------------------------------------------------------------------------------
def test_bodies_at_and_past_the_limit():
    # 1000 objects, 499 rails of two pipes, 1 wall and the ground: 2000
    data = {
        "objects": {f"object{i}": {"shape": "sphere", "x": i % 100, "y": i // 100, "radius": 0.1} for i in range(1000)},
        "rails": {f"rail{i}": {"x": i, "y": -5, "length": 1} for i in range(499)},
        "walls": {"wall0": {"x": 0, "y": -10, "length": 1}},
    }
    parse_world(data)
    data["objects"]["object1000"] = {"shape": "sphere", "x": 0, "y": 20, "radius": 0.1}
    found = world_problems(data)
    assert list(found) == ["objects"]
    assert found["objects"].value == 1001
    assert found["objects"].rule == (
        "makes 2001 pybullet bodies over the world's entries and the ground, 1001 of them here; at most 2000"
    )


def test_the_bodies_of_a_rows_entry_and_a_polytunnel():
    # rows: one body a row; a tunnel: 3 and 3 a table. 665 tables: 3 + 1995, the ground and an object 2000
    tunnel = {"x": 0, "y": 0, "length": 3.5, "width": 8, "tables": 665, "table_width": 0.01}
    parse_world({"polytunnels": {"polytunnel0": tunnel}, "objects": {"object0": CRATE_OBJECT}})
    found = world_problems({"polytunnels": {"polytunnel0": {**tunnel, "tables": 666}}})
    assert found["polytunnels.polytunnel0.tables"].rule.startswith("makes 2002 pybullet bodies")
    parse_world({"rows": {"row0": rows_entry(1999, 0.1)}})
    found = world_problems({"rows": {"row0": rows_entry(2000, 0.1)}})
    assert found["rows.row0.count"].rule.startswith("makes 2001 pybullet bodies")


CRATE_OBJECT = {"shape": "mesh", "x": 10, "y": 10, "file": CRATE}


def test_the_body_count_is_the_scenes(client):
    # one of everything (legs, a table-top tunnel and a tunnel without crop): the budget's count is
    # what build_scene makes
    data = {
        "patches": {"patch0": {"x": 5, "y": 5, "size_x": 1, "size_y": 1, "lateral_friction": 0.5}},
        "slopes": {"slope0": {"x": -10, "y": 0, "width": 2, "angle": 0.3, "height": 0.3}},
        "rails": {"rail0": {"x": 0, "y": -5, "length": 3}},
        "objects": {"object0": CRATE_OBJECT},
        "rows": {"row0": rows_entry(3, 2.0, x=-5, y=-20)},
        "polytunnels": {
            "polytunnel0": {"x": 30, "y": 0, "length": 10, "tables": 2},
            "polytunnel1": {"x": 30, "y": 20, "length": 10, "crop": "none"},
        },
        "walls": {"wall0": {"x": 0, "y": 30, "length": 4}},
    }
    scene = build_scene(client, parse_world(data))
    # 1 + 1 + 2 + 1 + 3 + (3 + 6) + 3 + 1, and the ground
    assert len(scene.bodies) == 22
    with pytest.raises(ConfigError) as e:
        parse_world(data, limits=Limits(bodies=21))
    assert [pr.rule[:26] for pr in e.value.problems] == ["makes 22 pybullet bodies o"]


def _patches(n, soft):
    patches = {f"patch{i}": {"x": i * 2, "y": 0, "size_x": 1, "size_y": 1, "lateral_friction": 0.5} for i in range(n)}
    if soft:
        patches["patch0"]["surface"] = "mud"
    return {"patches": patches}


def test_holes_at_and_past_the_limit():
    assert len(soft_patches(parse_world(_patches(LIMITS.holes, soft=True)).patches)) == 1
    found = world_problems(_patches(LIMITS.holes + 1, soft=True))
    assert found["patches"].value == 51
    assert found["patches"].rule == ("makes 51 holes in the ground (one under every patch, as one is soft); at most 50")
    # without a soft patch there are no holes: as many patches as bodies allow
    assert len(parse_world(_patches(LIMITS.holes + 1, soft=False)).patches) == 51
    # a soft kind made firm by its sinkage key makes no holes either
    firm = _patches(LIMITS.holes + 1, soft=True)
    firm["patches"]["patch0"]["sinkage"] = 0
    parse_world(firm)


def test_ground_lookups_at_and_past_the_limit():
    # 50 000 plants (50 rows of 1000) each looking over the ground and 39 patches: 2 000 000
    data = {"rows": {"row0": rows_entry(50, 999, x=0, y=100)}, **_patches(39, soft=False)}
    parse_world(data)
    data["objects"] = {"object0": {"shape": "sphere", "x": 0, "y": -20, "radius": 0.1}}
    found = world_problems(data)
    assert list(found) == ["rows.row0.plant_spacing"]
    assert found["rows.row0.plant_spacing"].rule == (
        "makes 2000040 ground look-ups (plants, points every 0.5 m along walls, objects and tunnels, each over"
        " the ground, 39 hills and patches), 2000000 of them here; at most 2000000"
    )


def test_walls_that_would_search_the_ground_for_hours_are_refused_at_once():
    # 100 walls of 10 km: 20 001 points each, among a hill: 2 x 2 000 100 look-ups
    walls = {f"wall{i}": {"x": 0, "y": i, "length": 10_000} for i in range(100)}
    hill = {"x": 0, "y": 0, "width": 1, "angle": 0.3, "height": 0.5}
    start = time.perf_counter()
    found = world_problems({"walls": walls, "slopes": {"slope0": hill}})
    assert time.perf_counter() - start < 2.0  # the walls are not searched
    assert found["walls.wall0.length"].rule.startswith("makes 4000200 ground look-ups")
    # one wall of 10 km among the hill is searched: 40 002 look-ups
    (wall,) = parse_world({"walls": {"wall0": walls["wall0"]}, "slopes": {"slope0": hill}}).walls
    assert wall.z == 0.0


def test_a_world_over_a_budget_searches_no_ground(monkeypatch):
    # objects, tunnels and walls look for the ground under them as they are made; in a world over a
    # budget (refused anyway) they do not: thousands of them among thousands of patches could take
    # minutes before the refusal
    searches = []
    real = loader.ground_height
    monkeypatch.setattr(loader, "ground_height", lambda *a: searches.append(1) or real(*a))
    data = {
        "objects": {f"object{i}": {"shape": "sphere", "x": 0, "y": 0, "radius": 0.1} for i in range(3)},
        "polytunnels": {"polytunnel0": {"x": 0, "y": 50, "length": 10, "crop": "none"}},
        "walls": {"wall0": {"x": 0, "y": -50, "length": 10}},
    }
    parse_world(data)
    # 3 objects, a tunnel, 21 points along the wall (every 0.5 m over 10 m)
    assert len(searches) == 3 + 1 + 21
    searches.clear()
    data.update(_patches(3000, soft=False))
    found = world_problems(data)
    # 3000 patches, 3 objects, the tunnel's 3, the wall and the ground
    assert found["patches"].rule.startswith("makes 3008 pybullet bodies")
    assert searches == []


# ---------------------------------------------------------------------------------------------
# Height fields: grid, image, noise
# ---------------------------------------------------------------------------------------------
def test_grid_points_at_and_past_the_limit():
    # 199.8 m every 0.2 m: 999 cells, 1000 points a side
    field = {"size_x": 199.8, "size_y": 199.8, "resolution": 0.2}
    assert parse_world({"height_field": field}).height_field.grid_shape() == (1000, 1000)
    found = world_problems({"height_field": {**field, "size_y": 200}})
    assert found["height_field.resolution"].rule == "makes 1000 x 1001 grid points; at most 1000000"


def test_image_pixels_at_and_past_the_limit_are_read_from_the_header(tmp_path):
    Image.fromarray(np.zeros((1000, 1000), dtype=np.uint8)).save(tmp_path / "at.png")
    Image.fromarray(np.zeros((1001, 1000), dtype=np.uint8)).save(tmp_path / "past.png")
    field = {"size_x": 100, "size_y": 100}
    hf = parse_world({"height_field": {**field, "image": "at.png"}}, base_dir=str(tmp_path)).height_field
    assert hf.grid_shape() == (1000, 1000)
    found = world_problems({"height_field": {**field, "image": "past.png"}}, base_dir=str(tmp_path))
    assert found["height_field.image"].rule == "makes 1000 x 1001 grid points (its pixels); at most 1000000"
    # another format than PNG: its size from PIL, which reads only the header until it loads it
    Image.fromarray(np.zeros((1001, 1000), dtype=np.uint8)).save(tmp_path / "past.bmp")
    found = world_problems({"height_field": {**field, "image": "past.bmp"}}, base_dir=str(tmp_path))
    assert found["height_field.image"].rule == "makes 1000 x 1001 grid points (its pixels); at most 1000000"


def test_an_image_too_big_for_pil_is_one_clean_problem(tmp_path):
    # a BMP header saying 20 000 x 20 000 (4e8 pixels, beyond PIL's own 1.8e8): PIL refuses to open it
    Image.fromarray(np.zeros((4, 4), dtype=np.uint8)).save(tmp_path / "huge.bmp")
    with open(tmp_path / "huge.bmp", "r+b") as f:
        f.seek(18)
        f.write(struct.pack("<ii", 20_000, 20_000))
    found = world_problems({"height_field": {"size_x": 10, "size_y": 10, "image": "huge.bmp"}}, base_dir=str(tmp_path))
    assert found["height_field.image"].rule.startswith("cannot read the image: Image size (400000000 pixels)")


def test_image_bytes_at_and_past_the_limit(tmp_path):
    # a 2 x 2 PNG with zeros after its end to the limit (sparse: no disk, nothing read but its header)
    for name, size in (("at.png", LIMITS.image_bytes), ("past.png", LIMITS.image_bytes + 1)):
        Image.fromarray(np.array([[0, 255], [255, 0]], dtype=np.uint8)).save(tmp_path / name)
        with open(tmp_path / name, "r+b") as f:
            f.truncate(size)
    field = {"size_x": 10, "size_y": 10}
    assert parse_world({"height_field": {**field, "image": "at.png"}}, base_dir=str(tmp_path)).height_field
    found = world_problems({"height_field": {**field, "image": "past.png"}}, base_dir=str(tmp_path))
    assert found["height_field.image"].rule == "is a file of 32000001 bytes; at most 32000000"


def test_noise_lattice_at_and_past_the_limit():
    # 998 m at feature_length 1: lattice points from -499 to 499 and one beyond: 1000 a side
    field = {"size_x": 998, "size_y": 998, "resolution": 1, "amplitude": 0.1, "feature_length": 1}
    parse_world({"height_field": field})
    # 999 m: -499.5 .. 499.5, points from -500 to 500 and one beyond: 1001
    found = world_problems({"height_field": {**field, "size_y": 999}})
    assert found["height_field.feature_length"].rule == (
        "makes 1000 x 1001 noise lattice points (size / feature_length); at most 1000000"
    )
    # without an amplitude there is no noise to make
    parse_world({"height_field": {**field, "size_y": 999, "amplitude": 0}})


def test_the_noise_lattice_counted_is_the_one_made(monkeypatch):
    # the lattice _value_noise draws: one random number a point; counted through the generator
    made = []
    real = random.Random

    class Counting(real):
        def uniform(self, a, b):
            made.append(1)
            return super().uniform(a, b)

    monkeypatch.setattr(random, "Random", Counting)
    field = {"size_x": 9, "size_y": 5, "resolution": 0.5, "amplitude": 0.1, "feature_length": 2}
    parse_world({"height_field": field}).height_field.heights()
    # x: -4.5 / 2 .. 4.5 / 2 = -2.25 .. 2.25: floor 2 - floor -3 + 2 = 7; y: -1.25 .. 1.25: 1 + 2 + 2 = 5
    assert len(made) == 7 * 5
    found = world_problems({"height_field": field}, limits=Limits(noise_points=34))
    assert found["height_field.feature_length"].rule.startswith("makes 7 x 5 ")


# ---------------------------------------------------------------------------------------------
# Mesh bytes (the checks of each file: test_world_mesh_files.py)
# ---------------------------------------------------------------------------------------------
def test_mesh_bytes_over_every_object_at_and_past_the_limit(tmp_path):
    # a 32 000-byte OBJ (a triangle and a comment) named by 1000 objects: 32 000 000 bytes
    text = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n#"
    (tmp_path / "tri.obj").write_bytes(text + b"x" * (32_000 - len(text)))
    objects = {f"object{i}": {"shape": "mesh", "x": i % 100, "y": i // 100, "file": "tri.obj"} for i in range(1000)}
    assert len(parse_world({"objects": objects}, base_dir=str(tmp_path)).objects) == 1000
    objects["object1000"] = {"shape": "mesh", "x": 0, "y": 50, "file": CRATE}
    found = world_problems({"objects": objects}, base_dir=str(tmp_path))
    crate = os.path.getsize(CRATE)
    assert list(found) == ["objects.object0.file"]
    assert found["objects.object0.file"].rule == (
        f"makes {32_000_000 + crate} bytes of mesh files over the world's objects (each object's counted), "
        "32000 of them here; at most 32000000"
    )


def test_a_mesh_file_over_the_limit_is_refused_without_being_read(tmp_path):
    # 40 MB of zeros (sparse): read, it would be "binary bytes"; it is refused by its size alone
    with open(tmp_path / "big.obj", "wb") as f:
        f.truncate(40_000_000)
    data = {"objects": {"object0": {"shape": "mesh", "x": 0, "y": 0, "file": "big.obj"}}}
    found = world_problems(data, base_dir=str(tmp_path))
    assert found["objects.object0.file"].rule == (
        "makes 40000000 bytes of mesh files over the world's objects (each object's counted); at most 32000000"
    )


# ---------------------------------------------------------------------------------------------
# The shipped worlds are well inside every budget
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", sorted(f[:-5] for f in os.listdir(worlds_dir()) if f.endswith(".yaml")))
def test_the_shipped_worlds_use_a_twentieth_of_each_budget_at_most(name):
    # as the module says: crop_rows' 2471 plants are the most (of 2500 here); farm_track's 6 patches
    # are 6 holes, an eighth of 50
    budgets = (
        "plants",
        "hoops",
        "table_legs",
        "bodies",
        "ground_lookups",
        "mesh_bytes",
        "field_points",
        "noise_points",
    )
    tight = Limits(**{budget: getattr(LIMITS, budget) // 20 for budget in budgets}, holes=LIMITS.holes // 8)
    load_world(os.path.join(worlds_dir(), name + ".yaml"), tight)
