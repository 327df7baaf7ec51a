#!/usr/bin/env python3
"""base_driver: a command older than ~command_timeout (0.5 s) stops the wheels and keeps the steering.

Times are compared on the messages' stamps (the node's loop time, on the same clock as this test):
the node stamps each command when it arrives, which is after this test began to publish it, so the wheels
cannot stop before the last publication + 0.5 s, and must have stopped within one 50 Hz cycle after
that; 0.2 s of margin absorbs a loaded machine.
"""

import time
import unittest

import rospy
import rostest
from driver_testing import (
    WAIT,
    Topic,
    commands_are,
    describe,
    driver_stream,
    drives_from_params,
    expected_commands,
    twist,
)

from thorvald_msgs.msg import BaseState

TIMEOUT = 0.5  # [s] base_driver's default ~command_timeout
CYCLE = 1.0 / 50  # [s] base_driver's default ~rate
MARGIN = 0.2  # [s]


def stopped(m):
    return len(m.prop_speed) > 0 and all(v == 0.0 for v in m.prop_speed)


class CommandTimeoutTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.commands = Topic("joint_commands", BaseState)
        cls.states = Topic("base_state", BaseState)
        cls.cmd = driver_stream(cls.commands)
        cls.drives = drives_from_params()

    def test_wheels_stop_and_steering_stays_after_the_timeout(self):
        # vx 0.5, vy 0.2, wz 0.3: steering between 0.06 and 0.73 rad, speeds 0.41 to 0.69 m/s
        expected = expected_commands(self.drives, 0.5, 0.2, 0.3)
        steering = [a for a, _ in expected]
        self.cmd.send(twist(0.5, 0.2, 0.3))
        self.assertIsNotNone(
            self.commands.wait_for(lambda m: commands_are(m, expected), timeout=WAIT), describe(self.commands.latest())
        )
        # let the simulated drives reach the command (speed ramps at 1.5 m/s^2, steering at 4 rad/s)
        self.assertIsNotNone(
            self.states.wait_for(lambda m: commands_are(m, expected, tol=1e-3), timeout=WAIT),
            describe(self.states.latest()),
        )
        last = self.cmd.stop()

        first_stop = self.commands.wait_for(stopped, timeout=TIMEOUT + WAIT, since=last)
        self.assertIsNotNone(first_stop, "the wheels were never stopped: " + describe(self.commands.latest()))
        delay = first_stop.header.stamp.to_sec() - last
        self.assertGreaterEqual(delay, TIMEOUT, "stopped before the timeout")
        self.assertLessEqual(delay, TIMEOUT + CYCLE + MARGIN, "stopped late")
        # until then the last command stood
        before = [m for m in self.commands.since(last) if m.header.stamp < first_stop.header.stamp]
        self.assertTrue(before, "no joint_commands between the last command and the stop")
        for m in before:
            self.assertTrue(commands_are(m, expected), describe(m))

        # the steering is kept (commanded and measured) while the measured wheels ramp down to 0
        self.assertEqual(list(first_stop.steer_pos), steering)
        settled = self.states.wait_for(lambda m: all(abs(v) < 1e-9 for v in m.prop_speed), timeout=WAIT)
        self.assertIsNotNone(settled, "the wheels did not stop: " + describe(self.states.latest()))
        for a, b in zip(settled.steer_pos, steering):
            self.assertAlmostEqual(a, b, delta=1e-3)
        time.sleep(0.3)
        for m in self.commands.since(time.time() - 0.3):
            self.assertTrue(stopped(m))
            self.assertEqual(list(m.steer_pos), steering)

    def test_a_new_command_drives_again(self):
        self.cmd.send(twist(0.3))
        expected = [(0.0, 0.3)] * len(self.drives)
        self.assertIsNotNone(self.commands.wait_for(lambda m: commands_are(m, expected), timeout=WAIT))
        last = self.cmd.stop()
        self.assertIsNotNone(self.commands.wait_for(stopped, timeout=TIMEOUT + WAIT, since=last))
        self.cmd.send(twist(0.3))
        self.assertIsNotNone(self.commands.wait_for(lambda m: commands_are(m, expected), timeout=WAIT))
        self.cmd.stop()


if __name__ == "__main__":
    rospy.init_node("command_timeout_test")
    rostest.rosrun("thorvald_base", "base_driver_command_timeout", CommandTimeoutTest)
