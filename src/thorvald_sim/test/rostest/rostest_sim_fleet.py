#!/usr/bin/env python3
"""Four different robots in one world, each commanded in its own namespace (the paper's Figure 11).

The differential and the rear-wheel one-wheel-drive robots drive arcs of vx 0.4 m/s, wz 0.3 rad/s;
the 9WD9WS robot drives straight at 0.5 m/s; the standard robot is not commanded and stays put.
Meanwhile a broken description is spawned and refused, and the others keep moving. /clock advances
and base_driver's odometry is stamped with it.
"""

import math
import unittest

import rospy
import rostest
from rosgraph_msgs.msg import Clock
from sim_testing import Commander, Latest, delta, planar, sim_sleep

from thorvald_msgs.srv import SpawnRobot

VX, WZ, SECONDS = 0.4, 0.3, 6.0


class SimFleetTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.robots = ("diff", "rwd", "nine", "still")
        cls.truth = {r: Latest(f"/{r}/odometry/gazebo") for r in cls.robots}
        cls.odometry = {r: Latest(f"/{r}/odometry/base_raw") for r in cls.robots}
        cls.nav = {r: Commander(f"/{r}/nav_vel") for r in cls.robots}
        cls.clock = Latest("/clock", Clock)
        for r in cls.robots:
            cls.truth[r].wait()
            cls.odometry[r].wait()
            cls.nav[r].wait_for_subscriber()
        sim_sleep(1.0)
        cls.start = {r: (planar(cls.truth[r].get()), planar(cls.odometry[r].get())) for r in cls.robots}
        cls.clock_start = cls.clock.get().clock.to_sec()
        for r in ("diff", "rwd"):
            cls.nav[r].send(VX, 0.0, WZ)
        cls.nav["nine"].send(0.5)
        sim_sleep(SECONDS / 2)
        spawn = rospy.ServiceProxy("/simulator/spawn_robot", SpawnRobot)
        cls.refused = spawn(
            "broken", "/broken", "<robot name='broken'><link name='a'/><joint", 9.0, 9.0, 0.0, 0.0, "", -1, ""
        )
        cls.mid = {r: planar(cls.truth[r].get()) for r in cls.robots}
        cls.mid_twist = {r: cls.truth[r].get().twist.twist for r in cls.robots}
        sim_sleep(SECONDS / 2)
        for r in ("diff", "rwd", "nine"):
            cls.nav[r].send()
        sim_sleep(1.5)
        cls.end = {r: (planar(cls.truth[r].get()), planar(cls.odometry[r].get())) for r in cls.robots}
        cls.stamp_lag = rospy.get_time() - cls.odometry["nine"].get().header.stamp.to_sec()
        cls.clock_end = cls.clock.get().clock.to_sec()

    def motion(self, robot):
        (truth0, odom0), (truth1, odom1) = self.start[robot], self.end[robot]
        return delta(truth0, truth1), delta(odom0, odom1)

    def check_arc(self, robot, radius):
        """The turn and the path that base_driver's drive states describe, and, mid-arc, base_link
        turning about the centre of rotation the command gives, radius [m] away."""
        truth, odom = self.motion(robot)
        t = self.mid_twist[robot]
        measured = math.hypot(t.linear.x, t.linear.y) / t.angular.z
        rospy.loginfo(
            "%s arc: ground truth %.4f m chord, %.4f rad, radius %.4f m; odometry %.4f m chord, %.4f rad",
            robot,
            truth[0],
            truth[2],
            measured,
            odom[0],
            odom[2],
        )
        self.assertGreater(odom[2], WZ * SECONDS * 0.6)  # it turned (a busy machine may start it late)
        self.assertAlmostEqual(truth[2], odom[2], delta=0.03 * abs(odom[2]))
        self.assertAlmostEqual(truth[0], odom[0], delta=0.03 * odom[0])
        self.assertAlmostEqual(measured, radius, delta=0.03 * radius)

    def test_the_differential_robot_follows_its_arc(self):
        # axle through base_link: base_link turns about (0, vx / wz)
        self.check_arc("diff", VX / WZ)

    def test_the_one_wheel_drive_robot_follows_its_arc(self):
        # support wheels' axle at x = 0.45: the centre of rotation (0.45, vx / wz), base_link at the
        # distance to it
        self.check_arc("rwd", math.hypot(0.45, VX / WZ))

    def test_the_nine_wheel_robot_drives_straight(self):
        truth, odom = self.motion("nine")
        rospy.loginfo("nine straight: ground truth %.4f m, odometry %.4f m", truth[0], odom[0])
        self.assertGreater(odom[0], 0.5 * SECONDS * 0.6)  # it drove
        self.assertAlmostEqual(truth[0], odom[0], delta=0.02 * odom[0])
        self.assertAlmostEqual(truth[1], 0.0, delta=0.02)

    def test_the_uncommanded_robot_stays_put(self):
        truth, _ = self.motion("still")
        rospy.loginfo("still: moved %.5f m, turned %.5f rad", truth[0], truth[2])
        self.assertLess(truth[0], 0.01)
        self.assertLess(abs(truth[2]), 0.01)

    def test_a_broken_description_is_refused_and_the_others_keep_moving(self):
        self.assertFalse(self.refused.success)
        self.assertIn("broken: the robot description is not valid XML", self.refused.message)
        for r in ("diff", "rwd", "nine"):
            moved = delta(self.mid[r], self.end[r][0])[0]
            self.assertGreater(moved, 0.5, f"{r} stopped after the refused spawn")

    def test_clock_advances_and_odometry_follows_it(self):
        self.assertGreater(self.clock_end - self.clock_start, SECONDS)
        self.assertLess(abs(self.stamp_lag), 0.1)


if __name__ == "__main__":
    rospy.init_node("sim_fleet_test")
    rostest.rosrun("thorvald_sim", "sim_fleet", SimFleetTest)
