"""Robots and operators on separate hosts (issue 13): ROS 1 across a real network link, and what
happens when the link drops.

The suite builds its own network on this machine and tears it down afterwards, even when a check
fails: network namespaces ("hosts") joined by veth pairs to a Linux bridge, all on one /24.

    host          namespace        address       runs
    robot host 1  thvnet<pid>-r1   10.213.0.1    the ROS master, the simulator (/clock) and robot_1
                                                 (sim.launch: base_driver, twist_mux,
                                                 robot_state_publisher, the spawn)
    robot host 2  thvnet<pid>-r2   10.213.0.2    robot_2 (robot.launch against host 1's master)
    operator      thvnet<pid>-op   10.213.0.10   the command sources (robot_1/nav_vel, and
                                                 robot_2/teleop_joy/cmd_vel as a laptop's joystick),
                                                 a subscriber of odometry/base_raw and /tf
    switch        thvnet<pid>-sw   (none)        the bridge, one port per host

Every process runs with its host's ROS_IP and ROS_MASTER_URI=http://10.213.0.1:11311, ROS_HOME and
ROS_LOG_DIR in a temporary folder per host (their tails are in every failure message). The hosts
have no other interface than ``lo`` and their veth, no default route, IPv6 off and the multicast
flag cleared, so nothing can leave them; the last test checks that it did not.

Why this layout. One master serves the fleet, the usual ROS 1 layout (each robot in its namespace
with its tf_prefix ``robot_k/``). It lives on robot host 1, so robot_1's whole control chain
(master, clock, twist_mux, base_driver, the simulated drives) stays on robot_1's own host, and
cutting the operator's link takes away exactly the commands: the case the link checks are about.
One simulator gives one world and one /clock (two simulators under one master would publish two
clocks on one topic); robot_2's base_driver on host 2 runs on that /clock received across the
network and sends its base_state back across it to the simulator, so robot_2's control loop crosses
the link both ways, and the fleet check shows it still drives robot_2 independently of robot_1.

Time: everything runs on the simulator's clock at real_time_factor 1. The checks are measured on
simulated time from the robot's host: an agent (``netns_helpers.py``, a small rospy node) inside
robot host 1's namespace records when each command reached ``twist_mux/cmd_vel`` (what base_driver
subscribes to), the ``joint_commands`` and ``base_state`` base_driver publishes, and the ground truth
``odometry/gazebo``. The pytest process never joins a namespace: it talks to the agents through
pipes, and waits for simulated-time conditions with wall-clock deadlines only as bounds. The
operator's agent streams its commands at 20 Hz of wall time, as a joystick or a navigation stack
keeps doing whatever the network does, and can always be killed: nothing it does can hang a test.

Needs root (CI has it): where network namespaces cannot be made, the tests fail and say why.
"""

import ipaddress
import math
import os
import subprocess
import sys
import time

import netns_helpers as nh
import pytest

pytestmark = [pytest.mark.ros, pytest.mark.slow, pytest.mark.root, pytest.mark.long(60)]

MASTER_URI = f"http://{nh.SUBNET}.1:{nh.MASTER_PORT}"
SUBNET = ipaddress.ip_network(f"{nh.SUBNET}.0/24")
CONFIG = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "src", "thorvald_model", "config")
# robot name -> (host key, example robot, spawn pose x, y, the command source the operator drives)
ROBOTS = {
    "robot_1": ("r1", "thorvald_ii_4wd4ws_std", 0.0, 0.0, "nav_vel"),
    "robot_2": ("r2", "thorvald_ii_2wd_diff", 0.0, 5.0, "teleop_joy/cmd_vel"),
}
HOST_NAMES = {"r1": "robot host 1", "r2": "robot host 2", "op": "operator"}

STARTUP = 120.0  # [s] wall: the network, both robot hosts and the agents on a busy machine
WALL = 30.0  # [s] wall: bound of a wait for the robots (simulated time runs at real time, or slower)
RESTORE_WALL = 30.0  # [s] wall: commands must flow again within this after a link comes back
SPEED = 0.3  # [m/s] forward speed of the link checks
HOLD = 1.0  # [s] simulated: how long the link stays cut after the wheels stopped
STILL = 0.005  # [m/s], [rad/s]: a robot moving slower than this stands still
# [s] simulated: how far apart two processes on robot host 1 (base_driver and the watcher) may time
# the arrival of one message on a busy machine; each reads /clock on its own (0.025 s measured with
# both cores loaded by other test suites, 0.01 s or less on an idle machine)
ARRIVAL_TOL = 0.05


