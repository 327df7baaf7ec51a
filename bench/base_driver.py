#!/usr/bin/env python3
"""base_driver and twist_mux benchmark: latency, CPU share and the highest loop rate held.

    python3 bench/base_driver.py [--port PORT] [--samples 250] [--window 10]

Starts its own roscore (on a free port unless --port says) and its own nodes through the tests'
harness (thorvald_testing), measures, and stops every process it started, also on an error or
Ctrl-C. Needs the workspace sourced.

1. Latency from a cmd_vel message to the joint_commands that carries it, 4-drive standard robot at
   50 Hz: each command has its own vx (0.2 m/s + 2 mm/s per message, straight ahead, so every wheel's
   commanded speed is exactly vx); latency = receipt of the first joint_commands with that speed -
   publication of the command. The loop picks a command up at its next cycle, so up to one period
   (20 ms) of it is waiting for the loop. Median and 99th percentile.
2. CPU share of the base_driver process at 50 Hz (4 and 9 drives), driving (vx 0.3, wz 0.1 at 20 Hz)
   with a subscriber on every topic it publishes: utime + stime from /proc/<pid>/stat over a window.
   Target: 9 drives below 10 % of one core.
3. The highest loop rate held with 9 drives: ~rate 100, 200, 400, 800 Hz; the achieved rate is that
   of odometry/base_raw by its stamps over 5 s; held = at least 95 % of ~rate. Target: 200 Hz.
4. The latency twist_mux adds: publication on nav_vel -> receipt on twist_mux/cmd_vel (two TCPROS
   hops through the mux process), median and 99th percentile. Target: under 1 ms median.
"""

import argparse
import contextlib
import os
import random
import signal
import statistics
import sys
import tempfile
import threading
import time

import rospkg
import rospy
import yaml
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState
from tf2_msgs.msg import TFMessage

from thorvald_msgs.msg import BaseState
from thorvald_testing import Master, Processes, cpu_seconds, poll

STD = "thorvald_ii_4wd4ws_std"
NINE = "thorvald_ii_9wd9ws"
RATES = (100, 200, 400, 800)  # [Hz]
HELD = 0.95  # achieved / requested rate that counts as held


# ---- the session: the benchmarks' one way to run ROS (thorvald_testing, as the tests) ----------
@contextlib.contextmanager
def ros_session(name, core_only=False, port=None):
    """(master, processes): a ROS master of the benchmark's own (thorvald_testing.Master, ROS_HOME in
    a temporary folder; core_only: a bare rosmaster, no rosout), this process a node called name on
    it, and a thorvald_testing.Processes for what the benchmark starts. Everything is stopped on the
    way out, also on an error, Ctrl-C or SIGTERM (which main turns into SystemExit)."""
    with tempfile.TemporaryDirectory(prefix=f"{name}_") as home:
        master = Master(home, core_only=core_only, port=port)
        procs = Processes()
        try:
            os.environ.update(master.env)  # rospy and every process started from here use the master
            rospy.init_node(name, disable_signals=True)
            yield master, procs
        finally:
            with contextlib.suppress(Exception):
                rospy.signal_shutdown("benchmark done")
            procs.stop_all()
            master.stop()


def percentile(values, q):
    values = sorted(values)
    k = (len(values) - 1) * q
    lo = int(k)
    hi = min(lo + 1, len(values) - 1)
    return values[lo] + (values[hi] - values[lo]) * (k - lo)


