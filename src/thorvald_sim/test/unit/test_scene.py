"""The scene built in pybullet: ray tests prove the geometry, dynamics info the surfaces, and a box
sliding on ice and on tarmac that the friction is the world's."""

import math

import pybullet as p
import pytest

from thorvald_sim.physics.scene import build_scene
from thorvald_sim.world import load_world, parse_world, resolve_world, shipped_worlds

TOP = 5.0  # [m]: rays start this high and end 1 m below the ground


def shipped(name):
    return load_world(resolve_world(name))


def ray_down(client, x, y):
    """(body id, z [m]) of the first thing a vertical ray at (x, y) hits."""
    body, _, fraction, position, _ = p.rayTest((x, y, TOP), (x, y, -1.0), physicsClientId=client)[0]
    assert body >= 0, f"nothing under ({x}, {y})"
    assert position[2] == pytest.approx(TOP - fraction * (TOP + 1.0))
    return body, position[2]


def along(x, y, yaw, u, v):
    """The world point (u, v) [m] of a frame at (x, y) turned by yaw."""
    return x + math.cos(yaw) * u - math.sin(yaw) * v, y + math.sin(yaw) * u + math.cos(yaw) * v


def surface_of(client, body):
    info = p.getDynamicsInfo(body, -1, physicsClientId=client)
    return {"mass": info[0], "lateral": info[1], "restitution": info[5], "rolling": info[6], "spinning": info[7]}


# ---------------------------------------------------------------------------------------------
# Every shipped world
# ---------------------------------------------------------------------------------------------
def expected_bodies(world):
    """The scene's body names in order, but the ``.partN`` of meshes split for their size."""
    names = ["ground"]
    names += [f"patches.{pa.name}" for pa in world.patches]
    names += [f"slopes.{s.name}" for s in world.slopes]
    names += [f"rails.{r.name}.{side}" for r in world.rails for side in ("left", "right")]
    names += [f"objects.{o.name}" for o in world.objects]
    names += [f"rows.{r.name}.{k}" for r in world.rows for k in range(r.count)]
    for t in world.polytunnels:
        names += [f"polytunnels.{t.name}.{part}" for part in ("legs_left", "legs_right", "roof")]
        names += [f"polytunnels.{t.name}.{kind}{k}" for k in range(t.tables) for kind in ("table", "plants", "berries")]
    names += [f"walls.{w.name}" for w in world.walls]
    return names


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
@pytest.mark.parametrize("name", shipped_worlds())
def test_every_shipped_world_builds(client, name):
    world = shipped(name)
    scene = build_scene(client, world)
    assert scene.world is world
    expected = expected_bodies(world)
    assert [n for n in scene.bodies if ".part" not in n] == expected
    assert p.getNumBodies(physicsClientId=client) == len(scene.bodies)
    assert len(set(scene.bodies.values())) == len(scene.bodies)
    moving = {f"objects.{o.name}" for o in world.objects if o.mass > 0}
    for body_name, body in scene.bodies.items():
        if body_name not in moving:
            assert surface_of(client, body)["mass"] == 0.0, f"{body_name} static"
    gravity = p.getPhysicsEngineParameters(physicsClientId=client)
    assert (gravity["gravityAccelerationX"], gravity["gravityAccelerationY"]) == (0.0, 0.0)
    assert gravity["gravityAccelerationZ"] == pytest.approx(-world.gravity)
    if world.height_field is None:
        # far from everything, the ground plane at z = 0
        assert ray_down(client, 60.0, -70.0) == (scene.bodies["ground"], pytest.approx(0.0, abs=1e-9))


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
@pytest.mark.parametrize("name", shipped_worlds())
def test_every_shipped_world_leaves_room_for_a_robot_at_the_origin(client, name):
    # a robot of 1.5 x 1.4 m and 1 m tall heading +x, and 5 cm more all round: rays down from 1.2 m every
    # 5 cm over 1.6 x 1.5 m reach the ground, at 0 (the polytunnel's aisle between tables is 1.6 m wide)
    scene = build_scene(client, shipped(name))
    starts = [(i * 0.05, j * 0.05, 1.2) for i in range(-16, 17) for j in range(-15, 16)]
    hits = p.rayTestBatch(starts, [(x, y, -1.0) for x, y, _ in starts], physicsClientId=client)
    assert {h[0] for h in hits} == {scene.bodies["ground"]}
    assert max(abs(h[3][2]) for h in hits) < 1e-6  # a height field's heights are 32-bit floats