def yaw_turn(a, b):
    return math.remainder(b - a, 2 * math.pi)


def moved(before, after):
    """Planar distance [m] between two odometry records [t, stamp, x, y, yaw, ...]."""
    return math.hypot(after[2] - before[2], after[3] - before[3])


def forward(before, after):
    """Distance along before's heading [m]."""
    return (after[2] - before[2]) * math.cos(before[4]) + (after[3] - before[3]) * math.sin(before[4])


class Fleet:
    """The network, the robot hosts' roslaunch processes and the two agents (watcher on robot host 1,
    operator on the operator host), with the waits and reads the tests share."""

    def __init__(self, net, base_dir):
        self.net = net
        self.dirs = {key: base_dir / key for key in nh.HOSTS}
        for d in self.dirs.values():
            (d / "log").mkdir(parents=True)
        self.procs = []
        self.launches = []
        self.watcher = self.operator = None
        self.figures = {}

    # ---- bring-up ---------------------------------------------------------------------------------
    def logs(self):
        return nh.log_tails(self.dirs.values())

    def spawn(self, name, key, argv, out, pipe=False):
        env = nh.host_env(self.net.hosts[key].address, MASTER_URI, self.dirs[key])
        proc = nh.HostProcess(name, self.net.hosts[key].ns, argv, env, self.dirs[key] / out, pipe=pipe)
        self.procs.append(proc)
        return proc

    def start(self):
        helpers = nh.__file__
        robot_args = {}
        for robot, (_key, model, x, y, _source) in ROBOTS.items():
            path = os.path.abspath(os.path.join(CONFIG, model, model + ".yaml"))
            robot_args[robot] = [f"robot_name:={robot}", f"robot_model:={path}", f"x:={x}", f"y:={y}"]
        # robot host 1: the master (roslaunch starts it: the URI is this host's), simulator, robot_1
        argv = ["roslaunch", "-p", str(nh.MASTER_PORT), "thorvald_bringup", "sim.launch", "real_time_factor:=1"]
        self.launches.append(
            self.spawn("roslaunch (robot host 1)", "r1", argv + robot_args["robot_1"], "roslaunch.out")
        )
        # robot host 2: robot_2 against host 1's master, once that master holds /use_sim_time
        wait = [sys.executable, helpers, "wait-master", MASTER_URI, "/use_sim_time", str(STARTUP)]
        launch = ["roslaunch", "thorvald_sim", "robot.launch", *robot_args["robot_2"]]
        script = '"$@" && exec ' + " ".join(launch)
        argv = ["sh", "-c", script, "sh", *wait]
        self.launches.append(self.spawn("roslaunch (robot host 2)", "r2", argv, "roslaunch.out"))
        agent = [sys.executable, helpers, "agent", "--wait", str(STARTUP), "--name"]
        watcher = self.spawn("watcher", "r1", [*agent, "netns_watcher"], "watcher.err", pipe=True)
        operator = self.spawn("operator", "op", [*agent, "netns_operator"], "operator.err", pipe=True)
        self.watcher = nh.AgentClient(watcher, self.logs)
        self.operator = nh.AgentClient(operator, self.logs)
        deadline = time.monotonic() + STARTUP
        self.watcher.wait_ready(STARTUP)
        self.operator.wait_ready(max(1.0, deadline - time.monotonic()))
        for robot, (_key, _model, _x, _y, source) in ROBOTS.items():
            for topic, kind in (
                ("odometry/gazebo", "odom"),
                ("base_state", "state"),
                ("joint_commands", "state"),
                ("twist_mux/cmd_vel", "twist"),
            ):
                self.watcher.request("watch", topic=f"/{robot}/{topic}", kind=kind)
            self.operator.request("watch", topic=f"/{robot}/odometry/base_raw", kind="odom")
            self.operator.request("stream", topic=f"/{robot}/{source}", twist=None)
        self.operator.request("watch", topic="/tf", kind="tf")

        def ready():
            w, o = self.watcher.request("status"), self.operator.request("status")
            missing = [t for t, v in w["topics"].items() if v["count"] == 0 and "cmd_vel" not in t]
            missing += [f"{t} (operator)" for t, v in o["topics"].items() if v["count"] == 0 and t != "/tf"]
            missing += [f"{t} subscribed" for t, v in o["streams"].items() if v["connections"] == 0]
            missing += [f"/tf {r}/odom -> {r}/base_link (operator)" for r in ROBOTS if not self.tf_pair(o, r)]
            self._missing = missing
            return not missing

        self.wait(ready, lambda: f"both robots up and seen from the operator; missing: {self._missing}", STARTUP)

    # ---- reads ------------------------------------------------------------------------------------
    @staticmethod
    def tf_pair(status, robot):
        return status["tf"].get(f"{robot}/odom {robot}/base_link")

    def status(self):
        return self.watcher.request("status")

    def now(self):
        return self.status()["time"]

    def last(self, topic, status=None):
        return (status or self.status())["topics"][topic]["last"]

    def history(self, topic, since=0.0, agent=None):
        return (agent or self.watcher).request("history", topic=topic, since=since, timeout=20.0)["records"]

    def param(self, name, default=None):
        value = self.watcher.request("param", name=name, default=default)["value"]
        assert value is not None, f"parameter {name} is not set"
        return value

    def node_pids(self):
        return {name: pid for name, (_uri, pid) in self.watcher.request("nodes", timeout=30.0)["nodes"].items()}

    def seq(self, robot):
        source = ROBOTS[robot][4]
        return self.operator.request("status")["streams"][f"/{robot}/{source}"]["seq"]

    # ---- waits ------------------------------------------------------------------------------------
    def wait(self, predicate, what, timeout=WALL):
        """predicate()'s first true value, polled; fails with the logs if a robot host's roslaunch ends."""

        def checked():
            for p in self.launches:
                if not p.running():
                    raise AssertionError(
                        f"{p.name} exited (status {p.popen.poll()}) while waiting for "
                        f"{what() if callable(what) else what}\n{self.logs()}"
                    )
            return predicate()

        try:
            return nh.poll(checked, timeout, what)
        except AssertionError as e:
            if "\n----" in str(e):
                raise
            raise AssertionError(f"{e}\n{self.logs()}") from None

    def wait_sim(self, seconds):
        """Waits for seconds of simulated time (read on robot host 1)."""
        end = self.now() + seconds
        return self.wait(lambda: self.now() >= end, f"simulated time to reach {end:.2f} s", WALL + 5 * seconds)

    # ---- commands ---------------------------------------------------------------------------------
    def command(self, robot, twist):
        """The operator streams twist (vx, vy, wz) to robot's command source; None: stops sending."""
        source = ROBOTS[robot][4]
        self.operator.request("stream", topic=f"/{robot}/{source}", twist=None if twist is None else list(twist))

    def still(self, robot, status=None):
        status = status or self.status()
        truth = self.last(f"/{robot}/odometry/gazebo", status)
        state = self.last(f"/{robot}/base_state", status)
        return (
            truth is not None
            and state is not None
            and state[2] == 0.0
            and max(abs(truth[5]), abs(truth[6]), abs(truth[7])) < STILL
        )

    def stop(self, robot):
        """Zero until the robot stands still, then silence (base_driver's timeout holds it)."""
        self.command(robot, (0.0, 0.0, 0.0))
        self.wait(lambda: self.arrived(robot, lambda r: r[2:5] == [0.0, 0.0, 0.0]), f"{robot}'s zero command")
        self.wait(lambda: self.still(robot), f"{robot} to stand still")
        self.command(robot, None)

    def arrived(self, robot, test):
        """The latest command that reached robot's twist_mux/cmd_vel, if it passes test."""
        record = self.last(f"/{robot}/twist_mux/cmd_vel")
        return record if record is not None and test(record) else None

    def fail(self, message):
        return f"{message}\n{self.logs()}"


