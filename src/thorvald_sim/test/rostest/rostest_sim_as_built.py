#!/usr/bin/env python3
"""As-built robots: base_driver's odometry, on the configuration, against the built robot's ground truth.

- Every tyre 1 % larger: the wheels turn as commanded (base_driver converts with the configured
  0.2 m), the ground passes 1 % faster than odometry counts: odometry reads 1 % short, 1/1.01 of
  ground truth's distance on a straight drive.
- Every steering module homed 0.02 rad to the left: commanded straight, each wheel stands at 0.02 rad,
  so the robot crabs 0.02 rad to the left of its heading without turning, while odometry (reading
  0 on every module) says straight ahead.
- field:3 with encoders: the drive states come in whole steering counts (str_enc_ppr 1024 x 4 x gear
  42.857 per turn of the module) and whole motor rpm (one rpm: 2 pi 0.2 / 60 / 42 m/s at the rim).
"""

import math
import unittest

import rospy
import rostest
from sim_testing import Commander, Latest, delta, planar, sim_sleep

from thorvald_msgs.msg import BaseState

ROBOTS = ("large", "offset", "field")


class SimAsBuiltTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.truth = {r: Latest(f"/{r}/odometry/gazebo") for r in ROBOTS}
        cls.odometry = {r: Latest(f"/{r}/odometry/base_raw") for r in ROBOTS}
        cls.nav = {r: Commander(f"/{r}/nav_vel") for r in ROBOTS}
        cls.states = Latest("/field/drive_states", BaseState)
        for r in ROBOTS:
            cls.truth[r].wait()
            cls.odometry[r].wait()
            cls.nav[r].wait_for_subscriber()
        sim_sleep(1.0)

    def straight(self, robot, seconds=8.0, speed=1.0):
        """Ground truth's and odometry's motion (length, direction, turn) over a straight drive at speed
        [m/s] for seconds, both sampled at rest before and after."""
        self.nav[robot].send()
        sim_sleep(1.0)
        truth0, odom0 = planar(self.truth[robot].get()), planar(self.odometry[robot].get())
        self.nav[robot].send(speed)
        sim_sleep(seconds)
        self.nav[robot].send()
        sim_sleep(2.0)
        truth1, odom1 = planar(self.truth[robot].get()), planar(self.odometry[robot].get())
        return delta(truth0, truth1), delta(odom0, odom1)

    def test_tyres_one_percent_larger_make_odometry_read_one_percent_short(self):
        truth, odom = self.straight("large")
        rospy.loginfo("large: ground truth %.4f m, odometry %.4f m", truth[0], odom[0])
        self.assertGreater(truth[0], 7.0)
        # 1 % short, to 0.1 % (in lockstep: 0.99010 here; off it, base_driver's cycles on a busy
        # machine sampled the measured drives late enough to read 0.9935)
        self.assertAlmostEqual(odom[0] / truth[0], 1.0 / 1.01, delta=0.001)

    def test_a_steering_offset_crabs_a_commanded_straight_line(self):
        truth, odom = self.straight("offset")
        rospy.loginfo(
            "offset: ground truth %.4f m at %.5f rad (turned %.5f), odometry %.4f m at %.5f rad",
            truth[0], truth[1], truth[2], odom[0], odom[1],
        )  # fmt: skip
        self.assertGreater(truth[0], 7.0)
        self.assertAlmostEqual(truth[1], 0.02, delta=0.003)  # the path 0.02 rad left of the heading
        self.assertLess(abs(truth[2]), 0.003)  # no turn: every wheel at the same angle
        self.assertLess(abs(odom[1]), 0.001)  # odometry: straight ahead
        # the sideways distance the offset gives over the drive: length * sin(0.02)
        self.assertAlmostEqual(truth[0] * math.sin(truth[1]), truth[0] * math.sin(0.02), delta=0.03)

    def test_the_encoders_count_whole_counts_and_whole_rpm(self):
        self.nav["field"].send(0.37, 0.0, 0.05)
        sim_sleep(3.0)
        msg = self.states.get()
        self.nav["field"].send()
        per_radian = 1024 * 4 * 42.8571429 / (2 * math.pi)
        rpm = 2 * math.pi * 0.2 / 60.0 / 42.0  # [m/s] of one motor rpm
        for angle, speed in zip(msg.steer_pos, msg.prop_speed):
            self.assertAlmostEqual(angle * per_radian, round(angle * per_radian), delta=1e-4)
            self.assertAlmostEqual(speed / rpm, round(speed / rpm), delta=1e-4)
        self.assertTrue(any(abs(a) > 0.01 for a in msg.steer_pos))  # turning: the modules steer
        self.assertTrue(all(abs(s) > 0.2 for s in msg.prop_speed))  # moving


if __name__ == "__main__":
    rospy.init_node("sim_as_built_test")
    rostest.rosrun("thorvald_sim", "sim_as_built", SimAsBuiltTest)
