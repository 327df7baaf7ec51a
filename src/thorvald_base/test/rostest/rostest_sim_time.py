#!/usr/bin/env python3
"""base_driver on simulated time (/use_sim_time true): stamps and motion follow /clock, not the wall.

This test is the clock: simulated time starts at 1000 s and runs at twice the wall clock's speed,
computed from the wall clock (so a late publication does not slow it down), published every 10 ms.
Moving at 0.5 m/s for some simulated seconds, the robot covers 0.5 m per simulated second, twice
what the wall clock would give; with the clock paused, it does not move at all.
"""

import threading
import time
import unittest

import rospy
import rostest
from driver_testing import STARTUP_TIMEOUT, WAIT, CommandStream, Topic, twist
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock

SIM_START = 1000.0  # [s]
SPEED_UP = 2.0  # simulated seconds per wall second
VX = 0.5  # [m/s]


class SimClock:
    def __init__(self):
        self.pub = rospy.Publisher("/clock", Clock, queue_size=10)
        self.lock = threading.Lock()
        self.sim = SIM_START
        self.wall = time.time()
        self.paused = False
        threading.Thread(target=self.run, daemon=True).start()

    def now(self):
        with self.lock:
            if not self.paused:
                wall = time.time()
                self.sim += SPEED_UP * (wall - self.wall)
                self.wall = wall
            return self.sim

    def pause(self, paused):
        self.now()
        with self.lock:
            self.paused = paused
            self.wall = time.time()

    def run(self):
        while not rospy.is_shutdown():
            self.pub.publish(Clock(rospy.Time.from_sec(self.now())))
            time.sleep(0.01)


class SimTimeTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        assert rospy.get_param("/use_sim_time") is True
        cls.clock = SimClock()
        cls.odom = Topic("odometry/base_raw", Odometry)
        cls.cmd = CommandStream("twist_mux/cmd_vel")
        assert cls.cmd.wait_for_subscriber(), "base_driver did not subscribe to twist_mux/cmd_vel"
        assert cls.odom.wait_for(lambda m: m.header.stamp.to_sec() > SIM_START, timeout=STARTUP_TIMEOUT, since=0)
        cls.cmd.send(twist(VX))
        assert cls.odom.wait_for(lambda m: abs(m.twist.twist.linear.x - VX) < 1e-9, timeout=WAIT), "not at speed"

    @classmethod
    def tearDownClass(cls):
        cls.cmd.stop()

    def test_stamps_follow_simulated_time(self):
        start = time.time()
        time.sleep(1.0)
        msgs = self.odom.since(start)
        self.assertGreater(len(msgs), 20)
        now = self.clock.now()
        stamps = [m.header.stamp.to_sec() for m in msgs]
        self.assertEqual(stamps, sorted(stamps))
        for s in stamps:
            self.assertGreater(s, SIM_START)
            self.assertLessEqual(s, now)  # never ahead of the clock (and nowhere near the wall clock's 1.7e9 s)
        # at 50 Hz of simulated time, one second of wall time holds about 2 s of simulated stamps
        self.assertGreater(stamps[-1] - stamps[0], 1.5)

    def test_moves_as_far_as_simulated_time_says(self):
        a = self.odom.wait_for()
        b = self.odom.wait_for(lambda m: (m.header.stamp - a.header.stamp).to_sec() >= 2.0, timeout=WAIT)
        self.assertIsNotNone(b)
        sim_dt = (b.header.stamp - a.header.stamp).to_sec()
        distance = b.pose.pose.position.x - a.pose.pose.position.x
        # 0.5 m per simulated second (by the wall clock it would be half that)
        self.assertAlmostEqual(distance, VX * sim_dt, delta=0.01 * VX * sim_dt)

    def test_paused_clock_stops_the_robot(self):
        self.clock.pause(True)
        try:
            time.sleep(0.3)  # messages of the last simulated instant in flight
            frozen = self.odom.latest()
            start = time.time()
            time.sleep(1.0)  # commands keep streaming meanwhile
            later = [m for m in self.odom.since(start) if m.header.stamp > frozen.header.stamp]
            self.assertEqual(later, [], "odometry went on while simulated time stood still")
            self.assertEqual(self.odom.latest().pose.pose.position.x, frozen.pose.pose.position.x)
        finally:
            self.clock.pause(False)
        moved = self.odom.wait_for(lambda m: m.pose.pose.position.x > frozen.pose.pose.position.x, timeout=WAIT)
        self.assertIsNotNone(moved, "the robot did not move on with the clock")


if __name__ == "__main__":
    rospy.init_node("sim_time_test")
    rostest.rosrun("thorvald_base", "base_driver_sim_time", SimTimeTest)
