"""Polytunnels: keys and rules, the geometry (pure), and the tubes, tables and plants pybullet builds."""

import math

import pybullet as p
import pytest
from sim_test_helpers import world_problems

from thorvald_sim.physics.scene import build_scene
from thorvald_sim.world import load_world, parse_world, resolve_world
from thorvald_sim.world.kinds.polytunnels import ARCH_SEGMENTS, TABLE_DEPTH

TUNNEL = {"x": 0.0, "y": 0.0, "length": 20.0}


def tunnel_of(**keys):
    return parse_world({"polytunnels": {"polytunnel0": {**TUNNEL, **keys}}}).polytunnels[0]


def problems_of(**keys):
    return world_problems({"polytunnels": {"polytunnel0": {**TUNNEL, **keys}}})


def ray(client, start, end):
    """(body id, hit point) of the first thing on the segment from start to end."""
    body, _, _, position, _ = p.rayTest(start, end, physicsClientId=client)[0]
    return body, position


# ---------------------------------------------------------------------------------------------
# Keys and geometry (pure)
# ---------------------------------------------------------------------------------------------
def test_defaults_are_a_haygrove_type_tunnel_with_four_rows_of_table_tops():
    t = tunnel_of()
    assert (t.width, t.height, t.leg_height, t.hoop_spacing, t.tube, t.yaw, t.z) == (8.0, 4.0, 2.0, 2.0, 0.05, 0.0, 0.0)
    assert (t.crop, t.tables, t.table_height, t.table_width, t.leg_spacing) == ("table_tops", 4, 1.1, 0.4, 1.8)
    assert (t.bed_height, t.end_gap, t.plant_spacing) == (0.2, 1.5, 0.25)
    # 20 m at 2 m: 11 hoops from end to end
    assert t.hoop_stations() == pytest.approx([-10.0 + 2.0 * k for k in range(11)])
    # 8 m / 4 tables: centres 2 m apart, the outer ones 1 m from the legs
    assert t.table_offsets() == pytest.approx((-3.0, -1.0, 1.0, 3.0))
    assert t.table_span() == (-8.5, 8.5)
    # 17 m of table at 1.8 m asked: round(9.44) = 9 bays of 1.889 m, 10 leg pairs
    assert t.table_leg_stations() == pytest.approx([-8.5 + 17.0 * k / 9 for k in range(10)])
    # plants every 0.25 m, half a spacing in from the ends: 68 of them
    stations = t.plant_stations()
    assert len(stations) == 68 and stations[0] == -8.375 and stations[-1] == pytest.approx(8.375)
    assert t.plant_radius == pytest.approx(0.12) and t.plant_top == pytest.approx(1.1 + 0.18)


