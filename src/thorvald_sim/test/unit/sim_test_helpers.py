"""What the simulator's unit tests share: a pybullet client, a ray straight down, a world's problems,
a publisher that records what a sensor publishes.

A unique module name, so the conftest.py files of several packages never shadow each other in one
pytest run (conftest.py imports the fixture from here)."""

import io

import pybullet as p
import pytest

from thorvald_sim.world import LIMITS, ConfigError, parse_world


@pytest.fixture
def client():
    """A pybullet physics client without a display, disconnected after the test."""
    c = p.connect(p.DIRECT)
    yield c
    p.disconnect(c)


def ray_down(client, x, y, top=5.0, bottom=-1.0):
    """(body id, z [m]) of the first thing a vertical ray from top to bottom at (x, y) hits
    (-1 and bottom when nothing)."""
    body, _, fraction, _, _ = p.rayTest((x, y, top), (x, y, bottom), physicsClientId=client)[0]
    return body, top - fraction * (top - bottom)


def world_problems(data, source="test-world", base_dir=None, limits=LIMITS):
    """The problems parse_world finds in data held to the limits, by key path (it must find some)."""
    with pytest.raises(ConfigError) as e:
        parse_world(data, source, base_dir, limits)
    return {pr.path: pr for pr in e.value.problems}


class Recorder:
    """A publisher every topic is subscribed to: each message serialised as rospy would, and kept."""

    def __init__(self, topic, msg_type):
        self.topic, self.type = topic, msg_type
        self.messages = []

    def get_num_connections(self) -> int:
        return 1

    def publish(self, msg) -> None:
        buff = io.BytesIO()
        msg.serialize(buff)
        self.messages.append(self.type().deserialize(buff.getvalue()))

    def unregister(self) -> None:
        pass