@pytest.fixture(scope="module")
def hosts(tmp_path_factory):
    """The network, both robot hosts and the agents, for the whole module; torn down at its end
    (processes killed, namespaces deleted, checked) whatever happened."""
    reason = nh.namespaces_unavailable()
    if reason:
        pytest.fail(
            f"cannot make network namespaces: {reason}. These tests build their own network and need root "
            "(CI runs them as root); they fail rather than skip.",
            pytrace=False,
        )
    net = nh.Network()
    stale = nh.clean_stale_namespaces(net.tag)
    if stale:
        print(f"deleted namespaces of an earlier run: {stale}")
    fleet = Fleet(net, tmp_path_factory.mktemp("netns"))
    started = time.monotonic()
    try:
        net.create()
        fleet.start()
        fleet.figures["start-up [s wall]"] = round(time.monotonic() - started, 1)
        yield fleet
    finally:
        for agent in (fleet.watcher, fleet.operator):
            if agent is not None:
                agent.quit()
        pids = [pid for ns in net.created for pid in nh.namespace_pids(ns)]
        nh.stop_processes(fleet.procs)
        problems = net.destroy()
        deadline = time.monotonic() + 5.0  # a killed process may take a moment to be reaped
        while True:
            survivors = [pid for pid in pids if nh.process_alive(pid)]
            if not survivors or time.monotonic() > deadline:
                break
            time.sleep(0.05)
        if survivors:
            problems.append(f"processes of the hosts still running after teardown: {survivors}")
        print("figures:", fleet.figures)
        assert not problems, "teardown: " + "; ".join(problems)


