"""Models built in pybullet: where they stand and rest, static ones holding still, a gate swinging and
damped, masses and inertias as given, shapes shared by instances, meshes of every format, poses and
teleports, and the spawn time of a small static SDF model."""

import math
from dataclasses import replace

import pybullet as p
import pytest
from models_fixtures import box_sdf, gate_sdf, write_ascii_stl, write_binary_stl, write_dae, write_obj
from sim_test_helpers import ray_down

from thorvald_sim.errors import ModelError
from thorvald_sim.models import parse_sdf_model, parse_urdf_model
from thorvald_sim.models.build import ShapeCache, SimModel
from thorvald_sim.models.spec import Inertial, ModelSpec, replace_link

RATE = 240.0


@pytest.fixture
def world(client):
    """The client with gravity and a flat ground at z = 0."""
    p.setGravity(0, 0, -9.81, physicsClientId=client)
    p.setPhysicsEngineParameter(fixedTimeStep=1 / RATE, physicsClientId=client)
    p.createMultiBody(0, p.createCollisionShape(p.GEOM_PLANE, physicsClientId=client), physicsClientId=client)
    return client


def step(client, seconds):
    for _ in range(int(seconds * RATE)):
        p.stepSimulation(physicsClientId=client)


def test_links_joints_and_collisions_by_name(client):
    gate = SimModel(client, parse_sdf_model(gate_sdf(), "gate"), (3.0, 0.0, 0.0))
    assert gate.name == "gate" and not gate.static
    assert gate.links == {"post": -1, "door": 0}
    assert gate.joints == {"hinge": 0}
    assert gate.collisions == {"post::collision": -1, "door::collision": 0}
    door = gate.link_pose("door")
    assert door[0] == pytest.approx((3.6, 0.0, 0.5), abs=1e-6)


def test_the_model_frame_and_link_frames_where_the_spec_puts_them(client):
    text = """<sdf version='1.6'><model name='m'>
      <link name='a'><pose>0 0 1 0 0 0.3</pose>
        <inertial><pose>0.3 0.2 0.1 0.2 0.1 0.4</pose><mass>3</mass></inertial></link>
      <link name='b'><pose>1 0 1 0 0 0</pose><inertial><pose>-0.2 0.1 0 0.5 0 0</pose><mass>1</mass></inertial></link>
      <joint name='j' type='revolute'><pose>0.1 0.2 0.3 0.3 0.2 0.1</pose><parent>a</parent><child>b</child></joint>
    </model></sdf>"""
    spec = parse_sdf_model(text, "m")
    at = ((1.0, 2.0, 3.0), p.getQuaternionFromEuler((0.1, 0.2, 0.3)))
    model = SimModel(client, spec, *at)
    assert close_pose(model.pose(), at)
    for name in ("a", "b"):
        want = p.multiplyTransforms(*at, *spec.link(name).pose)
        assert close_pose(model.link_pose(name), want, 1e-5)  # pybullet keeps links' states in float32


def test_a_box_lands_and_rests_at_its_height(world):
    box = SimModel(world, parse_sdf_model(box_sdf(size=(0.4, 0.4, 0.2)), "box"), (0.0, 0.0, 1.0))
    step(world, 1.5)
    (x, y, z), q = box.pose()
    assert z == pytest.approx(0.1, abs=2e-3)  # half its 0.2 m height (bullet's contact slop aside)
    assert abs(x) < 5e-3 and abs(y) < 5e-3 and abs(q[3]) == pytest.approx(1.0, abs=1e-4)


def test_a_static_box_holds_still_when_a_box_hits_it(world):
    wall = SimModel(
        world, parse_sdf_model(box_sdf(name="wall", size=(0.2, 2.0, 1.0), static=True), "wall"), (0.0, 0.0, 0.5)
    )
    assert wall.static
    ball = SimModel(world, parse_sdf_model(box_sdf(name="crate", mass=50.0), "crate"), (-1.0, 0.0, 0.15))
    ball.set_pose((-1.0, 0.0, 0.15), (0, 0, 0, 1), linear=(6.0, 0.0, 0.0))
    step(world, 1.0)
    assert wall.pose()[0] == pytest.approx((0.0, 0.0, 0.5), abs=1e-9)
    assert ball.pose()[0][0] < -0.2  # stopped by the wall, not through it


def test_a_gate_swings_freely_and_its_damping_slows_it(world):
    free = SimModel(world, parse_sdf_model(gate_sdf(), "gate"), (0.0, 0.0, 0.0))
    damped = SimModel(world, parse_sdf_model(gate_sdf(damping=5.0), "gate"), (0.0, 5.0, 0.0))
    for gate in (free, damped):
        p.resetJointState(gate.body, gate.joints["hinge"], 0.0, targetVelocity=2.0, physicsClientId=world)
    step(world, 1.0)
    angle, speed = p.getJointState(free.body, 0, physicsClientId=world)[:2]
    assert speed == pytest.approx(2.0, rel=1e-3) and angle == pytest.approx(2.0, rel=1e-2)  # no motor holds it
    # damped: I = 0.42 + 5 * 0.5² = 1.67 kg m² about the hinge; ω = 2 exp(-5 t / 1.67) = 0.1 rad/s at 1 s
    speed = p.getJointState(damped.body, 0, physicsClientId=world)[1]
    assert speed == pytest.approx(2.0 * math.exp(-5.0 / 1.67), rel=0.1)
    assert free.pose()[0] == pytest.approx((0.0, 0.0, 0.0), abs=1e-9)  # the post is fixed to the world


