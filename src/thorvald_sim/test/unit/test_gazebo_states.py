"""model_states and link_states serialised straight from the numbers (thorvald_sim.gazebo.api's
packed_states): the bytes genpy writes for the same message, which every subscriber reads back."""

import io
import math

import pytest
from geometry_msgs.msg import Point, Pose, Quaternion, Twist, Vector3

from gazebo_msgs.msg import LinkStates, ModelStates
from thorvald_sim.gazebo.api import packed_states


def genpy_bytes(kind, names, poses, twists):
    msg = kind()
    for name, p, t in zip(names, poses, twists):
        msg.name.append(name)
        msg.pose.append(Pose(Point(*p[:3]), Quaternion(*p[3:])))
        msg.twist.append(Twist(Vector3(*t[:3]), Vector3(*t[3:])))
    buff = io.BytesIO()
    msg.serialize(buff)
    return buff.getvalue()


@pytest.mark.parametrize("kind", [ModelStates, LinkStates])
@pytest.mark.parametrize("count", [0, 1, 21])
def test_the_packed_message_is_the_bytes_genpy_writes(kind, count):
    names = [f"thorvald_{k:03d}::thorvald_{k:03d}/base_link" if kind is LinkStates else f"r{k}" for k in range(count)]
    names[:1] = ["grüne_reihe"] if count else []  # a name beyond ASCII: its length in bytes
    poses = [(k, -2.5 * k, 0.1, 0.0, 0.0, math.sin(k), math.cos(k)) for k in range(count)]
    twists = [(0.5, 0.0, 0.0, 0.0, 0.0, 0.1 * k) for k in range(count)]
    packed = packed_states(kind, names, poses, twists)
    assert isinstance(packed, kind)  # what a publisher of kind accepts
    buff = io.BytesIO()
    packed.serialize(buff)
    assert buff.getvalue() == genpy_bytes(kind, names, poses, twists)
    back = kind().deserialize(buff.getvalue())
    assert back.name == names
    if count:
        assert back.pose[-1].orientation.w == pytest.approx(math.cos(count - 1))
