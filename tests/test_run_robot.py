"""run_robot, the simulator without ROS, against the ROS path: the same manoeuvre gives the same ground
truth (run_robot's own tests: src/thorvald_sim/test/unit/test_runner.py).

The ROS path is the main job's: odometry_report drives the verification manoeuvre with robot.launch
in lockstep (base_driver on measured drives, following stamped commands) and records the stamped
commands and ground truth. run_robot is given exactly those commands (read back from the bag), the
same robot, world and model extras, and its ground truth must be the bag's to 1 mm at every instant
both have.
"""

import csv
import math
import os
import subprocess

import pytest

from thorvald_model.description import package_file as model_file
from thorvald_sim.tools.runner import RunOptions, TimedTwist, read_commands, run_robot, write_commands

pytestmark = [pytest.mark.ros, pytest.mark.slow, pytest.mark.long(20)]

ROBOT = "thorvald_ii_4wd4ws_std"
ROBOT_FILE = model_file("config", ROBOT, ROBOT + ".yaml")
HERE = os.path.dirname(os.path.abspath(__file__))
EXTRAS = os.path.join(HERE, "..", "src", "thorvald_bringup", "urdf", "odometry_report_sensors.xacro")
SAME = 0.001  # [m]: the ROS path and run_robot, at every instant both have


def bag_messages(bag_path, topic):
    import rosbag  # noqa: PLC0415  (genpy: only here, where the ROS path's bag is read)

    with rosbag.Bag(bag_path) as bag:
        return [msg for _, msg, _ in bag.read_messages(topics=[topic])]


@pytest.fixture(scope="module")
def ros_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("ros_path")
    proc = subprocess.run(
        ["rosrun", "thorvald_bringup", "odometry_report", "--robot", ROBOT, "--world", "flat", "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=900,
    )
    assert proc.returncode in (0, 1), proc.stdout[-2000:] + proc.stderr[-2000:]  # 1: a target missed, still a drive
    bag = str(out / "odometry_report.bag")
    stamped = {}
    for msg in bag_messages(bag, "/thorvald_001/cmd_vel_stamped"):
        t = msg.header.stamp.to_sec()
        stamped[t] = TimedTwist(t, msg.twist.linear.x, msg.twist.linear.y, msg.twist.angular.z)
    truth = [
        (m.header.stamp.to_sec(), m.pose.pose.position.x, m.pose.pose.position.y)
        for m in bag_messages(bag, "/thorvald_001/odometry/gazebo")
    ]
    commands = [stamped[t] for t in sorted(stamped)]
    return commands, truth


def read_samples(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return {round(float(r["t"]), 6): (float(r["x"]), float(r["y"])) for r in rows}


def test_run_robot_gives_the_ros_paths_ground_truth(ros_run, tmp_path):
    commands, truth = ros_run
    assert len(commands) > 1000 and len(truth) > 1000
    cmds = tmp_path / "commands.csv"
    write_commands(str(cmds), commands)
    end = truth[-1][0]
    run_robot(
        ROBOT_FILE,
        read_commands(str(cmds)),
        RunOptions(world="flat", model_extras=EXTRAS, hold=end - commands[-1].t),
        out_dir=str(tmp_path / "run"),
    )
    ours = read_samples(tmp_path / "run" / "ground_truth.csv")
    common = [(t, x, y) for t, x, y in truth if round(t, 6) in ours]
    # ground truth at 50 Hz on the physics steps nearest its multiples, the cycles at the first 80 Hz
    # tick at or after theirs: every tenth of a second both fall on one step
    assert len(common) > 0.15 * len(truth), f"{len(common)} instants in common of {len(truth)}"
    worst = max(math.hypot(x - ours[round(t, 6)][0], y - ours[round(t, 6)][1]) for t, x, y in common)
    moved = max(math.hypot(x, y) for _, x, y in truth)
    assert moved > 3.0  # the manoeuvre went somewhere
    print(f"{len(common)} instants in common; the largest difference {worst * 1000:.6f} mm")
    assert worst < SAME, f"run_robot's ground truth is {worst * 1000:.3f} mm from the ROS path's"