def test_joint_friction_holds_a_gate_below_it(world):
    gate = SimModel(world, parse_sdf_model(gate_sdf(friction=50.0), "gate"), (0.0, 0.0, 0.0))
    p.resetJointState(gate.body, 0, 0.0, targetVelocity=1.0, physicsClientId=world)
    step(world, 0.5)
    assert abs(p.getJointState(gate.body, 0, physicsClientId=world)[1]) < 1e-3  # stopped by 50 N m


def test_mass_and_inertia_as_given(client):
    text = """<model name='m'><link name='l'><inertial><pose>0.1 0.2 0.3 0 0 0</pose><mass>7</mass>
      <inertia><ixx>2</ixx><iyy>3</iyy><izz>4</izz><ixy>0.5</ixy><ixz>0</ixz><iyz>0</iyz></inertia></inertial>
      <collision name='c'><geometry><sphere><radius>0.1</radius></sphere></geometry></collision></link></model>"""
    model = SimModel(client, parse_sdf_model(text, "m"))
    mass, _, diagonal, position, orientation = p.getDynamicsInfo(model.body, -1, physicsClientId=client)[:5]
    assert mass == 7.0 and position == pytest.approx((0.1, 0.2, 0.3))
    # the principal frame turned back gives the tensor: R diag R^T == [[2, .5, 0], [.5, 3, 0], [0, 0, 4]]
    r = p.getMatrixFromQuaternion(orientation)
    tensor = [[sum(r[3 * i + k] * diagonal[k] * r[3 * j + k] for k in range(3)) for j in range(3)] for i in range(3)]
    assert tensor == [pytest.approx(row, abs=1e-9) for row in ([2, 0.5, 0], [0.5, 3, 0], [0, 0, 4])]


def test_a_static_model_is_massless_and_fixed(client):
    wall = SimModel(client, parse_sdf_model(box_sdf(static=True), "wall"))
    assert p.getDynamicsInfo(wall.body, -1, physicsClientId=client)[0] == 0.0


def test_surfaces_on_the_links(client):
    extra = (
        "<surface><friction><ode><mu>0.3</mu><mu2>0.1</mu2></ode></friction>"
        "<contact><ode><kp>1e5</kp></ode></contact></surface>"
    )
    box = SimModel(client, parse_sdf_model(box_sdf(extra=extra), "box"))
    info = p.getDynamicsInfo(box.body, -1, physicsClientId=client)
    assert info[1] == pytest.approx(0.3)  # lateral friction: mu
    assert info[9] == pytest.approx(1e5) and info[8] == pytest.approx(1.0)  # stiffness, damping (SDF's kd 1)


def test_instances_of_a_mesh_share_one_shape(client, tmp_path):
    obj = write_obj(tmp_path / "plant.obj")
    text = f"""<model name='plant'><static>true</static><link name='l'><collision name='c'><geometry>
      <mesh><uri>{obj}</uri><scale>0.2 0.2 0.5</scale></mesh></geometry></collision>
      <visual name='v'><geometry><mesh><uri>{obj}</uri></mesh></geometry></visual></link></model>"""
    spec = parse_sdf_model(text, "plant")
    cache = ShapeCache(client)
    plants = [SimModel(client, spec, (i, 0.0, 0.0), shapes=cache) for i in range(3)]
    assert len(cache.collision) == 1 and len(cache.visual) == 1
    for i, plant in enumerate(plants):  # each its own static rigid body of the one shape, where it was put
        assert plant.rigid and p.getBasePositionAndOrientation(plant.body, physicsClientId=client)[0] == (i, 0.0, 0.0)
        hit = p.rayTest((i, 0.0, 2.0), (i, 0.0, -1.0), physicsClientId=client)[0]
        assert hit[0] == plant.body
    assert len({p.getNumBodies(physicsClientId=client)}) == 1 and p.getNumBodies(physicsClientId=client) == 3
    with pytest.raises(ModelError):
        SimModel(client + 1, spec, shapes=cache)


def test_a_static_rigid_body_collides_where_a_teleport_puts_it(world):
    """A static model of one link is a static rigid body (bullet updates none of them each step): a
    teleport moves what collides with it, and a kinematic one (an actor) stays a multibody."""
    post = SimModel(world, parse_sdf_model(box_sdf("post", (0.2, 0.2, 1.0), static=True), "post"), (0.0, 0.0, 0.5))
    assert post.rigid
    post.set_pose((3.0, 1.0, 0.5), (0.0, 0.0, 0.0, 1.0))
    step(world, 0.1)
    assert ray_down(world, 3.0, 1.0)[1] == pytest.approx(1.0, abs=1e-6)
    assert ray_down(world, 0.0, 0.0)[1] == pytest.approx(0.0, abs=1e-6)  # the ground where it was
    assert post.pose()[0] == pytest.approx((3.0, 1.0, 0.5), abs=1e-9)
    kinematic = replace(parse_sdf_model(box_sdf("actor", static=True), "actor"), kinematic=True)
    assert not SimModel(world, kinematic, (5.0, 0.0, 0.5)).rigid


