#!/usr/bin/env python3
"""Twelve robots in one world on simulated time, each commanded on its own (issue 24).

r0 .. r5 run base_driver and twist_mux processes of their own, r6 .. r11 share one fleet_driver.
Every robot but r4 and r10 drives its own twist (0.30 to 0.39 m/s; straight, left or right arcs);
r4 and r10 are never commanded. Then, mid-run, r2's base_driver process is killed (SIGKILL: no
goodbye, the simulator's command timeout has to stop it) and r8, one of fleet_driver's, is sent
NaN commands, which its base_driver refuses: those two stop, every other robot drives on as
commanded, and the two idle ones stay put. fleet_driver's robots exchange their drive topics with
the simulator on its fleet topics (fleet_driver.launch's default), their own topics unread; a batch
whose lengths differ (refused with a warning) and one naming a topic no robot follows (dropped, as a
message nobody reads), sent there meanwhile, change nothing.

With physics workers (sim_fleet12_workers.test: the test node's ``~physics_workers`` 2, the simulator's
strips split at x = 9), the same, and then worker 1 (its pid from the simulator's ``~worker_pids``),
holding the robots at x 12 and 18, is killed: its robots' topics go silent, the other worker's
robots drive on as commanded, the simulator reports the death on /diagnostics, and one of the dead
worker's robots is deleted.
"""

import math
import os
import signal
import threading
import time
import unittest
import xmlrpc.client

import rosgraph
import rosnode
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import Twist
from rosgraph_msgs.msg import Log
from sim_testing import Latest, planar, sim_sleep

from thorvald_msgs.msg import BaseState, BaseStateBatch
from thorvald_msgs.srv import DeleteRobot

ROBOTS = [f"r{k}" for k in range(12)]
IDLE = ("r4", "r10")
KILLED = "r2"  # its own base_driver process, killed
REFUSED = "r8"  # fleet_driver's, sent NaN commands
PHASE = 4.0  # [s] simulated, each phase
STRIP = 9.0  # [m] with physics workers: worker 0 holds the robots at x 0 and 6, worker 1 those at 12 and 18
AFTER_KILL = 2.0  # [s] simulated
DELETED = "r3"  # a robot of the killed worker, deleted after its death
TOUCHING = 2.5  # [m] between two standard robots' base_links: their frames may touch
DIAGNOSTICS_WAIT = 30.0  # [s] wall, for /diagnostics (1 Hz of wall time) to report the dead worker


def spawn_x(robot):
    """[m] the robot's spawn x in sim_fleet12.test: 0, 6, 12, 18 along each row."""
    return 6.0 * (ROBOTS.index(robot) % 4)


