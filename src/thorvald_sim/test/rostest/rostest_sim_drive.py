#!/usr/bin/env python3
"""The Figure 7 robot in the simulator: ground truth (odometry/gazebo) against the motion that
base_driver's drive states describe (its odometry of base_state).

Forward 0.5 m/s for 4 s: distance within 2 %. Spin in place at 0.5 rad/s for 4 s: turn within 3 %,
centre within 0.05 m. A 45 degree crab: direction within 2 degrees, distance within 2 %. Run in
sequence on one robot; each compares the motion from just before the command to after the robot
has stopped. Where the two differ most is the start of a command that slews the steering while
the wheels already drive (base_driver's drives, as the original's): odometry's model of wheels
that disagree and the physics of them resolve differently.
"""

import math
import unittest

import rospy
import rostest
from sim_testing import Commander, Latest, drive, sim_sleep


class SimDriveTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.truth = Latest("odometry/gazebo")
        cls.odometry = Latest("odometry/base_raw")
        cls.nav = Commander("nav_vel")
        cls.truth.wait()
        cls.odometry.wait()
        cls.nav.wait_for_subscriber()
        sim_sleep(1.0)  # settled on its wheels

    def test_1_forward(self):
        truth, odom = drive(self.nav, (0.5, 0.0, 0.0), 4.0, self.truth, self.odometry)
        rospy.loginfo("forward: ground truth %.4f m, odometry %.4f m", truth[0], odom[0])
        # it drove (0.5 m/s for 4 s, ramping at 1.5 m/s^2: 1.92 m, less the command's late start on a busy machine)
        self.assertGreater(odom[0], 1.5)
        self.assertAlmostEqual(truth[0], odom[0], delta=0.02 * odom[0])
        self.assertAlmostEqual(truth[1], 0.0, delta=0.02)  # straight ahead
        self.assertAlmostEqual(truth[2], 0.0, delta=0.02)

    def test_2_spin_in_place(self):
        truth, odom = drive(self.nav, (0.0, 0.0, 0.5), 4.0, self.truth, self.odometry, settle=1.5)
        rospy.loginfo(
            "spin: ground truth turned %.4f rad, moved %.4f m; odometry %.4f rad", truth[2], truth[0], odom[2]
        )
        self.assertGreater(odom[2], 1.5)  # it spun: 0.5 rad/s for 4 s, less the slew and a late start
        self.assertAlmostEqual(truth[2], odom[2], delta=0.03 * odom[2])
        self.assertLess(truth[0], 0.05, "the centre of the spin moved")

    def test_3_crab_45_degrees(self):
        v = 0.5 / math.sqrt(2.0)
        truth, odom = drive(self.nav, (v, v, 0.0), 4.0, self.truth, self.odometry, settle=1.5)
        rospy.loginfo("crab: ground truth %.4f m at %.4f rad; odometry %.4f m at %.4f rad", *truth[:2], *odom[:2])
        self.assertAlmostEqual(truth[1], math.pi / 4, delta=math.radians(2))
        self.assertAlmostEqual(truth[0], odom[0], delta=0.02 * odom[0])
        self.assertAlmostEqual(truth[2], 0.0, delta=0.02)


if __name__ == "__main__":
    rospy.init_node("sim_drive_test")
    rostest.rosrun("thorvald_sim", "sim_drive", SimDriveTest)
