#!/usr/bin/env python3
"""The simulator's speed against raw pybullet, side by side in one run, for 1, 4 and 9 robots.

    python bench/sim.py [--seconds S] [--robots 1 4 9] [--clock-rate HZ]

Raw: pybullet alone (no ROS, no Python between steps) steps at 240 Hz the very world the simulator
builds: the flat world and N standard robots set up by the simulator's Simulation class (merged
fixed links, thin tyre contact discs, torque-limited motors, no drag), commanded 0.5 m/s once.
Core: Simulation.step on the same world (the wheels' ramps and the springs in Python between
steps), no ROS. Node:
the simulator node on the benchmark's master, N robots through robot.launch (base_driver,
twist_mux, robot_state_publisher each), driven at 0.5 m/s through twist_mux, the simulator as fast
as it can (real_time_factor 0; it waits for robots whose commands lag, ~max_lag).

Figures: real-time factor (simulated seconds per wall second); CPU of the stepping process per
simulated second, against raw stepping's (target: at most 1.25 times); CPU of every node together.
The simulator's /diagnostics split the node's CPU: "solver" is the part spent inside pybullet's
stepSimulation (the thread's CPU clock around it), so solver/raw is what the same physics costs in
the node beside the other processes, and node/solver what ROS and Python add to it.
Target: four robots at least 3 times real time on this 2-core machine.
"""

import argparse
import contextlib
import os
import shutil
import signal
import sys
import tempfile
import threading
import time

from base_driver import ros_session  # the base_driver benchmark's tools