@pytest.fixture
def fleet(hosts):
    """The fleet with no command streaming and both robots standing still (a test that failed may
    have left one driving)."""
    for robot in ROBOTS:
        hosts.command(robot, None)
    hosts.wait(lambda: all(hosts.still(r) for r in ROBOTS), "both robots to stand still")
    return hosts


def test_network_namespaces_can_be_made():
    reason = nh.namespaces_unavailable()
    assert reason is None, f"cannot make network namespaces: {reason} (these tests need root, as CI has)"


def test_nodes_run_on_their_hosts_with_their_addresses(fleet):
    nodes = fleet.watcher.request("nodes", timeout=30.0)["nodes"]
    hosts = {name: uri.split("/")[2].split(":")[0] for name, (uri, _pid) in nodes.items()}
    expected = {
        "/simulator": "r1",
        "/rosout": "r1",
        "/netns_watcher": "r1",
        "/robot_1/base_driver": "r1",
        "/robot_1/twist_mux": "r1",
        "/robot_1/rsp/robot_state_publisher": "r1",
        "/robot_2/base_driver": "r2",
        "/robot_2/twist_mux": "r2",
        "/robot_2/rsp/robot_state_publisher": "r2",
        "/netns_operator": "op",
    }
    for name, key in expected.items():
        assert hosts.get(name) == fleet.net.hosts[key].address, fleet.fail(
            f"{name} should run on {HOST_NAMES[key]} ({fleet.net.hosts[key].address}); the master has {nodes}"
        )
    outside = {name: host for name, host in hosts.items() if ipaddress.ip_address(host) not in SUBNET}
    assert not outside, f"nodes registered with addresses outside {SUBNET}: {outside}"


def test_operator_commands_drive_the_robot_and_odometry_and_tf_reach_the_operator(fleet):
    """The operator's nav_vel stream drives robot_1 (ground truth on the robot's host), and the
    operator receives odometry/base_raw and /tf (odom -> base_link, and robot_state_publisher's joint
    transforms) that show the same motion, up to date."""
    robot, speed, seconds = "robot_1", 0.4, 1.5
    truth_topic, raw_topic = f"/{robot}/odometry/gazebo", f"/{robot}/odometry/base_raw"
    status, seen = fleet.status(), fleet.operator.request("status")
    start_truth, start_raw, t0 = fleet.last(truth_topic, status), seen["topics"][raw_topic]["last"], status["time"]
    fleet.command(robot, (speed, 0.0, 0.0))
    fleet.wait(lambda: fleet.arrived(robot, lambda r: r[2] == speed), f"{robot}'s command on its host")
    fleet.wait(lambda: fleet.last(truth_topic)[5] > 0.9 * speed, f"{robot} driving at {speed} m/s (ground truth)")
    fleet.wait_sim(seconds)
    fleet.stop(robot)
    end_truth = fleet.last(truth_topic)
    commands = fleet.history(f"/{robot}/twist_mux/cmd_vel", since=t0)
    started = next(r[0] for r in commands if r[2] == speed)
    ended = next(r[0] for r in commands if r[0] > started and r[2] == 0.0)
    expected = speed * (ended - started)  # the ramps up and down cancel out
    distance, along = moved(start_truth, end_truth), forward(start_truth, end_truth)
    fleet.figures["operator drive: ground truth / commanded [m]"] = (round(along, 3), round(expected, 3))
    assert abs(along - expected) <= 0.05 * expected + 0.03, fleet.fail(
        f"{robot} drove {along:.3f} m forward by ground truth; the commands that arrived ask {expected:.3f} m"
    )
    turn = yaw_turn(start_truth[4], end_truth[4])
    assert abs(turn) < 0.03 and distance - along < 0.02, f"{robot} turned {turn:.3f} rad or slid sideways"

    # the operator host received odometry and tf showing the same motion, up to date
    def operator_caught_up():
        o = fleet.operator.request("status")
        odom, tf = o["topics"][raw_topic]["last"], fleet.tf_pair(o, robot)
        return odom[1] >= end_truth[1] and tf[1] >= end_truth[1] and (o, odom, tf)

    o, odom, tf = fleet.wait(operator_caught_up, "the operator's odometry and tf to reach the robot's stop")
    raw_distance = moved(start_raw, odom)
    assert abs(raw_distance - distance) < 0.01, fleet.fail(
        f"odometry/base_raw on the operator host moved {raw_distance:.3f} m, ground truth {distance:.3f} m"
    )
    assert math.hypot(odom[2] - end_truth[2], odom[3] - end_truth[3]) < 0.005, (
        f"the operator's odometry/base_raw ends at ({odom[2]:.3f}, {odom[3]:.3f}), ground truth at "
        f"({end_truth[2]:.3f}, {end_truth[3]:.3f})"
    )
    assert math.hypot(tf[2] - end_truth[2], tf[3] - end_truth[3]) < 0.005, (
        f"the operator's tf {robot}/odom -> {robot}/base_link ends at ({tf[2]:.3f}, {tf[3]:.3f}), ground truth at "
        f"({end_truth[2]:.3f}, {end_truth[3]:.3f})"
    )
    received = fleet.history(raw_topic, since=t0, agent=fleet.operator)
    span = end_truth[1] - start_truth[1]
    assert len(received) > 25 * span, f"the operator got {len(received)} odometry messages in {span:.1f} s (50 Hz)"
    leg = o["tf"].get(f"{robot}/base_link {robot}/leg0")  # robot_state_publisher, from the joint states
    assert leg is not None and leg[1] >= end_truth[1] - 1.0, f"the operator lacks {robot}'s joint transforms: {leg}"