def in_world(robot, pose):
    """(x, y) [m] in the world of a pose in the robot's odom frame (its spawn pose, heading along x)."""
    return spawn_x(robot) + pose[0], 6.0 * (ROBOTS.index(robot) // 4) + pose[1]


def twist_of(k):
    """Robot k's own command (vx [m/s], wz [rad/s])."""
    return 0.30 + 0.03 * (k % 4), (0.0, 0.2, -0.2)[k % 3]


class FleetCommander:
    """Every robot's twist on its nav_vel at 20 Hz of simulated time, from one thread."""

    def __init__(self):
        self.pubs = {r: rospy.Publisher(f"/{r}/nav_vel", Twist, queue_size=1) for r in ROBOTS}
        self.twists = {}
        self.lock = threading.Lock()
        threading.Thread(target=self.run, daemon=True).start()

    def send(self, robot, vx, wz):
        t = Twist()
        t.linear.x, t.angular.z = vx, wz
        with self.lock:
            self.twists[robot] = t

    def run(self):
        last = None
        while not rospy.is_shutdown():
            now = rospy.get_time()
            if last is None or now - last >= 0.05 or now < last:
                last = now
                with self.lock:
                    twists = dict(self.twists)
                for robot, twist in twists.items():
                    self.pubs[robot].publish(twist)
            time.sleep(0.002)


def speeds(truth):
    """(speed [m/s], yaw rate [rad/s]) of the latest ground truth."""
    t = truth.get().twist.twist
    return math.hypot(t.linear.x, t.linear.y), t.angular.z


class SimulatorDiagnostics:
    """The simulator's latest /diagnostics status of each name (other nodes publish there too)."""

    def __init__(self):
        self.statuses = {}
        self.lock = threading.Lock()
        self.sub = rospy.Subscriber("/diagnostics", DiagnosticArray, self.on_diagnostics, queue_size=10)

    def on_diagnostics(self, msg):
        with self.lock:
            for status in msg.status:
                if status.name.startswith("/simulator: "):
                    self.statuses[status.name] = status

    def wait_for(self, name, level):
        """The status name once it has level (within DIAGNOSTICS_WAIT of wall time)."""
        deadline = time.time() + DIAGNOSTICS_WAIT
        while time.time() < deadline and not rospy.is_shutdown():
            with self.lock:
                status = self.statuses.get(name)
            if status is not None and status.level == level:
                return status
            time.sleep(0.1)
        raise AssertionError(f"no {name} of level {level} on /diagnostics; last: {status}")


def kill_process_of(node):
    uri = rosgraph.Master("/sim_fleet12_test").lookupNode(node)
    code, _, pid = xmlrpc.client.ServerProxy(uri).getPid("/sim_fleet12_test")
    if code != 1:
        raise AssertionError(f"{node} did not give its pid")
    os.kill(pid, signal.SIGKILL)
    return pid


def send_bad_batches():
    """On the simulator's fleet command topic: lengths that differ, and a topic no robot follows."""
    pub = rospy.Publisher("/simulator/fleet/drive_commands", BaseStateBatch, queue_size=10)
    deadline = time.time() + 30
    while pub.get_num_connections() == 0 and time.time() < deadline:
        time.sleep(0.05)
    stop = BaseState(prop_speed=[0.0] * 4, steer_pos=[0.0] * 4)
    pub.publish(BaseStateBatch(topics=["/r9/drive_commands", "/r11/drive_commands"], messages=[stop]))
    pub.publish(BaseStateBatch(topics=["/nobody/drive_commands"], messages=[stop]))


class SimFleet12Test(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.said = []  # /rosout from the start
        rospy.Subscriber("/rosout", Log, cls.said.append, queue_size=1000)
        cls.truth = {r: Latest(f"/{r}/odometry/gazebo") for r in ROBOTS}
        cls.odometry = {r: Latest(f"/{r}/odometry/base_raw") for r in ROBOTS}
        cls.commander = FleetCommander()
        for r in ROBOTS:
            cls.truth[r].wait()
            cls.odometry[r].wait()
        deadline = time.time() + 120
        while any(p.get_num_connections() == 0 for p in cls.commander.pubs.values()):
            if time.time() > deadline:
                raise AssertionError("a robot's twist_mux never subscribed to its nav_vel")
            time.sleep(0.1)
        sim_sleep(1.0)
        cls.start = {r: planar(cls.truth[r].get()) for r in ROBOTS}
        for k, r in enumerate(ROBOTS):
            if r not in IDLE:
                cls.commander.send(r, *twist_of(k))
        sim_sleep(PHASE)
        cls.first = {r: speeds(cls.truth[r]) for r in ROBOTS}
        cls.mid = {r: planar(cls.truth[r].get()) for r in ROBOTS}
        cls.killed_pid = kill_process_of(f"/{KILLED}/base_driver")
        cls.commander.send(REFUSED, math.nan, 0.0)
        cls.graph = dict(zip(("publishers", "subscribers"), rosgraph.Master("/sim_fleet12_test").getSystemState()))
        send_bad_batches()  # the simulator's /rosout has long been connected: the robots came on it
        sim_sleep(PHASE)
        cls.second = {r: speeds(cls.truth[r]) for r in ROBOTS}
        cls.end = {r: planar(cls.truth[r].get()) for r in ROBOTS}
        sim_sleep(1.0)
        cls.last = {r: planar(cls.truth[r].get()) for r in ROBOTS}
        cls.fleet_driver_alive = rosnode.rosnode_ping("/fleet_driver", max_count=1)

    def check_as_commanded(self, robot, measured):
        vx, wz = twist_of(ROBOTS.index(robot))
        speed, rate = measured
        rospy.loginfo("%s: %.3f m/s, %.3f rad/s (commanded %.2f, %.2f)", robot, speed, rate, vx, wz)
        self.assertAlmostEqual(speed, vx, delta=0.05 * vx, msg=f"{robot}'s speed")
        self.assertAlmostEqual(rate, wz, delta=0.03, msg=f"{robot}'s yaw rate")

    def test_every_commanded_robot_drives_its_own_twist(self):
        for r in ROBOTS:
            if r not in IDLE:
                with self.subTest(robot=r):
                    self.check_as_commanded(r, self.first[r])

    def test_the_uncommanded_robots_stay_put(self):
        for r in IDLE:
            moved = math.hypot(self.last[r][0] - self.start[r][0], self.last[r][1] - self.start[r][1])
            rospy.loginfo("%s (idle): moved %.4f m", r, moved)
            self.assertLess(moved, 0.01, f"{r} moved")

    def test_a_killed_base_driver_stops_only_its_robot(self):
        speed, _ = self.second[KILLED]
        moved = math.hypot(self.last[KILLED][0] - self.end[KILLED][0], self.last[KILLED][1] - self.end[KILLED][1])
        rospy.loginfo("%s (base_driver pid %d killed): %.4f m/s, then %.4f m", KILLED, self.killed_pid, speed, moved)
        self.assertLess(speed, 0.02)
        self.assertLess(moved, 0.01)

    def test_nan_commands_stop_only_their_robot_in_the_fleet_driver(self):
        speed, _ = self.second[REFUSED]
        rospy.loginfo("%s (NaN commands): %.4f m/s", REFUSED, speed)
        self.assertLess(speed, 0.02)
        self.assertTrue(self.fleet_driver_alive, "fleet_driver went down")

    def test_fleet_driver_uses_the_fleet_topics_and_the_others_their_own(self):
        def nodes(kind, topic):
            return dict(self.graph[kind]).get(topic, [])

        self.assertEqual(nodes("subscribers", "/simulator/fleet/drive_states"), ["/fleet_driver"])
        self.assertEqual(nodes("publishers", "/simulator/fleet/drive_commands"), ["/fleet_driver"])
        for r in ROBOTS:
            with self.subTest(robot=r):
                own = f"/{r}/base_driver"
                fleet = ROBOTS.index(r) >= 6
                self.assertEqual(nodes("subscribers", f"/{r}/drive_states"), [] if fleet else [own])
                self.assertEqual(nodes("publishers", f"/{r}/drive_commands"), [] if fleet else [own])

    def test_a_bad_fleet_batch_is_refused_with_a_warning(self):
        warned = [m.msg for m in self.said if m.name == "/simulator" and m.level == Log.WARN]
        self.assertTrue(any("2 topics for 1 messages: refused" in m for m in warned), warned)

    def test_the_others_drive_on(self):
        for r in ROBOTS:
            if r not in (*IDLE, KILLED, REFUSED):
                with self.subTest(robot=r):
                    self.check_as_commanded(r, self.second[r])


class SimFleet12WorkersTest(SimFleet12Test):
    """sim_fleet12_workers.test: the same, the physics in two workers; then worker 1 is killed."""

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        # Worker 1 (x >= STRIP) killed mid-drive: its robots' topics go silent, worker 0's drive on
        cls.diagnostics = SimulatorDiagnostics()
        cls.dead = [r for r in ROBOTS if spawn_x(r) >= STRIP]
        cls.worker_pid = rospy.get_param("/simulator/worker_pids")[1]
        cls.before_kill = {r: planar(cls.truth[r].get()) for r in ROBOTS}
        cls.killed_at = rospy.get_time()
        os.kill(cls.worker_pid, signal.SIGKILL)
        sim_sleep(AFTER_KILL)
        cls.after_kill = {r: planar(cls.truth[r].get()) for r in ROBOTS}
        cls.heard = {r: cls.truth[r].get().header.stamp.to_sec() for r in ROBOTS}
        cls.checked_at = rospy.get_time()
        # the death on /diagnostics (read here: a robot deleted below leaves it), then a dead robot deleted
        try:
            cls.workers_status = cls.diagnostics.wait_for("/simulator: physics workers", 2)
            cls.robot_statuses = {r: cls.diagnostics.wait_for(f"/simulator: robot {r}", 2) for r in cls.dead}
        except AssertionError as e:
            cls.workers_status, cls.robot_statuses = None, str(e)
        cls.deleted = rospy.ServiceProxy("/simulator/delete_robot", DeleteRobot)(model_name=DELETED)

    def test_a_killed_physics_worker_silences_only_its_robots(self):
        self.assertEqual(sorted(self.dead), ["r10", "r11", "r2", "r3", "r6", "r7"])
        for r in ROBOTS:
            with self.subTest(robot=r):
                rospy.loginfo(
                    "%s: last ground truth at %.3f s (worker killed at %.3f s)", r, self.heard[r], self.killed_at
                )
                if r in self.dead:
                    self.assertLess(self.heard[r], self.killed_at + 0.5, f"{r} still heard after its worker died")
                else:
                    self.assertGreater(self.heard[r], self.checked_at - 0.5, f"{r} went silent")
        live = [r for r in ROBOTS if r not in self.dead]
        checked = []
        for r in live:
            # r1 and r5 circle towards each other, and meet about now: a robot that touches another is left out
            here = in_world(r, self.after_kill[r])
            touching = [o for o in live if o != r and math.dist(here, in_world(o, self.after_kill[o])) < TOUCHING]
            if r not in (*IDLE, KILLED, REFUSED) and not touching:
                with self.subTest(robot=r):
                    vx, _ = twist_of(ROBOTS.index(r))
                    start, end = self.before_kill[r], self.after_kill[r]
                    moved = math.hypot(end[0] - start[0], end[1] - start[1])
                    rospy.loginfo(
                        "%s: %.3f m in %.1f s after the worker died (commanded %.2f m/s)", r, moved, AFTER_KILL, vx
                    )
                    self.assertGreater(moved, 0.9 * vx * AFTER_KILL, f"{r} stopped with the other worker")
                    checked.append(r)
        self.assertGreaterEqual(len(checked), 2, "too few robots free to drive to judge")

    def test_a_killed_physics_worker_is_reported_on_diagnostics(self):
        self.assertIsNotNone(self.workers_status, self.robot_statuses)
        self.assertIn(f"worker 1 (pid {self.worker_pid})", self.workers_status.message)
        for r in self.dead:
            with self.subTest(robot=r):
                robot = self.robot_statuses[r]
                self.assertIn("physics worker 1", robot.message)
                self.assertIn("killed by signal 9", robot.message)

    def test_a_robot_of_a_dead_worker_can_be_deleted(self):
        self.assertTrue(self.deleted.success, self.deleted.message)
        self.assertEqual(self.deleted.message, f"deleted {DELETED}")


if __name__ == "__main__":
    rospy.init_node("sim_fleet12_test")
    if rospy.get_param("~physics_workers", 1) > 1:
        rostest.rosrun("thorvald_sim", "sim_fleet12_workers", SimFleet12WorkersTest)
    else:
        rostest.rosrun("thorvald_sim", "sim_fleet12", SimFleet12Test)
