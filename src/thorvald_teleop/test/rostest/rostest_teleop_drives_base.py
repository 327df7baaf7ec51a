#!/usr/bin/env python3
"""teleop_node with the xbox controller file, in front of twist_mux and base_driver.

The deadman gates the commands, turbo scales them, releasing sends one zero and then nothing, the
priority button locks navigation out through twist_mux, the home button reaches base_driver, and
joystick messages stopping with the deadman held stop the robot. Expected values come from the
controller file, read here with plain YAML.
"""

import os
import threading
import time
import unittest

import rospkg
import rospy
import rostest
import yaml
from geometry_msgs.msg import Twist
from sensor_msgs.msg import Joy
from std_msgs.msg import Bool

from thorvald_msgs.msg import BaseState

CONFIG = os.path.join(rospkg.RosPack().get_path("thorvald_teleop"), "config", "xbox.yaml")
STARTUP = 40.0  # [s]
WAIT = 5.0  # [s]


class Recorder:
    def __init__(self, topic, msg_type):
        self.lock = threading.Lock()
        self.messages = []
        self.sub = rospy.Subscriber(topic, msg_type, self.on, queue_size=1000)

    def on(self, msg):
        with self.lock:
            self.messages.append((time.time(), msg))

    def since(self, t):
        with self.lock:
            return [m for s, m in self.messages if s > t]

    def wait_for(self, predicate, since, timeout=WAIT):
        deadline = time.time() + timeout
        while time.time() < deadline:
            for m in self.since(since):
                if predicate(m):
                    return m
            time.sleep(0.01)
        return None


class Joystick:
    """A joystick publishing its state at 20 Hz, as joy_node with autorepeat."""

    def __init__(self, axes=8, buttons=11):
        self.pub = rospy.Publisher("joy", Joy, queue_size=10)
        self.axes = [0.0] * axes
        self.buttons = [0] * buttons
        self.running = True
        self.lock = threading.Lock()
        threading.Thread(target=self.run, daemon=True).start()

    def run(self):
        while not rospy.is_shutdown():
            with self.lock:
                if self.running:
                    self.pub.publish(Joy(axes=list(self.axes), buttons=list(self.buttons)))
            time.sleep(0.05)

    def set(self, axes=None, buttons=None):
        with self.lock:
            for k, v in (axes or {}).items():
                self.axes[k] = v
            for k, v in (buttons or {}).items():
                self.buttons[k] = v
            self.pub.publish(Joy(axes=list(self.axes), buttons=list(self.buttons)))

    def press(self, button):
        self.set(buttons={button: 1})
        time.sleep(0.15)
        self.set(buttons={button: 0})


def twist_is(vx, vy, wz, tol=1e-6):
    return lambda m: abs(m.linear.x - vx) < tol and abs(m.linear.y - vy) < tol and abs(m.angular.z - wz) < tol


class TeleopTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        with open(CONFIG) as f:
            cls.c = yaml.safe_load(f)
        cls.teleop = Recorder("teleop_joy/cmd_vel", Twist)
        cls.mux = Recorder("twist_mux/cmd_vel", Twist)
        cls.priority = Recorder("teleop_joy/joy_priority", Bool)
        cls.state = Recorder("base_state", BaseState)
        cls.nav = rospy.Publisher("nav_vel", Twist, queue_size=10)
        cls.joy = Joystick()
        deadline = time.time() + STARTUP
        while time.time() < deadline and not (cls.joy.pub.get_num_connections() and cls.nav.get_num_connections()):
            time.sleep(0.1)
        assert cls.state.wait_for(lambda m: True, since=0, timeout=STARTUP), "no base_state from base_driver"

    def tearDown(self):
        self.joy.set(axes=dict.fromkeys(range(8), 0.0), buttons=dict.fromkeys(range(11), 0))

    def test_1_deadman_turbo_and_one_zero_on_release(self):
        c = self.c
        t0 = time.time()
        self.joy.set(axes={c["axis_linear"]["x"]: 0.5, c["axis_angular"]["yaw"]: -0.4})
        time.sleep(0.5)
        self.assertEqual(self.teleop.since(t0), [], "commands without the deadman")
        self.joy.set(buttons={c["enable_button"]: 1})
        expected = (0.5 * c["scale_linear"]["x"], 0.0, -0.4 * c["scale_angular"]["yaw"])
        self.assertIsNotNone(self.teleop.wait_for(twist_is(*expected), since=t0))
        self.assertIsNotNone(self.mux.wait_for(twist_is(*expected), since=t0), "the mux did not pass the joystick")
        self.joy.set(buttons={c["enable_button"]: 0, c["enable_turbo_button"]: 1})
        turbo = (0.5 * c["scale_linear_turbo"]["x"], 0.0, -0.4 * c["scale_angular_turbo"]["yaw"])
        self.assertIsNotNone(self.teleop.wait_for(twist_is(*turbo), since=t0))
        released = time.time()
        self.joy.set(buttons={c["enable_turbo_button"]: 0})
        self.assertIsNotNone(self.teleop.wait_for(twist_is(0, 0, 0), since=released))
        time.sleep(1.0)  # the joystick keeps publishing its (released) state meanwhile
        after = [m for m in self.teleop.since(released)]
        # turbo commands published before the release may still arrive after it on a busy machine
        while after and twist_is(*turbo)(after[0]):
            after.pop(0)
        zeros = [m for m in after if twist_is(0, 0, 0)(m)]
        self.assertEqual(len(zeros), 1, "one zero twist on release")
        self.assertEqual(len(after), 1, "silence after the zero")

    def test_2_priority_locks_navigation_out(self):
        c = self.c
        stream = {"on": True}

        def navigate():
            msg = Twist()
            msg.linear.x = 0.2
            while stream["on"] and not rospy.is_shutdown():
                self.nav.publish(msg)
                time.sleep(0.05)

        threading.Thread(target=navigate, daemon=True).start()
        try:
            t0 = time.time()
            self.assertIsNotNone(self.mux.wait_for(twist_is(0.2, 0, 0), since=t0), "navigation does not pass")
            self.joy.press(c["priority_button"])
            self.assertIsNotNone(self.priority.wait_for(lambda m: m.data, since=t0), "joy_priority not set")
            locked = time.time()
            # the mux passes nothing from navigation: base_driver's command timeout stops the wheels
            stopped = self.state.wait_for(
                lambda m: all(abs(v) < 1e-3 for v in m.prop_speed), since=locked, timeout=WAIT
            )
            self.assertIsNotNone(stopped, "the lock did not stop the base")
            later = time.time()
            time.sleep(1.0)
            self.assertEqual([m for m in self.mux.since(later) if twist_is(0.2, 0, 0)(m)], [], "navigation passed")
            self.joy.press(c["priority_button"])
            self.assertIsNotNone(self.priority.wait_for(lambda m: not m.data, since=locked), "joy_priority not cleared")
            self.assertIsNotNone(self.mux.wait_for(twist_is(0.2, 0, 0), since=later), "navigation not back")
        finally:
            stream["on"] = False

    def test_3_home_steering_reaches_base_driver(self):
        c = self.c
        t0 = time.time()
        self.joy.press(c["home_steering_button"])
        homing = self.state.wait_for(lambda m: m.drive_mode == BaseState.MODE_HOME, since=t0)
        self.assertIsNotNone(homing, "base_driver did not home")

    def test_4_joystick_lost_with_the_deadman_held(self):
        c = self.c
        t0 = time.time()
        self.joy.set(axes={c["axis_linear"]["x"]: 1.0}, buttons={c["enable_button"]: 1})
        self.assertIsNotNone(self.teleop.wait_for(lambda m: m.linear.x > 0, since=t0))
        with self.joy.lock:
            self.joy.running = False  # the joystick goes silent, deadman held
        lost = time.time()
        try:
            zero = self.teleop.wait_for(twist_is(0, 0, 0), since=lost, timeout=3.0)
            self.assertIsNotNone(zero, "no stop after the joystick went silent")
            took = time.time() - lost
            # joy_timeout after the last joystick message, which came before `lost`; 1 s for delivery
            # and scheduling on a busy machine (the test's purpose: a stop, not none)
            self.assertLess(took, c["joy_timeout"] + 1.0)
        finally:
            with self.joy.lock:
                self.joy.running = True


if __name__ == "__main__":
    rospy.init_node("teleop_test")
    rostest.rosrun("thorvald_teleop", "teleop_drives_base", TeleopTest)
