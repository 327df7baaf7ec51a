#!/usr/bin/env python3
"""Two publishers of one robot's odom -> base_link (sim_odom_tf_conflict.test): base_driver with
enable_odom_tf, and the simulator for a robot spawned with spawn_model's arguments.

The simulator must leave the transform to base_driver while it publishes it, say so once with both
names, and publish it again when base_driver is gone; the tree never carries two publishers of it
at once after the warning.
"""

import threading
import time
import unittest

import rosnode
import rospy
import rostest
from rosgraph_msgs.msg import Log
from tf2_msgs.msg import TFMessage

from thorvald_msgs.srv import SpawnRobot, SpawnRobotRequest

STARTUP = 60.0  # [s] wall
CHILD = "r1/base_link"


class Watch:
    """Who published r1/base_link's transform when (simulated time), and the simulator's words."""

    def __init__(self):
        self.lock = threading.Lock()
        self.publishers = []  # (simulated time [s], callerid)
        self.logs = []  # (level, msg) of the simulator
        rospy.Subscriber("/tf", TFMessage, self.on_tf, queue_size=200)
        self.rosout = rospy.Subscriber("/rosout", Log, self.on_log, queue_size=1000)

    def on_tf(self, msg):
        caller = msg._connection_header["callerid"]
        for t in msg.transforms:
            if t.child_frame_id.lstrip("/") == CHILD:
                with self.lock:
                    self.publishers.append((t.header.stamp.to_sec(), caller, t.header.frame_id))

    def on_log(self, msg):
        if msg.name == "/simulator":
            with self.lock:
                self.logs.append((msg.level, msg.msg))

    def since(self, t0):
        with self.lock:
            return [p for p in self.publishers if p[0] >= t0]

    def said(self, words, level=None):
        with self.lock:
            return [m for lv, m in self.logs if words in m and (level is None or lv == level)]


def wait(predicate, what, timeout=STARTUP):
    deadline = time.time() + timeout
    while time.time() < deadline and not rospy.is_shutdown():
        value = predicate()
        if value:
            return value
        time.sleep(0.05)
    raise AssertionError(f"timed out waiting for {what}")


def sim_sleep(seconds):
    end = rospy.get_time() + seconds
    wait(lambda: rospy.get_time() >= end, f"{seconds} s of simulated time")


class OdomTfConflict(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.watch = Watch()
        rospy.wait_for_service("/simulator/spawn_robot", timeout=STARTUP)
        wait(lambda: cls.watch.rosout.get_num_connections() >= 2, "/rosout of the simulator")  # and ours
        wait(lambda: rospy.has_param("/r1/robot_description"), "r1's description")
        spawn = rospy.ServiceProxy("/simulator/spawn_robot", SpawnRobot)
        # what spawn_robot sends for spawn_model's arguments: publish_tf -1, the simulator's default
        xml = rospy.get_param("/r1/robot_description")
        answer = spawn(SpawnRobotRequest(model_name="r1", robot_namespace="/r1/", robot_description=xml, publish_tf=-1))
        assert answer.success, answer.message

    def test_1_one_warning_naming_both_then_one_publisher(self):
        warning = wait(
            lambda: self.watch.said("r1/odom -> r1/base_link on /tf, and so does the simulator"), "the warning"
        )
        self.assertIn("/r1/base_driver", warning[0])
        self.assertIn("/simulator", warning[0])
        t0 = rospy.get_time()
        sim_sleep(3.0)
        seen = self.watch.since(t0)
        self.assertGreater(len(seen), 50)  # 50 Hz of base_driver's over 3 s
        self.assertEqual({caller for _, caller, _ in seen}, {"/r1/base_driver"})
        self.assertEqual({parent for _, _, parent in seen}, {"r1/odom"})
        self.assertEqual(len(self.watch.said("and so does the simulator", Log.WARN)), 1)

    def test_2_the_simulator_takes_it_back_when_base_driver_is_gone(self):
        rosnode.kill_nodes(["/r1/base_driver"])
        wait(lambda: self.watch.said("stopped publishing r1/odom -> r1/base_link"), "the simulator to take it back")
        t0 = rospy.get_time()
        sim_sleep(2.0)
        seen = self.watch.since(t0)
        self.assertGreater(len(seen), 20)
        self.assertEqual({caller for _, caller, _ in seen}, {"/simulator"})
        self.assertEqual(len(self.watch.said("and so does the simulator", Log.WARN)), 1)  # still said once


if __name__ == "__main__":
    rospy.init_node("sim_odom_tf_conflict")
    rostest.rosrun("thorvald_sim", "sim_odom_tf_conflict", OdomTfConflict)
