"""The ``fleet_driver`` node: the base_driver and twist_mux of every robot of a fleet, in one process.

A fleet brought up with ``fleet_driver:=true`` (thorvald_sim robot.launch, multi_sim.launch) has
each robot's parameters where its own base_driver and twist_mux would read them
(``/robot_1/base_driver/...``, ``/robot_1/twist_mux/...``), and this one process drives them all:
the same topics, services, parameters and frames per robot as the robot's own processes give, one
``/clock`` subscription and one process instead of two per robot (bench/fleet.py measures both).

Private parameters:

=================  ===============================================================================
``~robots``        the robots' namespaces: a list, or one string separated by spaces or commas
``~cmd_vel``       where each base_driver reads its commands, in its robot's namespace
                   (default ``twist_mux/cmd_vel``: twist_mux's output, as robot.launch remaps it)
``~joint_states``  where each base_driver publishes its joint states, in its robot's namespace
                   (default ``joint_states``, as the simulated robot.launch remaps it)
``~twist_mux``     run each robot's twist_mux too (default true)
``~robot_state_publisher``  publish each robot's joints on /tf and /tf_static from its
                   ``robot_description`` and ``joint_states`` as robot_state_publisher does
                   (default true; thorvald_base.state_publisher), so the fleet needs none per robot
``~publish_frequency``  robot_state_publisher's parameter of that name [Hz] (default 50)
``~fleet_topics``  a simulator node's name (``/simulator``; fleet_driver.launch gives it): the robots
                   on simulated drives (``simulated_joints``) take their drive states and currents
                   from its fleet topics and send their commands on it, one message an instant for
                   all (thorvald_sim.node.fleet_topics), instead of three topics per robot; default
                   empty: each robot's own ``drive_commands``, ``drive_states``, ``drive_currents``
=================  ===============================================================================

One robot's fault stays in that robot: a robot whose configuration is refused is left out with a
fatal log naming it and the others run (the node exits 1 only when it drives none); a robot whose
loop fails is stopped (zero-speed commands) and logged, and the others drive on; a robot's bad
command or stale drive states are refused or stop that robot alone, as in its own base_driver.
"""

import sys
import threading
import traceback

import rospy
import tf2_ros

from thorvald_model import ConfigError
from thorvald_msgs.msg import BaseStateBatch, DriveCurrentsBatch

from . import conversions
from .base_driver_node import EXIT_REFUSED, BaseDriverNode, MessageDriveTopics, spin_together
from .bases.handle import DriveTopics
from .errors import ThorvaldBaseError
from .node_names import Names, Throttle
from .params import robot_namespaces
from .state_publisher import FleetStatePublisher
from .twist_mux_node import TwistMuxNode


class FleetDriveTopics:
    """A fleet_driver's side of the simulator's fleet topics (thorvald_sim.node.fleet_topics): every
    robot's drive states and currents arrive in one message an instant, and its drive commands go in one
    (:meth:`flush`, after the cycles of all robots of an instant), each entry named by the per-robot
    topic it stands for."""

    def __init__(self, simulator: str):
        base = simulator.rstrip("/") + "/fleet/"
        # a queue: in lockstep each robot's answer goes alone, and none may be dropped
        self.pub = rospy.Publisher(base + "drive_commands", BaseStateBatch, queue_size=100)
        self.lock = threading.Lock()
        self.pending = {}  # per-robot command topic: its newest command, until flushed
        self.on_states = {}  # per-robot topic: the robot's handler of its entry
        self.on_currents = {}
        self.throttle = Throttle()
        self.subs = [
            rospy.Subscriber(base + "drive_states", BaseStateBatch, self._states, queue_size=1),
            rospy.Subscriber(base + "drive_currents", DriveCurrentsBatch, self._currents, queue_size=1),
        ]

    def robot(self, command_topic: str, state_topic: str, current_topic: str, immediate: bool) -> DriveTopics:
        """One robot's drive topics (what RosPorts.drive_topics gives its handle)."""
        return _FleetRobotTopics(self, command_topic, state_topic, current_topic, immediate)

    def send(self, topic: str, msg, immediate: bool) -> None:
        with self.lock:
            self.pending[topic] = msg  # a newer command replaces the one not sent yet
        if immediate:
            self.flush()

    def flush(self) -> None:
        """Every robot's commands since the last flush, in one message."""
        with self.lock:
            pending, self.pending = self.pending, {}
        if pending:
            stamp = max(m.header.stamp for m in pending.values())
            self.pub.publish(conversions.batch_msg(BaseStateBatch, stamp, list(pending.items())))

    def _states(self, msg):
        self._dispatch(self.on_states, msg, "drive_states")

    def _currents(self, msg):
        self._dispatch(self.on_currents, msg, "drive_currents")

    def _dispatch(self, handlers, msg, what):
        try:
            entries = conversions.batch_entries(msg)
        except ValueError as e:
            self.throttle.warn("fleet_driver: the simulator's fleet %s: %s: refused", what, e)
            return
        for topic, entry in entries:
            handler = handlers.get(topic)
            if handler is not None:
                handler(entry)


