#!/usr/bin/env python3
"""base_driver: ~reset_base_odom sets the odometry pose (x, y, yaw) back to zero.

The robot drives an arc (ending with its wheels straight), stops, and is reset: the pose reads zero,
its covariance starts again from the twist covariance, and driving straight ahead afterwards moves
along x only (the heading was reset too, not just the position).
"""

import time
import unittest

import rospy
import rostest
from driver_testing import WAIT, Topic, driver_service, driver_stream, twist, yaw_of
from nav_msgs.msg import Odometry
from std_srvs.srv import Trigger

from thorvald_msgs.msg import BaseState


def at_rest(m):
    return len(m.prop_speed) > 0 and all(abs(v) < 1e-9 for v in m.prop_speed)


class OdomResetTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.odom = Topic("odometry/base_raw", Odometry)
        cls.states = Topic("base_state", BaseState)
        cls.cmd = driver_stream(cls.odom)
        cls.reset = driver_service("reset_base_odom", Trigger)

    def drive_until(self, vx, wz, predicate):
        self.cmd.send(twist(vx, 0.0, wz))
        msg = self.odom.wait_for(predicate, timeout=2 * WAIT)
        self.cmd.stop()
        self.assertIsNotNone(msg, f"odometry did not get there: {self.odom.latest().pose.pose}")
        self.assertIsNotNone(self.states.wait_for(at_rest, timeout=WAIT), "the wheels did not stop")

    def test_reset_zeroes_the_pose(self):
        self.drive_until(0.5, 0.3, lambda m: m.pose.pose.position.x > 0.4 and yaw_of(m.pose.pose) > 0.2)
        # straighten the wheels (they slew at 4 rad/s), so that driving straight after the reset
        # has no steering transient
        self.cmd.send(twist(0.3))
        straight = self.states.wait_for(lambda m: m.steer_pos and all(a == 0.0 for a in m.steer_pos), timeout=WAIT)
        self.assertIsNotNone(straight, "the wheels did not straighten")
        self.cmd.stop()
        self.assertIsNotNone(self.states.wait_for(at_rest, timeout=WAIT), "the wheels did not stop")
        before = self.odom.wait_for()
        self.assertGreater(before.pose.covariance[0], 0.001, "the pose covariance did not grow while moving")

        response = self.reset()
        returned = rospy.Time.now()
        self.assertTrue(response.success)
        # a cycle stamped after the reset returned (base_driver stamps a cycle before it steps): one
        # published before the reset may still be on its way when the service returns
        after = self.odom.wait_for(lambda m: m.header.stamp > returned)
        self.assertIsNotNone(after)
        pose = after.pose.pose
        self.assertEqual((pose.position.x, pose.position.y, yaw_of(pose)), (0.0, 0.0, 0.0))
        self.assertEqual(after.pose.covariance[0], 0.001)  # back to the twist covariance
        self.assertEqual(after.pose.covariance[35], 0.03)
        # still zero a while later: the robot is at rest
        time.sleep(0.3)
        self.assertEqual(self.odom.latest().pose.pose.position.x, 0.0)

        # straight ahead from the reset pose: along x, y stays 0 because the heading is 0 again
        self.drive_until(0.5, 0.0, lambda m: m.pose.pose.position.x > 0.3)
        end = self.odom.latest().pose.pose
        self.assertGreater(end.position.x, 0.3)
        self.assertAlmostEqual(end.position.y, 0.0, places=6)
        self.assertAlmostEqual(yaw_of(end), 0.0, places=6)


if __name__ == "__main__":
    rospy.init_node("odom_reset_test")
    rostest.rosrun("thorvald_base", "base_driver_odom_reset", OdomResetTest)
