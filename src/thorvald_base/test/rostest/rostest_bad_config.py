#!/usr/bin/env python3
"""base_driver refuses to start on a bad robot file, naming the key, without a traceback.

Each case loads a robot file into a fresh private namespace, as base_bringup.launch does, and runs
``rosrun thorvald_base base_driver __name:=<that namespace>`` on the rostest's master. The good
standard robot file, run the same way, starts and drives: the refusals come from the bad values.
"""

import os
import signal
import subprocess
import time
import unittest

import rospkg
import rospy
import rostest
import yaml
from nav_msgs.msg import Odometry

DATA = os.path.join(rospkg.RosPack().get_path("thorvald_base"), "test", "data")
GOOD = os.path.join(
    rospkg.RosPack().get_path("thorvald_model"), "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml"
)
EXIT_TIMEOUT = 40.0  # [s] for the node to start Python, read its parameters and exit on a loaded machine


def start_driver(name, robot_file, **node_params):
    """Loads the file into /<name>/ with the node's parameters and starts base_driver there."""
    with open(robot_file) as f:
        params = yaml.safe_load(f)
    params.update({"robot_model": robot_file, "simple_sim": True})
    params.update(node_params)
    rospy.set_param("/" + name, params)
    return subprocess.Popen(
        ["rosrun", "thorvald_base", "base_driver", "__name:=" + name],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        universal_newlines=True,
        start_new_session=True,
    )


class BadConfigTest(unittest.TestCase):
    def refuses(self, name, robot_file, key, **node_params):
        proc = start_driver(name, robot_file, **node_params)
        try:
            out, err = proc.communicate(timeout=EXIT_TIMEOUT)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGINT)
            proc.communicate(timeout=10)
            self.fail(f"base_driver started on {robot_file} instead of refusing")
        text = out + err
        self.assertNotEqual(proc.returncode, 0, text)
        self.assertIn(key, err, "the key path is not in the node's error output")
        self.assertIn("refusing to start", err)
        self.assertIn("FATAL", err)
        self.assertNotIn("Traceback", text)
        return err

    def test_value_out_of_range(self):
        err = self.refuses("bad_str_lim", os.path.join(DATA, "bad_str_lim.yaml"), "motor_drives.drive1.str_lim")
        self.assertIn("4.5", err)  # the bad value, and where it is allowed
        self.assertIn("(0, pi]", err)
        self.assertIn("bad_str_lim.yaml", err)  # the file

    def test_value_of_the_wrong_type(self):
        err = self.refuses("bad_r_wheel", os.path.join(DATA, "bad_r_wheel_type.yaml"), "motor_drives.drive2.r_wheel")
        self.assertIn("'big'", err)

    def test_bad_node_parameter(self):
        self.refuses("bad_rate", GOOD, "~rate", rate=-5.0)

    def test_good_file_starts(self):
        # the same way of starting the node, with the good file: it runs and publishes odometry
        received = []
        sub = rospy.Subscriber("/odometry/base_raw", Odometry, received.append)
        proc = start_driver("good_driver", GOOD)
        try:
            deadline = time.time() + EXIT_TIMEOUT
            while time.time() < deadline and not received and proc.poll() is None:
                time.sleep(0.05)
            if proc.poll() is not None:
                self.fail(f"base_driver exited on the good file: {proc.communicate()}")
            self.assertTrue(received, "no odometry from base_driver on the good file")
        finally:
            sub.unregister()
            if proc.poll() is None:
                os.killpg(proc.pid, signal.SIGINT)
            proc.communicate(timeout=20)


if __name__ == "__main__":
    rospy.init_node("bad_config_test")
    rostest.rosrun("thorvald_base", "base_driver_bad_config", BadConfigTest)
