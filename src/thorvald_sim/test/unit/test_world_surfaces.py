"""Surfaces that cost grip: the surface kinds (the numbers thorvald_sim.world.surfaces documents), soft
ground that sinks a wheel (a ground with holes under soft patches), and what pybullet makes of them: a
ball and a rolling wheel sink by the documented amount and stay put, a coasting wheel slows on high
rolling resistance, a driven one needs more torque there, and a sunk wheel still rolls r * omega."""

import math
import os

import pybullet as p
import pytest
import sim_test_helpers
from sim_test_helpers import ray_down

from thorvald_model.description import generate_urdf
from thorvald_sim.physics.robot import Pose2D, yaw_of
from thorvald_sim.physics.scene import build_scene
from thorvald_sim.physics.simulation import Simulation
from thorvald_sim.world import ConfigError, load_world, parse_world, resolve_world
from thorvald_sim.world.geometry import ground_pieces
from thorvald_sim.world.kinds.patches import PATCH_TOP, SOFT_DEPTH, soft_patches
from thorvald_sim.world.surfaces import MAX_SINKAGE, REFERENCE_WHEEL_RADIUS, SINKAGE_LOAD, SURFACE_KINDS, Surface

HERE = os.path.dirname(os.path.abspath(__file__))
STD = os.path.join(HERE, "..", "..", "..", "thorvald_model", "config", "thorvald_ii_4wd4ws_std")
STD = os.path.abspath(os.path.join(STD, "thorvald_ii_4wd4ws_std.yaml"))
G = 9.81  # [m/s^2], the worlds' gravity
DT = 1.0 / 240  # [s], pybullet's default step and the simulator's

# thorvald_sim.world.surfaces' docstring's table: kind: (lateral friction, C_rr, rolling friction [m], sinkage [m])
TABLE = {
    "tarmac": (0.9, 0.015, 0.003, 0.0),
    "concrete": (0.85, 0.012, 0.0024, 0.0),
    "gravel": (0.6, 0.05, 0.01, 0.0),
    "grass": (0.55, 0.06, 0.012, 0.004),
    "wet_grass": (0.3, 0.08, 0.016, 0.008),
    "mud": (0.35, 0.2, 0.04, 0.015),
    "sand": (0.5, 0.25, 0.05, 0.02),
    "ice": (0.1, 0.01, 0.002, 0.0),
    "soil": (0.6, 0.08, 0.016, 0.006),
}
SOFT = [kind for kind, numbers in TABLE.items() if numbers[3] > 0]

_URDF = {}


def std_urdf():
    if "std" not in _URDF:
        _URDF["std"] = generate_urdf(STD)
    return _URDF["std"]


def patch(x=0.0, y=0.0, size_x=4.0, size_y=4.0, **keys):
    return {"x": x, "y": y, "size_x": size_x, "size_y": size_y, **keys}


def problems_of(data):
    return sim_test_helpers.world_problems(data)


# ---------------------------------------------------------------------------------------------
# The kinds and their keys
# ---------------------------------------------------------------------------------------------
def test_the_kinds_are_the_documented_table():
    assert list(SURFACE_KINDS) == list(TABLE)
    for kind, (lateral, c_rr, rolling, sinkage) in TABLE.items():
        k = SURFACE_KINDS[kind]
        assert (k.lateral_friction, k.rolling_resistance, k.rolling_friction, k.sinkage) == (
            lateral,
            c_rr,
            rolling,
            sinkage,
        )
        # pybullet's rolling friction is a torque per normal force: C_rr times the 0.2 m wheel's radius
        assert k.rolling_friction == pytest.approx(c_rr * REFERENCE_WHEEL_RADIUS, abs=1e-12)
        assert len(k.rgba) == 4 and all(0.0 <= c <= 1.0 for c in k.rgba)


@pytest.mark.parametrize("kind", list(TABLE))
def test_a_kind_names_the_numbers_of_the_ground_and_of_a_patch(kind):
    lateral, _, rolling, sinkage = TABLE[kind]
    world = parse_world({"ground": {"surface": kind}, "patches": {"patch0": patch(5.0, 5.0, surface=kind)}})
    for surface in (world.ground, world.patches[0].surface):
        assert surface == Surface(lateral, rolling, 0.0, 0.0, sinkage)
        assert surface.kind == kind
    assert world.ground_rgba == SURFACE_KINDS[kind].rgba
    assert world.patches[0].rgba == SURFACE_KINDS[kind].rgba
    assert soft_patches(world.patches) == (world.patches if sinkage > 0 else ())


def test_a_key_beside_a_kind_overrides_its_number_and_nothing_else():
    world = parse_world(
        {
            "ground": {"surface": "grass", "lateral_friction": 0.7, "rgba": [0.1, 0.2, 0.3]},
            "patches": {"patch0": patch(surface="mud", rolling_friction=0.05, sinkage=0, spinning_friction=0.01)},
        }
    )
    assert world.ground == Surface(0.7, 0.012, 0.0, 0.0, 0.004)
    assert world.ground_rgba == (0.1, 0.2, 0.3, 1.0)
    mud = world.patches[0]
    assert mud.surface == Surface(0.35, 0.05, 0.01, 0.0, 0.0)
    assert (mud.surface.kind, mud.rgba) == ("mud", SURFACE_KINDS["mud"].rgba)
    assert soft_patches(world.patches) == ()


