#!/usr/bin/env python3
"""base_driver beside robot_state_publisher and a simulator's odometry (model_passthrough.test).

1. joint_states names only the joints the description moves: robot_state_publisher logs no
   "was received but not found in URDF" warning for the differential robot (its type-1 drives have
   fixed steering joints), and its transforms reach the wheels under the older tf_prefix convention
   ("diff" gives diff/base_link).
2. passthrough_gazebo_odometry: once odometry/gazebo arrives, odometry/base_raw is that message with
   the frame set to odom_frame_id, and base_driver's own odometry stops.
"""

import threading
import time
import unittest

import rospy
import rostest
import tf2_ros
from driver_testing import STARTUP_TIMEOUT, WAIT, CommandStream, Topic, twist
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Log
from sensor_msgs.msg import JointState

NOT_IN_URDF = "was received but not found in URDF"
SWITCHING = "Switching to using Gazebo odometry"
WATCH = 3.0  # [s] of joint_states watched for robot_state_publisher's warning


class RosoutWatch:
    """Every /rosout message, to find warnings by node and text."""

    def __init__(self):
        self._lock = threading.Lock()
        self.logs = []
        self.sub = rospy.Subscriber("/rosout", Log, self._on_log, queue_size=1000)

    def _on_log(self, msg):
        with self._lock:
            self.logs.append(msg)

    def matching(self, text, node=""):
        with self._lock:
            return [m for m in self.logs if text in m.msg and node in m.name]


class ModelPassthroughTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.rosout = RosoutWatch()
        cls.joints = Topic("/diff/base_driver/joint_states", JointState)
        cls.odom = Topic("/diff/odometry/base_raw", Odometry)
        cls.buffer = tf2_ros.Buffer()
        cls.listener = tf2_ros.TransformListener(cls.buffer)
        cls.cmd = CommandStream("/diff/twist_mux/cmd_vel")
        assert cls.cmd.wait_for_subscriber(), "base_driver did not subscribe to twist_mux/cmd_vel"
        assert cls.joints.wait_for(timeout=STARTUP_TIMEOUT, since=0), "no joint_states"

    @classmethod
    def tearDownClass(cls):
        cls.cmd.stop()

    def test_1_robot_state_publisher_takes_every_joint_state(self):
        self.cmd.send(twist(0.3, 0.0, 0.2))  # moving wheels: joint_states change every cycle
        start = time.time()
        wheel = self.buffer.lookup_transform("diff/base_link", "diff/wheel0_link", rospy.Time(0), rospy.Duration(WAIT))
        self.assertEqual(wheel.child_frame_id, "diff/wheel0_link")
        received = self.joints.wait_for(lambda m: m.velocity and abs(m.velocity[0]) > 0.1, timeout=WAIT)
        self.assertIsNotNone(received, "the wheels did not turn")
        self.assertEqual(list(received.name), ["diff/wheel0", "diff/wheel1"])
        while time.time() < start + WATCH:
            time.sleep(0.05)
        warnings = self.rosout.matching(NOT_IN_URDF)
        self.assertEqual([], [f"{m.name}: {m.msg}" for m in warnings])
        self.assertGreater(len(self.joints.since(start)), 20)

    def test_2_gazebo_odometry_passes_through(self):
        own = self.odom.wait_for(timeout=WAIT, since=0)
        self.assertIsNotNone(own, "no odometry before the simulator's")
        self.assertEqual((own.header.frame_id, own.child_frame_id), ("diff/odom", "diff/base_link"))
        gazebo = rospy.Publisher("/diff/odometry/gazebo", Odometry, queue_size=10)
        deadline = time.time() + STARTUP_TIMEOUT
        while not gazebo.get_num_connections() and time.time() < deadline:
            time.sleep(0.05)
        self.assertTrue(gazebo.get_num_connections(), "base_driver did not subscribe to odometry/gazebo")
        sent = []
        for k in range(20):
            msg = Odometry()
            msg.header.stamp = rospy.Time.now()
            msg.header.frame_id = "diff/odom_in_the_simulator"
            msg.child_frame_id = "diff/base_link"
            msg.pose.pose.position.x = 100.0 + k  # far from anything base_driver computes
            msg.pose.pose.orientation.w = 1.0
            msg.twist.twist.linear.x = 0.3
            sent.append(msg.pose.pose.position.x)
            if k == 0:
                first_sent = time.time()
            gazebo.publish(msg)
            time.sleep(0.05)
        last = self.odom.wait_for(lambda m: m.pose.pose.position.x == sent[-1], timeout=WAIT, since=first_sent)
        self.assertIsNotNone(last, "odometry/base_raw never carried the simulator's last odometry")
        time.sleep(0.5)  # base_driver's own odometry would appear at 50 Hz meanwhile
        after = self.odom.since(self.odom_switch_time(sent[0], first_sent))
        self.assertEqual([m.pose.pose.position.x for m in after], sent)
        self.assertTrue(all(m.header.frame_id == "diff/odom" for m in after))
        self.assertEqual(len(self.rosout.matching(SWITCHING, "base_driver")), 1)

    def odom_switch_time(self, first_x, since):
        """The wall time just before base_raw carried the simulator's first message."""
        first = self.odom.wait_for(lambda m: m.pose.pose.position.x == first_x, timeout=WAIT, since=since)
        self.assertIsNotNone(first, "the simulator's first odometry did not pass through")
        with self.odom._lock:
            stamps = [t for t, m in self.odom._messages if m is first]
        return stamps[0] - 1e-6


if __name__ == "__main__":
    rospy.init_node("model_passthrough_test")
    rostest.rosrun("thorvald_base", "base_driver_model_passthrough", ModelPassthroughTest)