@pytest.mark.parametrize("side", ["operator", "robot"])
def test_link_cut_stops_the_wheels_and_restoring_it_gives_control_back(fleet, side):
    """Cuts the link at the operator's end (its veth down) or at the robot's (robot host 1's veth
    down, which also cuts robot host 2 from the master and the clock for a while) while the operator
    streams a forward command; the wheels must stop within base_driver's command_timeout plus one
    control cycle of the last command that arrived, base_driver and the simulator keep running, and
    after the link comes back the operator's new commands drive the robot again, nothing restarted."""
    robot, key = "robot_1", {"operator": "op", "robot": "r1"}[side]
    cmd_topic, truth_topic = f"/{robot}/twist_mux/cmd_vel", f"/{robot}/odometry/gazebo"
    timeout = float(fleet.param(f"/{robot}/base_driver/command_timeout", 0.5))
    cycle = 1.0 / float(fleet.param(f"/{robot}/base_driver/rate", 50.0))
    tick = 1.0 / float(fleet.param("/simulator/clock_rate", 80.0))
    accel = float(fleet.param(f"/{robot}/base_driver/motor_drives/drive0/prp_sim_a"))
    odometry_rate = float(fleet.param("/simulator/odometry_rate", 50.0))
    pids = fleet.node_pids()

    fleet.command(robot, (SPEED, 0.0, 0.0))
    fleet.wait(lambda: fleet.last(truth_topic)[5] > 0.95 * SPEED, f"{robot} driving at {SPEED} m/s")
    fleet.wait_sim(0.3)
    t_cut, seq_cut = fleet.now(), fleet.seq(robot)
    fleet.net.set_link(key, up=False)
    # the link went down between t_cut and t_down (setting it down is a process of its own, which a
    # loaded machine may start late: 0.9 s of simulated time was seen once)
    t_down = fleet.now()
    try:
        fleet.wait(lambda: fleet.still(robot), f"{robot} to stop with the link cut")
        fleet.wait_sim(HOLD)
        seq_held = fleet.seq(robot)
        t_restore = fleet.now()
        commands = fleet.history(cmd_topic, since=t_cut - 2.0)
        joint_commands = fleet.history(f"/{robot}/joint_commands", since=t_cut - 2.0)
        states = fleet.history(f"/{robot}/base_state", since=t_cut - 2.0)
        truth = fleet.history(truth_topic, since=t_cut - 2.0)
        operator_odom = fleet.operator.request("status")["topics"][f"/{robot}/odometry/base_raw"]["last"]
    finally:
        fleet.net.set_link(key, up=True)  # always: the other tests need the network
    wall_restore = time.monotonic()

    # while the link was down: the operator went on sending, nothing arrived, the wheels stopped
    assert seq_held - seq_cut >= 20, f"the operator sent only {seq_held - seq_cut} commands during the cut"
    assert commands, fleet.fail("no command reached the robot before the cut")
    last = commands[-1]
    assert last[0] < t_cut + 1.0, fleet.fail(f"commands kept arriving {last[0] - t_cut:.2f} s after the cut")
    assert last[2] == SPEED
    stop_cmd = next((r for r in joint_commands if r[1] >= last[0] and r[2] == 0.0), None)
    assert stop_cmd is not None, fleet.fail("base_driver never commanded the wheels to stop")
    driving = [r for r in joint_commands if last[0] <= r[1] < stop_cmd[1]]
    assert all(r[2] > 0 for r in driving), "the wheels were stopped before the command timed out, then driven"
    assert all(r[2] == 0.0 for r in joint_commands if r[1] >= stop_cmd[1]), "wheels commanded again during the cut"
    stop_state = next((r for r in states if r[1] >= last[0] and r[2] == 0.0), None)
    truth_stop = next((r for r in truth if r[1] >= last[0] and abs(r[5]) < STILL), None)
    assert stop_state is not None and truth_stop is not None, fleet.fail("the drives or the robot never stopped")
    to_command, to_state, to_truth = stop_cmd[1] - last[0], stop_state[1] - last[0], truth_stop[1] - last[0]
    fleet.figures[f"{side}-side cut: last command -> wheels commanded 0 / drives at 0 / robot still [s sim]"] = (
        round(to_command, 3),
        round(to_state, 3),
        round(to_truth, 3),
    )
    # base_driver's rule: a command older than command_timeout stops the wheels at the next cycle
    bound = timeout + cycle + tick
    assert timeout - ARRIVAL_TOL <= to_command <= bound + ARRIVAL_TOL, fleet.fail(
        f"{side}-side cut: the wheels were commanded to stop {to_command:.3f} s after the last command arrived; "
        f"base_driver's command_timeout {timeout} s + one cycle {cycle} s + one /clock tick {tick} s is "
        f"{bound:.3f} s (± {ARRIVAL_TOL} s for timing the arrival in another process)"
    )
    ramp = SPEED / accel  # the simulated drives ramp down at prp_sim_a
    assert to_state <= bound + ramp + cycle + ARRIVAL_TOL, fleet.fail(
        f"the drives reached zero {to_state:.3f} s after the last command; the command timeout and the ramp "
        f"down ({SPEED} m/s at {accel} m/s²) take {bound + ramp:.3f} s (+ one cycle, ± {ARRIVAL_TOL} s)"
    )
    # base_driver and the simulator kept running, and publishing, through the cut
    window = (stop_state[1], stop_state[1] + HOLD)
    state_count = sum(window[0] <= r[1] <= window[1] for r in states)
    truth_count = sum(window[0] <= r[1] <= window[1] for r in truth)
    assert state_count >= 0.8 * HOLD / cycle, f"base_driver published {state_count} base_state in {HOLD} s of the cut"
    assert truth_count >= 0.8 * HOLD * odometry_rate, f"the simulator published {truth_count} odometry in {HOLD} s"
    assert moved(truth_stop, truth[-1]) < 0.01, "the robot crept on after stopping"
    # and the operator was cut off from the robot: no odometry after what was in flight at the cut
    fleet.figures[f"{side}-side cut: operator's odometry ends after the cut [s sim]"] = round(
        operator_odom[1] - t_cut, 3
    )
    assert operator_odom[1] < t_down + 0.3, (
        f"the operator received odometry stamped {operator_odom[1] - t_down:.2f} s after the link was down "
        f"({operator_odom[1] - t_cut:.2f} s after it was cut)"
    )

    # the link is back: a new command (backwards) drives the robot again
    fleet.command(robot, (-SPEED, 0.0, 0.0))
    fleet.wait(
        lambda: fleet.arrived(robot, lambda r: r[2] == -SPEED) and fleet.last(truth_topic)[5] < -0.9 * SPEED,
        f"{robot} driving backwards on the operator's new command after the link came back",
        RESTORE_WALL,
    )
    after = fleet.history(cmd_topic, since=t_restore)
    first = after[0]
    first_new = next(r for r in after if r[2] == -SPEED)
    stale = sum(1 for r in after if r[2] == SPEED)
    fleet.figures[f"{side}-side cut: restore -> first command / new command arrives [s wall], stale commands"] = (
        round(first[1] - wall_restore, 2),
        round(first_new[1] - wall_restore, 2),
        stale,
    )
    assert stale <= seq_held - seq_cut + 10, "more stale commands than were sent during the cut"
    seqs = [r[5] for r in after]
    assert seqs == sorted(seqs), f"commands arrived out of order after the link came back: {seqs}"
    # the operator sees the robot again, and nothing restarted
    t_back = fleet.now()
    fleet.wait(
        lambda: fleet.operator.request("status")["topics"][f"/{robot}/odometry/base_raw"]["last"][1] >= t_back,
        "the operator to receive odometry again",
    )
    fleet.stop(robot)
    now_pids = fleet.node_pids()
    restarted = {n: (pid, now_pids.get(n)) for n, pid in pids.items() if now_pids.get(n) != pid}
    assert not restarted, fleet.fail(f"nodes restarted or lost (old, new pid): {restarted}")
    assert all(p.running() for p in fleet.launches)