def test_without_a_kind_everything_is_as_before():
    world = parse_world({"patches": {"patch0": patch(lateral_friction=0.6)}})
    assert world.ground == Surface(0.9, 0.0, 0.0, 0.0) and world.ground.sinkage == 0.0
    assert world.ground_rgba == (0.35, 0.35, 0.37, 1.0)
    assert world.patches[0].surface == Surface(0.6, 0.0, 0.0, 0.0, 0.0)
    assert world.patches[0].rgba is None  # the scene's gravel brown (ice blue below 0.3)
    assert (world.ground.kind, world.patches[0].surface.kind) == ("", "")


def test_a_soft_surface_is_a_critically_damped_spring_for_the_reference_load():
    s = Surface(0.35, 0.04, 0.0, 0.0, 0.015)
    # 500 N sink it 15 mm: 33 333 N/m; critical for the 51 kg that weigh 500 N: 2 sqrt(k m) = 2607 N s/m
    assert s.contact_stiffness == pytest.approx(SINKAGE_LOAD / 0.015)
    assert s.contact_damping == pytest.approx(2.0 * math.sqrt(33333.333 * 500.0 / 9.81), rel=1e-6)
    assert s.contact_damping == pytest.approx(2607, abs=1)
    rigid = Surface(0.9, 0.0, 0.0)
    assert (rigid.soft, rigid.contact_stiffness, rigid.contact_damping) == (False, math.inf, 0.0)


@pytest.mark.parametrize(
    "data, path, value, rule",
    [
        ({"ground": {"surface": "marsh"}}, "ground.surface", "marsh", "must be one of tarmac, concrete, gravel"),
        ({"patches": {"patch0": patch(surface="Mud")}}, "patches.patch0.surface", "Mud", "must be one of tarmac"),
        ({"patches": {"patch0": patch(surface=3)}}, "patches.patch0.surface", 3, "must be a string"),
        ({"ground": {"sinkage": -0.01}}, "ground.sinkage", -0.01, f"must be in [0, {MAX_SINKAGE}] [m]"),
        (
            {"patches": {"patch0": patch(surface="mud", sinkage=0.06)}},
            "patches.patch0.sinkage",
            0.06,
            "must be in [0, 0.05] [m]",
        ),
        (
            {"patches": {"patch0": patch(surface="mud", sinkage="deep")}},
            "patches.patch0.sinkage",
            "deep",
            "must be a finite number",
        ),
        (
            {"patches": {"patch0": patch(surface="mud", rolling_friction=-1)}},
            "patches.patch0.rolling_friction",
            -1,
            "must be >= 0",
        ),
        (
            {"patches": {"patch0": patch(surface="mud")}, "height_field": {"size_x": 4, "size_y": 4}},
            "patches.patch0.sinkage",
            0.015,
            "must be 0 with a height_field (write sinkage: 0 beside a soft surface kind): a soft patch needs a hole",
        ),
        (
            {"ground": {"surface": "grass"}, "height_field": {"size_x": 4, "size_y": 4}},
            "ground.sinkage",
            0.004,
            "must be 0 with a height_field (write sinkage: 0 beside a soft surface kind): bullet touches a wheel",
        ),
        (
            {"patches": {"patch0": patch(x=998.0, surface="mud")}},
            "patches.patch0.sinkage",
            0.015,
            "needs the patch within 999 m of the origin in x and y",
        ),
    ],
)
def test_a_bad_surface_is_refused_with_its_key_path_value_and_rule(data, path, value, rule):
    found = problems_of(data)
    assert list(found) == [path]
    assert found[path].value == value
    assert found[path].rule.startswith(rule), found[path].rule


def test_a_patch_needs_a_lateral_friction_or_a_kind_and_every_problem_is_told_at_once():
    found = problems_of(
        {
            "ground": {"surface": "bog"},
            "patches": {
                "patch0": {"x": 0, "size_x": 1, "size_y": 1},  # neither, and no y
                "patch1": patch(surface="sand"),  # a kind is enough
                "patch2": patch(surface="mud", sinkage=1),
            },
        }
    )
    assert sorted(found) == [
        "ground.surface",
        "patches.patch0.lateral_friction",
        "patches.patch0.y",
        "patches.patch2.sinkage",
    ]
    assert found["patches.patch0.lateral_friction"].rule == "is required"


def test_a_bad_kind_says_so_once_not_that_the_lateral_friction_is_missing():
    with pytest.raises(ConfigError) as e:
        parse_world({"patches": {"patch0": patch(surface="clay")}}, "w")
    assert [pr.path for pr in e.value.problems] == ["patches.patch0.surface"]
    assert "w: patches.patch0.surface: 'clay': must be one of tarmac, concrete, gravel, grass, wet_grass, mud" in str(
        e.value
    )


