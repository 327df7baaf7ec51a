#!/usr/bin/env python3
"""twist_mux drives base_driver: navigation moves the wheels, the joystick overrides it.

base_driver listens only to twist_mux/cmd_vel, which only twist_mux publishes. Navigation asks for
vx 0.3 (wheels straight, 0.3 m/s); the joystick for vx = vy = 0.2 (wheels at 45 degrees,
0.2 * sqrt(2) = 0.283 m/s), so joint_commands show which input is driving.
"""

import math
import time
import unittest

import rospy
import rostest
from driver_testing import STARTUP_TIMEOUT, WAIT, CommandStream, Topic, commands_are, describe, twist

from thorvald_msgs.msg import BaseState

NAV = [(0.0, 0.3)] * 4
JOY = [(math.pi / 4, 0.2 * math.sqrt(2.0))] * 4
MUX_TIMEOUT = 0.5  # [s] of both inputs in thorvald_bringup/config/twist_mux.yaml


class MuxDrivesBaseTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.commands = Topic("joint_commands", BaseState)
        cls.nav = CommandStream("nav_vel")
        cls.joy = CommandStream("teleop_joy/cmd_vel")
        for s in (cls.nav, cls.joy):
            assert s.wait_for_subscriber(), "twist_mux did not subscribe to " + s.pub.resolved_name
        assert cls.commands.wait_for(timeout=STARTUP_TIMEOUT, since=0), "no joint_commands from base_driver"

    def tearDown(self):
        self.nav.stop()
        self.joy.stop()

    def wait_commands(self, expected, what):
        msg = self.commands.wait_for(lambda m: commands_are(m, expected), timeout=WAIT)
        self.assertIsNotNone(msg, what + "; joint_commands: " + describe(self.commands.latest()))

    def test_navigation_moves_the_wheels(self):
        self.nav.send(twist(0.3))
        self.wait_commands(NAV, "navigation did not reach the base")

    def test_joystick_overrides_navigation_until_it_times_out(self):
        self.nav.send(twist(0.3))
        self.wait_commands(NAV, "navigation did not reach the base")
        self.joy.send(twist(0.2, 0.2))
        self.wait_commands(JOY, "the joystick did not override navigation")
        # while both stream, the joystick keeps the base
        self.assertTrue(commands_are(self.commands.wait_for(since=time.time() + 0.3, timeout=WAIT), JOY))
        self.joy.stop()
        self.wait_commands(NAV, f"navigation did not take over after the joystick's {MUX_TIMEOUT:.1f} s timeout")


if __name__ == "__main__":
    rospy.init_node("mux_drives_base_test")
    rostest.rosrun("thorvald_base", "base_driver_mux_drives_base", MuxDrivesBaseTest)
