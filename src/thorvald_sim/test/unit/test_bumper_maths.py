"""The bumper's maths and messages without pybullet (thorvald_sim.sensors.kinds.bumper): contact points
to ContactStates as gazebo_ros_bumper fills them, a point on a collision's shape or not, and the
gazebo_msgs/ContactsState made of a reading.

Every expected number is derived in a comment from the figures of the case.
"""

import io
import math

import pytest

from gazebo_msgs.msg import ContactsState
from thorvald_sim.sensors.kinds.bumper import (
    BumperReading,
    ContactPoint,
    Shape,
    bumper_messages,
    contact_state,
    on_shape,
    rotation,
)

YAW_90 = (0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4))  # the link turned 90 degrees left
IDENTITY = (0.0, 0.0, 0.0, 1.0)


def close(a, b, tol=1e-9):
    return all(abs(x - y) <= tol for x, y in zip(a, b))


def test_a_wrench_is_the_force_on_the_bumper_and_its_torque_about_the_centre_of_mass_in_the_links_axes():
    # the link turned 90 degrees left, its centre of mass at (1, 0, 0); a wall pushes at (2, 1, 0.5)
    # with 10 N along -x. Torque about the centre: r = (1, 1, 0.5), F = (-10, 0, 0),
    # r x F = (1*0 - 0.5*0, 0.5*(-10) - 1*0, 1*0 - 1*(-10)) = (0, -5, 10) in the world.
    # The link's axes: x is the world's y, y the world's -x, so a world vector (a, b, c) is (b, -a, c):
    # force (0, 10, 0), torque (-5, 0, 10).
    point = ContactPoint((2.0, 1.0, 0.5), (-1.0, 0.0, 0.0), 0.002, (-10.0, 0.0, 0.0))
    state = contact_state("r::base_link::bumper", "ground_plane::link::collision", [point], YAW_90, (1.0, 0.0, 0.0))
    ((force, torque),) = state.wrenches
    assert close(force, (0.0, 10.0, 0.0)) and close(torque, (-5.0, 0.0, 10.0))
    # positions and normals stay in the world (gazebo_ros_bumper leaves them there)
    assert state.positions == ((2.0, 1.0, 0.5),) and state.normals == ((-1.0, 0.0, 0.0),)
    assert state.depths == (0.002,)
    assert (state.collision1, state.collision2) == ("r::base_link::bumper", "ground_plane::link::collision")


def test_the_total_wrench_sums_the_points():
    # two points 0.4 m either side of the centre in y, 5 N each along -x: forces sum to (-10, 0, 0);
    # torques (0, 0.4, 0) x (-5, 0, 0) = (0, 0, 2) and (0, -0.4, 0) x (-5, 0, 0) = (0, 0, -2) cancel
    points = [
        ContactPoint((0.0, 0.4, 0.0), (-1.0, 0.0, 0.0), 0.0, (-5.0, 0.0, 0.0)),
        ContactPoint((0.0, -0.4, 0.0), (-1.0, 0.0, 0.0), 0.0, (-5.0, 0.0, 0.0)),
    ]
    state = contact_state("a", "b", points, IDENTITY, (0.0, 0.0, 0.0))
    assert close(state.wrenches[0][1], (0.0, 0.0, 2.0)) and close(state.wrenches[1][1], (0.0, 0.0, -2.0))
    assert close(state.total[0], (-10.0, 0.0, 0.0)) and close(state.total[1], (0.0, 0.0, 0.0))


def test_rotation_turns_the_links_axes_into_the_worlds():
    m = rotation(YAW_90)
    assert close(m @ (1.0, 0.0, 0.0), (0.0, 1.0, 0.0)) and close(m @ (0.0, 1.0, 0.0), (-1.0, 0.0, 0.0))


@pytest.mark.parametrize(
    ("shape", "point", "on"),
    [
        # a box 0.1 x 0.8 x 0.15: its faces at 0.05, 0.4, 0.075; 1 cm of margin beyond them
        (Shape("box", (0.1, 0.8, 0.15)), (0.05, 0.4, -0.075), True),
        (Shape("box", (0.1, 0.8, 0.15)), (0.059, 0.0, 0.0), True),
        (Shape("box", (0.1, 0.8, 0.15)), (0.0, 0.0, 0.09), False),
        # a cylinder of radius 0.2, 0.05 long along z: (0.12, 0.16) is 0.2 from its axis
        (Shape("cylinder", (0.2, 0.05)), (0.12, 0.16, 0.025), True),
        (Shape("cylinder", (0.2, 0.05)), (0.15, 0.16, 0.0), False),
        (Shape("cylinder", (0.2, 0.05)), (0.0, 0.0, 0.04), False),
        (Shape("sphere", (0.05,)), (0.03, 0.04, 0.0), True),
        (Shape("sphere", (0.05,)), (0.0, 0.0, -0.061), False),
    ],
)
def test_a_point_is_on_a_shape_within_the_margin(shape, point, on):
    assert on_shape(shape, point) is on


class Out:
    """What a kind's messages ask SensorIO for: a ContactsState stamped and framed."""

    def message(self, role):
        assert role == "bumper"
        msg = ContactsState()
        msg.header.frame_id = "thorvald_001/bumper_link"
        return msg


def test_a_reading_becomes_a_contacts_state_that_crosses_the_wire():
    point = ContactPoint((2.9, 0.4, 0.55), (-1.0, 0.0, 0.0), 0.001, (-100.0, 2.0, 0.0))
    state = contact_state(
        "thorvald_001::base_link::b", "ground_plane::link::collision", [point, point], IDENTITY, (0.0, 0.0, 0.5)
    )
    ((role, msg),) = list(bumper_messages(Out(), BumperReading((state,), 5.25), {"bumper": True}))
    assert role == "bumper" and msg.header.frame_id == "thorvald_001/bumper_link"
    buff = io.BytesIO()
    msg.serialize(buff)
    got = ContactsState().deserialize(buff.getvalue())
    (s,) = got.states
    assert (s.collision1_name, s.collision2_name) == ("thorvald_001::base_link::b", "ground_plane::link::collision")
    assert "5.25" in s.info and "thorvald_001::base_link::b" in s.info
    assert [(v.x, v.y, v.z) for v in s.contact_positions] == [(2.9, 0.4, 0.55)] * 2
    assert [(v.x, v.y, v.z) for v in s.contact_normals] == [(-1.0, 0.0, 0.0)] * 2
    assert list(s.depths) == [0.001, 0.001]
    # torque about (0, 0, 0.5): r = (2.9, 0.4, 0.05), F = (-100, 2, 0):
    # r x F = (0.4*0 - 0.05*2, 0.05*(-100) - 2.9*0, 2.9*2 - 0.4*(-100)) = (-0.1, -5, 45.8)
    w = s.wrenches[0]
    assert close((w.force.x, w.force.y, w.force.z), (-100.0, 2.0, 0.0))
    assert close((w.torque.x, w.torque.y, w.torque.z), (-0.1, -5.0, 45.8), 1e-9)
    t = s.total_wrench
    assert close((t.force.x, t.torque.z), (-200.0, 91.6), 1e-9)


def test_no_contact_is_a_contacts_state_without_states():
    ((_, msg),) = list(bumper_messages(Out(), BumperReading((), 1.0), {"bumper": True}))
    assert msg.states == []