# ---------------------------------------------------------------------------------------------
# The ground with holes (pure)
# ---------------------------------------------------------------------------------------------
def _area(polygon):
    return 0.5 * sum(x1 * y2 - x2 * y1 for (x1, y1), (x2, y2) in zip(polygon, polygon[1:] + polygon[:1]))


def _inside(polygon, x, y, margin=0.0):
    """Whether (x, y) is inside the convex counter-clockwise polygon, at least margin from its edges."""
    for (x1, y1), (x2, y2) in zip(polygon, polygon[1:] + polygon[:1]):
        if ((x2 - x1) * (y - y1) - (y2 - y1) * (x - x1)) / math.hypot(x2 - x1, y2 - y1) < margin:
            return False
    return True


HOLES = {
    "one square": [((1.0, 1.0), (3.0, 1.0), (3.0, 2.0), (1.0, 2.0))],
    "turned and apart": [
        parse_world({"patches": {"patch0": patch(2.0, -1.0, 3.0, 1.0, yaw=0.5, lateral_friction=1)}})
        .patches[0]
        .corners(),
        ((-4.0, 0.0), (-2.0, 0.0), (-2.0, 3.0), (-4.0, 3.0)),
    ],
    "overlapping": [
        ((0.0, 0.0), (2.0, 0.0), (2.0, 2.0), (0.0, 2.0)),
        parse_world({"patches": {"patch0": patch(2.0, 2.0, 2.0, 2.0, yaw=0.7, lateral_friction=1)}})
        .patches[0]
        .corners(),
        ((1.0, -1.0), (5.0, -1.0), (5.0, 0.5), (1.0, 0.5)),
    ],
}


@pytest.mark.parametrize("holes", list(HOLES))
@pytest.mark.slow  # a dense grid of probes
def test_the_ground_pieces_cover_the_square_but_the_holes_once_each(holes):
    extent = 20.0
    pieces = ground_pieces(HOLES[holes], extent)
    for piece in pieces:
        assert len(piece) in (3, 4)
        assert _area(list(piece)) > 0, "counter-clockwise, not degenerate"
        for k in range(len(piece)):  # convex: every corner turns left
            (x0, y0), (x1, y1), (x2, y2) = piece[k - 1], piece[k], piece[(k + 1) % len(piece)]
            assert (x1 - x0) * (y2 - y1) - (y1 - y0) * (x2 - x1) >= -1e-12
    # every point 1 mm clear of every edge is in exactly one piece, or in a hole and no piece
    step = 0.0737  # not a round number, so no sample lies on a cut
    n = 0
    for i in range(-100, 101):
        for j in range(-100, 101):
            x, y = i * step + 0.0011, j * step + 0.0013
            near = [pc for pc in pieces if _inside(list(pc), x, y, -1e-3) and not _inside(list(pc), x, y, 1e-3)]
            near += [h for h in HOLES[holes] if _inside(list(h), x, y, -1e-3) and not _inside(list(h), x, y, 1e-3)]
            if near:
                continue
            in_hole = any(_inside(list(h), x, y) for h in HOLES[holes])
            assert sum(_inside(list(pc), x, y) for pc in pieces) == (0 if in_hole else 1), (x, y)
            n += 1
    assert n > 30000
    if holes != "overlapping":
        holes_area = sum(_area(list(h)) for h in HOLES[holes])
        assert sum(_area(list(pc)) for pc in pieces) == pytest.approx((2 * extent) ** 2 - holes_area, rel=1e-12)


def test_without_holes_the_ground_is_one_square():
    assert ground_pieces([], 5.0) == [((-5.0, -5.0), (5.0, -5.0), (5.0, 5.0), (-5.0, 5.0))]


