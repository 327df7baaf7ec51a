#!/usr/bin/env python3
"""base_driver with ~calibration serves the calibrated values; a bad calibration file stops it.

The calibration (test/data/calibration_std.yaml, read here with plain YAML): drive0's wheel rolls
with 0.21 m instead of the robot file's 0.2 m, and its steering stands 0.05 rad to the left of what
its controller reads; drive2's 0.03 rad to the right.

* The parameters base_driver publishes (~motor_drives) hold the calibrated values.
* Commands are rim speeds: at 0.5 m/s drive0's wheel turns at 0.5 / 0.21 = 2.381 rad/s, the others
  at 0.5 / 0.2 = 2.5 rad/s (joint_states), while odometry reads 0.5 m/s.
* Odometry has the calibration's correction: driven straight at 0.5 m/s it reads 0.002 rad/m x 0.5 m/s
  of yaw rate, turning at 0.2 rad/s 1.01 x 0.2 rad/s more.
* Homing drives every steering controller to its own 0, where the wheel truly stands at the offset:
  joint_states (true angles) shows 0.05 rad for steering0 and -0.03 rad for steering2.
* A calibration file with a steering offset of 0.35 rad (beyond 0.2 rad) makes base_driver refuse to
  start, exit status non-zero, naming the file, the key path, the value and the rule, no traceback.
"""

import os
import signal
import subprocess
import unittest

import rospkg
import rospy
import rostest
import yaml
from driver_testing import WAIT, Topic, driver_service, driver_stream, twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState
from std_srvs.srv import Trigger

DATA = os.path.join(rospkg.RosPack().get_path("thorvald_base"), "test", "data")
STD = os.path.join(
    rospkg.RosPack().get_path("thorvald_model"), "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml"
)
SPEED = 0.5  # [m/s]
EXIT_TIMEOUT = 40.0  # [s] for a refusing node to start Python, read its parameters and exit on a loaded machine


def joint(js, name):
    return dict(zip(js.name, js.velocity if name.startswith("wheel") else js.position)).get(name)


class CalibrationTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        with open(os.path.join(DATA, "calibration_std.yaml")) as f:
            cls.calibration = yaml.safe_load(f)["motor_drives"]
        with open(STD) as f:
            cls.robot = yaml.safe_load(f)["motor_drives"]
        cls.joints = Topic("base_driver/joint_states", JointState)
        cls.odom = Topic("odometry/base_raw", Odometry)
        cls.cmd = driver_stream(cls.joints)
        cls.home = driver_service("home_steering", Trigger)

    def value(self, drive, key):
        """The calibrated value, else the robot file's (else its default)."""
        return self.calibration.get(drive, {}).get(key, self.robot[drive].get(key, 0.0 if key != "r_wheel" else 0.2))

    def test_base_driver_publishes_the_calibrated_values(self):
        for drive in self.robot:
            for key in ("r_wheel", "steering_offset"):
                with self.subTest(drive=drive, key=key):
                    served = rospy.get_param(f"base_driver/motor_drives/{drive}/{key}")
                    self.assertAlmostEqual(served, self.value(drive, key), places=12)
        self.assertEqual(rospy.get_param("base_driver/calibration"), os.path.join(DATA, "calibration_std.yaml"))

    def test_wheels_turn_as_the_calibrated_radii_say(self):
        self.cmd.send(twist(SPEED))
        rates = {f"wheel{n}": SPEED / self.value(f"drive{n}", "r_wheel") for n in range(len(self.robot))}
        self.assertAlmostEqual(rates["wheel0"], 2.380952381, places=6)  # 0.5 / 0.21
        msg = self.joints.wait_for(lambda m: all(abs(joint(m, w) - r) < 1e-9 for w, r in rates.items()), timeout=WAIT)
        self.assertIsNotNone(msg, f"joint_states: {self.joints.latest()}")
        # the steering stands truly straight, and odometry reads the commanded rim speed
        self.assertTrue(all(abs(joint(msg, f"steering{n}")) < 1e-9 for n in range(len(self.robot))), msg)
        self.assertAlmostEqual(self.odom.wait_for().twist.twist.linear.x, SPEED, places=6)

    def test_odometry_reads_with_the_calibrations_correction(self):
        self.cmd.send(twist(SPEED))
        msg = self.odom.wait_for(lambda m: abs(m.twist.twist.linear.x - SPEED) < 1e-6, timeout=WAIT)
        self.assertIsNotNone(msg, f"odometry/base_raw: {self.odom.latest()}")
        self.assertAlmostEqual(msg.twist.twist.angular.z, 0.002 * SPEED, places=6)
        self.cmd.send(twist(SPEED, wz=0.2))
        expected = 1.01 * 0.2 + 0.002 * SPEED
        msg = self.odom.wait_for(lambda m: abs(m.twist.twist.angular.z - expected) < 1e-6, timeout=WAIT)
        self.assertIsNotNone(msg, f"odometry/base_raw: {self.odom.latest()}, {expected} rad/s expected")
        self.cmd.send(twist(SPEED))  # straight again, as the other tests expect the wheels
        straight = self.odom.wait_for(lambda m: abs(m.twist.twist.angular.z - 0.002 * SPEED) < 1e-9, timeout=WAIT)
        self.assertIsNotNone(straight, f"odometry/base_raw: {self.odom.latest()}")

    def test_homing_stands_each_wheel_at_its_offset(self):
        self.cmd.send(twist(SPEED))
        self.assertIsNotNone(self.joints.wait_for(lambda m: abs(joint(m, "wheel1") - SPEED / 0.2) < 1e-9, timeout=WAIT))
        self.cmd.stop()
        self.assertTrue(self.home().success)
        offsets = {f"steering{n}": self.value(f"drive{n}", "steering_offset") for n in range(len(self.robot))}
        self.assertEqual((offsets["steering0"], offsets["steering2"]), (0.05, -0.03))
        msg = self.joints.wait_for(lambda m: all(abs(joint(m, s) - o) < 1e-9 for s, o in offsets.items()), timeout=WAIT)
        self.assertIsNotNone(msg, f"joint_states while homing: {self.joints.latest()}")
        # a new command ends homing: straight ahead is true 0 again
        self.cmd.send(twist(SPEED))
        straight = self.joints.wait_for(lambda m: all(abs(joint(m, s)) < 1e-9 for s in offsets), timeout=WAIT)
        self.assertIsNotNone(straight, f"joint_states after homing: {self.joints.latest()}")

    def refuses(self, name, calibration):
        proc = subprocess.Popen(
            [
                "rosrun",
                "thorvald_base",
                "base_driver",
                "__name:=" + name,
                "_robot_model:=" + STD,
                "_simple_sim:=true",
                "_calibration:=" + calibration,
            ],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            universal_newlines=True,
            start_new_session=True,
        )
        try:
            out, err = proc.communicate(timeout=EXIT_TIMEOUT)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, signal.SIGINT)
            proc.communicate(timeout=10)
            self.fail(f"base_driver started with {calibration} instead of refusing")
        self.assertNotEqual(proc.returncode, 0, out + err)
        self.assertIn("refusing to start", err)
        self.assertNotIn("Traceback", out + err)
        return err

    def test_a_bad_calibration_file_stops_base_driver(self):
        bad = os.path.join(DATA, "bad_calibration.yaml")
        err = self.refuses("bad_calibration_driver", bad)
        self.assertIn(f"{bad}: invalid calibration file", err)
        self.assertIn("motor_drives.drive1.steering_offset: 0.35: must be within +-0.2 rad", err)

    def test_a_missing_calibration_file_stops_base_driver(self):
        missing = os.path.join(DATA, "no_such_calibration.yaml")
        err = self.refuses("missing_calibration_driver", missing)
        self.assertIn(f"{missing}: cannot read the calibration file: No such file or directory", err)


if __name__ == "__main__":
    rospy.init_node("calibration_test")
    rostest.rosrun("thorvald_base", "base_driver_calibration", CalibrationTest)
