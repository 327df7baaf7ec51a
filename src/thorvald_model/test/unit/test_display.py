"""RViz without a display: one line that says what to do, instead of Qt's abort (exit -6)."""

import os
import subprocess

import pytest

from thorvald_model.display import display_problem


def test_a_display_or_none():
    assert display_problem({"DISPLAY": ":1"}) is None
    assert display_problem({"WAYLAND_DISPLAY": "wayland-0"}) is None
    problem = display_problem({})
    assert problem.startswith("no display (DISPLAY is not set): RViz needs one.")
    assert "xvfb-run -a -s '-screen 0 1280x1024x24' env LIBGL_ALWAYS_SOFTWARE=1 roslaunch" in problem


@pytest.mark.slow  # a process: the wrapper as roslaunch starts it
def test_the_rviz_wrapper_says_it_and_exits_1_without_starting_rviz():
    env = {k: v for k, v in os.environ.items() if k not in ("DISPLAY", "WAYLAND_DISPLAY")}
    proc = subprocess.run(
        ["rosrun", "thorvald_model", "rviz", "-d", "model.rviz"], env=env, capture_output=True, text=True, timeout=60
    )
    assert proc.returncode == 1
    assert proc.stderr.startswith("rviz: no display (DISPLAY is not set): RViz needs one.")
    assert "Traceback" not in proc.stderr
