"""``place_robot`` node: a static transform from a world frame to a robot's base_link.

Stands in for static_transform_publisher (not packaged here) when several robots are shown at once
(fleet.launch): private parameters ~parent (default "world"), ~child (e.g. "robot_1/base_link"),
~x, ~y [m] and ~yaw [rad].

A static transform needs no clock: on simulated time the node stops reading /clock once the
transform is out (rospy subscribes every node to /clock, 100 messages a simulated second, which in a
fleet of twenty costs the simulator and this node more than the transform ever does).
"""

import math
import sys

import rospy
import tf2_ros
from geometry_msgs.msg import TransformStamped


def stop_reading_clock() -> None:
    """Unsubscribes rospy's own /clock subscriber (on simulated time; nothing otherwise)."""
    from rospy.impl import simtime  # noqa: PLC0415  (rospy keeps it there, unnamed in its API)

    clock = getattr(simtime, "_clock_sub", None)
    if clock is not None:
        clock.unregister()


def main() -> int:
    rospy.init_node("place_robot")
    t = TransformStamped()
    t.header.stamp = rospy.Time.now()
    t.header.frame_id = rospy.get_param("~parent", "world")
    t.child_frame_id = rospy.get_param("~child", "base_link")
    t.transform.translation.x = float(rospy.get_param("~x", 0.0))
    t.transform.translation.y = float(rospy.get_param("~y", 0.0))
    yaw = float(rospy.get_param("~yaw", 0.0))
    t.transform.rotation.z = math.sin(yaw / 2.0)
    t.transform.rotation.w = math.cos(yaw / 2.0)
    broadcaster = tf2_ros.StaticTransformBroadcaster()
    broadcaster.sendTransform(t)
    stop_reading_clock()
    rospy.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())