# ---------------------------------------------------------------------------------------------
# The scene
# ---------------------------------------------------------------------------------------------
def test_a_soft_patch_is_let_into_the_ground_and_every_other_patch_too(client):
    world = parse_world(
        {
            "ground": {"surface": "grass", "sinkage": 0},
            "patches": {
                "patch0": patch(3.0, 0.0, 2.0, 2.0, yaw=0.4, surface="mud"),
                "patch1": patch(-3.0, 1.0, 2.0, 1.0, surface="gravel"),
            },
        }
    )
    scene = build_scene(client, world)
    ground, mud, gravel = (scene.bodies[k] for k in ("ground", "patches.patch0", "patches.patch1"))
    assert p.getNumBodies(physicsClientId=client) == 3
    for body, pa in ((mud, world.patches[0]), (gravel, world.patches[1])):
        # the top 1 mm up, and under it no ground: a ray from below meets the patch's bottom
        assert ray_down(client, pa.x, pa.y) == (body, pytest.approx(PATCH_TOP, abs=1e-6))
        hit = p.rayTest((pa.x, pa.y, -1.0), (pa.x, pa.y, 1.0), physicsClientId=client)[0]
        depth = SOFT_DEPTH if pa.surface.soft else 0.1
        assert (hit[0], hit[3][2]) == (body, pytest.approx(-depth, abs=1e-6))
        # just beyond a corner (in the patch's frame, so the yaw counts): the ground, at 0
        c, s = math.cos(pa.yaw), math.sin(pa.yaw)
        u, v = pa.size_x / 2 + 0.01, pa.size_y / 2 + 0.01
        assert ray_down(client, pa.x + c * u - s * v, pa.y + s * u + c * v) == (ground, pytest.approx(0.0, abs=1e-6))
    for x, y in ((0.0, 0.0), (60.0, -70.0), (-990.0, 990.0)):
        assert ray_down(client, x, y) == (ground, pytest.approx(0.0, abs=1e-6))
    # the mud is a spring and damper (getDynamicsInfo: ... contact damping, contact stiffness ...)
    info = p.getDynamicsInfo(mud, -1, physicsClientId=client)
    assert (info[9], info[8]) == pytest.approx((500.0 / 0.015, world.patches[0].surface.contact_damping))
    assert (info[1], info[6]) == pytest.approx((0.35, 0.04))
    assert p.getDynamicsInfo(gravel, -1, physicsClientId=client)[9] == -1.0  # rigid: none set
    assert p.getDynamicsInfo(ground, -1, physicsClientId=client)[1] == pytest.approx(0.55)
    # drawn as the plane, in the grass's colour
    shape = p.getVisualShapeData(ground, physicsClientId=client)[0]
    assert (shape[2], shape[7]) == (p.GEOM_PLANE, pytest.approx(SURFACE_KINDS["grass"].rgba))
    assert p.getVisualShapeData(mud, physicsClientId=client)[0][7] == pytest.approx(SURFACE_KINDS["mud"].rgba)


def test_a_box_slides_across_a_seam_of_the_ground_with_holes_as_on_the_plane():
    # A soft patch whose bounding box's lower left corner is (-3.718, 2.5): the pieces around it meet
    # along x = -3.718 below it. A 0.2 m box sliding at 2 m/s (wheel friction 1.0, tarmac 0.9) stops
    # after v^2 / (2 mu g) = 0.227 m wherever it starts, across the seam or not.
    world = parse_world({"patches": {"patch0": patch(-2.718, 3.0, 2.0, 1.0, surface="mud")}})
    ends = []
    for x in (-3.95, -3.85, -3.75, -6.0):
        client = p.connect(p.DIRECT)
        try:
            build_scene(client, world)
            box = p.createMultiBody(
                1.0,
                p.createCollisionShape(p.GEOM_BOX, halfExtents=(0.1, 0.1, 0.1), physicsClientId=client),
                -1,
                basePosition=(x, -1.0, 0.1),
                physicsClientId=client,
            )
            p.changeDynamics(
                box, -1, lateralFriction=1.0, linearDamping=0.0, angularDamping=0.0, physicsClientId=client
            )
            p.resetBaseVelocity(box, (2.0, 0.0, 0.0), (0.0, 0.0, 0.0), physicsClientId=client)
            for _ in range(round(1.0 / DT)):
                p.stepSimulation(physicsClientId=client)
            (x1, y1, _), q = p.getBasePositionAndOrientation(box, physicsClientId=client)
            ends.append(x1 - x)
            assert abs(y1 + 1.0) < 1e-3 and abs(p.getEulerFromQuaternion(q)[2]) < 1e-3
        finally:
            p.disconnect(client)
    for travel in ends:
        assert travel == pytest.approx(2.0**2 / (2 * 0.9 * G), rel=0.05)
    assert max(ends) - min(ends) < 1e-3


def test_without_soft_patches_the_ground_is_the_plane_and_may_be_soft(client):
    world = parse_world({"ground": {"surface": "mud"}, "patches": {"patch0": patch(3.0, 0.0, surface="gravel")}})
    scene = build_scene(client, world)
    ground = scene.bodies["ground"]
    assert p.getCollisionShapeData(ground, -1, physicsClientId=client)[0][2] == p.GEOM_PLANE
    assert p.getDynamicsInfo(ground, -1, physicsClientId=client)[9] == pytest.approx(500.0 / 0.015)
    for name in ("tarmac_gravel", "flat"):
        assert not soft_patches(load_world(resolve_world(name)).patches)


# ---------------------------------------------------------------------------------------------
# Physics: sinking, rolling resistance, stability
# ---------------------------------------------------------------------------------------------
def _ball(client, position, mass, radius=0.2):
    shape = p.createCollisionShape(p.GEOM_SPHERE, radius=radius, physicsClientId=client)
    body = p.createMultiBody(mass, shape, -1, basePosition=position, physicsClientId=client)
    # a wheel's friction and no drag (pybullet gives every new body 0.04 / s)
    p.changeDynamics(body, -1, lateralFriction=1.0, linearDamping=0.0, angularDamping=0.0, physicsClientId=client)
    return body


