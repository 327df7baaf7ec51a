"""The ``verification_drive`` node: drives the paper's verification manoeuvre on simulated time.

It publishes the planned twists on ``cmd_vel`` (remap it to an input of twist_mux, e.g.
``nav_vel``) and, stamped with the instant each holds from and published ahead of it, on
``cmd_vel_stamped`` (geometry_msgs/TwistStamped: what base_driver in lockstep follows, so a
lockstep run commands the same at every instant whatever the machine's load), records
``odometry/base_raw`` and prints the report. The manoeuvre starts on a whole second of simulated
time (``~settle`` or more after the robot is ready), on the commands' grid. Run it with ``/use_sim_time``
true. With ``~own_clock`` true (the default, for base_driver's own simulated drives) it owns the
simulated clock: it publishes ``/clock`` ``~speedup`` times faster than real time. With
``~own_clock`` false it follows the clock of a simulator (thorvald_sim), which sets the pace.

Parameters: ``~robot_model`` (the robot's YAML, for the plan and the report), ``~own_clock``
(default true), ``~speedup`` (default 5), ``~clock_step`` [s] of simulated time per /clock message
(default 0.005), ``~command_rate`` [Hz] (default 20), ``~startup_timeout`` [s] of wall time
(default 30), ``~command_subscribers`` (default 1: twist_mux), ``~stamped_subscribers`` (of
``cmd_vel_stamped``, default 0; 1 for a base_driver in lockstep), ``~ready_topic`` (an Odometry
topic that must publish before the drive starts, e.g. ``odometry/gazebo``: the robot is in the
simulator; default none), ``~settle`` [s] of simulated time standing still before and after the
manoeuvre (default 1), ``~recorder`` and ``~recorded_topics`` (a ``rosbag record`` node and the
topics it records, a list or a space-separated string: the drive starts only when every
publisher of each of them has a connection to the recorder, as ``rosnode info`` shows; default
none), ``~connections`` (more such waits: a list of ``"NODE TOPIC"``, e.g. ``"base_driver
drive_states"``: every publisher of TOPIC connected to NODE; default none), ``~unpause`` (the
service that unpauses a simulator started paused, e.g. ``/simulator/unpause``: the drive waits
for its connections alone, as nothing moves yet, publishes its first stamped commands and
unpauses, so the run is the same from its first instant; the drive's own /clock subscription is
among the connections waited for; default none), ``~manoeuvre``
(``verification``, the paper's, the default; or ``calibration``: what calibrate_odometry needs,
:func:`thorvald_base.verification.plan_named`) and ``~side`` [m] (the calibration drive's square,
default 4).
"""

import math
import os
import sys
import time
import xmlrpc.client
from typing import Optional

import rosgraph
import rospy
from geometry_msgs.msg import Twist as TwistMsg
from geometry_msgs.msg import TwistStamped
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from std_srvs.srv import Empty

from thorvald_model import ConfigError, load_robot_config

from . import conversions
from .verification import SIDE, duration, plan_named, report, twist_at

CONNECTION_POLL = 0.2  # [s] wall between questions to the publishers of the awaited topics


