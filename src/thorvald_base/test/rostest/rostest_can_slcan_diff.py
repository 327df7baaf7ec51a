#!/usr/bin/env python3
"""base_driver over SLCAN drives the 2WD differential robot: one prop/prop controller, two channels.

The odometry base_driver computes from the speeds the emulated controller reports follows the
commanded twist, straight and turning; the wheel speeds are the differential robot's, from the
robot file's wheel positions (read here with plain YAML).
"""

import unittest

import rospy
import rostest
from driver_testing import STARTUP_TIMEOUT, Topic, driver_stream, drives_from_params, twist
from nav_msgs.msg import Odometry

from thorvald_msgs.msg import BaseState, ControllerArray


class CanSlcanDiffTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.state = Topic("base_state", BaseState)
        cls.odom = Topic("odometry/base_raw", Odometry)
        cls.controllers = Topic("motor_controller_data", ControllerArray)
        cls.cmd = driver_stream(cls.state)

    def test_1_one_prop_prop_controller_online(self):
        online = self.controllers.wait_for(
            lambda m: len(m.controllers) == 1 and m.controllers[0].controller_mode == 3,
            timeout=STARTUP_TIMEOUT,
            since=0,
        )
        self.assertIsNotNone(online, "the differential robot's controller never reported online")
        self.assertEqual(online.controllers[0].type, "RoboteqFbl2360Diff")
        self.assertEqual([v.type for v in online.controllers[0].motor_vars], ["propulsion", "propulsion"])

    def test_2_odometry_follows_the_commands(self):
        drives = drives_from_params()
        for vx, wz in ((0.4, 0.0), (0.3, 0.4)):
            with self.subTest(vx=vx, wz=wz):
                self.cmd.send(twist(vx, 0.0, wz))
                # each wheel at its contact point's speed along x: vx - wz * y
                expected = [vx - wz * d["y"] for d in drives]
                state = self.state.wait_for(
                    lambda m, e=expected: all(abs(a - b) < 0.01 for a, b in zip(m.prop_speed, e)), timeout=10.0
                )
                self.assertIsNotNone(state, f"the wheels never reached {expected}")
                odom = self.odom.wait_for(
                    lambda m, v=vx, w=wz: (
                        abs(m.twist.twist.linear.x - v) < 0.01 and abs(m.twist.twist.angular.z - w) < 0.01
                    ),
                    timeout=5.0,
                )
                self.assertIsNotNone(odom, "odometry did not follow the command")


if __name__ == "__main__":
    rospy.init_node("can_slcan_diff_test")
    rostest.rosrun("thorvald_base", "can_slcan_diff", CanSlcanDiffTest)