@pytest.mark.parametrize("kind", SOFT)
def test_a_ball_resting_on_a_soft_patch_sinks_by_its_load_times_the_sinkage_and_stays(client, kind):
    world = parse_world({"patches": {"patch0": patch(0.0, 0.0, 6.0, 6.0, surface=kind)}})
    build_scene(client, world)
    sinkage = TABLE[kind][3]
    # a ball touches at one point: the reference load (51 kg) sinks it by sinkage, twice that by twice
    # as much; on tarmac (the rigid ground) it stays on top
    r = 0.2
    one = _ball(client, (-1.5, 0.0, PATCH_TOP + r), SINKAGE_LOAD / G)
    two = _ball(client, (1.5, 0.0, PATCH_TOP + r), 2 * SINKAGE_LOAD / G)
    tarmac = _ball(client, (5.0, 0.0, r), SINKAGE_LOAD / G)
    track = {b: [] for b in (one, two, tarmac)}
    for step in range(round(10.0 / DT)):  # 10 s
        p.stepSimulation(physicsClientId=client)
        if step * DT >= 1.0:
            for b, samples in track.items():
                pos, _ = p.getBasePositionAndOrientation(b, physicsClientId=client)
                vel, _ = p.getBaseVelocity(b, physicsClientId=client)
                samples.append((pos, vel))
    for b, load in ((one, 1), (two, 2)):
        zs = [pos[2] for pos, _ in track[b]]
        # critically damped (time constant 2 sqrt(m / k) = 0.08 s for mud): settled after 1 s to 0.1 mm
        # (the rolling constraint takes nothing from a ball at rest)
        assert PATCH_TOP + r - zs[-1] == pytest.approx(load * sinkage, abs=1e-4)
        # 9 s more without a bounce or a drift: a few micrometres of z, no vertical speed to speak of
        assert max(zs) - min(zs) < 5e-6
        assert max(abs(vel[2]) for _, vel in track[b]) < 1e-4
        (x0, y0, _), (x1, y1, _) = track[b][0][0], track[b][-1][0]
        assert math.hypot(x1 - x0, y1 - y0) < 1e-5
    assert r - track[tarmac][-1][0][2] < 1e-4


def test_a_hill_of_a_surface_kind_has_its_grip_and_sinks_by_its_sinkage(client):
    # a hill names a kind as the ground and patches do; a key of its own overrides the kind's; a hill
    # of none is rigid tarmac-like ground (0.9) as before
    hill = {"x": 0.0, "y": 0.0, "width": 4.0, "angle": 0.2, "height": 0.5, "top_length": 4.0}
    world = parse_world({"slopes": {
        "slope0": dict(hill, surface="mud"),
        "slope1": dict(hill, y=10.0, surface="grass", lateral_friction=0.7, sinkage=0.01),
        "slope2": dict(hill, y=-10.0),
    }})  # fmt: skip
    mud, grass, plain = (s.surface for s in world.slopes)
    assert (mud.lateral_friction, mud.sinkage, mud.kind) == (0.35, 0.015, "mud")
    assert (grass.lateral_friction, grass.rolling_friction, grass.sinkage) == (0.7, 0.012, 0.01)
    assert (plain.lateral_friction, plain.sinkage, plain.soft) == (0.9, 0.0, False)
    scene = build_scene(client, world)
    assert p.getDynamicsInfo(scene.bodies["slopes.slope0"], -1, physicsClientId=client)[9] == pytest.approx(
        500.0 / 0.015
    )
    # the reference load resting on the mud hill's level top sinks by the sinkage, as on a patch
    r = 0.2
    ball = _ball(client, (0.0, 0.0, 0.5 + r), SINKAGE_LOAD / G)
    for _ in range(round(2.0 / DT)):
        p.stepSimulation(physicsClientId=client)
    z = p.getBasePositionAndOrientation(ball, physicsClientId=client)[0][2]
    assert 0.5 + r - z == pytest.approx(0.015, abs=1e-4)


def _robot(sim, x=0.0, y=0.0, yaw=0.0):
    robot = sim.spawn("r", std_urdf(), Pose2D(x, y, 0.0, yaw))
    return robot


def _wheel_loads(sim, robot):
    """[N] the ground's normal force on each of the robot's wheels, in drive order."""
    loads = []
    for j, _, _ in robot.wheels:
        contacts = p.getContactPoints(robot.body, linkIndexA=j, physicsClientId=sim.client)
        loads.append(sum(cp[9] for cp in contacts))
    return loads


def _wheel_heights(sim, robot):
    return [p.getLinkState(robot.body, j, physicsClientId=sim.client)[0][2] for j, _, _ in robot.wheels]


