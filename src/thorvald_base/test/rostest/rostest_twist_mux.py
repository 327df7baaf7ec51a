#!/usr/bin/env python3
"""twist_mux on a real master: priorities, timeouts and the joystick lock of the bringup config."""

import time
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import Twist
from std_msgs.msg import Bool


def twist(vx):
    msg = Twist()
    msg.linear.x = vx
    return msg


class TwistMuxTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.received = []
        cls.diagnostics = []
        cls.joy = rospy.Publisher("teleop_joy/cmd_vel", Twist, queue_size=10)
        cls.nav = rospy.Publisher("nav_vel", Twist, queue_size=10)
        cls.lock = rospy.Publisher("teleop_joy/joy_priority", Bool, queue_size=1, latch=True)
        rospy.Subscriber("twist_mux/cmd_vel", Twist, lambda m: cls.received.append(m.linear.x))
        rospy.Subscriber("/diagnostics", DiagnosticArray, cls.diagnostics.append)
        deadline = time.time() + 20
        while time.time() < deadline and not (
            cls.joy.get_num_connections() and cls.nav.get_num_connections() and cls.lock.get_num_connections()
        ):
            time.sleep(0.05)

    def setUp(self):
        self.lock.publish(Bool(False))
        time.sleep(0.7)  # let every input time out (0.5 s)
        del self.received[:]

    def stream(self, seconds, joy=None, nav=None, hz=20):
        end = time.time() + seconds
        while time.time() < end:
            if joy is not None:
                self.joy.publish(twist(joy))
            if nav is not None:
                self.nav.publish(twist(nav))
            time.sleep(1.0 / hz)
        time.sleep(0.2)
        got = list(self.received)
        del self.received[:]
        return got

    def test_navigation_alone_is_relayed_exactly(self):
        got = self.stream(0.5, nav=0.31)
        self.assertGreater(len(got), 3)
        self.assertEqual(set(got), {0.31})

    def test_joystick_overrides_navigation(self):
        got = self.stream(0.8, joy=0.7, nav=0.31)
        self.assertIn(0.7, got)
        # after the first joystick message, navigation never passes
        first = got.index(0.7)
        self.assertEqual(set(got[first:]), {0.7})

    def test_navigation_resumes_after_the_joystick_times_out(self):
        self.stream(0.3, joy=0.7)  # ends 0.2 s after the last joystick message
        # navigation from 0.2 s to 0.3 s after the joystick's last message: within its 0.5 s timeout
        self.assertEqual(self.stream(0.1, nav=0.31), [])
        self.assertIn(0.31, self.stream(0.6, nav=0.31))

    def test_joystick_lock_blocks_navigation(self):
        self.lock.publish(Bool(True))
        time.sleep(0.3)
        self.assertEqual(self.stream(0.6, nav=0.31), [])
        self.assertEqual(set(self.stream(0.4, joy=0.2)), {0.2})
        self.lock.publish(Bool(False))
        time.sleep(0.8)
        self.assertIn(0.31, self.stream(0.4, nav=0.31))

    def test_state_on_diagnostics(self):
        self.stream(1.5, nav=0.31)
        statuses = [s for m in self.diagnostics for s in m.status if "twist mux" in s.name]
        self.assertTrue(statuses, "no twist_mux diagnostics")
        values = {kv.key: kv.value for kv in statuses[-1].values}
        self.assertEqual(values["selected"], "navigation")
        self.assertIn("lock joystick_priority", values)


if __name__ == "__main__":
    rospy.init_node("twist_mux_test")
    rostest.rosrun("thorvald_base", "twist_mux_priorities_timeouts_locks", TwistMuxTest)
