"""Fixtures of the thorvald_teleop tests; the helpers live in teleop_test_helpers.py."""

import pytest
from teleop_test_helpers import ros_master


@pytest.fixture(scope="module")
def ros_env(tmp_path_factory):
    """A ROS master of the test module's own; the environment to run processes with."""
    yield from ros_master(tmp_path_factory.mktemp("ros_home"))
