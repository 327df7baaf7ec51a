#!/usr/bin/env python3
"""base_driver: ~set_drive_params changes a drive parameter at run time (the wheel radius).

Commands are rim speeds [m/s], so a larger wheel radius leaves joint_commands and odometry as they
were; what changes is how fast the wheel turns: joint_states reports the wheel joints' angular
velocity = rim speed / r_wheel, and their angle integrates it. r_wheel 0.2 m -> 0.25 m (x 1.25) at
0.5 m/s: 2.5 rad/s -> 2.0 rad/s. An invalid value is refused (status 0) and the old one kept.
"""

import unittest

import rospy
import rostest
from driver_testing import WAIT, Topic, describe, driver_service, driver_stream, drives_from_params, speeds_are, twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState

from thorvald_msgs.msg import BaseState, DriveParam
from thorvald_msgs.srv import DriveParams

SPEED = 0.5  # [m/s]


def wheel_velocities(js):
    return [v for n, v in zip(js.name, js.velocity) if n.startswith("wheel")]


def wheel_positions(js):
    return [p for n, p in zip(js.name, js.position) if n.startswith("wheel")]


class DriveParamsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.commands = Topic("joint_commands", BaseState)
        cls.joints = Topic("base_driver/joint_states", JointState)
        cls.odom = Topic("odometry/base_raw", Odometry)
        cls.cmd = driver_stream(cls.joints)
        cls.set_params = driver_service("set_drive_params", DriveParams)
        cls.drives = drives_from_params()
        cls.cmd.send(twist(SPEED))
        # at speed: the simulated wheels ramp at 1.5 m/s^2
        assert cls.joints.wait_for(
            lambda m: m.name and all(abs(w - SPEED / 0.2) < 1e-9 for w in wheel_velocities(m)), timeout=WAIT
        ), "the wheels did not reach 2.5 rad/s"

    def wheel_radius_seen(self):
        """The radius every wheel turns with: rim speed / wheel angular velocity [m] (all equal)."""
        js = self.joints.wait_for()
        radii = [SPEED / w for w in wheel_velocities(js)]
        self.assertEqual(len(radii), len(self.drives))
        for r in radii:
            self.assertAlmostEqual(r, radii[0], places=9)
        return radii[0]

    def wheel_rate_over(self, seconds):
        """Mean angular velocity [rad/s] of the wheel joints from their angles over a time window."""
        a = self.joints.wait_for()
        b = self.joints.wait_for(lambda m: (m.header.stamp - a.header.stamp).to_sec() >= seconds, timeout=WAIT)
        dt = (b.header.stamp - a.header.stamp).to_sec()
        return [(q1 - q0) / dt for q0, q1 in zip(wheel_positions(a), wheel_positions(b))]

    def test_wheel_radius_changed_at_run_time(self):
        r0 = self.drives[0]["r_wheel"]
        self.assertAlmostEqual(self.wheel_radius_seen(), r0, places=9)
        r1 = 1.25 * r0  # 0.25 m
        response = self.set_params([DriveParam(i, "r_wheel", r1) for i in range(len(self.drives))])
        self.assertEqual(response.status, len(self.drives), response.message)

        # the wheels now turn at 0.5 / 0.25 = 2.0 rad/s, by velocity and by angle
        msg = self.joints.wait_for(lambda m: all(abs(w - SPEED / r1) < 1e-9 for w in wheel_velocities(m)), timeout=WAIT)
        self.assertIsNotNone(msg, f"joint_states still shows {wheel_velocities(self.joints.latest())}")
        for w in self.wheel_rate_over(0.5):
            self.assertAlmostEqual(w, SPEED / r1, delta=0.02 * SPEED / r1)
        # ... while the rim speeds commanded and the odometry are unchanged
        self.assertTrue(speeds_are(self.commands.wait_for(), SPEED), describe(self.commands.latest()))
        self.assertAlmostEqual(self.odom.wait_for().twist.twist.linear.x, SPEED, places=6)

    def test_invalid_value_refused_and_old_value_kept(self):
        before = self.wheel_radius_seen()
        response = self.set_params([DriveParam(0, "r_wheel", -1.0)])
        self.assertEqual(response.status, 0)
        self.assertIn("motor_drives.drive0.r_wheel", response.message)
        response = self.set_params([DriveParam(1, "node", 7.0)])  # defines the hardware: restart only
        self.assertEqual(response.status, 0)
        self.assertIn("cannot be changed at run time", response.message)
        response = self.set_params([DriveParam(9, "r_wheel", 0.3)])  # no such drive
        self.assertEqual(response.status, 0)
        self.assertAlmostEqual(self.wheel_radius_seen(), before, places=9)
        self.assertTrue(speeds_are(self.commands.wait_for(), SPEED))


if __name__ == "__main__":
    rospy.init_node("drive_params_test")
    rostest.rosrun("thorvald_base", "base_driver_drive_params", DriveParamsTest)