def test_gravity_is_the_worlds(client):
    build_scene(client, parse_world({"gravity": 1.62}))
    assert p.getPhysicsEngineParameters(physicsClientId=client)["gravityAccelerationZ"] == pytest.approx(-1.62)


# ---------------------------------------------------------------------------------------------
# Geometry
# ---------------------------------------------------------------------------------------------
def test_patches_lie_1_mm_above_the_ground(client):
    world = shipped("tarmac_gravel")
    scene = build_scene(client, world)
    for pa in world.patches:
        body = scene.bodies[f"patches.{pa.name}"]
        # the centre, and 5 cm inside a corner (in the patch's own frame, so the yaw counts)
        for u, v in ((0.0, 0.0), (pa.size_x / 2 - 0.05, pa.size_y / 2 - 0.05)):
            assert ray_down(client, *along(pa.x, pa.y, pa.yaw, u, v)) == (body, pytest.approx(0.001, abs=1e-6))
        # 5 cm outside the corner: tarmac (no patch touches another one)
        outside = along(pa.x, pa.y, pa.yaw, pa.size_x / 2 + 0.05, pa.size_y / 2 + 0.05)
        assert ray_down(client, *outside) == (scene.bodies["ground"], pytest.approx(0.0, abs=1e-9))


HILLS = {
    "slope.yaml": None,
    "turned, no top": {"x": -3.0, "y": 4.0, "yaw": 2.0, "width": 2.0, "angle": 0.5, "height": 0.7, "top_length": 0.0},
    "steep": {"x": 1.0, "y": -2.0, "yaw": -0.6, "width": 3.0, "angle": 1.1, "height": 1.5, "top_length": 0.8},
}


@pytest.mark.parametrize("hill", list(HILLS))
def test_a_hill_has_its_height_on_top_and_half_of_it_half_way_up(client, hill):
    if HILLS[hill] is None:
        world = shipped("slope")
    else:
        world = parse_world({"ground": {"lateral_friction": 0.7}, "slopes": {"slope0": HILLS[hill]}})
    scene = build_scene(client, world)
    s = world.slopes[0]
    body = scene.bodies["slopes.slope0"]
    # along the hill: the foot at -L/2, the top from -t/2 to t/2 (L = t + 2 h / tan(angle))
    half_l, half_t = (s.top_length + 2 * s.height / math.tan(s.angle)) / 2, s.top_length / 2
    for v in (0.0, s.width / 2 - 0.05, -(s.width / 2 - 0.05)):
        # the top (for a hill without one, the ridge)
        assert ray_down(client, *along(s.x, s.y, s.yaw, 0.0, v)) == (body, pytest.approx(s.height, abs=2e-4))
        # both ramps, half-way along: half the height
        for sign in (-1, 1):
            u = sign * (half_l + half_t) / 2
            assert ray_down(client, *along(s.x, s.y, s.yaw, u, v)) == (body, pytest.approx(s.height / 2, abs=2e-4))
        # a quarter of the way up the near ramp: its slope is tan(angle)
        u = -half_l + (half_l - half_t) / 4
        assert ray_down(client, *along(s.x, s.y, s.yaw, u, v)) == (body, pytest.approx(s.height / 4, abs=2e-4))
    # just beyond the feet and the sides: ground
    for u, v in ((-half_l - 0.02, 0.0), (half_l + 0.02, 0.0), (0.0, s.width / 2 + 0.02), (0.0, -s.width / 2 - 0.02)):
        assert ray_down(client, *along(s.x, s.y, s.yaw, u, v)) == (scene.bodies["ground"], pytest.approx(0.0, abs=1e-9))


def test_the_shipped_hill_starts_3_m_ahead(client):
    scene = build_scene(client, shipped("slope"))
    hill, ground = scene.bodies["slopes.slope0"], scene.bodies["ground"]
    assert ray_down(client, 2.97, 0.0)[0] == ground
    # 3 cm past the foot at 10 degrees: 3 cm x tan(10 deg) = 5.3 mm up
    assert ray_down(client, 3.03, 0.0) == (hill, pytest.approx(0.03 * math.tan(math.radians(10)), abs=2e-4))


