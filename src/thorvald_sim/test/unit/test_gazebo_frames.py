"""The Gazebo API's frame arithmetic (thorvald_sim.gazebo.frames) and name resolution
(thorvald_sim.gazebo.entities), pure: no ROS, no pybullet.

The expectations are worked by hand from gazebo_ros's api plugin (ignition's ``a + b`` and ``a - b``
on poses, ``transformWrench``) and ``World::EntityByName``, not from the code under test."""

import math
import random

import pytest

from thorvald_sim.gazebo import frames
from thorvald_sim.gazebo.entities import GROUND, WORLD, Entities, Joint, Link, Model


def yaw_q(yaw):
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


def random_pose(rng):
    q = frames.normalised([rng.uniform(-1, 1) for _ in range(4)])
    return tuple(rng.uniform(-5, 5) for _ in range(3)), q


def same_pose(a, b, tol=1e-9):
    assert a[0] == pytest.approx(b[0], abs=tol)
    sign = 1.0 if sum(x * y for x, y in zip(a[1], b[1])) >= 0 else -1.0  # q and -q are one rotation
    assert tuple(sign * v for v in a[1]) == pytest.approx(b[1], abs=tol)


# ---- frames -------------------------------------------------------------------------------------
def test_a_pose_in_a_turned_and_moved_frame_by_hand():
    frame = ((1.0, 2.0, 0.0), yaw_q(math.pi / 2))  # the robot at (1, 2) facing +y
    mark = ((1.0, 0.0, 0.0), frames.IDENTITY)  # 1 m ahead of it
    world = frames.in_parent(mark, frame)
    assert world[0] == pytest.approx((1.0, 3.0, 0.0))  # ahead is +y
    same_pose(world, ((1.0, 3.0, 0.0), yaw_q(math.pi / 2)))
    same_pose(frames.seen_from(world, frame), mark)


def test_in_parent_and_seen_from_undo_each_other():
    rng = random.Random(3)
    for _ in range(200):
        pose, frame = random_pose(rng), random_pose(rng)
        same_pose(frames.seen_from(frames.in_parent(pose, frame), frame), pose)
        same_pose(frames.in_parent(frames.seen_from(pose, frame), frame), pose)


def test_a_quaternion_of_zeros_is_the_identity_as_ignition_normalises_it():
    assert frames.normalised((0, 0, 0, 0)) == frames.IDENTITY
    assert frames.normalised((0, 0, 0, 2)) == frames.IDENTITY
    assert frames.normalised((0, 0, 3, 4)) == pytest.approx((0, 0, 0.6, 0.8))


def test_a_twist_seen_from_a_moving_turned_frame():
    frame = ((0.0, 0.0, 0.0), yaw_q(math.pi / 2))
    linear, angular = frames.twist_seen_from((1.0, 2.0, 0.0), (0.0, 0.0, 0.5), frame, (1.0, 0.0, 0.0), (0, 0, 0.2))
    # relative (0, 2, 0) in the world's axes is (2, 0, 0) in a frame facing +y
    assert linear == pytest.approx((2.0, 0.0, 0.0))
    assert angular == pytest.approx((0.0, 0.0, 0.3))


def test_a_wrench_at_a_point_moves_to_the_body_with_its_moment():
    world = ((0.0, 0.0, 0.0), frames.IDENTITY)
    body = ((0.0, 0.0, 0.0), frames.IDENTITY)
    # 10 N along x at 1 m along y: a torque of -10 N m about z
    force, torque = frames.wrench_on_body((10.0, 0, 0), (0, 0, 0), (0, 1.0, 0), world, body)
    assert force == pytest.approx((10.0, 0, 0))
    assert torque == pytest.approx((0, 0, -10.0))


def test_a_wrench_in_a_turned_reference_frame_is_turned():
    reference = ((0.0, 0.0, 0.0), yaw_q(math.pi / 2))  # x of the reference is the world's y
    body = ((0.0, 0.0, 0.0), frames.IDENTITY)
    force, torque = frames.wrench_on_body((5.0, 0, 0), (0, 0, 1.0), (0, 0, 0), reference, body)
    assert force == pytest.approx((0, 5.0, 0))
    assert torque == pytest.approx((0, 0, 1.0))


def test_euler_of_gives_roll_pitch_yaw():
    assert frames.euler_of(yaw_q(0.7)) == pytest.approx((0, 0, 0.7))
    roll = (math.sin(0.2), 0.0, 0.0, math.cos(0.2))
    assert frames.euler_of(roll) == pytest.approx((0.4, 0, 0))


def test_finite():
    assert frames.finite((1, 2), (3,))
    assert not frames.finite((1, math.nan))
    assert not frames.finite((), (math.inf,))


# ---- entities ------------------------------------------------------------------------------------
def world_of_three():
    entities = Entities()
    entities.add(Model(GROUND, "ground", (Link("link", -1, ("collision",)),), static=True))
    robot_links = (
        Link("thorvald_001/base_link", -1, ("thorvald_001/base_link_collision",)),
        Link("thorvald_001/wheel0", 3, ()),
    )
    entities.add(Model("thorvald_001", "robot", robot_links, (Joint("thorvald_001/steering0", 2, "revolute"),)))
    gate_links = (Link("post", -1), Link("door", 0, ("collision",)))
    entities.add(Model("gate", "model", gate_links, (Joint("hinge", 0, "revolute"),)))
    return entities


def test_models_links_and_collisions_by_scoped_and_own_names():
    e = world_of_three()
    assert e.find("thorvald_001").kind == "model"
    link = e.find("thorvald_001/base_link")
    assert (link.kind, link.model.name, link.link.index) == ("link", "thorvald_001", -1)
    assert e.find("thorvald_001::thorvald_001/wheel0").link.index == 3
    assert e.find("gate::door").scoped == "gate::door"
    assert e.find("gate::door::collision").kind == "collision"
    assert e.find("nosuch") is None and e.find("gate::nosuch") is None


def test_the_first_entity_of_a_name_is_found_models_in_order():
    e = world_of_three()
    # "collision" is the ground's collision's own name before the gate door's
    found = e.find("collision")
    assert (found.kind, found.model.name) == ("collision", GROUND)
    assert e.find("link").model.name == GROUND


def test_world_names_are_the_world_unless_an_entity_is_called_so():
    e = world_of_three()
    for name in ("", "world", "map", "/map"):
        assert e.frame(name) is WORLD
    assert e.frame("nosuch") is None
    e.add(Model("map", "model", (Link("link", -1),)))
    assert e.frame("map").kind == "model"


def test_links_only_where_a_link_is_asked_for():
    e = world_of_three()
    assert e.link("thorvald_001") is None  # a model is not a link
    assert e.link("gate::post").link.name == "post"


def test_joints_by_own_and_scoped_names():
    e = world_of_three()
    model, joint = e.joint("gate::hinge")
    assert (model.name, joint.index) == ("gate", 0)
    assert e.joint("thorvald_001/steering0")[1].kind == "revolute"
    assert e.joint("door") is None


def test_a_second_model_of_a_name_is_refused_and_names_keep_their_order():
    e = world_of_three()
    with pytest.raises(KeyError, match="exists already"):
        e.add(Model("gate", "model", (Link("l", -1),)))
    assert e.names() == [GROUND, "thorvald_001", "gate"]
    e.remove("thorvald_001")
    assert e.names() == [GROUND, "gate"] and len(e) == 2
