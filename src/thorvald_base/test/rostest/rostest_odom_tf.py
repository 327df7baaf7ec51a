#!/usr/bin/env python3
"""base_driver: odom -> base_link on /tf when enable_odom_tf is true, nothing when it is false.

robot_on and robot_off are the same robot with tf_prefix robot_on/ and robot_off/ and odom frames
robot_on/odom and robot_off/odom; both drive forward while /tf is recorded.
"""

import time
import unittest

import rospy
import rostest
import tf2_ros
from driver_testing import STARTUP_TIMEOUT, WAIT, CommandStream, Topic, twist
from nav_msgs.msg import Odometry
from tf2_msgs.msg import TFMessage

WINDOW = 1.5  # [s] of /tf recorded while both robots drive


class OdomTfTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.buffer = tf2_ros.Buffer()
        cls.listener = tf2_ros.TransformListener(cls.buffer)
        cls.tf = Topic("/tf", TFMessage, queue_size=1000)
        cls.odom = {r: Topic(f"/{r}/odometry/base_raw", Odometry) for r in ("robot_on", "robot_off")}
        cls.cmd = {r: CommandStream(f"/{r}/twist_mux/cmd_vel") for r in ("robot_on", "robot_off")}
        for r in ("robot_on", "robot_off"):
            assert cls.cmd[r].wait_for_subscriber(), r + "/base_driver did not subscribe to twist_mux/cmd_vel"
            assert cls.odom[r].wait_for(timeout=STARTUP_TIMEOUT, since=0), "no odometry from " + r
        # both robots drive forward, so a broadcast transform would be a moving one
        start = time.time()
        for r in ("robot_on", "robot_off"):
            cls.cmd[r].send(twist(0.3))
        for r in ("robot_on", "robot_off"):
            assert cls.odom[r].wait_for(lambda m: m.pose.pose.position.x > 0.05, timeout=2 * WAIT), r + " did not move"
        time.sleep(WINDOW)
        cls.window = (start, time.time())

    @classmethod
    def tearDownClass(cls):
        for c in cls.cmd.values():
            c.stop()

    def test_odometry_frames(self):
        for r in ("robot_on", "robot_off"):
            m = self.odom[r].latest()
            self.assertEqual(m.header.frame_id, r + "/odom")
            self.assertEqual(m.child_frame_id, r + "/base_link")

    def test_transform_broadcast_when_enabled(self):
        odom = self.odom["robot_on"].latest()
        # the transform at the odometry's own stamp is the odometry's pose
        t = self.buffer.lookup_transform("robot_on/odom", "robot_on/base_link", odom.header.stamp, rospy.Duration(WAIT))
        self.assertEqual(t.header.frame_id, "robot_on/odom")
        self.assertEqual(t.child_frame_id, "robot_on/base_link")
        self.assertGreater(t.transform.translation.x, 0.05)
        self.assertAlmostEqual(t.transform.translation.x, odom.pose.pose.position.x, places=9)
        self.assertAlmostEqual(t.transform.translation.y, odom.pose.pose.position.y, places=9)
        self.assertAlmostEqual(t.transform.rotation.z, odom.pose.pose.orientation.z, places=9)
        self.assertAlmostEqual(t.transform.rotation.w, odom.pose.pose.orientation.w, places=9)

    def test_no_transform_when_disabled(self):
        start = self.window[0]
        recorded = [t for m in self.tf.since(start) for t in m.transforms]
        # /tf was received in the window (robot_on's transforms), so silence from robot_off means something
        self.assertTrue(any(t.child_frame_id == "robot_on/base_link" for t in recorded), "no /tf received at all")
        self.assertGreater(len(self.odom["robot_off"].since(start)), 20, "robot_off was not running")
        for t in recorded:
            self.assertFalse(t.header.frame_id.startswith("robot_off/"), t.header.frame_id)
            self.assertFalse(t.child_frame_id.startswith("robot_off/"), t.child_frame_id)
        self.assertFalse(self.buffer.can_transform("robot_off/odom", "robot_off/base_link", rospy.Time(0)))


if __name__ == "__main__":
    rospy.init_node("odom_tf_test")
    rostest.rosrun("thorvald_base", "base_driver_odom_tf", OdomTfTest)