def test_a_long_cut_of_the_operators_link_does_not_stall_the_simulation(fleet):
    """The operator's nodes read /clock too. With the link down longer than TCP keeps writing into
    its send buffer (about 14 s here), a /clock written synchronously to every reader blocked the
    simulator: simulated time stopped for every robot until the link came back. Each reader now has
    a writer thread and a queue of one tick of its own, so the robots' hosts do not notice."""
    cut = 25.0  # [s] wall
    fleet.net.set_link("op", up=False)
    try:
        samples = []
        start = time.monotonic()
        while time.monotonic() - start < cut:
            samples.append((time.monotonic() - start, fleet.now()))
            time.sleep(1.0)
    finally:
        fleet.net.set_link("op", up=True)
    fleet.figures["25 s operator-side cut: simulated time advanced [s]"] = round(samples[-1][1] - samples[0][1], 1)
    # at real_time_factor 1 simulated time keeps pace with the wall clock, also in the last seconds
    late = [(w, t) for w, t in samples if w >= cut - 8.0]
    assert late[-1][1] - late[0][1] >= 0.5 * (late[-1][0] - late[0][0]), fleet.fail(
        f"simulated time stalled with the operator's link cut: (wall s, sim s) {samples}"
    )
    assert samples[-1][1] - samples[0][1] >= 0.5 * (samples[-1][0] - samples[0][0]), fleet.fail(str(samples))
    fleet.wait(
        lambda: fleet.operator.request("status")["topics"]["/robot_1/odometry/base_raw"]["last"][1] > samples[-1][1],
        "the operator to receive odometry again after the long cut",
        RESTORE_WALL,
    )