class _FleetRobotTopics(MessageDriveTopics):
    """One robot's drive topics as entries of the fleet topics."""

    def __init__(self, fleet: FleetDriveTopics, command_topic, state_topic, current_topic, immediate):
        super().__init__(state_topic, current_topic)
        self.fleet = fleet
        self.command_topic = command_topic
        self.immediate = immediate

    def send(self, commands, time, drives):
        self.fleet.send(self.command_topic, self.command_msg(commands, time, drives), self.immediate)

    def listen(self, on_states):
        self.fleet.on_states[self.state_topic] = self.states_reader(on_states)

    def listen_currents(self, on_currents):
        self.fleet.on_currents[self.current_topic] = self.currents_reader(on_currents)

    def close(self):
        self.fleet.on_states.pop(self.state_topic, None)
        self.fleet.on_currents.pop(self.current_topic, None)
        self.fleet.flush()  # what it sent last (zero speeds, at shutdown) goes out


class Robot:
    """One robot of the fleet: its base_driver and its twist_mux."""

    def __init__(
        self, ns: str, cmd_vel: str, joint_states: str, *, with_mux: bool, tf_broadcaster, state=None, fleet=None
    ):
        self.ns = ns
        if state is not None:
            state.add(ns)  # first: a robot without a usable description is refused before it drives
        self.driver = BaseDriverNode(
            Names(ns, ns + "base_driver/", {"cmd_vel": cmd_vel, "joint_states": joint_states}), tf_broadcaster, fleet
        )
        self.mux = None
        if with_mux:
            try:
                self.mux = TwistMuxNode(Names(ns, ns + "twist_mux/", {"cmd_vel_out": "twist_mux/cmd_vel"}))
            except ThorvaldBaseError:
                self.driver.shutdown()
                raise


def stop_failed(driver) -> None:
    """A driver whose cycle raised: logged with its traceback, its wheels stopped; the rest drive on."""
    rospy.logerr(
        "fleet_driver: %s failed; its wheels are stopped, the other robots drive on:\n%s",
        driver.label,
        traceback.format_exc(),
    )
    driver.shutdown()


def run_lockstep(driver) -> None:
    try:
        driver.spin_lockstep()
    except Exception:  # one robot's failure stays in that robot
        stop_failed(driver)


def loops(drivers, after_cycles=None) -> list:
    """The threads that drive them: one loop for all drivers of one rate (a wake-up per instant of
    /clock for the lot, not one per robot, then after_cycles()), one thread each in lockstep (each
    waits for its own drive states)."""
    by_rate = {}
    threads = []
    for driver in drivers:
        if driver.lockstep:
            threads.append(threading.Thread(target=run_lockstep, args=(driver,), daemon=True))
        else:
            by_rate.setdefault(driver.rate, []).append(driver)
    for rate, group in by_rate.items():
        threads.append(
            threading.Thread(target=spin_together, args=(group, rate, stop_failed, after_cycles), daemon=True)
        )
    return threads


def main():
    rospy.init_node("fleet_driver")
    try:
        namespaces = robot_namespaces(rospy.get_param("~robots", ""))
        cmd_vel = str(rospy.get_param("~cmd_vel", "twist_mux/cmd_vel"))
        joint_states = str(rospy.get_param("~joint_states", "joint_states"))
        with_mux = bool(rospy.get_param("~twist_mux", True))
        simulator = str(rospy.get_param("~fleet_topics", "") or "")
        state = None
        if rospy.get_param("~robot_state_publisher", True):
            state = FleetStatePublisher(float(rospy.get_param("~publish_frequency", 50.0)))
    except ThorvaldBaseError as e:
        rospy.logfatal("fleet_driver: refusing to start: %s", e)
        sys.exit(EXIT_REFUSED)
    broadcaster = tf2_ros.TransformBroadcaster()
    fleet = FleetDriveTopics(rospy.resolve_name(simulator)) if simulator else None
    robots = []
    for ns in namespaces:
        try:
            kwargs = {"with_mux": with_mux, "tf_broadcaster": broadcaster, "state": state, "fleet": fleet}
            robots.append(Robot(ns, cmd_vel, joint_states, **kwargs))
        except (ConfigError, ThorvaldBaseError) as e:
            rospy.logfatal("fleet_driver: %sbase_driver refusing to start: %s", ns, e)
    if not robots:
        rospy.logfatal("fleet_driver: no robot to drive")
        sys.exit(EXIT_REFUSED)
    if state is not None:
        state.publish_static()
    for robot in robots:
        rospy.on_shutdown(robot.driver.shutdown)
    rospy.loginfo(
        "fleet_driver: driving %s%s",
        " ".join(r.ns.strip("/") for r in robots),
        f" (simulated drives on {fleet.pub.resolved_name.rsplit('/', 1)[0]})" if fleet else "",
    )
    for thread in loops((r.driver for r in robots), fleet.flush if fleet else None):
        thread.start()
    rospy.spin()
