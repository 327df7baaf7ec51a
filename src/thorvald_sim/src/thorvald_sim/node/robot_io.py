"""The ROS side of one simulated robot in the simulator node: its command topic, ground truth, joint
states, drive states and currents, and its sensors' messages, each published from what the physics
read after a step (:mod:`thorvald_sim.physics.engine`) and only while somebody reads it."""

import threading
import time

import rosgraph
import rospy
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState

from thorvald_base import conversions
from thorvald_base.publishing import NonBlockingPublisher, recorded_publisher
from thorvald_msgs.msg import BaseState, DriveCurrents

from ..physics.engine import Reads
from ..sensors.mounted import refused_sensors
from .commands import APPLY, HOLD, CommandSlot
from .sensor_io import RobotSensors
from .tf_watch import TfWatch

WARN_PERIOD = 5.0  # [s] between repeats of one warning
TF_POLL = 2.0  # [s] wall: how often the master is asked who publishes /tf (another odom -> base_link)


class RobotIO:
    """The ROS side of one simulated robot."""

    def __init__(self, node, robot, namespace: str, command_topic: str, publish_tf: bool):
        self.robot = robot
        d = robot.description
        ns = namespace.rstrip("/") + "/" if namespace else "/"
        self.namespace = ns
        self.publish_tf = publish_tf
        # ground truth and the sensors, which a lockstep run records: nothing lost then (the world waits)
        self.odom_pub = recorded_publisher(node.lockstep)(ns + d.odometry_topic, Odometry)
        self.joint_pub = NonBlockingPublisher(ns + "joint_states", JointState)
        self.drive_pub = NonBlockingPublisher(ns + "drive_states", BaseState)
        self.current_pub = NonBlockingPublisher(ns + "drive_currents", DriveCurrents)
        self.commands = CommandSlot(len(robot.wheels))  # the latest, to apply in the loop
        self.node = node
        self.alive = True  # False once its physics worker died: its topics go silent
        self.sub = rospy.Subscriber(ns + command_topic, BaseState, self.on_command, queue_size=1)
        self.passive = [j for j, _ in robot.passive] + [j for j, _ in robot.springs]
        self.passive_names = [info.name for _, info in robot.passive] + [s.joint for _, s in robot.springs]
        self.sensors = RobotSensors(
            robot.sensors,
            namespace or "/",
            refused_sensors(robot.sensor_blocks, robot.sensor_problems),
            publisher=recorded_publisher(node.lockstep),
        )

    def on_command(self, msg):
        stamp = msg.header.stamp.to_sec()
        problem = self.commands.put(msg.steer_pos, msg.prop_speed, msg.steer_max_speed, self.node.sim.time, stamp)
        if problem:
            rospy.logwarn_throttle(WARN_PERIOD, "simulator: %s: %s", self.robot.name, problem)
            return
        if self.node.lockstep and self.node.waits.answered(self.robot.name, stamp):
            rospy.loginfo("simulator: %s in lockstep", self.robot.name)

    def apply(self, now: float, timeout: float) -> None:
        """In the loop, before a step: the latest command, or a stop if commands stopped coming."""
        action, command = self.commands.take(now, timeout)
        if action == APPLY:
            self.robot.command(*command)
        elif action == HOLD:
            self.robot.hold()

    def restart_time(self) -> None:
        """Simulated time went back to zero (the Gazebo API's reset_simulation)."""
        self.commands.restart_time()
        self.sensors.restart_time()

    def reads(
        self, drives: bool, currents: bool, odometry: bool, tf_read: bool, now: float, *, fleet=(False, False)
    ) -> Reads:
        """What to read of this robot after the step to now: what is due, and read (here, or on the
        fleet topics: fleet is whether their drive states and currents are read)."""
        return Reads(
            states=drives and (fleet[0] or self.drive_pub.get_num_connections() > 0),
            currents=currents and (fleet[1] or self.current_pub.get_num_connections() > 0),
            odometry=odometry and bool(self.odom_pub.get_num_connections() or (self.publish_tf and tf_read)),
            joints=odometry and bool(self.passive) and self.joint_pub.get_num_connections() > 0,
            sensors=self.sensors.requests(now),
        )

    def publish_odometry(self, stamp, tf_read: bool):
        """odometry/gazebo, joint_states of the passive joints: what was read after the step (what
        somebody reads); the transform of odometry/gazebo for /tf if tf_read and this robot publishes
        it, else None."""
        got = self.robot.got
        transform = None
        if got.odometry and (self.odom_pub.get_num_connections() or (self.publish_tf and tf_read)):
            transform = self._publish_odometry(stamp, tf_read)
        if got.joints and self.passive and self.joint_pub.get_num_connections():
            states = self.robot.joint_states(self.passive)
            self.joint_pub.publish(
                conversions.joint_state_msg(stamp, self.passive_names, [s[0] for s in states], [s[1] for s in states])
            )
        return transform

    def _publish_odometry(self, stamp, tf_read: bool):
        d = self.robot.description
        position, orientation = self.robot.odom_pose()
        linear, angular = self.robot.body_twist()
        msg = conversions.pose_odometry_msg(
            stamp,
            d.odometry_frame,
            d.base_frame,
            position=position,
            orientation=orientation,
            linear=linear,
            angular=angular,
        )
        self.odom_pub.publish(msg)
        return conversions.odometry_transform(msg) if self.publish_tf and tf_read else None

    def publish_drives(self, stamp, fleet=(None, None)):
        """drive_currents and drive_states at stamp: what was read after the step (those due, each if
        somebody reads it); fleet: the fleet topics' lists of drive states and of drive currents, which
        this robot's messages join as (its topic, message), each None while nobody reads it."""
        now = stamp.to_sec()
        got = self.robot.got
        # the currents first: a lockstep base_driver runs its cycle once the instant's states came
        if got.currents:
            here = self.current_pub.get_num_connections() > 0
            if here or fleet[1] is not None:
                currents = self.robot.drive_currents(now)
                msg = conversions.currents_msg(stamp, [c[0] for c in currents], [c[1] for c in currents])
                if here:
                    self.current_pub.publish(msg)
                if fleet[1] is not None:
                    fleet[1].append((self.current_pub.resolved_name, msg))
        if got.states:
            here = self.drive_pub.get_num_connections() > 0  # base_driver with measured drives
            if here or fleet[0] is not None:
                # its reader is there: in lockstep from its first drive states on, not its first answer
                if self.node.lockstep and self.node.waits.published(self.robot.name, now):
                    rospy.loginfo("simulator: %s in lockstep", self.robot.name)
                msg = conversions.state_msg(stamp, self.robot.drive_states(now))
                if here:
                    self.drive_pub.publish(msg)
                if fleet[0] is not None:
                    fleet[0].append((self.drive_pub.resolved_name, msg))

    def close(self):
        self.sub.unregister()
        for pub in (self.odom_pub, self.joint_pub, self.drive_pub, self.current_pub):
            pub.unregister()
        self.sensors.close()