def test_two_robots_on_two_hosts_move_independently(fleet):
    """One operator drives robot_1 (host 1, nav_vel) straight and spins robot_2 (host 2, its
    joystick input teleop_joy/cmd_vel) at once, then drives robot_2 alone: each robot does what it was
    told, the idle one does not move, and the operator receives both robots' odometry."""
    r1, r2 = "robot_1", "robot_2"
    speed, spin, seconds = 0.3, 0.5, 2.0
    status = fleet.status()  # both standing still (the fixture)
    t0 = status["time"]
    before = {r: fleet.last(f"/{r}/odometry/gazebo", status) for r in (r1, r2)}
    fleet.command(r1, (speed, 0.0, 0.0))
    fleet.command(r2, (0.0, 0.0, spin))
    fleet.wait(
        lambda: fleet.arrived(r1, lambda r: r[2] == speed) and fleet.arrived(r2, lambda r: r[4] == spin),
        "both robots' commands on their hosts",
    )
    fleet.wait_sim(seconds)
    fleet.command(r1, (0.0, 0.0, 0.0))
    fleet.command(r2, (0.0, 0.0, 0.0))
    fleet.stop(r1)
    fleet.stop(r2)
    status = fleet.status()
    middle = {r: fleet.last(f"/{r}/odometry/gazebo", status) for r in (r1, r2)}
    t1 = status["time"]

    def commanded(robot, index, value, since, until):
        records = [r for r in fleet.history(f"/{robot}/twist_mux/cmd_vel", since=since) if r[0] <= until]
        start = next(r[0] for r in records if r[index] == value)
        end = next(r[0] for r in records if r[0] > start and r[index] == 0.0)
        return value * (end - start)

    want_1, want_2 = commanded(r1, 2, speed, t0, t1), commanded(r2, 4, spin, t0, t1)
    along_1, turn_1 = forward(before[r1], middle[r1]), yaw_turn(before[r1][4], middle[r1][4])
    turn_2, shift_2 = yaw_turn(before[r2][4], middle[r2][4]), moved(before[r2], middle[r2])
    fleet.figures["fleet: robot_1 forward / commanded [m], robot_2 turn / commanded [rad]"] = (
        round(along_1, 3),
        round(want_1, 3),
        round(turn_2, 3),
        round(want_2, 3),
    )
    assert abs(along_1 - want_1) <= 0.05 * want_1 + 0.03, fleet.fail(f"robot_1 drove {along_1:.3f} m for {want_1:.3f}")
    assert abs(turn_1) < 0.03, f"robot_1 turned {turn_1:.3f} rad while driving straight"
    assert abs(turn_2 - want_2) <= 0.08 * want_2 + 0.03, fleet.fail(f"robot_2 turned {turn_2:.3f} rad for {want_2:.3f}")
    assert shift_2 < 0.05, f"robot_2 moved {shift_2:.3f} m while spinning in place"

    # robot_2 alone: robot_1 stays where it is
    fleet.command(r2, (speed, 0.0, 0.0))
    fleet.wait(lambda: fleet.last(f"/{r2}/odometry/gazebo")[5] > 0.9 * speed, "robot_2 driving alone")
    fleet.wait_sim(1.0)
    fleet.stop(r2)
    status = fleet.status()
    end = {r: fleet.last(f"/{r}/odometry/gazebo", status) for r in (r1, r2)}
    want_2 = commanded(r2, 2, speed, t1, status["time"])
    along_2 = forward(middle[r2], end[r2])
    idle = moved(middle[r1], end[r1])
    fleet.figures["fleet: robot_2 alone forward / commanded [m], idle robot_1 moved [m]"] = (
        round(along_2, 3),
        round(want_2, 3),
        round(idle, 4),
    )
    assert abs(along_2 - want_2) <= 0.05 * want_2 + 0.03, fleet.fail(f"robot_2 drove {along_2:.3f} m for {want_2:.3f}")
    assert idle < 0.002, f"robot_1 moved {idle:.4f} m while only robot_2 was commanded"

    # the operator received both robots' odometry, robot_2's from base_driver on host 2
    o = fleet.operator.request("status")
    for robot in (r1, r2):
        odom = o["topics"][f"/{robot}/odometry/base_raw"]["last"]
        assert odom[1] >= end[robot][1] - 0.5 and moved(odom, end[robot]) < 0.01, (
            f"the operator's odometry of {robot} ({odom}) does not match its ground truth ({end[robot]})"
        )


