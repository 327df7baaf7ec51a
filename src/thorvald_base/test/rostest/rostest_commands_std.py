#!/usr/bin/env python3
"""base_driver, standard robot: a twist gives the steering angles and rim speeds of the geometry.

Each wheel of a rigid body moving with twist (vx, vy, wz) rolls along the velocity of its contact
point (x, y): (vx - wz y, vy + wz x). Its steering angle is that vector's direction and its rim speed
its length. The expected numbers are derived here from the drive positions the launch loaded.
"""

import math
import time
import unittest

import rospy
import rostest
from driver_testing import (
    WAIT,
    Topic,
    commands_are,
    contact_velocity,
    describe,
    driver_stream,
    drives_from_params,
    expected_commands,
    max_wheel_speed,
    twist,
)

from thorvald_msgs.msg import BaseState


class CommandsStdTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.commands = Topic("joint_commands", BaseState)
        cls.cmd = driver_stream(cls.commands)
        cls.drives = drives_from_params()

    def tearDown(self):
        self.cmd.stop()

    def drive(self, vx, vy, wz, predicate):
        """Streams the twist; returns the first joint_commands satisfying predicate (or fails)."""
        self.cmd.send(twist(vx, vy, wz))
        msg = self.commands.wait_for(predicate, timeout=WAIT)
        self.assertIsNotNone(msg, "joint_commands never matched; last: " + describe(self.commands.latest()))
        return msg

    def test_standard_robot_has_four_drives(self):
        # the robot file of Figure 5: a wrong file would make the other tests meaningless
        self.assertEqual(len(self.drives), 4)
        self.assertEqual(
            sorted((d["x"], d["y"]) for d in self.drives), [(-0.547, -0.3), (-0.547, 0.3), (0.547, -0.3), (0.547, 0.3)]
        )

    def test_commands_carry_each_drives_steering_speed_limit_and_channel(self):
        # steer_max_speed is the configured steering speed str_sim_v [rad/s]; every type-0 drive has a
        # controller of its own, so its propulsion is channel 1
        msg = self.commands.wait_for(lambda m: len(m.steer_max_speed) == 4, timeout=WAIT)
        self.assertIsNotNone(msg, describe(self.commands.latest()))
        self.assertEqual(list(msg.steer_max_speed), [float(d["str_sim_v"]) for d in self.drives])
        self.assertEqual(list(msg.channel), [1, 1, 1, 1])

    def test_the_configuration_is_in_the_private_namespace_with_defaults_filled_in(self):
        # base_driver read the file itself; what it drives is visible as the original's parameters,
        # with the defaults of keys the file leaves out
        drives = rospy.get_param("base_driver/motor_drives")
        self.assertEqual(sorted(drives), ["drive0", "drive1", "drive2", "drive3"])
        for k, d in enumerate(self.drives):
            got = drives[f"drive{k}"]
            self.assertEqual((got["x"], got["y"], got["node"]), (d["x"], d["y"], d["node"]))
            self.assertEqual(got["str_sim_v"], d["str_sim_v"])
            self.assertEqual(got["w_wheel"], 0.16)  # not in the file: the default
        self.assertEqual(rospy.get_param("base_driver/base_calculator"), "pltf_clc_std::PltfClcStd")

    def test_translation_and_rotation(self):
        # vx 0.5, vy 0.2, wz 0.3: e.g. drive1 at (0.547, -0.3) rolls along (0.5 + 0.09, 0.2 + 0.1641)
        # = (0.59, 0.3641): steering 0.5529 rad, speed 0.6933 m/s. All angles stay below 90 degrees.
        expected = expected_commands(self.drives, 0.5, 0.2, 0.3)
        self.assertTrue(all(abs(a) < math.pi / 2 for a, _ in expected))
        self.drive(0.5, 0.2, 0.3, lambda m: commands_are(m, expected))
        # and it holds while the command is repeated
        time.sleep(0.3)
        self.assertTrue(commands_are(self.commands.latest(), expected), describe(self.commands.latest()))

    def test_spin_in_place_wheels_roll_along_the_contact_velocity(self):
        # wz 0.5 alone: every wheel rolls tangentially at 0.5 * 0.6239 = 0.312 m/s. Drives may point
        # backwards and reverse instead of steering past 90 degrees, so compare the wheel's velocity
        # vector speed * (cos a, sin a) with the contact point's, and the angle with the steering stop.
        def rolls_along(m):
            if len(m.steer_pos) != len(self.drives):
                return False
            for d, a, v in zip(self.drives, m.steer_pos, m.prop_speed):
                ux, uy = contact_velocity(d, 0.0, 0.0, 0.5)
                if abs(v * math.cos(a) - ux) > 1e-6 or abs(v * math.sin(a) - uy) > 1e-6:
                    return False
            return True

        msg = self.drive(0.0, 0.0, 0.5, rolls_along)
        for d, a, v in zip(self.drives, msg.steer_pos, msg.prop_speed):
            self.assertLessEqual(abs(a), d["str_lim"])
            self.assertAlmostEqual(abs(v), 0.5 * math.hypot(d["x"], d["y"]), places=6)

    def test_too_fast_scales_all_wheels_down_together(self):
        # vx 3 m/s straight ahead, beyond the motors: 3000 rpm / 42 * 2 pi / 60 * 0.2 m = 1.496 m/s,
        # so every wheel runs at that limit, straight ahead (not refused: below 10 times the limit).
        limit = min(max_wheel_speed(d) for d in self.drives)
        self.assertAlmostEqual(limit, 1.496, places=3)
        expected = [(0.0, limit)] * len(self.drives)
        self.drive(3.0, 0.0, 0.0, lambda m: commands_are(m, expected))

    def test_no_command_means_zero_speed(self):
        # nothing streamed for longer than the 0.5 s timeout: the wheels are commanded to stop
        self.cmd.stop()
        msg = self.commands.wait_for(lambda m: m.prop_speed and all(v == 0.0 for v in m.prop_speed), timeout=WAIT)
        self.assertIsNotNone(msg, describe(self.commands.latest()))


if __name__ == "__main__":
    rospy.init_node("commands_std_test")
    rostest.rosrun("thorvald_base", "base_driver_commands_std", CommandsStdTest)
