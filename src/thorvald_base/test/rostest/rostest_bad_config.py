#!/usr/bin/env python3
"""base_driver refuses to start on a bad robot file, naming the key, without a traceback.

Bad content: each case loads a robot file into a fresh private namespace, as the original's launch
files do, and runs ``rosrun thorvald_base base_driver __name:=<that namespace>`` on the rostest's
master. Unreadable files (not UTF-8, a directory, missing, no read permission): base_driver gets
only ``~robot_model``, as base_bringup.launch gives it, and reads the file itself. The good
standard robot file, run the same way, starts and drives: the refusals come from the bad files.
"""

import os
import shutil
import signal
import subprocess
import sys
import tempfile
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
        env=dict(os.environ, PYTHONFAULTHANDLER="1"),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        universal_newlines=True,
        start_new_session=True,
    )


def without_file_override():
    """A command prefix under which root, too, is refused files it has no permission to read."""
    if os.geteuid() != 0:
        return []
    caps = "-dac_override,-dac_read_search"
    return [shutil.which("setpriv"), "--inh-caps=" + caps, "--bounding-set=" + caps]


def start_driver_on_file(name, robot_file):
    """base_driver with only ~robot_model (and simple_sim), as base_bringup.launch starts it."""
    return subprocess.Popen(
        [
            *without_file_override(),
            "rosrun",
            "thorvald_base",
            "base_driver",
            "__name:=" + name,
            "_robot_model:=" + robot_file,
            "_simple_sim:=true",
        ],
        env=dict(os.environ, PYTHONFAULTHANDLER="1"),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        universal_newlines=True,
        start_new_session=True,
    )


class BadConfigTest(unittest.TestCase):
    def refuses(self, name, robot_file, key, proc=None, **node_params):
        proc = proc or start_driver(name, robot_file, **node_params)
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

    def refuses_unreadable(self, name, make, reason):
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "robot.yaml")
            make(path)
            err = self.refuses(name, path, f"{path}: {reason}", proc=start_driver_on_file(name, path))
        fatal = [line for line in err.splitlines() if "FATAL" in line]
        self.assertEqual(len(fatal), 1, err)
        return err

    def test_file_that_is_not_utf8(self):
        def latin1(path):
            with open(GOOD, "rb") as good, open(path, "wb") as f:
                f.write("# Ås\n".encode("latin-1") + good.read())

        self.refuses_unreadable("not_utf8", latin1, "not a text file: byte 0xc5 at offset 2 is not UTF-8")

    def test_directory(self):
        self.refuses_unreadable("a_directory", os.mkdir, "cannot read the robot configuration: Is a directory")

    def test_missing_file(self):
        self.refuses_unreadable(
            "missing_file", lambda path: None, "cannot read the robot configuration: No such file or directory"
        )

    def test_file_without_read_permission(self):
        def no_permission(path):
            shutil.copy(GOOD, path)
            os.chmod(path, 0)

        self.refuses_unreadable(
            "no_permission", no_permission, "cannot read the robot configuration: Permission denied"
        )

    def test_bad_node_parameter(self):
        self.refuses("bad_rate", GOOD, "~rate", rate=-5.0)

    def test_can_buses_that_cannot_be_used(self):
        cases = (
            ("enc_pcb", "enc_pcb_v1rev6", "/dev/ttyUSB0", "never published; use a python-can interface instead"),
            ("unknown_interface", "warpcan", "x", "'warpcan': not a python-can interface"),
            ("no_interface", "", "", "~can_interface_type: empty"),
            ("missing_adapter", "slcan", "/nonexistent/ttyACM0", "CAN bus slcan '/nonexistent/ttyACM0' will not open"),
        )
        for name, interface, channel, reason in cases:
            with self.subTest(interface=interface):
                err = self.refuses(
                    name, GOOD, reason, simple_sim=False, can_interface_type=interface, can_interface_name=channel
                )
                self.assertEqual(len([line for line in err.splitlines() if "FATAL" in line]), 1, err)

    def test_good_file_starts(self):
        # the same ways of starting the node, with the good file: it runs and publishes odometry
        for name, start in (("good_driver", start_driver), ("good_driver_on_file", start_driver_on_file)):
            with self.subTest(start=start.__name__):
                self.starts_and_publishes(start(name, GOOD))

    def starts_and_publishes(self, proc):
        received = []
        sub = rospy.Subscriber("/odometry/base_raw", Odometry, received.append)
        try:
            deadline = time.time() + EXIT_TIMEOUT
            while time.time() < deadline and not received and proc.poll() is None:
                time.sleep(0.05)
            if proc.poll() is not None:
                self.fail(f"base_driver exited on the good file: {proc.communicate()}")
            self.assertTrue(received, "no odometry from base_driver on the good file")
        finally:
            sub.unregister()
            self.stop(proc)

    def stop(self, proc):
        """SIGINT, as roslaunch does; a node that is still running 30 s later fails the test, with its output."""
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGINT)
        try:
            proc.communicate(timeout=30)
        except subprocess.TimeoutExpired:
            # faulthandler (PYTHONFAULTHANDLER) prints every thread's stack on SIGABRT
            os.killpg(proc.pid, signal.SIGABRT)
            try:
                out, err = proc.communicate(timeout=10)
            except subprocess.TimeoutExpired:
                os.killpg(proc.pid, signal.SIGKILL)
                out, err = proc.communicate(timeout=10)
            said = f"base_driver did not exit within 30 s of SIGINT; its threads:\n{out}\n{err}"
            sys.stderr.write(said + "\n")  # into the test's log too: rosunit's XML drops a subTest's failure text
            self.fail(said)


if __name__ == "__main__":
    rospy.init_node("bad_config_test")
    rostest.rosrun("thorvald_base", "base_driver_bad_config", BadConfigTest)
