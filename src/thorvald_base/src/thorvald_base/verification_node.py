"""The ``verification_drive`` node: drives the paper's verification manoeuvre on simulated time.

It publishes the planned twists on ``cmd_vel`` (remap it to an input of twist_mux, e.g.
``nav_vel``), records ``odometry/base_raw`` and prints the report. Run it with ``/use_sim_time``
true. With ``~own_clock`` true (the default, for base_driver's own simulated drives) it owns the
simulated clock: it publishes ``/clock`` ``~speedup`` times faster than real time. With
``~own_clock`` false it follows the clock of a simulator (thorvald_sim), which sets the pace.

Parameters: ``~robot_model`` (the robot's YAML, for the plan and the report), ``~own_clock``
(default true), ``~speedup`` (default 5), ``~clock_step`` [s] of simulated time per /clock message
(default 0.005), ``~command_rate`` [Hz] (default 20), ``~startup_timeout`` [s] of wall time
(default 30), ``~command_subscribers`` (default 1: twist_mux), ``~ready_topic`` (an Odometry
topic that must publish before the drive starts, e.g. ``odometry/gazebo``: the robot is in the
simulator; default none), ``~settle`` [s] of simulated time standing still before and after the
manoeuvre (default 1), ``~recorder`` and ``~recorded_topics`` (a ``rosbag record`` node and the
topics it records, a list or a space-separated string: the drive starts only when every
publisher of each of them has a connection to the recorder, as ``rosnode info`` shows; default
none).
"""

import os
import sys
import time
import xmlrpc.client

import rosgraph
import rospy
from geometry_msgs.msg import Twist as TwistMsg
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock

from thorvald_model import ConfigError, load_robot_config

from .verification import duration, plan_for, report, twist_at

RECORDER_POLL = 0.2  # [s] wall between questions to the publishers of the recorded topics


