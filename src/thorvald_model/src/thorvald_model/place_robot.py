"""``place_robot`` node: a static transform from a world frame to a robot's base_link.

Stands in for static_transform_publisher (not packaged here) when several robots are shown at once
(fleet.launch): private parameters ~parent (default "world"), ~child (e.g. "robot_1/base_link"),
~x, ~y [m] and ~yaw [rad].
"""

import math
import sys

import rospy
import tf2_ros
from geometry_msgs.msg import TransformStamped


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
    rospy.spin()
    return 0


if __name__ == "__main__":
    sys.exit(main())
