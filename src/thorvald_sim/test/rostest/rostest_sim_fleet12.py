#!/usr/bin/env python3
"""Twelve robots in one world on simulated time, each commanded on its own (issue 24).

r0 .. r5 run base_driver and twist_mux processes of their own, r6 .. r11 share one fleet_driver.
Every robot but r4 and r10 drives its own twist (0.30 to 0.39 m/s; straight, left or right arcs);
r4 and r10 are never commanded. Then, mid-run, r2's base_driver process is killed (SIGKILL: no
goodbye, the simulator's command timeout has to stop it) and r8, one of fleet_driver's, is sent
NaN commands, which its base_driver refuses: those two stop, every other robot drives on as
commanded, and the two idle ones stay put.
"""

import math
import os
import signal
import threading
import time
import unittest
import xmlrpc.client

import rosgraph
import rosnode
import rospy
import rostest
from geometry_msgs.msg import Twist
from sim_testing import Latest, planar, sim_sleep

ROBOTS = [f"r{k}" for k in range(12)]
IDLE = ("r4", "r10")
KILLED = "r2"  # its own base_driver process, killed
REFUSED = "r8"  # fleet_driver's, sent NaN commands
PHASE = 4.0  # [s] simulated, each phase


def twist_of(k):
    """Robot k's own command (vx [m/s], wz [rad/s])."""
    return 0.30 + 0.03 * (k % 4), (0.0, 0.2, -0.2)[k % 3]


class FleetCommander:
    """Every robot's twist on its nav_vel at 20 Hz of simulated time, from one thread."""

    def __init__(self):
        self.pubs = {r: rospy.Publisher(f"/{r}/nav_vel", Twist, queue_size=1) for r in ROBOTS}
        self.twists = {}
        self.lock = threading.Lock()
        threading.Thread(target=self.run, daemon=True).start()

    def send(self, robot, vx, wz):
        t = Twist()
        t.linear.x, t.angular.z = vx, wz
        with self.lock:
            self.twists[robot] = t

    def run(self):
        last = None
        while not rospy.is_shutdown():
            now = rospy.get_time()
            if last is None or now - last >= 0.05 or now < last:
                last = now
                with self.lock:
                    twists = dict(self.twists)
                for robot, twist in twists.items():
                    self.pubs[robot].publish(twist)
            time.sleep(0.002)


def speeds(truth):
    """(speed [m/s], yaw rate [rad/s]) of the latest ground truth."""
    t = truth.get().twist.twist
    return math.hypot(t.linear.x, t.linear.y), t.angular.z


def kill_process_of(node):
    uri = rosgraph.Master("/sim_fleet12_test").lookupNode(node)
    code, _, pid = xmlrpc.client.ServerProxy(uri).getPid("/sim_fleet12_test")
    if code != 1:
        raise AssertionError(f"{node} did not give its pid")
    os.kill(pid, signal.SIGKILL)
    return pid


class SimFleet12Test(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.truth = {r: Latest(f"/{r}/odometry/gazebo") for r in ROBOTS}
        cls.odometry = {r: Latest(f"/{r}/odometry/base_raw") for r in ROBOTS}
        cls.commander = FleetCommander()
        for r in ROBOTS:
            cls.truth[r].wait()
            cls.odometry[r].wait()
        deadline = time.time() + 120
        while any(p.get_num_connections() == 0 for p in cls.commander.pubs.values()):
            if time.time() > deadline:
                raise AssertionError("a robot's twist_mux never subscribed to its nav_vel")
            time.sleep(0.1)
        sim_sleep(1.0)
        cls.start = {r: planar(cls.truth[r].get()) for r in ROBOTS}
        for k, r in enumerate(ROBOTS):
            if r not in IDLE:
                cls.commander.send(r, *twist_of(k))
        sim_sleep(PHASE)
        cls.first = {r: speeds(cls.truth[r]) for r in ROBOTS}
        cls.mid = {r: planar(cls.truth[r].get()) for r in ROBOTS}
        cls.killed_pid = kill_process_of(f"/{KILLED}/base_driver")
        cls.commander.send(REFUSED, math.nan, 0.0)
        sim_sleep(PHASE)
        cls.second = {r: speeds(cls.truth[r]) for r in ROBOTS}
        cls.end = {r: planar(cls.truth[r].get()) for r in ROBOTS}
        sim_sleep(1.0)
        cls.last = {r: planar(cls.truth[r].get()) for r in ROBOTS}
        cls.fleet_driver_alive = rosnode.rosnode_ping("/fleet_driver", max_count=1)

    def check_as_commanded(self, robot, measured):
        vx, wz = twist_of(ROBOTS.index(robot))
        speed, rate = measured
        rospy.loginfo("%s: %.3f m/s, %.3f rad/s (commanded %.2f, %.2f)", robot, speed, rate, vx, wz)
        self.assertAlmostEqual(speed, vx, delta=0.05 * vx, msg=f"{robot}'s speed")
        self.assertAlmostEqual(rate, wz, delta=0.03, msg=f"{robot}'s yaw rate")

    def test_every_commanded_robot_drives_its_own_twist(self):
        for r in ROBOTS:
            if r not in IDLE:
                with self.subTest(robot=r):
                    self.check_as_commanded(r, self.first[r])

    def test_the_uncommanded_robots_stay_put(self):
        for r in IDLE:
            moved = math.hypot(self.last[r][0] - self.start[r][0], self.last[r][1] - self.start[r][1])
            rospy.loginfo("%s (idle): moved %.4f m", r, moved)
            self.assertLess(moved, 0.01, f"{r} moved")

    def test_a_killed_base_driver_stops_only_its_robot(self):
        speed, _ = self.second[KILLED]
        moved = math.hypot(self.last[KILLED][0] - self.end[KILLED][0], self.last[KILLED][1] - self.end[KILLED][1])
        rospy.loginfo("%s (base_driver pid %d killed): %.4f m/s, then %.4f m", KILLED, self.killed_pid, speed, moved)
        self.assertLess(speed, 0.02)
        self.assertLess(moved, 0.01)

    def test_nan_commands_stop_only_their_robot_in_the_fleet_driver(self):
        speed, _ = self.second[REFUSED]
        rospy.loginfo("%s (NaN commands): %.4f m/s", REFUSED, speed)
        self.assertLess(speed, 0.02)
        self.assertTrue(self.fleet_driver_alive, "fleet_driver went down")

    def test_the_others_drive_on(self):
        for r in ROBOTS:
            if r not in (*IDLE, KILLED, REFUSED):
                with self.subTest(robot=r):
                    self.check_as_commanded(r, self.second[r])


if __name__ == "__main__":
    rospy.init_node("sim_fleet12_test")
    rostest.rosrun("thorvald_sim", "sim_fleet12", SimFleet12Test)