@pytest.mark.slow  # seconds of physics
def test_a_rolling_wheel_sinks_as_its_load_says_and_still_rolls_r_omega():
    # The standard robot (177 kg: 380 to 490 N a wheel) drives at 0.5 m/s from tarmac onto 12 m of mud.
    client = p.connect(p.DIRECT)
    try:
        world = parse_world({"patches": {"patch0": patch(9.0, 0.0, 12.0, 4.0, surface="mud")}})
        sim = Simulation(client, world)
        robot = _robot(sim)
        mud = world.patches[0].surface
        n = len(robot.wheels)
        for _ in range(round(1.0 / DT)):
            sim.step()
        on_tarmac, standing = _wheel_heights(sim, robot), _wheel_loads(sim, robot)
        robot.command([0.0] * n, [0.5] * n)
        while robot.odom_pose()[0][0] < 7.0:  # all four wheels 3.4 m into the mud and rolling
            sim.step()
        angles = [p.getJointState(robot.body, j, physicsClientId=client)[0] for j, _, _ in robot.wheels]
        x0 = robot.odom_pose()[0][0]
        depths, loads = [], []
        for _ in range(round(4.0 / DT)):  # 2 m more of mud
            sim.step()
            depths.append([PATCH_TOP + r - z for (_, _, r), z in zip(robot.wheels, _wheel_heights(sim, robot))])
            loads.append(_wheel_loads(sim, robot))
        x1 = robot.odom_pose()[0][0]
        turned = [
            p.getJointState(robot.body, j, physicsClientId=client)[0] - a for (j, _, _), a in zip(robot.wheels, angles)
        ]
        for k in range(n):
            depth = sum(d[k] for d in depths) / len(depths)
            load = sum(w[k] for w in loads) / len(loads)
            # one point a wheel while it rolls, so the spring's own law, load / stiffness (measured: to
            # 0.1 %; 11.4 to 14.7 mm)
            assert depth == pytest.approx(load / mud.contact_stiffness, rel=0.01)
            assert 0.010 < depth < 0.016, depth
            # lower than on tarmac (rigid: the wheel's centre at its radius) by that much, less the patch's 1 mm
            assert on_tarmac[k] == pytest.approx(robot.wheels[k][2], abs=5e-5)
            on_mud = sum(robot.wheels[k][2] + PATCH_TOP - d[k] for d in depths) / len(depths)
            assert on_tarmac[k] - on_mud == pytest.approx(depth - PATCH_TOP, abs=5e-5)
            # and yet it rolls at r omega (measured: 0.20000 m a radian): pybullet's friction acts at
            # the wheel's rim, not at the mud's surface, so a sunk wheel has no shorter rolling radius
            # (odometry does not read long there)
            assert (x1 - x0) / turned[k] == pytest.approx(robot.wheels[k][2], rel=1e-3)
        # and the documented amount, sinkage * load / 500 N, on average over the wheels with the loads
        # they stood on tarmac with: driving shifts the load between diagonals, not its sum
        mean_depth = sum(sum(d) for d in depths) / len(depths) / n
        assert mean_depth == pytest.approx(mud.sinkage * sum(standing) / n / SINKAGE_LOAD, rel=0.03)
        assert abs(yaw_of(robot.odom_pose()[1])) < 0.005
    finally:
        p.disconnect(client)


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_a_robot_standing_on_mud_for_10_s_neither_bounces_nor_drifts():
    client = p.connect(p.DIRECT)
    try:
        sim = Simulation(client, parse_world({"patches": {"patch0": patch(0.0, 0.0, 6.0, 6.0, surface="mud")}}))
        robot = _robot(sim)
        for _ in range(round(2.0 / DT)):
            sim.step()
        (x0, y0, _), _ = robot.odom_pose()
        zs, vzs = [], []
        for _ in range(round(10.0 / DT)):
            sim.step()
            zs.append(robot.odom_pose()[0][2])
            vzs.append(robot.body_twist()[0][2])
        (x1, y1, _), _ = robot.odom_pose()
        assert -0.015 < zs[0] < -0.005  # sunk, 2 s after it was put down at z = 0
        assert max(zs) - min(zs) < 1e-4
        assert max(abs(v) for v in vzs) < 1e-3
        # braked, it creeps as it does on bullet's plane (about 0.5 mm in 10 s there), no more
        assert math.hypot(x1 - x0, y1 - y0) < 1e-3
    finally:
        p.disconnect(client)


def _coast(client, x, y, v0, seconds):
    """[m/s^2] the deceleration of a free wheel (r 0.2 m, 10 kg, a solid disc 5 cm wide) set rolling
    along +x at v0 [m/s] from (x, y), over the given time [s]."""
    r, mass = 0.2, 10.0
    shape = p.createCollisionShape(p.GEOM_CYLINDER, radius=r, height=0.05, physicsClientId=client)
    # pybullet's cylinder axis is its z: rolled onto y, so that it rolls along x
    wheel = p.createMultiBody(
        mass,
        shape,
        -1,
        basePosition=(x, y, r + PATCH_TOP),
        baseOrientation=p.getQuaternionFromEuler((math.pi / 2, 0.0, 0.0)),
        physicsClientId=client,
    )
    p.changeDynamics(wheel, -1, lateralFriction=1.0, linearDamping=0.0, angularDamping=0.0, physicsClientId=client)
    for _ in range(round(0.2 / DT)):  # settle
        p.stepSimulation(physicsClientId=client)
    p.resetBaseVelocity(wheel, (v0, 0.0, 0.0), (0.0, v0 / r, 0.0), physicsClientId=client)
    for _ in range(round(0.1 / DT)):
        p.stepSimulation(physicsClientId=client)
    start = p.getBaseVelocity(wheel, physicsClientId=client)[0][0]
    for _ in range(round(seconds / DT)):
        p.stepSimulation(physicsClientId=client)
    end = p.getBaseVelocity(wheel, physicsClientId=client)[0][0]
    return (start - end) / seconds