RAILS = {
    "greenhouse.yaml": None,
    "turned": {"x": 2.0, "y": -1.0, "yaw": 0.7, "length": 6.0, "gauge": 0.8, "height": 0.15, "radius": 0.03},
}


@pytest.mark.parametrize("rails", list(RAILS))
def test_rails_are_two_pipes_with_their_tops_at_height_plus_radius(client, rails):
    if RAILS[rails] is None:
        world = shipped("greenhouse")
    else:
        world = parse_world({"rails": {"rail0": RAILS[rails]}})
    scene = build_scene(client, world)
    ground = scene.bodies["ground"]
    for r in world.rails:
        top = r.height + r.radius
        for u in (0.0, r.length / 2 - 0.05, -(r.length / 2 - 0.05)):
            # left of the rail's direction at +gauge/2, right at -gauge/2
            left = ray_down(client, *along(r.x, r.y, r.yaw, u, r.gauge / 2))
            right = ray_down(client, *along(r.x, r.y, r.yaw, u, -r.gauge / 2))
            assert left == (scene.bodies[f"rails.{r.name}.left"], pytest.approx(top, abs=1e-6))
            assert right == (scene.bodies[f"rails.{r.name}.right"], pytest.approx(top, abs=1e-6))
            # half a radius off the pipe's centre line the round top is lower: h + r cos(30 deg)
            side = ray_down(client, *along(r.x, r.y, r.yaw, u, r.gauge / 2 + r.radius / 2))
            assert side[1] == pytest.approx(r.height + r.radius * math.cos(math.radians(30)), abs=1e-4)
            # between the pipes, and just outside them: the ground
            for v in (0.0, r.gauge / 2 + 1.1 * r.radius, -(r.gauge / 2 + 1.1 * r.radius)):
                assert ray_down(client, *along(r.x, r.y, r.yaw, u, v)) == (ground, pytest.approx(0.0, abs=1e-9))
        # beyond the pipes' ends: the ground
        for u in (r.length / 2 + 0.02, -(r.length / 2 + 0.02)):
            assert ray_down(client, *along(r.x, r.y, r.yaw, u, r.gauge / 2))[0] == ground


def test_the_greenhouse_origin_is_free_and_the_pipes_start_2_m_ahead(client):
    scene = build_scene(client, shipped("greenhouse"))
    ground, left = scene.bodies["ground"], scene.bodies["rails.rail0.left"]
    assert ray_down(client, 0.0, 0.0)[0] == ground
    assert ray_down(client, 1.98, 0.275)[0] == ground
    assert ray_down(client, 2.02, 0.275)[0] == left


# ---------------------------------------------------------------------------------------------
# Surfaces
# ---------------------------------------------------------------------------------------------
def test_every_body_has_its_surface(client):
    world = parse_world(
        {
            "ground": {
                "lateral_friction": 0.7,
                "rolling_friction": 0.01,
                "spinning_friction": 0.02,
                "restitution": 0.3,
            },
            "patches": {
                "patch0": {"x": 5, "y": 0, "size_x": 1, "size_y": 1, "lateral_friction": 0.4, "rolling_friction": 0.03}
            },
            "slopes": {
                "slope0": {"x": -5, "y": 0, "width": 1, "angle": 0.3, "height": 0.2, "lateral_friction": 0.6},
            },
            "rails": {"rail0": {"x": 0, "y": 5, "length": 3, "lateral_friction": 0.5, "spinning_friction": 0.04}},
            "objects": {
                "object0": {"shape": "sphere", "x": 9, "y": 9, "radius": 0.2, "mass": 1, "restitution": 0.5},
            },
            "rows": {"row0": {"x": -9, "y": -9, "length": 2, "count": 2, "lateral_friction": 0.45}},
            "polytunnels": {"polytunnel0": {"x": 20, "y": 0, "length": 6, "lateral_friction": 0.55, "tables": 1}},
            "walls": {"wall0": {"x": 0, "y": -9, "length": 2, "rolling_friction": 0.05}},
        }
    )
    scene = build_scene(client, world)
    tunnel = "polytunnels.polytunnel0"
    expected = {
        "ground": (0.7, 0.01, 0.02, 0.3),
        "patches.patch0": (0.4, 0.03, 0.0, 0.0),
        "slopes.slope0": (0.6, 0.0, 0.0, 0.0),
        "rails.rail0.left": (0.5, 0.0, 0.04, 0.0),
        "rails.rail0.right": (0.5, 0.0, 0.04, 0.0),
        "objects.object0": (0.8, 0.0, 0.0, 0.5),
        "rows.row0.0": (0.45, 0.0, 0.0, 0.0),
        "rows.row0.1": (0.45, 0.0, 0.0, 0.0),
        **{
            f"{tunnel}.{part}": (0.55, 0.0, 0.0, 0.0)
            for part in ("legs_left", "legs_right", "roof", "table0", "plants0")
        },
        "walls.wall0": (0.8, 0.05, 0.0, 0.0),
    }
    for name, (lateral, rolling, spinning, restitution) in expected.items():
        got = surface_of(client, scene.bodies[name])
        assert got["lateral"] == pytest.approx(lateral), name
        assert got["rolling"] == pytest.approx(rolling), name
        assert got["spinning"] == pytest.approx(spinning), name
        assert got["restitution"] == pytest.approx(restitution), name


