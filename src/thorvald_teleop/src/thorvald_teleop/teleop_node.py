"""``teleop_node``: sensor_msgs/Joy to velocity commands (the paper's thorvald_teleop, Figure 4).

Subscribes ``joy``; publishes ``cmd_vel`` (geometry_msgs/Twist; the launch file remaps it to
``teleop_joy/cmd_vel``, twist_mux's joystick input) and ``joy_priority`` (std_msgs/Bool, latched;
remapped to ``teleop_joy/joy_priority``, twist_mux's lock on navigation); calls ``home_steering``
(std_srvs/Trigger; remapped to ``base_driver/home_steering``). Parameters: teleop_twist_joy's
(``enable_button``, ``enable_turbo_button``, ``axis_linear`` {x, y}, ``scale_linear``,
``scale_linear_turbo``, ``axis_angular`` {yaw}, ``scale_angular``, ``scale_angular_turbo``) and
ours: ``priority_button``, ``home_steering_button``, ``joy_timeout`` (0.5 s). The rules are in
thorvald_teleop.teleop; a controller file (config/*.yaml) sets them all.
"""

import sys
import threading

import rospy
from geometry_msgs.msg import Twist
from sensor_msgs.msg import Joy
from std_msgs.msg import Bool
from std_srvs.srv import Trigger

from .errors import ThorvaldTeleopError
from .teleop import Actions, TeleopConfig, TeleopCore

WARN_PERIOD = 5.0  # [s]


class TeleopNode:
    def __init__(self):
        self.config = TeleopConfig.from_params(rospy.get_param("~", {}))
        self.core = TeleopCore(self.config)
        self.lock = threading.Lock()
        self.cmd_pub = rospy.Publisher("cmd_vel", Twist, queue_size=1, tcp_nodelay=True)
        self.priority_pub = rospy.Publisher("joy_priority", Bool, queue_size=1, latch=True)
        self.priority_pub.publish(Bool(False))
        self.home = rospy.ServiceProxy("home_steering", Trigger)
        rospy.Subscriber("joy", Joy, self.on_joy, queue_size=1, tcp_nodelay=True)
        rospy.Timer(rospy.Duration(0.05), self.on_timer, reset=True)
        c = self.config
        rospy.loginfo(
            "teleop_node: deadman %d, turbo %d, priority toggle %d, home steering %d; linear %s x %s, angular %s x %s",
            c.enable_button,
            c.enable_turbo_button,
            c.priority_button,
            c.home_steering_button,
            c.axis_linear,
            c.scale_linear,
            c.axis_angular,
            c.scale_angular,
        )

    def on_joy(self, msg):
        with self.lock:
            actions = self.core.on_joy(msg.axes, msg.buttons, rospy.get_time())
        self.apply(actions)

    def on_timer(self, _event):
        with self.lock:
            actions = self.core.on_timer(rospy.get_time())
        if actions.twist is not None:
            rospy.logwarn_throttle(WARN_PERIOD, "teleop_node: joystick messages stopped with the deadman held: stop")
        self.apply(actions)

    def apply(self, actions: Actions):
        if actions.twist is not None:
            t = Twist()
            t.linear.x, t.linear.y, t.angular.z = actions.twist
            self.cmd_pub.publish(t)
        if actions.priority is not None:
            self.priority_pub.publish(Bool(actions.priority))
            rospy.loginfo(
                "teleop_node: joystick priority %s", "on: navigation locked out" if actions.priority else "off"
            )
        if actions.home_steering:
            threading.Thread(target=self.call_home, daemon=True).start()  # never block the joystick

    def call_home(self):
        try:
            self.home.wait_for_service(timeout=1.0)
            response = self.home()
            rospy.loginfo("teleop_node: home_steering: %s", response.message)
        except (rospy.ROSException, rospy.ServiceException) as e:
            rospy.logwarn("teleop_node: home_steering failed: %s", e)


def main():
    rospy.init_node("teleop_node")
    try:
        TeleopNode()
    except ThorvaldTeleopError as e:
        rospy.logfatal("teleop_node: refusing to start: %s", e)
        return 1
    rospy.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())
