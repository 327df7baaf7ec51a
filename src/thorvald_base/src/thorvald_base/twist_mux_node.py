"""The ``twist_mux`` node: relays the highest-priority live Twist input on ``cmd_vel_out``.

Parameters (in twist_mux's format): ``~topics`` and ``~locks``, lists of ``{name, topic, timeout,
priority}`` (or mappings from name to ``{topic, timeout, priority}``); ``~diagnostics_rate`` [Hz]
(default 1). Inputs are geometry_msgs/Twist, locks std_msgs/Bool. The state is published as
diagnostic_msgs/DiagnosticArray on ``/diagnostics``.
"""

import sys

import rospy
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from geometry_msgs.msg import Twist
from std_msgs.msg import Bool

from .errors import ThorvaldBaseError
from .mux import TwistMux, parse_sources
from .node_names import Names


class TwistMuxNode:
    def __init__(self, names: Names = None):
        """names: where this mux's names are (default: this process's node; a fleet_driver gives each
        robot's)."""
        self.names = names = names or Names()
        inputs = parse_sources(rospy.get_param(names.param("topics"), None), "~topics")
        locks = parse_sources(rospy.get_param(names.param("locks"), None), "~locks")
        if not inputs:
            raise ThorvaldBaseError(
                "~topics: no input topic configured: give at least one {name, topic, timeout, priority}"
            )
        self.mux = TwistMux(inputs, locks)
        self.pub = rospy.Publisher(names.topic("cmd_vel_out"), Twist, queue_size=1)
        self.diag_pub = rospy.Publisher("/diagnostics", DiagnosticArray, queue_size=1)
        self.subs = [rospy.Subscriber(names.topic(s.topic), Twist, self.on_input, s.name, queue_size=1) for s in inputs]
        self.subs += [rospy.Subscriber(names.topic(s.topic), Bool, self.on_lock, s.name, queue_size=1) for s in locks]
        rate = float(rospy.get_param(names.param("diagnostics_rate"), 1.0))
        if rate > 0:
            self.timer = rospy.Timer(rospy.Duration(1.0 / rate), self.publish_diagnostics, reset=True)
        # the topics as subscribed, remappings applied (a launch file may remap nav_vel)
        rospy.loginfo(
            "%s: inputs %s; locks %s",
            names.label("twist_mux"),
            ", ".join(f"{s.name} ({sub.resolved_name}, priority {s.priority})" for s, sub in zip(inputs, self.subs)),
            ", ".join(
                f"{s.name} ({sub.resolved_name}, priority {s.priority})"
                for s, sub in zip(locks, self.subs[len(inputs) :])
            )
            or "none",
        )

    def on_input(self, msg, name):
        if self.mux.on_input(name, rospy.get_time()):
            self.pub.publish(msg)

    def on_lock(self, msg, name):
        self.mux.on_lock(name, msg.data, rospy.get_time())

    def publish_diagnostics(self, _event=None):
        status = self.mux.status(rospy.get_time())
        diag = DiagnosticStatus(name=self.names.node + ": twist mux", hardware_id="none")
        selected = status["selected"]
        diag.level = DiagnosticStatus.OK if selected else DiagnosticStatus.WARN
        diag.message = f"relaying {selected}" if selected else "no live input"
        values = [KeyValue("selected", selected or "none"), KeyValue("lock priority", str(status["lock_priority"]))]
        for kind, key, words in (("input", "masked", ("live", "masked")), ("lock", "locked", ("open", "locked"))):
            for s in status[kind + "s"]:
                age = "never" if s["age"] is None else f"{s['age']:.2f} s ago"
                text = f"{s['topic']} priority {s['priority']}, last {age}, {words[bool(s[key])]}"
                values.append(KeyValue(f"{kind} {s['name']}", text))
        diag.values = values
        array = DiagnosticArray(status=[diag])
        array.header.stamp = rospy.Time.now()
        self.diag_pub.publish(array)


def main():
    rospy.init_node("twist_mux")
    try:
        TwistMuxNode()
    except ThorvaldBaseError as e:
        rospy.logfatal("twist_mux: %s", e)
        sys.exit(1)
    rospy.spin()
