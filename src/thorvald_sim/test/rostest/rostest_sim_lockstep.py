#!/usr/bin/env python3
"""Lockstep: two identical robots, commanded alike at the same simulated instants, move alike to the
millimetre, with a busy core beside them.

Without lockstep each robot's base_driver takes its commands and drive states when the machine lets
it, some cycles a clock tick late, so two identical robots (or two runs of one) part by centimetres
over a few metres; in lockstep every drive-state instant is answered before the world moves on.
The commands are sent once each, while the simulation is paused (they reach base_driver through
twist_mux in wall time, which is outside the lockstep), so both robots get them at the same simulated
instant.
"""

import math
import subprocess
import sys
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import Twist
from sim_testing import Latest, planar, sim_sleep
from std_srvs.srv import Empty

from thorvald_msgs.msg import BaseState

ROBOTS = ("a", "b")  # spawned 6 m apart; ground truth is in each one's odom frame, at its spawn pose


class Once:
    """Sends a Twist once (base_driver keeps it: its command timeout is long in this test)."""

    def __init__(self, topic):
        self.pub = rospy.Publisher(topic, Twist, queue_size=10)

    def send(self, vx=0.0, vy=0.0, wz=0.0):
        msg = Twist()
        msg.linear.x, msg.linear.y, msg.angular.z = vx, vy, wz
        self.pub.publish(msg)


class SimLockstepTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.truth = {r: Latest(f"/{r}/odometry/gazebo") for r in ROBOTS}
        cls.odometry = {r: Latest(f"/{r}/odometry/base_raw") for r in ROBOTS}
        cls.commands = {r: Latest(f"/{r}/drive_commands", BaseState) for r in ROBOTS}
        cls.nav = {r: Once(f"/{r}/nav_vel") for r in ROBOTS}
        for r in ROBOTS:
            cls.truth[r].wait()
            cls.odometry[r].wait()
            cls.commands[r].wait()  # base_driver answers: in lockstep
            wait_for_subscriber(cls.nav[r].pub)
        cls.pause = rospy.ServiceProxy("/simulator/pause", Empty)
        cls.unpause = rospy.ServiceProxy("/simulator/unpause", Empty)
        sim_sleep(1.0)

    def command_while_paused(self, twist):
        """Both robots' commands changed while the world stands still, given a wall second to arrive."""
        self.pause()
        # the instant the world stopped at is being answered: the new command must come after that
        # answer, not race it (the drivers answer in milliseconds)
        time.sleep(0.3)
        for r in ROBOTS:
            self.nav[r].send(*twist)
        time.sleep(1.0)
        self.unpause()

    @staticmethod
    def poses(series):
        """(x, y, yaw) of each robot: from its spawn pose (ground truth) or its odometry's start."""
        return {r: planar(series[r].get()) for r in ROBOTS}

    def test_two_identical_robots_move_alike_to_the_millimetre_beside_a_busy_core(self):
        burner = subprocess.Popen([sys.executable, "-c", "while True: pass"])  # a busy core beside the run
        try:
            self.command_while_paused((0.8, 0.0, 0.3))  # an arc
            sim_sleep(4.0)
            self.command_while_paused((0.0, 0.5, 0.0))  # a crab: every module turns 90 degrees
            sim_sleep(3.0)
            self.command_while_paused((0.0, 0.0, 0.0))
            sim_sleep(2.0)
            self.pause()
            time.sleep(0.5)  # the last messages of the stopped world arrive
            truth, odometry = self.poses(self.truth), self.poses(self.odometry)
            self.unpause()
        finally:
            burner.kill()
        rospy.loginfo("lockstep: ground truth a %s b %s; odometry a %s b %s", truth["a"], truth["b"],
                      odometry["a"], odometry["b"])  # fmt: skip
        moved = math.hypot(truth["a"][0], truth["a"][1])
        self.assertGreater(moved, 1.5)  # it drove: about 2.2 m from the spawn, after the arc and the crab
        for series in (truth, odometry):
            a, b = series["a"], series["b"]
            self.assertLess(math.hypot(a[0] - b[0], a[1] - b[1]), 0.001)
            self.assertLess(abs(math.remainder(a[2] - b[2], 2 * math.pi)), 0.001)


def wait_for_subscriber(pub, timeout=120.0):
    deadline = time.time() + timeout
    while time.time() < deadline and pub.get_num_connections() == 0:
        time.sleep(0.05)
    assert pub.get_num_connections() > 0, f"nobody subscribes to {pub.resolved_name}"


if __name__ == "__main__":
    rospy.init_node("sim_lockstep_test")
    rostest.rosrun("thorvald_sim", "sim_lockstep", SimLockstepTest)
