#!/usr/bin/env python3
"""Every example robot brought up (one base_driver each, namespace and tf_prefix "<name>/") and
driven forward at 0.3 m/s, all at once: each one's odometry moves forward and its joint names carry
its prefix.

Distances are measured on each robot's own odometry stamps, so a loaded machine that runs the ten
drivers late does not shorten the drive: after 1.5 s of its time at 0.3 m/s (ramping up at its
prp_sim_a first), every robot is more than 0.2 m ahead and still on the x axis.
"""

import os
import time
import unittest

import rospy
import rostest
from driver_testing import CommandStream, Topic, drives_from_params, twist, yaw_of
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState

STARTUP_TIMEOUT = 120.0  # [s]: ten Python nodes starting together on a shared machine
VX = 0.3  # [m/s]
DRIVE_TIME = 1.5  # [s] of each robot's own time
MIN_DISTANCE = 0.2  # [m]


class AllRobotsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.robots = rospy.get_param("~robots")
        cls.odom = {r: Topic(f"/{r}/odometry/base_raw", Odometry) for r in cls.robots}
        cls.joints = {r: Topic(f"/{r}/base_driver/joint_states", JointState) for r in cls.robots}
        cls.cmd = {r: CommandStream(f"/{r}/twist_mux/cmd_vel") for r in cls.robots}
        deadline = time.time() + STARTUP_TIMEOUT
        for r in cls.robots:
            assert cls.cmd[r].wait_for_subscriber(deadline - time.time()), r + ": base_driver not subscribed"
            assert cls.odom[r].wait_for(timeout=deadline - time.time(), since=0), r + ": no odometry"
            assert cls.joints[r].wait_for(timeout=deadline - time.time(), since=0), r + ": no joint_states"
        cls.start = {}
        for r in cls.robots:
            cls.start[r] = cls.odom[r].latest()
            cls.cmd[r].send(twist(VX))
        # poll until every robot has driven DRIVE_TIME of its own time since its command went out
        sent = time.time()
        cls.end = {}
        deadline = sent + 30.0
        while time.time() < deadline and len(cls.end) < len(cls.robots):
            for r in cls.robots:
                if r in cls.end:
                    continue
                msgs = cls.odom[r].since(sent)
                if msgs and (msgs[-1].header.stamp - msgs[0].header.stamp).to_sec() >= DRIVE_TIME:
                    cls.end[r] = msgs[-1]
            time.sleep(0.05)
        for r in cls.robots:
            cls.cmd[r].stop()

    def test_every_example_robot_is_in_the_launch(self):
        config = rospy.get_param("~config")
        examples = sorted(d for d in os.listdir(config) if os.path.isfile(os.path.join(config, d, d + ".yaml")))
        self.assertEqual(sorted(self.robots), examples)

    def test_every_robot_drives_forward(self):
        for r in self.robots:
            with self.subTest(robot=r):
                self.assertIn(r, self.end, f"{r}: odometry did not run for {DRIVE_TIME:.1f} s")
                start, end = self.start[r].pose.pose, self.end[r].pose.pose
                self.assertGreater(end.position.x - start.position.x, MIN_DISTANCE)
                self.assertAlmostEqual(end.position.y, start.position.y, delta=0.02)
                self.assertAlmostEqual(yaw_of(end), yaw_of(start), delta=0.02)
                self.assertAlmostEqual(self.end[r].twist.twist.linear.x, VX, delta=0.01)
                self.assertEqual(self.end[r].child_frame_id, r + "/base_link")

    def test_joint_names_carry_the_prefix(self):
        for r in self.robots:
            with self.subTest(robot=r):
                drives = drives_from_params(f"/{r}/base_driver")
                expected = []
                for k, d in enumerate(drives):
                    # a type-1 drive's steering joint is fixed in the description: not in joint_states
                    if d.get("type", 0) == 0:
                        expected.append(r + "/" + (d.get("steering_name") or f"steering{k}"))
                    expected.append(r + "/" + (d.get("wheel_name") or f"wheel{k}"))
                js = self.joints[r].latest()
                self.assertEqual(list(js.name), expected)
                self.assertEqual(len(js.position), len(expected))
                self.assertEqual(len(js.velocity), len(expected))


if __name__ == "__main__":
    rospy.init_node("all_robots_test")
    rostest.rosrun("thorvald_base", "base_driver_all_robots", AllRobotsTest)