class TfWatcher:
    """Other publishers of the robots' ``odom -> base_link`` (:mod:`thorvald_sim.node.tf_watch`), watched
    for the node from a thread of its own: every TF_POLL seconds of wall time (or at once after a
    spawn: :meth:`poll`) the master's /tf publishers go to TfWatch, /tf is read while it has something
    to judge, and each robot (robots: the node's RobotIO by name) leaves its transform to another
    publisher while that one publishes it, and takes it back when it stops, said once."""

    def __init__(self, node_name: str, robots):
        self.watch = TfWatch(node_name)
        self.robots = robots
        self.reader = None  # the /tf subscription while TfWatch has publishers to judge
        self.said = set()  # robots whose other publisher of odom -> base_link was warned about
        self.now = threading.Event()
        threading.Thread(target=self.run, name="tf_watch", daemon=True).start()

    def poll(self) -> None:
        """Look at /tf's publishers now, not at the next poll (a robot was spawned)."""
        self.now.set()

    def run(self):
        master = rosgraph.Master(rospy.get_name())
        while not rospy.is_shutdown():
            try:
                publishers = dict(master.getSystemState()[0]).get("/tf", [])
            except Exception as e:  # the master went away: nothing to judge until it is back
                rospy.logdebug("simulator: cannot ask the master for /tf's publishers: %s", e)
                publishers = []
            self.watch.publishers(publishers)
            for conflict in self.watch.resumed(time.monotonic()):
                io = self.robots.get(conflict.robot)
                if io is not None:
                    io.publish_tf = True
                    rospy.loginfo(
                        "simulator: %s: %s stopped publishing %s -> %s: the simulator publishes it again",
                        conflict.robot, conflict.publisher, conflict.parent, conflict.child,
                    )  # fmt: skip
            listening = self.watch.listening()
            if listening and self.reader is None:
                self.reader = rospy.Subscriber("/tf", rospy.AnyMsg, self.on_tf, queue_size=50)
            elif not listening and self.reader is not None:
                self.reader.unregister()
                self.reader = None
            self.now.wait(TF_POLL)
            self.now.clear()

    def on_tf(self, msg):
        caller = msg._connection_header.get("callerid", "")
        for conflict in self.watch.message(caller, msg._buff, time.monotonic()):
            io = self.robots.get(conflict.robot)
            if io is None:
                continue
            io.publish_tf = False
            if conflict.robot in self.said:
                rospy.loginfo(
                    "simulator: %s: %s publishes %s -> %s again: the simulator leaves it to it",
                    conflict.robot, conflict.publisher, conflict.parent, conflict.child,
                )  # fmt: skip
                continue
            self.said.add(conflict.robot)
            rospy.logwarn(
                "simulator: %s: %s publishes %s -> %s on /tf, and so does the simulator (%s, from ground truth): "
                "the simulator leaves it to %s while it does, so the tree does not flicker between the two "
                "(spawn with -no_publish_tf, or give base_driver enable_odom_tf:=false, to choose one yourself)",
                conflict.robot, conflict.publisher, conflict.parent, conflict.child, rospy.get_name(),
                conflict.publisher,
            )  # fmt: skip
