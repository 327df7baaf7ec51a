"""RViz shows a generated robot: a real screenshot under Xvfb (software GL), compared with the
empty scene of the same RViz configuration. Starts its own master (roslaunch) on a free port and
Xvfb on a free display; both stop when the test ends. About 20-30 s."""

import os

import numpy as np
import pytest
from urdf_helpers import PKG

from thorvald_model import load_robot_config
from thorvald_model.rviz_capture import (
    differing_pixels,
    robot_view,
    roslaunch,
    wait_for_render,
    write_rviz_config,
    xvfb,
)

pytestmark = [pytest.mark.ros, pytest.mark.slow, pytest.mark.long(12)]

STD = os.path.join(PKG, "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
WIDTH, HEIGHT = 640, 480

EMPTY_LAUNCH = """<launch>
  <node name="rviz" pkg="rviz" type="rviz" args="-d {config} -f base_link"/>
</launch>
"""


def orange_pixels(image):
    # The steering modules' orange (1.0, 0.45, 0.0), shaded by RViz's light; nothing else is orange.
    px = np.asarray(image, dtype=np.float64)
    r, g, b = px[..., 0], px[..., 1], px[..., 2]
    return int(((r > 120) & (g > 0.25 * r) & (g < 0.7 * r) & (b < 0.25 * r)).sum())


def test_rviz_shows_the_generated_robot(tmp_path):
    config = str(tmp_path / "view.rviz")
    write_rviz_config(config, robot_view(load_robot_config(STD)), WIDTH, HEIGHT)
    empty_launch = tmp_path / "empty.launch"
    empty_launch.write_text(EMPTY_LAUNCH.format(config=config))
    with xvfb(WIDTH, HEIGHT) as display:
        with roslaunch([str(empty_launch)], display, str(tmp_path)):
            empty = wait_for_render(display, timeout=40)
        display_launch = ["thorvald_model", "display.launch", f"robot_model:={STD}", f"rviz_config:={config}"]
        with roslaunch(display_launch, display, str(tmp_path)):
            robot = wait_for_render(display, timeout=40, min_changed=2000)
    empty.save(tmp_path / "empty.png")
    robot.save(tmp_path / "robot.png")
    assert orange_pixels(empty) == 0
    # The robot covers a good part of the view, with its four orange steering modules.
    assert differing_pixels(robot, empty) > 0.03 * WIDTH * HEIGHT, f"screenshots in {tmp_path}"
    assert orange_pixels(robot) > 200, f"screenshots in {tmp_path}"