# ---- the benchmark -----------------------------------------------------------------------------
class Bench:
    def __init__(self, procs):
        self.procs = procs
        self.config_dir = os.path.join(rospkg.RosPack().get_path("thorvald_model"), "config")
        self.mux_config = os.path.join(rospkg.RosPack().get_path("thorvald_bringup"), "config", "twist_mux.yaml")

    def robot_file(self, robot):
        return os.path.join(self.config_dir, robot, robot + ".yaml")

    def start_driver(self, ns, robot, rate, **extra):
        """base_driver in /ns with the robot's file, simple_sim unless extra parameters say otherwise."""
        path = self.robot_file(robot)
        with open(path) as f:
            params = yaml.safe_load(f)
        params.update({"robot_model": path, "simple_sim": True, "rate": float(rate), "enable_odom_tf": True})
        params.update(extra)
        rospy.set_param(f"/{ns}/base_driver", params)
        p = self.procs.start(
            [
                "rosrun",
                "thorvald_base",
                "base_driver",
                "__name:=base_driver",
                f"__ns:=/{ns}",
                "cmd_vel:=twist_mux/cmd_vel",
                "joint_states:=base_driver/joint_states",
            ]
        )
        rospy.wait_for_message(f"/{ns}/odometry/base_raw", Odometry, timeout=60)
        return p

    def wait_subscribed(self, pub, timeout=30.0):
        poll(pub.get_num_connections, timeout, f"a subscriber to {pub.resolved_name}")
        time.sleep(0.5)  # let the connection settle before timing it

    def stamped_latency(self, pub_topic, sub_topic, sub_type, *, speed_of, samples, interval):
        """Latencies [s] from publishing a Twist with a unique vx to receiving a message carrying it."""
        seen = {}
        lock = threading.Lock()

        def on_message(msg):
            t = time.time()
            key = round(speed_of(msg), 9)
            with lock:
                seen.setdefault(key, t)

        sub = rospy.Subscriber(sub_topic, sub_type, on_message, queue_size=100, tcp_nodelay=True)
        pub = rospy.Publisher(pub_topic, Twist, queue_size=10)
        self.wait_subscribed(pub)
        sent = {}
        for i in range(samples):
            vx = round(0.2 + 0.002 * i, 9)
            msg = Twist()
            msg.linear.x = vx
            sent[vx] = time.time()
            pub.publish(msg)
            time.sleep(random.uniform(*interval))
        time.sleep(0.5)
        sub.unregister()
        pub.unregister()
        with lock:
            latencies = [seen[k] - t for k, t in sent.items() if k in seen]
        if len(latencies) < 0.9 * samples:
            raise RuntimeError(f"only {len(latencies)} of {samples} commands came back on {sub_topic}")
        return latencies, samples - len(latencies)

    def command_latency(self, samples):
        p = self.start_driver("latency", STD, 50)
        try:
            return self.stamped_latency(
                "/latency/twist_mux/cmd_vel",
                "/latency/joint_commands",
                BaseState,
                speed_of=lambda m: m.prop_speed[0] if m.prop_speed else -1.0,
                samples=samples,
                interval=(0.04, 0.06),
            )
        finally:
            self.procs.stop(p)

    def mux_latency(self, samples):
        with open(self.mux_config) as f:
            rospy.set_param("/mux/twist_mux", yaml.safe_load(f))
        p = self.procs.start(
            [
                "rosrun",
                "thorvald_base",
                "twist_mux",
                "__name:=twist_mux",
                "__ns:=/mux",
                "cmd_vel_out:=twist_mux/cmd_vel",
            ]
        )
        try:
            return self.stamped_latency(
                "/mux/nav_vel",
                "/mux/twist_mux/cmd_vel",
                Twist,
                speed_of=lambda m: m.linear.x,
                samples=samples,
                interval=(0.005, 0.015),
            )
        finally:
            self.procs.stop(p)

    def consume_all(self, ns):
        """A subscriber on every topic the driver publishes, as a running robot has."""
        counts = {"odom": []}

        def on_odom(m):
            counts["odom"].append(m.header.stamp.to_sec())

        subs = [
            rospy.Subscriber(f"/{ns}/odometry/base_raw", Odometry, on_odom, queue_size=1000, tcp_nodelay=True),
            rospy.Subscriber(f"/{ns}/base_driver/joint_states", JointState, lambda m: None, queue_size=10),
            rospy.Subscriber(f"/{ns}/base_state", BaseState, lambda m: None, queue_size=10),
            rospy.Subscriber(f"/{ns}/joint_commands", BaseState, lambda m: None, queue_size=10),
            rospy.Subscriber("/tf", TFMessage, lambda m: None, queue_size=10),
        ]
        return subs, counts

    def drive_stream(self, ns, stop):
        pub = rospy.Publisher(f"/{ns}/twist_mux/cmd_vel", Twist, queue_size=10)
        self.wait_subscribed(pub)
        msg = Twist()
        msg.linear.x, msg.angular.z = 0.3, 0.1

        def run():
            while not stop.is_set():
                pub.publish(msg)
                time.sleep(0.05)

        t = threading.Thread(target=run, daemon=True)
        t.start()
        return t

    def cpu_and_rate(self, ns, robot, rate, window, **extra):
        """(CPU share of one core [%], achieved odometry rate [Hz]) of a driver at ~rate."""
        p = self.start_driver(ns, robot, rate, **extra)
        stop = threading.Event()
        subs = []
        try:
            subs, counts = self.consume_all(ns)
            self.drive_stream(ns, stop)
            time.sleep(2.0)  # connections up, wheels at speed
            counts["odom"].clear()
            c0, t0 = cpu_seconds(p.pid), time.time()
            time.sleep(window)
            c1, t1 = cpu_seconds(p.pid), time.time()
            stamps = sorted(counts["odom"])
            achieved = (len(stamps) - 1) / (stamps[-1] - stamps[0]) if len(stamps) > 1 else 0.0
            return 100.0 * (c1 - c0) / (t1 - t0), achieved
        finally:
            stop.set()
            for s in subs:
                s.unregister()
            self.procs.stop(p)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--port", type=int, default=None, help="the roscore's port (default: a free one)")
    parser.add_argument("--samples", type=int, default=250, help="commands per latency measurement")
    parser.add_argument("--window", type=float, default=10.0, help="CPU measurement window [s]")
    args = parser.parse_args()

    signal.signal(signal.SIGTERM, lambda *_: sys.exit(1))  # through ros_session's exit: stop every process
    load_before = os.getloadavg()[0]
    rows = []
    with ros_session("bench_base_driver", port=args.port) as (master, procs):
        bench = Bench(procs)
        print(
            f"roscore on port {master.port}; {os.cpu_count()} cores, load average {load_before:.2f} at start",
            flush=True,
        )

        lat, lost = bench.command_latency(args.samples)
        rows.append(
            ("cmd_vel -> joint_commands, median", "4 drives, 50 Hz", f"{1e3 * statistics.median(lat):.1f} ms", "")
        )
        rows.append(("cmd_vel -> joint_commands, p99", "4 drives, 50 Hz", f"{1e3 * percentile(lat, 0.99):.1f} ms", ""))
        print(f"  latency: {len(lat)} commands matched, {lost} not seen", flush=True)

        for robot, drives, target in ((STD, 4, ""), (NINE, 9, "< 10 %")):
            cpu, achieved = bench.cpu_and_rate(f"cpu{drives}", robot, 50, args.window)
            rows.append(("CPU share at 50 Hz", f"{drives} drives", f"{cpu:.1f} % of a core", target))
            print(f"  {drives} drives at 50 Hz: {cpu:.1f} % CPU, {achieved:.1f} Hz", flush=True)

        best = None
        for rate in RATES:
            cpu, achieved = bench.cpu_and_rate(f"rate{rate}", NINE, rate, 5.0)
            held = achieved >= HELD * rate
            best = rate if held else best
            rows.append(
                (f"~rate {rate} Hz", "9 drives", f"{achieved:.0f} Hz, {cpu:.0f} % CPU", "held" if held else "not held")
            )
            print(f"  9 drives at {rate} Hz: {achieved:.1f} Hz achieved, {cpu:.1f} % CPU", flush=True)
        rows.append(("highest loop rate held", "9 drives", f"{best or 0} Hz", ">= 200 Hz"))

        lat, lost = bench.mux_latency(2 * args.samples)
        rows.append(
            ("twist_mux nav_vel -> twist_mux/cmd_vel, median", "", f"{1e3 * statistics.median(lat):.2f} ms", "< 1 ms")
        )
        rows.append(("twist_mux nav_vel -> twist_mux/cmd_vel, p99", "", f"{1e3 * percentile(lat, 0.99):.2f} ms", ""))
        print(f"  mux: {len(lat)} commands matched, {lost} not seen", flush=True)

    table = [("measure", "robot", "figure", "target"), *rows]
    widths = [max(len(r[i]) for r in table) for i in range(4)]
    print()
    for r in table:
        print("  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip())
    print(f"\nload average {load_before:.2f} at start, {os.getloadavg()[0]:.2f} at the end ({os.cpu_count()} cores)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
