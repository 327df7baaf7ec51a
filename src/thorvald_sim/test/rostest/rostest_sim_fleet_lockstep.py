#!/usr/bin/env python3
"""Lockstep through the simulator's fleet topics (sim_fleet_lockstep.test): two robots driven by one
fleet_driver, the simulator and both base_drivers in lockstep. fleet_driver sends each robot's answer
on ~fleet/drive_commands in a message of its own at once, and the simulator counts an entry as that
robot's answer: both robots join lockstep (said on /rosout), simulated time goes on, r1 drives the
0.4 m/s it is commanded for 2 simulated seconds and r2, never commanded, stays put."""

import math
import time
import unittest

import rosgraph
import rospy
import rostest
from rosgraph_msgs.msg import Log
from sim_testing import Commander, Latest, drive

SPEED = 0.4  # [m/s]
SECONDS = 2.0  # [s] simulated
LOCKSTEP_WAIT = 120.0  # [s] wall, for both robots to join lockstep on a busy machine


class SimFleetLockstepTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.said = []
        rospy.Subscriber("/rosout", Log, cls.said.append, queue_size=1000)
        cls.truth = {r: Latest(f"/{r}/odometry/gazebo") for r in ("r1", "r2")}
        cls.odometry = {r: Latest(f"/{r}/odometry/base_raw") for r in ("r1", "r2")}
        for latest in (*cls.truth.values(), *cls.odometry.values()):
            latest.wait()
        deadline = time.time() + LOCKSTEP_WAIT
        while time.time() < deadline and len(cls.joined()) < 2:
            time.sleep(0.1)
        commander = Commander("/r1/nav_vel")
        commander.wait_for_subscriber()
        r2_before = cls.truth["r2"].get().pose.pose.position
        cls.r1_motion, cls.r1_odometry = drive(
            commander, (SPEED, 0.0, 0.0), SECONDS, cls.truth["r1"], cls.odometry["r1"]
        )
        r2_after = cls.truth["r2"].get().pose.pose.position
        cls.r2_moved = math.hypot(r2_after.x - r2_before.x, r2_after.y - r2_before.y)
        graph = rosgraph.Master("/sim_fleet_lockstep_test").getSystemState()
        cls.publishers, cls.subscribers = dict(graph[0]), dict(graph[1])

    @classmethod
    def joined(cls):
        return {
            r
            for r in ("r1", "r2")
            for m in cls.said
            if m.name == "/simulator" and m.msg == f"simulator: {r} in lockstep"
        }

    def test_both_robots_join_lockstep_through_the_fleet_topics(self):
        self.assertEqual(self.joined(), {"r1", "r2"})
        let_go = [m.msg for m in self.said if m.name == "/simulator" and "did not answer" in m.msg]
        self.assertEqual(let_go, [])  # every answer came, each in its own message
        self.assertEqual(self.publishers.get("/simulator/fleet/drive_commands"), ["/fleet_driver"])
        self.assertEqual(self.subscribers.get("/simulator/fleet/drive_states"), ["/fleet_driver"])

    def test_the_commanded_robot_drives_its_twist_and_the_other_stays_put(self):
        length, direction, _ = self.r1_motion
        rospy.loginfo("r1 drove %.3f m (commanded %.1f m/s for %.1f s); r2 moved %.4f m", length, SPEED, SECONDS,
                      self.r2_moved)  # fmt: skip
        self.assertAlmostEqual(length, SPEED * SECONDS, delta=0.15 * SPEED * SECONDS)
        self.assertLess(abs(direction), 0.05)
        self.assertLess(self.r2_moved, 0.01)


if __name__ == "__main__":
    rospy.init_node("sim_fleet_lockstep_test")
    rostest.rosrun("thorvald_sim", "sim_fleet_lockstep", SimFleetLockstepTest)