@pytest.mark.parametrize("write", [write_obj, write_binary_stl, write_ascii_stl, write_dae])
def test_every_mesh_format_collides_static_and_moving(world, tmp_path, write):
    path = write(tmp_path / ("cube" + {write_obj: ".obj", write_dae: ".dae"}.get(write, ".stl")))
    for static, x in (("true", 0.0), ("false", 2.0)):
        text = f"""<model name='m'><static>{static}</static><link name='l'><collision name='c'><geometry>
          <mesh><uri>{path}</uri><scale>0.4 0.4 0.4</scale></mesh></geometry></collision></link></model>"""
        SimModel(world, parse_sdf_model(text, "m"), (x, 0.0, 1.0))
    step(world, 1.0)
    assert ray_down(world, 0.0, 0.0)[1] == pytest.approx(1.2, abs=1e-6)  # static: where it was put
    assert ray_down(world, 2.0, 0.0)[1] == pytest.approx(0.4, abs=3e-3)  # moving: fell, rests (hull margin)


def test_collada_units_and_node_transforms(client, tmp_path):
    # Gazebo's ColladaLoader: node transforms composed, then everything times <unit meter>; up_axis ignored
    dae = write_dae(tmp_path / "c.dae", meter=0.5, node="<translate>0 0 0.25</translate><scale>2 2 2</scale>")
    text = f"""<model name='m'><static>true</static><link name='l'><collision name='c'><geometry>
      <mesh><uri>{dae}</uri></mesh></geometry></collision></link></model>"""
    SimModel(client, parse_sdf_model(text, "m"))
    assert ray_down(client, 0.0, 0.0)[1] == pytest.approx((1.0 + 0.25) * 0.5)  # the cube's top


def test_a_urdf_cart_built(client):
    urdf = """<robot name='cart'><link name='base'><inertial><mass value='10'/>
      <inertia ixx='1' iyy='1' izz='1' ixy='0' ixz='0' iyz='0'/></inertial>
      <collision><geometry><box size='1 0.6 0.2'/></geometry></collision></link>
      <joint name='axle' type='continuous'><parent link='base'/><child link='wheel'/>
        <origin xyz='0.5 0 0'/><axis xyz='0 1 0'/></joint>
      <link name='wheel'><inertial><mass value='1'/>
        <inertia ixx='0.1' iyy='0.1' izz='0.1' ixy='0' ixz='0' iyz='0'/></inertial>
      <collision><geometry><cylinder radius='0.2' length='0.1'/></geometry></collision></link></robot>"""
    cart = SimModel(client, parse_urdf_model(urdf, "cart.urdf"), (0.0, 0.0, 1.0))
    assert cart.collisions == {"base::base_collision": -1, "wheel::wheel_collision": 0}
    assert p.getJointInfo(cart.body, 0, physicsClientId=client)[13] == pytest.approx((0.0, 1.0, 0.0))


def test_set_pose_teleports_with_a_velocity_and_remove(client):
    box = SimModel(client, parse_sdf_model(box_sdf(), "box"))
    q = p.getQuaternionFromEuler((0.0, 0.0, 1.0))
    box.set_pose((5.0, 6.0, 7.0), q, linear=(1.0, 0.0, 0.0), angular=(0.0, 0.0, 0.5))
    assert close_pose(box.pose(), ((5.0, 6.0, 7.0), q))
    linear, angular = p.getBaseVelocity(box.body, physicsClientId=client)
    assert linear == pytest.approx((1.0, 0.0, 0.0)) and angular == pytest.approx((0.0, 0.0, 0.5))
    with pytest.raises(ModelError):
        box.set_pose((math.nan, 0.0, 0.0), (0, 0, 0, 1))
    box.remove()
    assert p.getNumBodies(physicsClientId=client) == 0


def test_build_refusals_before_pybullet_allocates(client):
    spec = parse_sdf_model(box_sdf(), "box")
    massless = replace_link(spec, "link", inertial=Inertial(0.0))
    with pytest.raises(ModelError, match="mass 0 in a moving model"):
        SimModel(client, massless)
    huge = ModelSpec("huge", True, tuple(replace_link(spec, "link", name=f"l{i}").links[0] for i in range(1001)))
    with pytest.raises(ModelError, match="more than the 1000"):
        SimModel(client, huge)
    with pytest.raises(ModelError, match="unit quaternion"):
        SimModel(client, spec, (0, 0, 0), (0, 0, 0, 2))
    assert p.getNumBodies(physicsClientId=client) == 0


def close_pose(a, b, tol=1e-9):
    same = all(abs(x - y) <= tol for x, y in zip(a[0], b[0]))
    dot = abs(sum(x * y for x, y in zip(a[1], b[1])))
    return same and dot == pytest.approx(1.0, abs=tol)
