#!/usr/bin/env python3
"""base_driver: ~safety_stop true holds the wheels at 0 (steering still commanded) until released."""

import math
import time
import unittest

import rospy
import rostest
from driver_testing import (
    WAIT,
    Topic,
    commands_are,
    describe,
    driver_service,
    driver_stream,
    drives_from_params,
    expected_commands,
    twist,
)
from std_srvs.srv import SetBool

from thorvald_msgs.msg import BaseState

HOLD = 1.2  # [s] of the driver's time: longer than the 0.5 s command timeout, while commands keep arriving


def stamp(msg) -> float:
    return msg.header.stamp.to_sec()


def held_for(commands, start, first, seconds):
    """The commands the driver stamped from first's stamp to seconds later (received after wall time
    start), once it has stamped one that late; None if it has not within WAIT + seconds. On the
    driver's own clock: a busy machine changes how many come, not which instants they cover."""
    last = commands.wait_for(lambda m: stamp(m) >= stamp(first) + seconds, timeout=WAIT + seconds, since=start)
    if last is None:
        return None
    return [m for m in commands.since(start) if stamp(first) <= stamp(m) <= stamp(last)]


class SafetyStopTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.commands = Topic("joint_commands", BaseState)
        cls.states = Topic("base_state", BaseState)
        cls.cmd = driver_stream(cls.commands)
        cls.safety_stop = driver_service("safety_stop", SetBool)
        cls.drives = drives_from_params()

    def tearDown(self):
        self.safety_stop(False)
        self.cmd.stop()

    def test_wheels_held_while_enabled_and_resume_when_disabled(self):
        # vx = vy = 0.3: every wheel steers 45 degrees and rolls at 0.3 * sqrt(2) = 0.424 m/s
        expected = expected_commands(self.drives, 0.3, 0.3, 0.0)
        held = [(math.pi / 4, 0.0)] * len(self.drives)
        self.assertAlmostEqual(expected[0][0], math.pi / 4)
        self.cmd.send(twist(0.3, 0.3, 0.0))
        self.assertIsNotNone(self.commands.wait_for(lambda m: commands_are(m, expected), timeout=WAIT))

        response = self.safety_stop(True)
        self.assertTrue(response.success)
        self.assertEqual(response.message, "safety stop enabled")
        start = time.time()
        first = self.commands.wait_for(lambda m: commands_are(m, held), timeout=WAIT, since=start)
        self.assertIsNotNone(first, "the wheels were not stopped: " + describe(self.commands.latest()))
        # held while the command keeps streaming, for HOLD of the driver's time (its commands at 50 Hz);
        # the measured wheels ramp down to 0 (1.5 m/s^2)
        during = held_for(self.commands, start, first, HOLD)
        self.assertIsNotNone(during, "the driver stopped publishing commands")
        self.assertGreater(len(during), 10)
        for m in during:
            self.assertTrue(commands_are(m, held), describe(m))
        state = self.states.latest()
        for v, a in zip(state.prop_speed, state.steer_pos):
            self.assertAlmostEqual(v, 0.0, places=9)
            self.assertAlmostEqual(a, math.pi / 4, places=3)

        response = self.safety_stop(False)
        self.assertTrue(response.success)
        self.assertEqual(response.message, "safety stop disabled")
        self.assertIsNotNone(
            self.commands.wait_for(lambda m: commands_are(m, expected), timeout=WAIT),
            "the wheels did not resume: " + describe(self.commands.latest()),
        )
        self.assertIsNotNone(self.states.wait_for(lambda m: commands_are(m, expected, tol=1e-3), timeout=WAIT))

    def test_enabled_without_a_command_holds_a_later_command(self):
        self.assertTrue(self.safety_stop(True).success)
        start = time.time()
        self.cmd.send(twist(0.5))
        first = self.commands.wait_for(timeout=WAIT, since=start)
        self.assertIsNotNone(first, "the driver publishes no commands")
        during = held_for(self.commands, start, first, 0.6)  # past the 0.5 s command timeout
        self.assertIsNotNone(during, "the driver stopped publishing commands")
        self.assertGreater(len(during), 5)
        for m in during:
            self.assertTrue(all(v == 0.0 for v in m.prop_speed), describe(m))
        self.assertTrue(self.safety_stop(False).success)
        expected = [(0.0, 0.5)] * len(self.drives)
        self.assertIsNotNone(self.commands.wait_for(lambda m: commands_are(m, expected), timeout=WAIT))


if __name__ == "__main__":
    rospy.init_node("safety_stop_test")
    rostest.rosrun("thorvald_base", "base_driver_safety_stop", SafetyStopTest)