def test_a_coasting_wheel_slows_as_its_rolling_resistance_says(client):
    # rigid patches side by side, so that only the rolling resistance differs
    world = parse_world(
        {
            "patches": {
                "patch0": patch(0.0, 0.0, 20.0, 2.0, surface="tarmac"),
                "patch1": patch(0.0, 4.0, 20.0, 2.0, surface="sand", sinkage=0),
            }
        }
    )
    build_scene(client, world)
    tarmac = _coast(client, -8.0, 0.0, 1.0, 0.5)
    sand = _coast(client, -8.0, 4.0, 1.0, 0.5)
    # the rolling friction C times the normal force is a torque against the turning; a solid disc
    # rolling without slip then slows at C g / (r (1 + 1/2)): on tarmac 0.003 * 9.81 / 0.3 = 0.098
    # m/s^2, in sand 0.05 * 9.81 / 0.3 = 1.64 m/s^2
    assert tarmac == pytest.approx(0.003 * G / 0.3, rel=0.1)
    assert sand == pytest.approx(0.05 * G / 0.3, rel=0.1)


@pytest.mark.slow  # seconds of physics
def test_a_driven_wheel_needs_its_rolling_friction_times_its_load_in_torque():
    # The standard robot at a steady 0.5 m/s on tarmac and in mud (the kinds' rolling friction 0.003
    # and 0.04 m): its velocity motors hold the speed and pay the rolling resistance in torque.
    client = p.connect(p.DIRECT)
    try:
        world = parse_world(
            {
                "patches": {
                    "patch0": patch(6.0, 0.0, 8.0, 4.0, surface="tarmac"),
                    "patch1": patch(16.0, 0.0, 8.0, 4.0, surface="mud"),
                }
            }
        )
        sim = Simulation(client, world)
        robot = _robot(sim, x=3.0)
        n = len(robot.wheels)
        robot.command([0.0] * n, [0.5] * n)
        torques = {}
        for name, x_from, x_to in (("tarmac", 4.0, 6.0), ("mud", 15.0, 17.0)):
            while robot.odom_pose()[0][0] < x_from - 3.0:
                sim.step()
            samples = []
            while robot.odom_pose()[0][0] < x_to - 3.0:
                sim.step()
                states = p.getJointStates(robot.body, [j for j, _, _ in robot.wheels], physicsClientId=client)
                samples.append([(s[3], load) for s, load in zip(states, _wheel_loads(sim, robot))])
            torques[name] = [
                (sum(t[k][0] for t in samples) / len(samples), sum(t[k][1] for t in samples) / len(samples))
                for k in range(n)
            ]
        # pybullet's rolling friction of a contact is the patch's times the wheel's own lateral
        # friction (the wheel has no rolling friction of its own)
        wheel_friction = p.getDynamicsInfo(robot.body, robot.wheels[0][0], physicsClientId=client)[1]
        for name, c in (("tarmac", 0.003), ("mud", 0.04)):
            # all of them together: the ground couples the wheels, so that the motors share the work
            # evenly, whatever each one's load (measured: 0.65 N m each on tarmac, 8.65 in mud, with the
            # wheels' lateral friction at 0.5)
            total = sum(torque for torque, _ in torques[name])
            assert total == pytest.approx(c * wheel_friction * sum(load for _, load in torques[name]), rel=0.02), name
            assert max(torque for torque, _ in torques[name]) < min(effort for _, effort, _ in robot.wheels)
        assert sum(t for t, _ in torques["mud"]) > 10 * sum(t for t, _ in torques["tarmac"])
    finally:
        p.disconnect(client)


# ---------------------------------------------------------------------------------------------
# The shipped worlds
# ---------------------------------------------------------------------------------------------
def _manoeuvre():
    """The verification manoeuvre's path (thorvald_base.verification's omnidirectional plan): a 10 m
    square, a 20 m circle about (0, 20 / 2 pi) and a 20 m sideways circle about (20 / 2 pi, 0); 1 cm
    steps, 80 m."""
    r = 20.0 / (2 * math.pi)
    points = []
    for k in range(1000):
        d = k / 100.0
        points += [(d, 0.0), (10.0, d), (10.0 - d, 10.0), (0.0, 10.0 - d)]
    for k in range(2000):
        a = 2 * math.pi * k / 2000
        points += [(r * math.sin(a), r - r * math.cos(a)), (r - r * math.cos(a), -r * math.sin(a))]
    return points