class VerificationDrive:
    def __init__(self):
        path = rospy.get_param("~robot_model")
        self.config = load_robot_config(path)
        self.name = os.path.splitext(os.path.basename(path))[0]
        self.speedup = float(rospy.get_param("~speedup", 5.0))
        self.step = float(rospy.get_param("~clock_step", 0.005))
        self.command_period = 1.0 / float(rospy.get_param("~command_rate", 20.0))
        self.startup_timeout = float(rospy.get_param("~startup_timeout", 30.0))
        self.own_clock = bool(rospy.get_param("~own_clock", True))
        self.command_subscribers = int(rospy.get_param("~command_subscribers", 1))
        self.settle = float(rospy.get_param("~settle", 1.0))
        recorder = str(rospy.get_param("~recorder", ""))
        self.recorder = rospy.resolve_name(recorder) if recorder else ""
        topics = rospy.get_param("~recorded_topics", [])
        self.recorded = [rospy.resolve_name(t) for t in (topics.split() if isinstance(topics, str) else topics)]
        self.unrecorded = list(self.recorded) if self.recorder else []
        self.recorder_checked = 0.0  # [s] wall
        ready_topic = str(rospy.get_param("~ready_topic", ""))
        self.ready = not ready_topic
        if ready_topic:
            self.ready_sub = rospy.Subscriber(ready_topic, Odometry, self.on_ready, queue_size=1)
        self.description, self.plan = plan_for(self.config)
        self.clock_pub = rospy.Publisher("/clock", Clock, queue_size=10) if self.own_clock else None
        self.cmd_pub = rospy.Publisher("cmd_vel", TwistMsg, queue_size=10)
        self.points = []
        self.recording = False
        self.odom_seen = False
        rospy.Subscriber("odometry/base_raw", Odometry, self.on_odometry, queue_size=100)
        self.sim_time = 1.0

    def on_odometry(self, msg):
        self.odom_seen = True
        if self.recording:
            p = msg.pose.pose.position
            self.points.append((p.x, p.y))

    def on_ready(self, _msg):
        self.ready = True

    def recording_all(self) -> bool:
        """Whether the recorder has a connection from every publisher of every recorded topic (asked
        at most every RECORDER_POLL s of wall time: one XML-RPC call per publisher)."""
        if not self.unrecorded or time.time() - self.recorder_checked < RECORDER_POLL:
            return not self.unrecorded
        self.recorder_checked = time.time()
        self.unrecorded = [t for t in self.unrecorded if not connected_to(self.recorder, t)]
        return not self.unrecorded

    def tick(self):
        if self.own_clock:
            self.sim_time += self.step
            self.clock_pub.publish(Clock(rospy.Time.from_sec(self.sim_time)))
            time.sleep(self.step / self.speedup)
            return
        # the simulator's clock: rospy wakes us when /clock passes the next step (roslaunch stops us
        # if the simulator dies: it is required)
        rospy.sleep(self.sim_time + self.step - rospy.get_time())
        self.sim_time = rospy.get_time()

    def settle_for(self, seconds):
        end = self.sim_time + seconds
        while self.sim_time < end and not rospy.is_shutdown():
            self.tick()

    def run(self):
        # Let time run until base_driver publishes odometry and twist_mux listens to our commands.
        deadline = time.time() + self.startup_timeout
        if not self.own_clock:
            while rospy.get_time() == 0.0:
                if time.time() > deadline or rospy.is_shutdown():
                    raise RuntimeError("no /clock: the simulator did not come up")
                time.sleep(0.01)
            self.sim_time = rospy.get_time()
        while not (
            self.ready
            and self.odom_seen
            and self.cmd_pub.get_num_connections() >= self.command_subscribers
            and self.recording_all()
        ):
            if time.time() > deadline or rospy.is_shutdown():
                raise RuntimeError(
                    "the robot did not come up: odometry/base_raw {}, ready topic {}, {} of {} subscribers of the "
                    "commands{}".format(
                        "heard" if self.odom_seen else "silent",
                        "heard" if self.ready else "silent",
                        self.cmd_pub.get_num_connections(),
                        self.command_subscribers,
                        f", {self.recorder} not connected to {' '.join(self.unrecorded)}" if self.unrecorded else "",
                    )
                )
            self.tick()
        self.settle_for(self.settle)  # standing still
        self.points = []
        self.recording = True
        start_sim, start_wall = self.sim_time, time.time()
        next_command = start_sim
        total = duration(self.plan)
        while not rospy.is_shutdown():
            t = self.sim_time - start_sim
            twist = twist_at(self.plan, t)
            if twist is None:
                break
            if self.sim_time >= next_command:
                msg = TwistMsg()
                msg.linear.x, msg.linear.y, msg.angular.z = twist.vx, twist.vy, twist.wz
                self.cmd_pub.publish(msg)
                next_command += self.command_period
            self.tick()
        self.settle_for(self.settle)  # let the robot come to rest
        self.recording = False
        return report(
            self.name,
            self.config,
            self.description,
            self.plan,
            self.points,
            sim_time=total,
            wall=time.time() - start_wall,
        )


def connected_to(subscriber: str, topic: str) -> bool:
    """Whether topic has publishers and each has a connection to the node subscriber (their bus info)."""
    master = rosgraph.Master(rospy.get_name())
    try:
        publishers = dict(master.getSystemState()[0]).get(topic, [])
        if not publishers:
            return False
        for node in publishers:
            info = xmlrpc.client.ServerProxy(master.lookupNode(node)).getBusInfo(rospy.get_name())[2]
            # rows: (connection id, the other end's node, direction, transport, topic, connected, ...)
            if not any(row[1] == subscriber and row[2] == "o" and row[4] == topic for row in info):
                return False
    except (OSError, xmlrpc.client.Error, rosgraph.MasterError):
        return False  # a node that is starting or leaving: asked again
    return True


def main():
    rospy.init_node("verification_drive")
    try:
        drive = VerificationDrive()
        text = drive.run()
    except ConfigError as e:
        rospy.logfatal("verification_drive: %s", e)
        sys.exit(2)
    except (RuntimeError, KeyError) as e:
        rospy.logfatal("verification_drive: %s", e)
        sys.exit(1)
    print(text, flush=True)
    rospy.signal_shutdown("verification drive done")