def test_a_height_field_has_the_grounds_surface_and_colour(client):
    world = parse_world(
        {
            "ground": {"lateral_friction": 0.6, "spinning_friction": 0.01, "rgba": [0.5, 0.4, 0.3]},
            "height_field": {"size_x": 4, "size_y": 4, "amplitude": 0.1},
        }
    )
    scene = build_scene(client, world)
    got = surface_of(client, scene.bodies["ground"])
    assert (got["lateral"], got["spinning"]) == pytest.approx((0.6, 0.01))
    assert p.getVisualShapeData(scene.bodies["ground"], physicsClientId=client)[0][7] == (0.5, 0.4, 0.3, 1.0)


def test_shipped_surfaces(client):
    world = shipped("tarmac_gravel")
    scene = build_scene(client, world)
    assert surface_of(client, scene.bodies["ground"])["lateral"] == pytest.approx(0.9)
    for pa in world.patches:
        got = surface_of(client, scene.bodies[f"patches.{pa.name}"])
        assert got["lateral"] == pytest.approx(pa.surface.lateral_friction)
        assert got["rolling"] == pytest.approx(pa.surface.rolling_friction)


def test_a_box_slides_farther_on_the_ice_patch_than_on_tarmac(client):
    world = shipped("tarmac_gravel")
    build_scene(client, world)
    ice = next(pa for pa in world.patches if pa.surface.lateral_friction < 0.3)
    g, v0, steps = world.gravity, 2.0, 240  # [m/s^2], [m/s], 1 s at pybullet's default step of 1/240 s

    def slide(x, y, ground_z):
        half = 0.1  # [m] of a 0.2 m cube: flat enough not to tip under any friction here
        shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=(half,) * 3, physicsClientId=client)
        box = p.createMultiBody(1.0, shape, -1, basePosition=(x, y, ground_z + half), physicsClientId=client)
        # A wheel's friction, so the contact's is the world's alone; and no velocity damping (pybullet
        # gives every new body 0.04 [1/s], which alone would slow the box on ice by 15 % more).
        p.changeDynamics(box, -1, lateralFriction=1.0, linearDamping=0.0, angularDamping=0.0, physicsClientId=client)
        p.resetBaseVelocity(box, (v0, 0.0, 0.0), (0.0, 0.0, 0.0), physicsClientId=client)
        for _ in range(steps):
            p.stepSimulation(physicsClientId=client)
        end = p.getBasePositionAndOrientation(box, physicsClientId=client)[0]
        p.removeBody(box, physicsClientId=client)
        return end[0] - x

    # Coulomb sliding decelerates at mu g: on tarmac (mu 0.9) the box stops after v0^2 / (2 mu g);
    # on ice (mu 0.1) it is still sliding after 1 s, having gone v0 t - mu g t^2 / 2.
    start = ice.x - ice.size_x / 2 + 0.3
    on_ice = slide(start, ice.y, 0.001)
    assert start + on_ice < ice.x + ice.size_x / 2, "stayed on the ice"
    assert on_ice == pytest.approx(v0 * 1.0 - ice.surface.lateral_friction * g / 2, rel=0.02)
    tarmac_spot = (-2.0, -1.0)
    assert not any(pa.contains(*tarmac_spot) for pa in world.patches)
    on_tarmac = slide(*tarmac_spot, 0.0)
    assert on_tarmac == pytest.approx(v0**2 / (2 * world.ground.lateral_friction * g), rel=0.05)
    assert on_ice > 5 * on_tarmac