def test_tarmac_gravel_has_grass_and_mud_across_the_manoeuvre_on_its_plane(client):
    world = load_world(resolve_world("tarmac_gravel"))
    by_kind = {}
    for pa in world.patches:
        by_kind.setdefault(pa.surface.kind, []).append(pa)
    assert sorted(by_kind) == ["", "grass", "gravel", "mud"]
    assert [pa.name for pa in by_kind[""]] == ["patch0"]  # the slip test's ice, as it was
    assert by_kind[""][0].surface == Surface(0.1, 0.0, 0.0)
    for pa in by_kind["gravel"]:  # their own numbers, as before
        assert 0.55 <= pa.surface.lateral_friction <= 0.6 and 0.01 <= pa.surface.rolling_friction <= 0.02
    for kind in ("grass", "mud"):
        for pa in by_kind[kind]:
            lateral, _, rolling, _ = TABLE[kind]
            # the kind's grip and rolling resistance, not its sinkage: the ground stays bullet's plane
            assert pa.surface == Surface(lateral, rolling, 0.0, 0.0, 0.0)
    assert not soft_patches(world.patches)
    scene = build_scene(client, world)
    assert p.getCollisionShapeData(scene.bodies["ground"], -1, physicsClientId=client)[0][2] == p.GEOM_PLANE
    # along the path (80 m): as the header says, about 15 m gravel, 5 m grass, 3 m mud
    points = _manoeuvre()
    metres = {
        kind: 80.0 * sum(any(pa.contains(x, y) for pa in by_kind[kind]) for x, y in points) / len(points)
        for kind in ("gravel", "grass", "mud")
    }
    assert metres["gravel"] == pytest.approx(15.0, abs=1.0)
    assert metres["grass"] == pytest.approx(5.0, abs=1.0)
    assert metres["mud"] == pytest.approx(3.0, abs=1.0)
    for pa in world.patches[1:]:  # every corner within the 20 x 20 m area, 2 m clear of the origin
        for x, y in pa.corners():
            assert abs(x) <= 10.0 + 1e-9 and abs(y) <= 10.0 + 1e-9, pa.name
        assert not any(pa.contains(2.0 * math.cos(a / 10), 2.0 * math.sin(a / 10)) for a in range(63)), pa.name
        assert not pa.contains(0.0, 0.0)


def test_farm_track_is_a_soft_field_with_a_track_through_a_muddy_gateway():
    world = load_world(resolve_world("farm_track"))
    assert world.ground.kind == "grass" and world.ground.sinkage == 0.004
    kinds = {pa.name: pa.surface.kind for pa in world.patches}
    assert sorted(set(kinds.values())) == ["gravel", "mud", "wet_grass"]
    assert {pa.surface.kind for pa in soft_patches(world.patches)} == {"mud", "wet_grass"}
    # the track's centre line, x from 3 to 39 m, is gravel but for the gateway's mud from 15 to 19 m
    for k in range(360):
        x = 3.05 + k / 10  # not on an edge, where two patches meet
        (on,) = [pa for pa in world.patches if pa.contains(x, 0.0)]
        assert on.surface.kind == ("mud" if 15.0 <= x <= 19.0 else "gravel"), x
    # nothing but grass within 3 m of the origin
    for i in range(-60, 61):
        for j in range(-60, 61):
            if math.hypot(i / 20, j / 20) < 3.0:
                assert not any(pa.contains(i / 20, j / 20) for pa in world.patches)


@pytest.mark.slow  # seconds of physics
def test_the_standard_robot_drives_through_the_farm_tracks_gateway_and_sinks_in_its_mud():
    client = p.connect(p.DIRECT)
    try:
        sim = Simulation(client, load_world(resolve_world("farm_track")))
        robot = _robot(sim)
        n = len(robot.wheels)
        robot.command([0.0] * n, [0.8] * n)
        heights = {"grass": [], "gravel": [], "mud": []}
        for _ in range(round(30.0 / DT)):
            sim.step()
            (x, y, z), q = robot.odom_pose()
            # the whole robot (1.4 m long) on one surface
            where = "grass" if x < 2.2 else "gravel" if 3.8 < x < 14.2 else "mud" if 15.8 < x < 18.2 else None
            if where:
                heights[where].append(z)
        (x, y, _), q = robot.odom_pose()
        assert x > 22.0, "through the gateway and out on the gravel again"
        assert abs(y) < 0.1 and abs(yaw_of(q)) < 0.01
        mean = {k: sum(v) / len(v) for k, v in heights.items()}
        # base_link sinks with its wheels: 0.87 of the 4 mm of grass, the gravel's top 1 mm up, 0.87 of
        # the 15 mm of mud (within the wheels' spread of loads)
        assert mean["grass"] == pytest.approx(-0.87 * 0.004, abs=0.001)
        assert mean["gravel"] == pytest.approx(PATCH_TOP, abs=1e-4)
        assert mean["mud"] == pytest.approx(-0.87 * 0.015, abs=0.002)
    finally:
        p.disconnect(client)