def test_the_hoops_are_shrunk_to_fit_a_whole_number_and_the_arch_is_a_half_ellipse():
    t = tunnel_of(length=21.0, width=7.0, height=3.5, leg_height=1.5)
    # 21 / 2 = 10.5 bays: 10 of 2.1 m
    assert t.hoop_stations() == pytest.approx([-10.5 + 2.1 * k for k in range(11)])
    arch = t.arch()
    assert len(arch) == ARCH_SEGMENTS + 1
    assert arch[0] == pytest.approx((3.5, 1.5)) and arch[-1] == pytest.approx((-3.5, 1.5))
    assert arch[ARCH_SEGMENTS // 2] == pytest.approx((0.0, 3.5))
    for v, z in arch:
        # on the ellipse with half axes 3.5 (across) and 2.0 (up) about (0, 1.5)
        assert (v / 3.5) ** 2 + ((z - 1.5) / 2.0) ** 2 == pytest.approx(1.0)
        assert t.roof_height(v) == pytest.approx(z)
    # a semicircle when the rise is half the width
    circle = tunnel_of(width=8.0, height=4.0, leg_height=0.0)
    assert all(math.hypot(v, z) == pytest.approx(4.0) for v, z in circle.arch())


def test_ground_beds_and_no_crop():
    beds = tunnel_of(crop="ground_beds", tables=5, table_width=0.8)
    assert beds.table_offsets() == pytest.approx((-3.2, -1.6, 0.0, 1.6, 3.2))
    assert beds.table_leg_stations() == () and beds.crop_top == 0.2
    assert beds.plant_top == pytest.approx(0.2 + 1.5 * 0.24)
    empty = tunnel_of(crop="none")
    assert (empty.table_offsets(), empty.plant_stations(), empty.table_leg_stations()) == ((), (), ())


def test_the_tunnel_frame_turns_with_yaw():
    t = tunnel_of(x=5.0, y=-3.0, yaw=math.pi / 2)
    assert t.to_world(2.0, 1.0) == pytest.approx((5.0 - 1.0, -3.0 + 2.0))


@pytest.mark.parametrize(
    ("keys", "path", "rule"),
    [
        ({"height": 2.0}, "height", "must be > leg_height (2.0 m)"),
        ({"end_gap": 10.0}, "end_gap", "must be < length / 2 (10.0 m): the tables would have no length"),
        ({"table_width": 2.0}, "table_width", "times tables (4) must be < width (8.0 m): an aisle between the tables"),
        ({"crop": "hydroponics"}, "crop", "must be one of table_tops, ground_beds, none"),
        ({"tables": 0}, "tables", "must be > 0"),
        ({"table_height": 0.1}, "table_height", f"must be in ({TABLE_DEPTH}, 10000] [m] (above the trough's depth)"),
        ({"leg_height": -1}, "leg_height", "must be in [0, 10000] [m]"),
        ({"hoop_spacing": 0}, "hoop_spacing", "must be in (0, 10000] [m]"),
    ],
)
def test_each_rule(keys, path, rule):
    found = problems_of(**keys)
    assert {k: pr.rule for k, pr in found.items()} == {f"polytunnels.polytunnel0.{path}": rule}


def test_the_plants_must_be_under_the_roof():
    # a low arch (1.5 m legs, 2.0 m ridge) over 1.8 m tables: the outer table's edge is at 3.2 m, where
    # the roof is 1.5 + 0.5 sqrt(1 - 0.8^2) = 1.8 m (1.775 m under the tube)
    found = problems_of(leg_height=1.5, height=2.0, table_height=1.8)
    assert list(found) == ["polytunnels.polytunnel0.table_height"]
    assert found["polytunnels.polytunnel0.table_height"].rule.startswith(
        "is too high: puts the plants (0.18 m above it)"
    )
    assert "under the roof (1.77 m at the outer table)" in found["polytunnels.polytunnel0.table_height"].rule


# ---------------------------------------------------------------------------------------------
# In pybullet
# ---------------------------------------------------------------------------------------------
def test_hoops_legs_tables_and_plants_are_where_the_geometry_says(client):
    world = parse_world({"polytunnels": {"polytunnel0": {"x": 3.0, "y": -2.0, "yaw": 0.3, "length": 12.0}}})
    t = world.polytunnels[0]
    scene = build_scene(client, world)
    name = "polytunnels.polytunnel0"
    assert [n for n in scene.bodies if n.startswith(name)] == [
        f"{name}.{part}"
        for part in (
            "legs_left",
            "legs_right",
            "roof",
            *(f"{kind}{k}" for k in range(4) for kind in ("table", "plants", "berries")),
        )
    ]
    roof, ground = scene.bodies[f"{name}.roof"], scene.bodies["ground"]

    def at(u, v, z):
        return (*t.to_world(u, v), z)

    hoops = t.hoop_stations()
    # half-way between two hoops over the centre line: the ridge pole's top
    between = (hoops[2] + hoops[3]) / 2
    assert ray(client, at(between, 0.0, 6.0), at(between, 0.0, -1.0)) == (roof, pytest.approx(at(between, 0.0, 4.025)))
    # over a leg row between the hoops: the pole along it, at the legs' top
    body, hit = ray(client, at(between, 4.0, 6.0), at(between, 4.0, -1.0))
    assert body == roof and hit[2] == pytest.approx(2.0 + 0.025)
    # from the centre line outwards at 1.6 m (over the tables' plants, under the arch): a leg's inner face
    for u in hoops[:3]:
        for side, body_name in ((1, "legs_left"), (-1, "legs_right")):
            body, hit = ray(client, at(u, 0.0, 1.6), at(u, side * 6.0, 1.6))
            assert body == scene.bodies[f"{name}.{body_name}"]
            assert hit == pytest.approx(at(u, side * (4.0 - 0.025), 1.6), abs=1e-4)
    # the arch 45 degrees out from the ridge: a ray from the centre at leg_height hits the tube's inside
    a = math.radians(45)
    direction = (4.0 * math.cos(a), 2.0 * math.sin(a))  # towards the ellipse's point at 45 degrees
    body, hit = ray(client, at(hoops[4], 0.0, 2.0), at(hoops[4], 1.5 * direction[0], 2.0 + 1.5 * direction[1]))
    assert body == roof
    assert math.hypot(hit[0] - at(hoops[4], 0, 0)[0], hit[1] - at(hoops[4], 0, 0)[1]) == pytest.approx(
        4.0 * math.cos(a), abs=0.03
    )
    start, end = t.table_span()
    legs = t.table_leg_stations()
    for k, v in enumerate(t.table_offsets()):
        table, plants = scene.bodies[f"{name}.table{k}"], scene.bodies[f"{name}.plants{k}"]
        # each plant's top over its centre, from under the roof
        for u in t.plant_stations()[::7]:
            assert ray(client, at(u, v, 2.5), at(u, v, 0.0)) == (plants, pytest.approx(at(u, v, t.plant_top), abs=1e-4))
        # the trough's top beside the plants (0.18 m out from the centre, the plants reach 0.12 m)
        for u in (start + 0.05, (legs[1] + legs[2]) / 2, end - 0.05):
            for side in (-1, 1):
                hit = ray(client, at(u, v + side * 0.18, 2.5), at(u, v + side * 0.18, 0.0))
                assert hit == (table, pytest.approx(at(u, v + side * 0.18, 1.1), abs=1e-4))
        # under the trough, between leg pairs: the ground; at a leg pair: the legs
        mid = (legs[3] + legs[4]) / 2
        assert ray(client, at(mid, v, 0.8), at(mid, v, -1.0))[0] == ground
        body, hit = ray(client, at(legs[3], v - 0.5, 0.5), at(legs[3], v + 0.5, 0.5))
        assert body == table and hit == pytest.approx(at(legs[3], v - 0.2, 0.5), abs=1e-4)
        # beyond the table's ends: the ground
        assert ray(client, at(start - 0.05, v, 1.5), at(start - 0.05, v, -1.0))[0] == ground
    # the aisles between the tables are free from the ground to the legs' height, end to end
    for u in [start + 0.25 * i for i in range(int((end - start) / 0.25) + 1)]:
        for v in (-2.0, 0.0, 2.0):
            assert ray(client, at(u, v, 1.9), at(u, v, -1.0))[0] == ground, (u, v)
    # berries are drawn only: no collision
    assert p.getCollisionShapeData(scene.bodies[f"{name}.berries0"], -1, physicsClientId=client) == ()


def test_ground_beds_in_pybullet(client):
    world = parse_world({"polytunnels": {"polytunnel0": {**TUNNEL, "crop": "ground_beds", "tables": 3}}})
    scene = build_scene(client, world)
    t = world.polytunnels[0]
    bed = scene.bodies["polytunnels.polytunnel0.table1"]  # the middle one, on the centre line
    assert t.table_offsets()[1] == pytest.approx(0.0)
    assert ray(client, (0.0, 0.18, 1.5), (0.0, 0.18, -1.0)) == (bed, pytest.approx((0.0, 0.18, 0.2), abs=1e-4))
    plants = scene.bodies["polytunnels.polytunnel0.plants1"]
    u = t.plant_stations()[10]
    assert ray(client, (u, 0.0, 1.5), (u, 0.0, -1.0)) == (plants, pytest.approx((u, 0.0, t.plant_top), abs=1e-4))


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_the_shipped_polytunnel_keeps_an_aisle_along_x_from_the_origin(client):
    world = load_world(resolve_world("polytunnel"))
    scene = build_scene(client, world)
    t0 = world.polytunnels[0]
    # the robot at the origin is inside polytunnel0, between its tables at y = -1 and 1
    assert abs(t0.x) < t0.length / 2 and abs(t0.y) < t0.width / 2
    offsets = sorted(t0.to_world(0.0, v)[1] for v in t0.table_offsets())
    assert offsets == pytest.approx([-3.0, -1.0, 1.0, 3.0])
    start, end = (t0.to_world(u, 0.0)[0] for u in t0.table_span())
    assert start < -1.0 and end > 40.0
    # free from the ground up to 1.9 m, up to the troughs' edges 0.8 m either side of the centre line,
    # from the origin to the tables' end (the robot: 1.4 m wide at most, 1 m tall)
    hits = p.rayTestBatch(
        [(0.1 * i, y, 1.9) for i in range(int(end * 10)) for y in (-0.79, -0.4, 0.0, 0.4, 0.79)],
        [(0.1 * i, y, -1.0) for i in range(int(end * 10)) for y in (-0.79, -0.4, 0.0, 0.4, 0.79)],
        physicsClientId=client,
    )
    assert {h[0] for h in hits} == {scene.bodies["ground"]}
    # the two tunnels share the leg row at y = 4
    assert world.polytunnels[1].y - world.polytunnels[1].width / 2 == t0.y + t0.width / 2
