#!/usr/bin/env python3
"""robot.launch as on a real robot, over CAN to the device emulator (SLCAN, another process).

base_driver comes up whether or not its adapter's port existed when it first looked (robot.launch
respawns it, as at a robot's boot); commands on nav_vel go through twist_mux and the bus to the
emulated drives, and the measured drive states come back: base_state follows, odometry moves
forward, base_driver publishes the odom -> base_link transform (enable_odom_tf, as on a real
robot) and robot_state_publisher the robot's links from the model robot.launch loaded. On wall
time, as a real robot runs.
"""

import time
import unittest

import rospy
import rostest
import tf2_ros
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry

from thorvald_msgs.msg import BaseState, ControllerArray
from thorvald_testing import poll
from thorvald_testing.topics import Latest

STARTUP = 60.0  # [s]: the emulator, base_driver's respawn and SLCAN's 2 s open on a busy machine
SPEED = 0.3  # [m/s]
DRIVE = 3.0  # [s]


class RobotOverCanTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.odom = Latest("odometry/base_raw", Odometry)
        cls.state = Latest("base_state", BaseState)
        cls.controllers = Latest("motor_controller_data", ControllerArray)
        cls.nav = rospy.Publisher("nav_vel", Twist, queue_size=1)
        cls.tf = tf2_ros.Buffer()
        cls.listener = tf2_ros.TransformListener(cls.tf)
        # online: base_driver heard every motor controller over the bus (mode 3, as the can_slcan test)
        poll(
            lambda: (
                cls.controllers.get() is not None
                and len(cls.controllers.get().controllers) == 4
                and all(c.controller_mode == 3 for c in cls.controllers.get().controllers)
            ),
            STARTUP,
            "base_driver to report its four motor controllers online over CAN",
        )
        poll(lambda: cls.state.get() is not None, STARTUP, "base_state")
        poll(lambda: cls.nav.get_num_connections() > 0, STARTUP, "twist_mux to subscribe nav_vel")

    def test_the_model_is_loaded_for_the_robot(self):
        description = rospy.get_param("robot_description")
        self.assertIn('link name="thorvald_001/base_link"', description)
        self.assertEqual(len(rospy.get_param("base_driver/motor_drives")), 4)

    def test_commands_drive_the_wheels_over_the_bus_and_odometry_and_tf_follow(self):
        start = self.odom.get().pose.pose.position.x
        msg = Twist()
        msg.linear.x = SPEED
        end = time.time() + DRIVE
        speeds = []
        while time.time() < end:
            self.nav.publish(msg)
            time.sleep(0.05)
            state = self.state.get()
            speeds.append(min(state.prop_speed))
        # the measured wheel speeds (encoders over CAN) reached the command
        self.assertGreater(max(speeds), 0.95 * SPEED)
        poll(lambda: max(abs(v) for v in self.state.get().prop_speed) < 0.01, 10.0, "the wheels to stop")
        moved = self.odom.get().pose.pose.position.x - start
        # 3 s at 0.3 m/s less the ramps (prp_sim_a 1.5 m/s^2) and the command timeout: 0.7 .. 1.1 m
        self.assertGreater(moved, 0.6)
        self.assertLess(moved, 1.2)
        odom = self.odom.get()
        t = self.tf.lookup_transform("thorvald_001/odom", "thorvald_001/base_link", rospy.Time(0), rospy.Duration(5.0))
        self.assertAlmostEqual(t.transform.translation.x, odom.pose.pose.position.x, delta=0.01)
        # robot_state_publisher: the wheels of the model, from base_driver's joint states
        w = self.tf.lookup_transform(
            "thorvald_001/base_link", "thorvald_001/wheel0_link", rospy.Time(0), rospy.Duration(5.0)
        )
        self.assertNotEqual((w.transform.translation.x, w.transform.translation.y), (0.0, 0.0))


if __name__ == "__main__":
    rospy.init_node("robot_can_test")
    rostest.rosrun("thorvald_bringup", "robot_can", RobotOverCanTest)
