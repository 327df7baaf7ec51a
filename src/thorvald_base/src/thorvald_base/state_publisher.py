"""robot_state_publisher's work for every robot of a fleet_driver, in its process.

Per robot (namespace ``/robot_1/``): the description from ``robot_description``, the joint
positions from ``joint_states``, and what robot_state_publisher (ROS 1, tf2) publishes from them:
each moving joint's transform on ``/tf`` stamped with the message's stamp, and every fixed joint's
once on the latched ``/tf_static``. Its rules are kept: a message is used when its stamp is at least
1 / publish_frequency past the last use of each of its joints (``~publish_frequency`` 50 Hz, its
default), frames are the links' names. Unlike it, nothing is computed while nobody reads ``/tf``,
and it never asks the master for ``tf_prefix`` per message (robot_state_publisher 1.15 searches the
parameter server twice for every joint_states message: in a fleet of twenty at 50 Hz, 2000 calls a
second to the master).
"""

from typing import Dict, List

import rospy
import tf2_ros
from geometry_msgs.msg import TransformStamped
from sensor_msgs.msg import JointState
from tf2_msgs.msg import TFMessage

from thorvald_model.errors import UrdfError
from thorvald_model.joint_tree import JointTree, joint_positions

from .conversions import transform_msg
from .errors import ParameterError


class _Robot:
    def __init__(self, ns: str, tree: JointTree):
        self.ns = ns
        self.tree = tree
        self.last_use: Dict[str, rospy.Time] = {}


class FleetStatePublisher:
    """/tf and /tf_static of several robots' joints, one publisher each for all of them."""

    def __init__(self, publish_frequency: float = 50.0):
        if not publish_frequency > 0:
            raise ParameterError(f"~publish_frequency: {publish_frequency!r}: must be above 0 [Hz]")
        self.interval = rospy.Duration.from_sec(1.0 / publish_frequency)
        self.tf_pub = rospy.Publisher("/tf", TFMessage, queue_size=100)
        self.static = tf2_ros.StaticTransformBroadcaster()
        self.static_transforms: List[TransformStamped] = []
        self.subs = []

    def add(self, ns: str) -> None:
        """Robot ns's joints: its robot_description read and checked (ParameterError), its joint_states followed."""
        name = ns + "robot_description"
        xml = rospy.get_param(name, None)
        if not isinstance(xml, str) or not xml.strip():
            raise ParameterError(f"{name}: <missing>: robot_state_publisher's work needs the robot's description")
        try:
            robot = _Robot(ns, JointTree(xml))
        except UrdfError as e:
            raise ParameterError(f"{name}: {e}") from None
        stamp = rospy.Time.now()
        self.static_transforms += [transform_msg(stamp, *fixed) for fixed in robot.tree.fixed_transforms()]
        self.subs.append(rospy.Subscriber(ns + "joint_states", JointState, self.on_joint_states, robot, queue_size=1))

    def publish_static(self) -> None:
        """Every robot's fixed joints in one latched message (the broadcaster keeps its last only)."""
        if self.static_transforms:
            self.static.sendTransform(self.static_transforms)

    def on_joint_states(self, msg: JointState, robot: _Robot) -> None:
        if not self.tf_pub.get_num_connections():
            return
        stamp = msg.header.stamp
        if robot.last_use:
            last = min((robot.last_use.get(n, rospy.Time()) for n in msg.name), default=stamp)
            if last > stamp + rospy.Duration(1.0):  # time moved backwards (a simulation restarted)
                robot.last_use.clear()
            elif stamp < last + self.interval:
                return
        transforms = robot.tree.moving_transforms(joint_positions(msg.name, msg.position))
        for n in msg.name:
            robot.last_use[n] = stamp
        if transforms:
            self.tf_pub.publish(TFMessage([transform_msg(stamp, *t) for t in transforms]))
