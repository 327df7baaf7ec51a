#!/usr/bin/env python3
"""base_driver: odometry/base_raw follows a commanded circle.

vx 0.5 m/s with wz 0.5 rad/s is a counter-clockwise circle of radius vx / wz = 1 m about (0, 1)
from the start pose (0, 0, 0). At heading th the robot is at (sin th, 1 - cos th), so every pose lies
1 m from (0, 1) and its heading is atan2(x, 1 - y). The simulated drives ramp up (1.5 m/s^2, 4 rad/s
of steering) for about 0.4 s, which shifts the circle by about 1.5 cm.
"""

import math
import time
import unittest

import rospy
import rostest
from driver_testing import Topic, driver_stream, twist, yaw_of
from nav_msgs.msg import Odometry

VX, WZ = 0.5, 0.5  # [m/s], [rad/s]
RADIUS = VX / WZ  # [m]
DRIVE_TIME = 3.5  # [s]: about 1.6 rad of the circle
RADIUS_TOL = 0.05  # [m]
HEADING_TOL = 0.05  # [rad]


def angle_diff(a, b):
    return math.atan2(math.sin(a - b), math.cos(a - b))


class OdomCircleTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.odom = Topic("odometry/base_raw", Odometry)
        cls.cmd = driver_stream(cls.odom)

    def test_pose_lies_on_the_circle_with_the_tangent_heading(self):
        start = self.odom.latest().pose.pose
        self.assertAlmostEqual(start.position.x, 0.0, places=9)
        self.assertAlmostEqual(start.position.y, 0.0, places=9)
        t0 = time.time()
        self.cmd.send(twist(VX, 0.0, WZ))
        deadline = t0 + 20.0  # wall time is not robot time under load: end on the odometry's own stamps
        first = None
        while time.time() < deadline:
            msgs = self.odom.since(t0)
            moving = [m for m in msgs if m.twist.twist.linear.x > 0.01]
            if moving:
                first = first or moving[0].header.stamp.to_sec()
                if msgs[-1].header.stamp.to_sec() - first > DRIVE_TIME:
                    break
            time.sleep(0.05)
        self.cmd.stop()
        path = [m for m in self.odom.since(t0) if first is not None and m.header.stamp.to_sec() >= first]
        self.assertGreater(len(path), 50, "too few odometry messages while driving")
        end = path[-1].pose.pose
        end_heading = yaw_of(end)
        self.assertGreater(end_heading, 1.2, "the robot did not go far round the circle")

        checked = 0
        for m in path:
            p = m.pose.pose.position
            if math.hypot(p.x, p.y) < 0.2:
                continue  # the heading of a short chord is ill-conditioned; the radius is checked below
            checked += 1
            heading = math.atan2(p.x, RADIUS - p.y)
            self.assertLess(abs(angle_diff(yaw_of(m.pose.pose), heading)), HEADING_TOL)
        self.assertGreater(checked, 30)
        for m in path:
            p = m.pose.pose.position
            r = math.hypot(p.x, p.y - RADIUS)
            self.assertAlmostEqual(r, RADIUS, delta=RADIUS_TOL, msg=f"pose ({p.x:.3f}, {p.y:.3f}) off the circle")

        # once the drives have ramped up, the reported twist is the commanded one
        steady = path[-1].twist.twist
        self.assertAlmostEqual(steady.linear.x, VX, delta=0.01)
        self.assertAlmostEqual(steady.linear.y, 0.0, delta=0.01)
        self.assertAlmostEqual(steady.angular.z, WZ, delta=0.01)
        # the pose covariance grows while moving (it starts equal to the twist covariance)
        self.assertGreater(path[-1].pose.covariance[0], path[0].pose.covariance[0])
        self.assertEqual(path[-1].header.frame_id, "odom")
        self.assertEqual(path[-1].child_frame_id, "base_link")


if __name__ == "__main__":
    rospy.init_node("odom_circle_test")
    rostest.rosrun("thorvald_base", "base_driver_odom_circle", OdomCircleTest)