from thorvald_testing import Launch, children, cmdline, cpu_seconds, poll

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
STD = os.path.join(ROOT, "src", "thorvald_model", "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
SPACING = 4.0  # [m] between robots
TARGET_OVERHEAD = 1.25
TARGET_FOUR = 3.0


def grid(k):
    return SPACING * (k % 3), SPACING * (k // 3)


def world(n: int):
    """A pybullet client with the flat world and n standard robots commanded 0.5 m/s, under way.

    Set up by the simulator's own Simulation class, so raw and core step the very bodies, motors,
    frictions and damping the node steps (an earlier hand-made copy of those settings kept
    pybullet's default drag of 0.04 /s, which the simulator removes, and stepped 18 % cheaper).
    """
    from thorvald_model.description import generate_urdf  # noqa: PLC0415
    from thorvald_sim.bullet import pybullet as p  # noqa: PLC0415
    from thorvald_sim.physics.robot import Pose2D  # noqa: PLC0415
    from thorvald_sim.physics.simulation import Simulation  # noqa: PLC0415
    from thorvald_sim.world import load_world, resolve_world  # noqa: PLC0415

    urdf = generate_urdf(STD)
    c = p.connect(p.DIRECT)
    sim = Simulation(c, load_world(resolve_world("flat")))
    for k in range(n):
        x, y = grid(k)
        sim.spawn(f"r{k}", urdf, Pose2D(x, y, 0.0)).command([0.0] * 4, [0.5] * 4)
    for _ in range(240):  # under way
        sim.step()
    return c, sim


def raw(n: int, seconds: float):
    """(real-time factor, CPU [s] per simulated second) of bare pybullet.stepSimulation, n robots."""
    from thorvald_sim.bullet import pybullet as p  # noqa: PLC0415

    c, _ = world(n)
    try:
        steps = round(seconds * 240)
        wall, cpu = time.perf_counter(), time.process_time()
        for _ in range(steps):
            p.stepSimulation(physicsClientId=c)
        wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    finally:
        p.disconnect(c)
    return seconds / wall, cpu / seconds


def core(n: int, seconds: float):
    """CPU [s] per simulated second of the simulator's Simulation.step (ramps, springs: Python) for n robots."""
    from thorvald_sim.bullet import pybullet as p  # noqa: PLC0415

    c, sim = world(n)
    try:
        steps = round(seconds * 240)
        cpu = time.process_time()
        for _ in range(steps):
            sim.step()
        return (time.process_time() - cpu) / seconds
    finally:
        p.disconnect(c)


def node(n: int, seconds: float, master, clock_rate: float):
    """(real-time factor, simulator CPU [s] per simulated second, all nodes' CPU share [cores]).

    Every case runs on the benchmark's one master (rospy initialises once per process) with a launch
    of its own, stopped before the next case.
    """
    import rospy  # noqa: PLC0415
    from diagnostic_msgs.msg import DiagnosticArray  # noqa: PLC0415
    from geometry_msgs.msg import Twist  # noqa: PLC0415
    from rosgraph_msgs.msg import Clock  # noqa: PLC0415

    from thorvald_testing.topics import Latest  # noqa: PLC0415

    xml = fleet_launch([grid(k) for k in range(n)], f'<arg name="clock_rate" value="{clock_rate:g}"/>')
    clock = Latest("/clock", Clock, queue_size=1)
    solver = []  # the simulator's own figure per window: pybullet's solver's CPU [s] per simulated second

    def on_diagnostics(msg):
        for status in msg.status:
            if status.name.endswith(": simulation") and measuring.is_set():
                values = {kv.key: kv.value for kv in status.values}
                solver.append(float(values["solver CPU per simulated second [s]"]))

    measuring = threading.Event()
    diagnostics = rospy.Subscriber("/diagnostics", DiagnosticArray, on_diagnostics)
    pubs = [rospy.Publisher(f"/r{k}/nav_vel", Twist, queue_size=1) for k in range(n)]
    stop = threading.Event()
    label = f"{n} robots"
    try:
        with case_launch(xml, master, f"sim_{n}_robots") as launch:
            twist = Twist()
            twist.linear.x = 0.5

            def drive():  # faster than any mux timeout at any real-time factor reached here
                while not stop.is_set():
                    for pub in pubs:
                        pub.publish(twist)
                    time.sleep(0.01)

            threading.Thread(target=drive, daemon=True).start()

            def started():
                check(launch, label)
                return clock.get() is not None and sum(p.get_num_connections() for p in pubs) >= n

            poll(started, 120 + 15 * n, f"{label}: /clock and every robot's nav_vel subscribed")
            time.sleep(3.0)  # spawned and driving

            def now():
                return clock.get().clock.to_sec()

            every = children(launch.proc.pid)  # roslaunch starts every node in a session of its own
            simulator = [pid for pid in every if "/simulator" in cmdline(pid).split(" __")[0]]
            t0, w0 = now(), time.perf_counter()
            c0 = sum(cpu_seconds(p, missing=0.0) for p in simulator)
            a0 = sum(cpu_seconds(p, missing=0.0) for p in every)
            measuring.set()
            # at least three of the simulator's /diagnostics windows (1 s of wall time each) for its solver figure
            while (
                (now() - t0 < seconds or len(solver) < 3)
                and time.perf_counter() - w0 < 20 * seconds
                and launch.running()
            ):
                time.sleep(0.1)
            check(launch, label)
            t1, w1 = now(), time.perf_counter()
            if t1 <= t0:
                raise RuntimeError(f"{label}: /clock stood still for {w1 - w0:.0f} s; see {launch.output}")
            measuring.clear()
            c1 = sum(cpu_seconds(p, missing=0.0) for p in simulator)
            a1 = sum(cpu_seconds(p, missing=0.0) for p in every)
            simulated = t1 - t0
            if not solver:
                raise RuntimeError(f"{label}: no /diagnostics from the simulator while measuring")
            in_node = sum(solver) / len(solver)
            return simulated / (w1 - w0), (c1 - c0) / simulated, in_node, (a1 - a0) / (w1 - w0)
    finally:
        stop.set()
        clock.sub.unregister()
        diagnostics.unregister()
        for pub in pubs:
            pub.unregister()


def fleet_launch(positions, simulator_args: str = "", robot_args: str = "", fleet_driver: bool = False):
    """A launch file's XML: simulator.launch as fast as it can, and
    robot.launch r0, r1, ... at positions [(x, y)], each with robot_args (launch XML) added; with
    fleet_driver, one fleet_driver process does every robot's base_driver, twist_mux and
    robot_state_publisher work."""
    if fleet_driver:
        robot_args += '<arg name="fleet_driver" value="true"/>'
    robots = "\n".join(
        f'  <include file="$(find thorvald_sim)/launch/robot.launch"><arg name="robot_name" value="r{k}"/>'
        f'<arg name="x" value="{x}"/><arg name="y" value="{y}"/>{robot_args}</include>'
        for k, (x, y) in enumerate(positions)
    )
    if fleet_driver:
        names = " ".join(f"r{k}" for k in range(len(positions)))
        robots += (
            '\n  <include file="$(find thorvald_bringup)/launch/fleet_driver.launch">'
            f'<arg name="robots" value="{names}"/></include>'
        )
    return (
        '<launch>\n  <include file="$(find thorvald_sim)/launch/simulator.launch">'
        '<arg name="real_time_factor" value="0"/><arg name="output" value="log"/>'
        f"{simulator_args}</include>\n{robots}\n</launch>\n"
    )


@contextlib.contextmanager
def case_launch(xml: str, master, label: str):
    """A case's launch file (xml) run on the benchmark's master through thorvald_testing.Launch, in a
    folder of its own (ROS_HOME, the logs, roslaunch's output): yields the Launch, stops it and
    everything it started on the way out, and removes the folder, or keeps it (and says where)
    when the case failed."""
    home = tempfile.mkdtemp(prefix=f"bench_{label}_")
    path = os.path.join(home, "case.launch")
    with open(path, "w") as f:
        f.write(xml)
    launch = Launch(home, path, port=master.port)
    ok = False
    try:
        yield launch
        ok = True
    finally:
        launch.stop()
        if ok:
            shutil.rmtree(home, ignore_errors=True)
        else:
            print(f"{label}: the launch's output and logs are kept in {home}", file=sys.stderr)


def check(launch, label: str) -> None:
    """Raises if the launch stopped (a required node, the simulator, died), with the end of its output."""
    if not launch.running():
        raise RuntimeError(
            f"{label}: the launch stopped (exit {launch.proc.returncode}); {launch.output} ends:\n{launch.tail()}"
        )


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seconds", type=float, default=20.0, help="simulated seconds measured per case")
    parser.add_argument("--robots", type=int, nargs="+", default=[1, 4, 9])
    parser.add_argument(
        "--clock-rate", type=float, default=80.0, help="the simulator's ~clock_rate [Hz] (80, its default)"
    )
    args = parser.parse_args()
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))  # the master and launches are stopped on the way out
    print(
        f"{'robots':>6} {'raw RTF':>8} {'node RTF':>9} {'raw CPU/s':>10} {'core CPU/s':>11} {'node CPU/s':>11}"
        f" {'solver':>9} {'overhead':>9} {'solver/raw':>11} {'node/solver':>12} {'all nodes':>10}"
    )
    results = {}
    with ros_session("bench_sim", core_only=True) as (master, _):
        for n in args.robots:
            raw_rtf, raw_cpu = raw(n, args.seconds)
            core_cpu = core(n, args.seconds)
            node_rtf, node_cpu, solver, all_cpu = node(n, args.seconds, master, args.clock_rate)
            results[n] = (raw_rtf, node_rtf, raw_cpu, node_cpu)
            print(
                f"{n:>6} {raw_rtf:>7.1f}x {node_rtf:>8.1f}x {raw_cpu:>9.3f}s {core_cpu:>10.3f}s {node_cpu:>10.3f}s"
                f" {solver:>8.3f}s {node_cpu / raw_cpu:>8.2f}x {solver / raw_cpu:>10.2f}x {node_cpu / solver:>11.2f}x"
                f" {all_cpu:>7.2f} cores",
                flush=True,
            )
    ok = True
    worst = max(results[n][3] / results[n][2] for n in results)
    verdict = worst <= TARGET_OVERHEAD
    ok &= verdict
    print(
        f"\ntarget: the simulator node's CPU per simulated second at most {TARGET_OVERHEAD} x raw stepping's: "
        f"{'met' if verdict else 'MISSED'} (worst {worst:.2f} x)"
    )
    if 4 in results:
        verdict = results[4][1] >= TARGET_FOUR
        ok &= verdict
        figure = f"{results[4][1]:.1f} x"
        print(f"target: 4 robots at least {TARGET_FOUR:g} x real time: {'met' if verdict else 'MISSED'} ({figure})")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