def test_traffic_stays_on_the_hosts_subnet(fleet):
    """No route off the subnet, every TCP/UDP socket of every host between the hosts' addresses (or on
    loopback), and no multicast received on any link of the network."""
    loopback = ipaddress.ip_network("127.0.0.0/8")
    for key, host in fleet.net.hosts.items():
        for route in fleet.net.routes(key):
            dst = route.get("dst", "")
            assert dst != "default", f"{HOST_NAMES[key]} has a default route: {route}"
            net = ipaddress.ip_network(dst, strict=False) if dst and dst[0].isdigit() else None
            assert net is not None and (net.subnet_of(SUBNET) or net.subnet_of(loopback)), (
                f"{HOST_NAMES[key]} has a route off the subnet: {route}"
            )
        sockets = subprocess.run(nh.in_namespace(host.ns, ["ss", "-tunaH"]), capture_output=True, text=True, timeout=15)
        assert sockets.returncode == 0, sockets.stderr
        peers = []
        for line in sockets.stdout.splitlines():
            fields = line.split()
            for address in fields[4:6]:
                addr = address.rsplit(":", 1)[0].strip("[]")
                if addr in ("*", "0.0.0.0", "::"):
                    continue
                ip_addr = ipaddress.ip_address(addr.split("%")[0])
                if ip_addr not in SUBNET and ip_addr not in loopback:
                    peers.append(line)
        assert not peers, f"{HOST_NAMES[key]} has sockets off the subnet: {peers}"
        established = [line for line in sockets.stdout.splitlines() if "ESTAB" in line]
        assert established, f"{HOST_NAMES[key]} has no TCP connection at all: {sockets.stdout}"
    multicast = {f"{ns}/{dev}": n for (ns, dev), n in fleet.net.link_stats().items() if n}
    assert not multicast, f"multicast packets were received on: {multicast}"
