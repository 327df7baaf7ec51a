#!/usr/bin/env python3
"""With ``<remap from="nav_vel" to="auto_nav/cmd_vel"/>`` before twist_mux.launch, navigation
commands on the paper's auto_nav/cmd_vel come out of the mux on twist_mux/cmd_vel."""

import unittest

import rosgraph
import rospy
import rostest
from driver_testing import WAIT, CommandStream, Topic, twist
from geometry_msgs.msg import Twist


class PaperNavTopicTest(unittest.TestCase):
    def test_auto_nav_cmd_vel_reaches_the_mux_output(self):
        out = Topic("twist_mux/cmd_vel", Twist)
        nav = CommandStream("auto_nav/cmd_vel")
        try:
            self.assertTrue(nav.wait_for_subscriber(), "twist_mux did not subscribe to auto_nav/cmd_vel")
            nav.send(twist(0.37))
            msg = out.wait_for(lambda m: m.linear.x == 0.37, timeout=WAIT)
            self.assertIsNotNone(msg, "auto_nav/cmd_vel did not come out on twist_mux/cmd_vel")
            # the remap moved the input: nothing subscribes to nav_vel
            _, subscribers, _ = rosgraph.Master("/paper_nav_topic_test").getSystemState()
            self.assertNotIn("/robot_1/nav_vel", [topic for topic, _ in subscribers])
        finally:
            nav.stop()


if __name__ == "__main__":
    rospy.init_node("paper_nav_topic_test")
    rostest.rosrun("thorvald_base", "twist_mux_paper_nav_topic", PaperNavTopicTest)
