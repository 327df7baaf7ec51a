#!/usr/bin/env python3
"""base_driver: NaN, infinite and absurd commands are refused, with a throttled warning.

A refused command is dropped: the previous command stands until it times out (0.5 s after it was
last received), so a source that sends only garbage stops the wheels. "Absurd" is beyond 10 times
what the fastest wheel can do: 10 x 1.496 m/s = 15 m/s, or 15 m/s / 0.624 m (farthest wheel from
the centre) = 24 rad/s, for the standard robot.
"""

import math
import time
import unittest

import rospy
import rostest
from driver_testing import (
    WAIT,
    Topic,
    describe,
    driver_stream,
    drives_from_params,
    speeds_are,
    twist,
)
from rosgraph_msgs.msg import Log

from thorvald_msgs.msg import BaseState

TIMEOUT = 0.5  # [s] base_driver's default ~command_timeout
MARGIN = 0.2  # [s] + one 50 Hz cycle
WARN_PERIOD = 5.0  # [s] base_driver repeats a warning at most this often
GOOD = 0.4  # [m/s]


def stopped(m):
    return len(m.prop_speed) > 0 and all(v == 0.0 for v in m.prop_speed)


class RefusedCommandsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.commands = Topic("joint_commands", BaseState)
        cls.rosout = Topic("/rosout", Log, queue_size=1000)
        cls.cmd = driver_stream(cls.commands)
        cls.drives = drives_from_params()

    def tearDown(self):
        self.cmd.stop()

    def drive_good(self):
        self.cmd.send(twist(GOOD))
        msg = self.commands.wait_for(lambda m: speeds_are(m, GOOD), timeout=WAIT)
        self.assertIsNotNone(msg, describe(self.commands.latest()))

    def check_refused(self, bad):
        """The previous command stands while bad ones stream, then the wheels stop at its timeout."""
        self.drive_good()
        # From here on every joint_commands follows the good command: a stopped one that base_driver
        # published before it took the command may still arrive after the command was sent.
        driving = time.time()
        last_good = self.cmd.stop()
        self.cmd.send(bad)
        first_stop = self.commands.wait_for(stopped, timeout=TIMEOUT + WAIT, since=driving)
        self.assertIsNotNone(first_stop, "the wheels were never stopped: " + describe(self.commands.latest()))
        delay = first_stop.header.stamp.to_sec() - last_good
        # a bad command taken would stop (or change) the wheels at once, not near the timeout; one CI run
        # with three rostests at a time stamped the stop 2 ms short of it, so the bound allows a cycle
        self.assertGreaterEqual(delay, TIMEOUT - 0.02, "the bad command replaced the good one")
        self.assertLessEqual(delay, TIMEOUT + 0.02 + MARGIN, "the wheels did not stop at the good command's timeout")
        before = [m for m in self.commands.since(driving) if m.header.stamp < first_stop.header.stamp]
        self.assertTrue(before)
        for m in before:
            self.assertTrue(speeds_are(m, GOOD), describe(m))
        # the bad commands went on arriving on the same connection: a good one after them is taken
        self.cmd.send(twist(0.2))
        self.assertIsNotNone(self.commands.wait_for(lambda m: speeds_are(m, 0.2), timeout=WAIT))

    def test_nan(self):
        self.check_refused(twist(float("nan"), 0.0, 0.0))

    def test_nan_in_rotation(self):
        self.check_refused(twist(0.1, 0.0, float("nan")))

    def test_infinite(self):
        self.check_refused(twist(0.0, float("-inf"), 0.0))

    def test_absurd_speed(self):
        self.check_refused(twist(20.0, 0.0, 0.0))

    def test_absurd_rotation(self):
        self.check_refused(twist(0.0, 0.0, 30.0))

    def test_within_the_absurd_limit_is_driven_scaled(self):
        # 12 m/s is beyond the motors but not absurd: driven, scaled down to 1.496 m/s
        self.cmd.send(twist(12.0))
        limit = 3000 / 42 * 2 * math.pi / 60 * 0.2
        self.assertIsNotNone(self.commands.wait_for(lambda m: speeds_are(m, limit), timeout=WAIT))

    def test_refusal_is_warned_on_rosout(self):
        # Warnings repeat at most every 5 s: stream NaN for longer than that, so a warning appears
        # even if an earlier test's refusal has just been warned.
        start = time.time()
        self.cmd.send(twist(float("nan")))

        def refused_warning(log):
            return log.level == Log.WARN and log.name.endswith("base_driver") and "refused" in log.msg

        log = self.rosout.wait_for(refused_warning, timeout=WARN_PERIOD + WAIT, since=start)
        self.assertIsNotNone(log, "no WARN mentioning 'refused' from base_driver on /rosout")
        self.assertIn("non-finite", log.msg)
        self.assertEqual(log.name, rospy.resolve_name("base_driver"))


if __name__ == "__main__":
    rospy.init_node("refused_commands_test")
    rostest.rosrun("thorvald_base", "base_driver_refused_commands", RefusedCommandsTest)
