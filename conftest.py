"""Settings and fixtures shared by every pytest suite of the workspace.

Hypothesis explores new random examples on every local run; under CI (CI=true) it is derandomized,
so a landing never depends on the luck of the draw. A failure found locally prints its example.

Markers (pyproject.toml): a test that uses the ``ros_env`` fixture, or whose module starts ROS
through thorvald_testing (a ``Launch``, ``ros_master``), is marked ``ros`` here without anyone
remembering to; modules that start ROS another way (roslaunch in an install space, the main job)
say ``pytestmark = pytest.mark.ros`` themselves. ``pytest -m "not ros"`` runs the pure core.
"""

import os

import pytest
from hypothesis import settings

import thorvald_testing

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
settings.register_profile("dev", deadline=None)
settings.load_profile("ci" if os.environ.get("CI") else "dev")

_STARTS_ROS = (thorvald_testing.Launch, thorvald_testing.ros_master)


@pytest.fixture(scope="module")
def ros_env(tmp_path_factory):
    """A ROS master of the test module's own (roscore on a free port); the environment to run
    processes with."""
    yield from thorvald_testing.ros_master(tmp_path_factory.mktemp("ros_home"))


def pytest_collection_modifyitems(config, items):
    for item in items:
        module = getattr(item, "module", None)
        starts_ros = module is not None and any(v is s for v in vars(module).values() for s in _STARTS_ROS)
        if "ros_env" in getattr(item, "fixturenames", ()) or starts_ros:
            item.add_marker(pytest.mark.ros)
    # the modules marked long(seconds) first, longest first (stable: the rest in their order), so that in
    # the parallel run (tools/run-tests: --dist loadfile --no-loadscope-reorder) no core waits at the end
    # on one that started last
    items.sort(key=lambda item: -_long_seconds(item))


def _long_seconds(item) -> float:
    marker = item.get_closest_marker("long")
    return float(marker.args[0]) if marker is not None and marker.args else 0.0