class VerificationDrive:
    def __init__(self, manoeuvre: Optional[str] = None):
        """manoeuvre: the plan's name (thorvald_base.verification.MANOEUVRES); None: ``~manoeuvre``."""
        path = rospy.get_param("~robot_model")
        self.config = load_robot_config(path)
        self.name = os.path.splitext(os.path.basename(path))[0]
        self.speedup = float(rospy.get_param("~speedup", 5.0))
        self.step = float(rospy.get_param("~clock_step", 0.005))
        self.command_period = 1.0 / float(rospy.get_param("~command_rate", 20.0))
        self.startup_timeout = float(rospy.get_param("~startup_timeout", 30.0))
        self.own_clock = bool(rospy.get_param("~own_clock", True))
        self.command_subscribers = int(rospy.get_param("~command_subscribers", 1))
        self.stamped_subscribers = int(rospy.get_param("~stamped_subscribers", 0))
        self.settle = float(rospy.get_param("~settle", 1.0))
        recorder = str(rospy.get_param("~recorder", ""))
        self.recorder = rospy.resolve_name(recorder) if recorder else ""
        topics = rospy.get_param("~recorded_topics", [])
        self.recorded = [rospy.resolve_name(t) for t in (topics.split() if isinstance(topics, str) else topics)]
        self.unconnected = [(self.recorder, t) for t in self.recorded] if self.recorder else []
        connections = rospy.get_param("~connections", [])
        for pair in connections if isinstance(connections, list) else [connections]:
            words = str(pair).split()
            if len(words) != 2:
                raise RuntimeError(f"~connections: {pair!r}: an entry is 'NODE TOPIC', e.g. 'base_driver drive_states'")
            self.unconnected.append((rospy.resolve_name(words[0]), rospy.resolve_name(words[1])))
        unpause = str(rospy.get_param("~unpause", "") or "")
        self.unpause = rospy.resolve_name(unpause) if unpause else ""
        if self.unpause and not self.own_clock:
            # our steps follow the simulator's /clock, which a paused simulator does not publish: heard
            # late, the first ticks after the unpause were lost, the first stamped commands after them
            # never went out, and the world stood 2 s of wall time until the lockstep let the robot go
            self.unconnected.append((rospy.get_name(), "/clock"))
        self.connections_checked = 0.0  # [s] wall
        ready_topic = str(rospy.get_param("~ready_topic", ""))
        self.ready = not ready_topic
        if ready_topic:
            self.ready_sub = rospy.Subscriber(ready_topic, Odometry, self.on_ready, queue_size=1)
        if manoeuvre is None:
            manoeuvre = str(rospy.get_param("~manoeuvre", "verification"))
        self.description, self.plan = plan_named(manoeuvre, self.config, float(rospy.get_param("~side", SIDE)))
        self.clock_pub = rospy.Publisher("/clock", Clock, queue_size=10) if self.own_clock else None
        self.cmd_pub = rospy.Publisher("cmd_vel", TwistMsg, queue_size=10)
        self.stamped_pub = rospy.Publisher("cmd_vel_stamped", TwistStamped, queue_size=100)
        self.points = []
        self.recording = False
        self.odom_seen = False
        rospy.Subscriber("odometry/base_raw", Odometry, self.on_odometry, queue_size=100)
        self.sim_time = 1.0

    def on_odometry(self, msg):
        self.odom_seen = True
        if self.recording:
            p = msg.pose.pose.position
            self.points.append((msg.header.stamp.to_sec(), p.x, p.y))

    def on_ready(self, _msg):
        self.ready = True

    def connected_all(self) -> bool:
        """Whether every awaited node (the recorder, ~connections) has a connection from every
        publisher of its topic (asked at most every CONNECTION_POLL s of wall time: one XML-RPC call
        per publisher)."""
        if not self.unconnected or time.time() - self.connections_checked < CONNECTION_POLL:
            return not self.unconnected
        self.connections_checked = time.time()
        self.unconnected = [(node, t) for node, t in self.unconnected if not connected_to(node, t)]
        return not self.unconnected

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

    def run(self):
        # Let time run until base_driver publishes odometry and twist_mux listens to our commands (or,
        # with a paused simulator to unpause, until every connection is there: nothing publishes yet).
        deadline = time.time() + self.startup_timeout
        paused = bool(self.unpause)
        if not self.own_clock and not paused:
            while rospy.get_time() == 0.0:
                if time.time() > deadline or rospy.is_shutdown():
                    raise RuntimeError("no /clock: the simulator did not come up")
                time.sleep(0.01)
            self.sim_time = rospy.get_time()
        elif paused:
            self.sim_time = rospy.get_time()
        while not (
            (paused or (self.ready and self.odom_seen))
            and self.cmd_pub.get_num_connections() >= self.command_subscribers
            and self.stamped_pub.get_num_connections() >= self.stamped_subscribers
            and self.connected_all()
        ):
            if time.time() > deadline or rospy.is_shutdown():
                raise RuntimeError(
                    "the robot did not come up: odometry/base_raw {}, ready topic {}, {} of {} subscribers of the "
                    "commands, {} of {} of the stamped commands{}".format(
                        "heard" if self.odom_seen else "silent",
                        "heard" if self.ready else "silent",
                        self.cmd_pub.get_num_connections(),
                        self.command_subscribers,
                        self.stamped_pub.get_num_connections(),
                        self.stamped_subscribers,
                        "".join(f", {node} not connected to {topic}" for node, topic in self.unconnected),
                    )
                )
            if paused:
                time.sleep(0.01)
            else:
                self.tick()
        # the manoeuvre from the first whole second settle after now: its instants (and those of the
        # commands, multiples of the command period) are the same in every run
        start = float(math.ceil(self.sim_time + self.settle - 1e-9))
        total = duration(self.plan)
        stop = start + total + self.settle  # the robot has come to rest
        period = self.command_period
        stamped = math.ceil(self.sim_time / period - 1e-9)  # index of the next stamped command
        plain = None  # index of the last plain command
        self.points = []
        self.recording = True
        start_wall = None
        if paused:
            stamped = self.publish_ahead(stamped, start)
            time.sleep(0.1)  # the first stamped commands on their way to base_driver before the world moves
            self.unpause_simulator()
        while self.sim_time < stop and not rospy.is_shutdown():
            if start_wall is None and self.sim_time >= start:
                start_wall = time.time()
            stamped = self.publish_ahead(stamped, start)
            k = math.floor(self.sim_time / period + 1e-9)
            if k != plain:
                plain = k
                self.cmd_pub.publish(conversions.twist_msg(self.twist_for(k * period - start)))
            self.tick()
            self.during(start, self.sim_time - start)
        self.recording = False
        points = [(x, y) for t, x, y in self.points if start - 1e-6 <= t <= stop + 1e-6]
        return report(
            self.name,
            self.config,
            self.description,
            self.plan,
            points,
            sim_time=total,
            wall=time.time() - (start_wall or time.time()),
        )

    def during(self, start: float, t: float) -> None:
        """Called after each step of simulated time, t [s] from the plan's start at start [s] of ROS
        time (negative before it): what a drive that acts on the robot between its legs does."""

    def publish_ahead(self, index: int, start: float) -> int:
        """Publishes the stamped commands from the one of index (its instant index x the command
        period) up to a period and a step ahead of now: base_driver in lockstep, waiting at an instant
        before our next wake-up, already holds a command stamped after it. The next index."""
        period = self.command_period
        while index * period <= self.sim_time + period + self.step:
            stamp = rospy.Time.from_sec(index * period)
            self.stamped_pub.publish(conversions.twist_stamped_msg(stamp, self.twist_for(index * period - start)))
            index += 1
        return index

    def unpause_simulator(self):
        try:
            rospy.wait_for_service(self.unpause, timeout=self.startup_timeout)
            rospy.ServiceProxy(self.unpause, Empty)()
        except (rospy.ROSException, rospy.ServiceException) as e:
            raise RuntimeError(f"~unpause: {self.unpause}: {e}") from None
        rospy.loginfo("verification_drive: %s called: the drive runs from %.3f s", self.unpause, self.sim_time)

    def twist_for(self, t):
        """The plan's twist at t [s] from its start; standing still before and after it."""
        twist = twist_at(self.plan, t) if t >= 0 else None
        return (twist.vx, twist.vy, twist.wz) if twist is not None else (0.0, 0.0, 0.0)


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
