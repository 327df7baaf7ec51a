#!/usr/bin/env python3
"""multi_sim.launch: four robots in one world, each in its own namespace, each answering only its
own commands; world -> robot_k/odom sits at each robot's spawn pose."""

import math
import threading
import time
import unittest

import rospy
import rostest
import tf2_ros
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry

from thorvald_testing.topics import Latest, TfPublishers

STARTUP = 90.0  # [s] of wall time for four robots to come up on a busy machine
SPAWN = {"robot_1": (2.5, 2.5), "robot_2": (2.5, -2.5), "robot_3": (-2.5, 2.5), "robot_4": (-2.5, -2.5)}


def position(msg):
    return msg.pose.pose.position.x, msg.pose.pose.position.y


def sim_sleep(seconds):
    """Sleeps simulated seconds (the test node runs on /clock)."""
    end = rospy.get_time() + seconds
    deadline = time.time() + 20 * seconds + 30
    while rospy.get_time() < end and time.time() < deadline and not rospy.is_shutdown():
        time.sleep(0.01)


class MultiSimTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tf_publishers = TfPublishers()
        cls.truth = {r: Latest(f"/{r}/odometry/gazebo", Odometry, queue_size=1) for r in SPAWN}
        cls.pubs = {r: rospy.Publisher(f"/{r}/nav_vel", Twist, queue_size=1) for r in SPAWN}
        deadline = time.time() + STARTUP
        while time.time() < deadline and not all(
            cls.truth[r].get() is not None and cls.pubs[r].get_num_connections() for r in SPAWN
        ):
            time.sleep(0.1)
        missing = [r for r in SPAWN if cls.truth[r].get() is None or not cls.pubs[r].get_num_connections()]
        assert not missing, f"not up: {missing}"
        cls.buffer = tf2_ros.Buffer()
        cls.listener = tf2_ros.TransformListener(cls.buffer)

    def drive(self, moving, seconds=3.0):
        """Commands the robots in moving forward at 0.4 m/s; returns each robot's distance."""
        start = {r: position(self.truth[r].get()) for r in SPAWN}
        stop = threading.Event()

        def stream():
            msg = Twist()
            msg.linear.x = 0.4
            while not stop.is_set():
                for r in moving:
                    self.pubs[r].publish(msg)
                time.sleep(0.05)

        t = threading.Thread(target=stream, daemon=True)
        t.start()
        sim_sleep(seconds)
        stop.set()
        t.join()
        sim_sleep(1.0)  # the mux times out, the robots stop
        return {r: math.dist(start[r], position(self.truth[r].get())) for r in SPAWN}

    def test_each_robot_answers_its_own_commands(self):
        for moving in (("robot_1", "robot_3"), ("robot_2", "robot_4")):
            with self.subTest(moving=moving):
                moved = self.drive(moving)
                for r in SPAWN:
                    if r in moving:
                        self.assertGreater(moved[r], 0.8, f"{r} did not drive: {moved}")
                    else:
                        self.assertLess(moved[r], 0.02, f"{r} moved without a command: {moved}")

    def test_world_to_odom_at_each_spawn_pose(self):
        for r, (x, y) in SPAWN.items():
            t = self.buffer.lookup_transform("world", f"{r}/odom", rospy.Time(0), rospy.Duration(10.0))
            self.assertAlmostEqual(t.transform.translation.x, x, places=6)
            self.assertAlmostEqual(t.transform.translation.y, y, places=6)

    def test_each_robots_links_are_on_tf_from_world(self):
        """robot_state_publisher's work (its node, or fleet_driver's): each robot's wheel links hang
        from its base_link, and the whole chain reaches world (the simulator's odom -> base_link)."""
        for r, (x, y) in SPAWN.items():
            t = self.buffer.lookup_transform("world", f"{r}/wheel0_link", rospy.Time(0), rospy.Duration(10.0))
            base = position(self.truth[r].get())
            wheel = (t.transform.translation.x, t.transform.translation.y)
            self.assertLess(math.dist(wheel, (x + base[0], y + base[1])), 1.5, f"{r}/wheel0_link far from its robot")

    def test_one_publisher_per_transform(self):
        """robot_state_publisher's (model.launch's, or fleet_driver's), the simulator's odom -> base_link
        and the world -> odom transforms: every frame published by one node, on one topic."""
        sim_sleep(2.0)
        children = self.tf_publishers.children()
        for r in SPAWN:
            self.assertTrue({f"{r}/base_link", f"{r}/leg0", f"{r}/odom"} <= children, f"{r}: {sorted(children)}")
        self.assertEqual(self.tf_publishers.shared(), {})


if __name__ == "__main__":
    rospy.init_node("multi_sim_test")
    rostest.rosrun("thorvald_bringup", "multi_sim", MultiSimTest)
