#!/usr/bin/env python3
"""What simulated sensors cost, side by side in one run: each sensor in the simulator node against raw
pybullet doing the same rays or renders, and four robots carrying sensors, subscribed and not.

    python bench/sensors.py [--seconds S] [--rounds R] [--robots N] [--part 1|2] [--stack per-robot|fleet|both]

Sensors (bench/data/bench_sensors.xacro on the standard robot): planar lidar 720 beams at 40 Hz,
IMU 100 Hz, RTK-GNSS 10 Hz, RGB-D camera 320 x 240 at 10 Hz, 16 x 440 3D lidar at 10 Hz, p3d 50 Hz.

1. Per sensor: raw is pybullet alone, in a process of its own running beside the simulator node
   while the node is measured (the two see the same machine over the same seconds), doing what a
   reading takes in pybullet alone: the mount's pose (the robot may move), then the same rays from
   it and their ranges (rayTestBatch, each hit's fraction) or the same image (getCameraImage, tiny
   renderer), at the sensor's rate between the physics steps of a simulated second (240 steps: a
   ray test right after a step finds the collision structures as the simulator's does, not hot in
   the cache from the last ray test), CPU of that work per simulated second; the same raw work is
   measured again with nothing beside it ("raw alone"). Node is the simulator's own figure for that
   sensor (its /diagnostics: CPU spent measuring, converting and publishing, per simulated second)
   while it is the one sensor read (the IMU and GNSS: with all read). Each sensor is measured in
   --rounds rounds, the sensors taking turns, and the median of its rounds' node/raw is kept (one
   phase on a shared 2-core machine can be a third off; the rounds' range is printed). Target:
   node within 1.3 times raw. Also printed: raw alone with the lidars' rays computed once from the mount's first
   pose ("rays fixed"), the reference this bench used before, and the node against it.
2. N robots (4) with these sensors, the simulator as fast as it can: real-time factor and the
   simulator's CPU per simulated second with no sensor subscribed, with the planar lidar, IMU and
   GNSS of every robot subscribed, and with everything subscribed; and the same robots without
   sensors. Once with each robot's own base_driver, twist_mux and robot_state_publisher
   (per-robot), once with one fleet_driver for all (fleet). Targets: with lidar, IMU and GNSS
   subscribed at least 2 times real time; an unsubscribed sensor costs under 1 % of the
   simulator's CPU.
"""

import argparse
import json
import math
import os
import signal
import subprocess
import sys
import threading
import time
from typing import Optional

import numpy as np
from base_driver import ros_session
from sim import case_launch, check, fleet_launch

from thorvald_testing import children, cmdline, cpu_seconds, poll

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
STD = os.path.join(ROOT, "src", "thorvald_model", "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
EXTRAS = os.path.join(ROOT, "bench", "data", "bench_sensors.xacro")
SPACING = 6.0
TARGET_RATIO = 1.3
TARGET_RTF = 2.0
TARGET_IDLE = 0.01
PHYSICS_RATE = 240.0  # the simulator's default
LIGHT = ("scan", "imu/data", "gps/fix")  # the planar lidar, the IMU and the GNSS
SENSOR_TOPICS = {  # of the sensors with a raw reference: what reading one alone subscribes
    "front_lidar": ("scan",),
    "velodyne": ("velodyne_points",),
    "rgbd": ("rgbd/rgb/image_raw", "rgbd/depth/image_raw", "rgbd/depth/points"),  # in <cameraName>
}


# ---------------------------------------------------------------------------------------------
# 1. raw pybullet, no ROS
# ---------------------------------------------------------------------------------------------
def raw_costs(wall: float, only=None, stop: Optional[threading.Event] = None, fixed: bool = False):
    """{sensor name: CPU [s] per simulated second} of raw pybullet doing each sensor's work at its rate
    (of the sensor named only, or of each with a raw reference), on the standard robot with the bench
    sensors in the flat world, for wall seconds each (or until stop is set). fixed: the lidars' rays
    computed once from the mount's first pose (cameras left out), as this bench measured before."""
    from thorvald_model.description import generate_urdf  # noqa: PLC0415
    from thorvald_sim.bullet import pybullet as p  # noqa: PLC0415
    from thorvald_sim.physics.robot import Pose2D  # noqa: PLC0415
    from thorvald_sim.physics.simulation import Simulation  # noqa: PLC0415
    from thorvald_sim.world import load_world, resolve_world  # noqa: PLC0415

    c = p.connect(p.DIRECT)
    try:
        sim = Simulation(c, load_world(resolve_world("flat")))
        robot = sim.spawn("r", generate_urdf(STD, model_extras=EXTRAS), Pose2D())
        for _ in range(240):
            sim.step()
        out = {}
        for sensor in robot.sensors:
            spec = sensor.spec
            if spec.name not in SENSOR_TOPICS or only not in (None, spec.name):
                continue
            steps = max(1, round(PHYSICS_RATE / spec.rate))  # physics steps between two readings
            if spec.kind in ("laser", "multilayer"):
                directions = sensor.directions.reshape(-1, 3)
                r_min, r_max = spec.config.range_min, spec.config.range_max

                def work(sensor=sensor, directions=directions, r_min=r_min, r_max=r_max):
                    """A lidar's reading in pybullet alone: its mount's pose (the robot moves), the
                    beams from there, the rays, their ranges."""
                    origin, quat = sensor.pose()
                    d = directions @ np.asarray(p.getMatrixFromQuaternion(quat)).reshape(3, 3).T
                    o = np.asarray(origin)
                    return [hit[2] for hit in p.rayTestBatch(o + d * r_min, o + d * r_max, physicsClientId=c)]

                origin, quat = sensor.pose()
                m = np.asarray(p.getMatrixFromQuaternion(quat)).reshape(3, 3)
                d = directions @ m.T
                starts = (np.asarray(origin) + d * r_min).tolist()
                ends = (np.asarray(origin) + d * r_max).tolist()

                def fixed_work(starts=starts, ends=ends):  # the rays cast from a mount computed once
                    return [hit[2] for hit in p.rayTestBatch(starts, ends, physicsClientId=c)]

            else:
                cfg = spec.config

                def work(sensor=sensor, cfg=cfg):  # a camera's reading: its mount's pose, the render
                    origin, quat = sensor.pose()
                    m = p.getMatrixFromQuaternion(quat)
                    ahead = (origin[0] + m[0], origin[1] + m[3], origin[2] + m[6])  # the mount's x axis
                    view = p.computeViewMatrix(origin, ahead, (m[2], m[5], m[8]), physicsClientId=c)
                    return p.getCameraImage(
                        cfg.width, cfg.height, view, sensor.projection,
                        renderer=p.ER_TINY_RENDERER, flags=p.ER_NO_SEGMENTATION_MASK, physicsClientId=c,
                    )  # fmt: skip

                fixed_work = None
            if fixed:
                if fixed_work is None:
                    continue
                work = fixed_work

            spent, readings, end = 0.0, 0, time.monotonic() + wall
            while readings == 0 or (time.monotonic() < end and not (stop and stop.is_set())):
                for _ in range(steps):
                    p.stepSimulation(physicsClientId=c)
                start = time.thread_time()
                work()
                spent += time.thread_time() - start
                readings += 1
            out[spec.name] = spent / (readings / spec.rate)
        return out
    finally:
        p.disconnect(c)


class RawBeside:
    """Raw pybullet doing one sensor's work in a process of its own while the node is measured: the
    two see the same machine (what else runs, how busy it is) over the same seconds."""

    def __init__(self, name: str):
        self.proc = subprocess.Popen(
            [sys.executable, os.path.abspath(__file__), "--raw", name],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
        )

    def result(self) -> float:
        """Stops it; its CPU per simulated second."""
        out, _ = self.proc.communicate("stop\n", timeout=600)
        return float(json.loads(out.strip().splitlines()[-1])["cpu"])


def raw_worker(name: str) -> int:
    """--raw NAME: raw_costs of that sensor until a line (or the end) on stdin; prints {"cpu": ...}."""
    stop = threading.Event()
    threading.Thread(target=lambda: (sys.stdin.readline(), stop.set()), daemon=True).start()
    cpu = raw_costs(float("inf"), only=name, stop=stop)[name]
    print(json.dumps({"cpu": cpu}), flush=True)
    return 0


# ---------------------------------------------------------------------------------------------
# 2. the simulator node
# ---------------------------------------------------------------------------------------------
def node_case(n: int, seconds: float, master, phases, *, sensors: bool = True, fleet_driver: bool = False, beside=None):
    """One launch of n robots, measured in phases one after the other, each reading its own topics:
    per phase (real-time factor, simulator CPU [s] per simulated second, {sensor: node CPU per
    simulated second} of robot r0, raw CPU per simulated second beside it or None). A phase: topic
    suffixes to read on every robot, "all", or (); beside: per phase, the sensor whose raw work runs
    beside the node while the phase is measured (RawBeside), or None."""
    import rospy  # noqa: PLC0415
    from diagnostic_msgs.msg import DiagnosticArray  # noqa: PLC0415
    from rosgraph_msgs.msg import Clock  # noqa: PLC0415
    from rospy import AnyMsg  # noqa: PLC0415

    from thorvald_testing.topics import Latest  # noqa: PLC0415

    extras = f'<arg name="model_extras" value="{EXTRAS}"/>' if sensors else ""
    xml = fleet_launch([(SPACING * k, 0) for k in range(n)], robot_args=extras, fleet_driver=fleet_driver)
    clock = Latest("/clock", Clock, queue_size=1)
    per_sensor = {}
    measuring = threading.Event()

    def on_diagnostics(msg):
        if not measuring.is_set():
            return
        for status in msg.status:
            if status.name.endswith("sensors of r0"):
                for kv in status.values:
                    if kv.key.endswith("CPU per simulated second [s]"):
                        per_sensor.setdefault(kv.key.split(" (")[0], []).append(float(kv.value))

    diagnostics = rospy.Subscriber("/diagnostics", DiagnosticArray, on_diagnostics)
    readers = []
    results = []
    label = f"{n} robots{' with sensors' if sensors else ''}{', fleet_driver' if fleet_driver else ''}"

    def now():
        return clock.get().clock.to_sec()

    try:
        with case_launch(xml, master, f"sensors_{n}_robots") as launch:
            spawned = {f"/r{k}/odometry/gazebo" for k in range(n)}  # the simulator's topics of a spawned robot

            def up():
                check(launch, label)
                return clock.get() is not None and spawned <= {t for t, _ in rospy.get_published_topics()}

            poll(up, 120 + 20 * n, f"{label}: /clock and every robot spawned", interval=0.5)
            time.sleep(5.0)  # their nodes up and settled
            sim_pid = [pid for pid in children(launch.proc.pid) if "/simulator" in cmdline(pid).split(" __")[0]]
            for subscribe, raw_name in zip(phases, beside or [None] * len(phases)):
                if subscribe == "all":
                    topics = [t for t, _ in rospy.get_published_topics() if t.startswith("/r") and _sensor_topic(t)]
                else:
                    topics = [f"/r{k}/{s}" for k in range(n) for s in subscribe]
                readers = [rospy.Subscriber(t, AnyMsg, lambda _m: None, queue_size=1) for t in topics]
                time.sleep(3.0)
                raw = RawBeside(raw_name) if raw_name else None
                time.sleep(2.0 if raw else 0.0)  # its robot loaded, its readings begun
                per_sensor.clear()
                t0, w0, c0 = now(), time.perf_counter(), sum(cpu_seconds(p, 0.0) for p in sim_pid)
                measuring.set()
                while now() - t0 < seconds and time.perf_counter() - w0 < 40 * seconds and launch.running():
                    time.sleep(0.1)
                measuring.clear()
                t1, w1, c1 = now(), time.perf_counter(), sum(cpu_seconds(p, 0.0) for p in sim_pid)
                raw_cpu = raw.result() if raw else None
                check(launch, label)
                simulated = t1 - t0
                if simulated <= 0:
                    raise RuntimeError(f"{label}: simulated time stood still; see {launch.output}")
                sensors_cpu = {k: float(np.median(v)) for k, v in per_sensor.items()}
                results.append((simulated / (w1 - w0), (c1 - c0) / simulated, sensors_cpu, raw_cpu))
                for r in readers:
                    r.unregister()
                readers = []
            return results
    finally:
        for r in readers:
            r.unregister()
        clock.sub.unregister()
        diagnostics.unregister()


def _sensor_topic(topic: str) -> bool:
    return any(topic.endswith(s) for s in ("scan", "imu/data", "gps/fix", "velodyne_points", "image_raw", "points"))


def sensors_part(seconds: float, master, rounds: int) -> bool:
    """Part 1, each sensor measured in rounds (one phase per sensor per round, the sensors taking
    turns); whether its target was met by the median over the rounds."""
    names = list(SENSOR_TOPICS)
    beside = [*names * rounds, None]  # the "all" phase last: no raw beside it
    phases = [SENSOR_TOPICS[name] if name else "all" for name in beside]
    ratios, raw, node, in_node = {}, {}, {}, {}
    for name, (_, _, cpu, raw_cpu) in zip(beside, node_case(1, seconds, master, phases, beside=beside)):
        by_name = {key.split(" ", 1)[1]: value for key, value in cpu.items()}  # "<kind> <name>" -> name
        if name:
            node_cpu = by_name.get(name, float("nan"))
            raw.setdefault(name, []).append(raw_cpu)
            node.setdefault(name, []).append(node_cpu)
            ratios.setdefault(name, []).append(node_cpu / raw_cpu)
        else:  # the sensors without a raw reference (IMU, GNSS), read with everything
            in_node = {k: v for k, v in by_name.items() if k not in SENSOR_TOPICS}
    alone = raw_costs(2.0)  # the same raw work again, with nothing beside it
    fixed = raw_costs(2.0, fixed=True)  # the lidars' rays from a mount computed once
    print(f"1. each sensor: CPU per simulated second, raw pybullet beside the simulator node (one robot), "
          f"medians of {rounds} rounds")  # fmt: skip
    print(f"{'sensor':>14} {'raw alone':>10} {'raw beside':>11} {'node [s]':>9} {'node/raw':>9} {'rounds':>12}"
          f" {'raw, rays fixed':>16} {'node/that':>10}")  # fmt: skip
    worst, unmeasured = 0.0, []
    for name in names:
        # a round whose phase heard no /diagnostics of the sensor has no figure: the median is of the
        # rounds that have one, and a sensor with none fails the target (nan would pass any max)
        kept = [k for k, r in enumerate(ratios[name]) if math.isfinite(r)]
        if not kept:
            unmeasured.append(name)
            print(f"{name:>14} not measured: no /diagnostics of it in any of its {len(ratios[name])} rounds")
            continue
        ratio = float(np.median([ratios[name][k] for k in kept]))
        node_cpu = float(np.median([node[name][k] for k in kept]))
        worst = max(worst, ratio)
        spread = f"{min(ratios[name][k] for k in kept):.2f}-{max(ratios[name][k] for k in kept):.2f}"
        if len(kept) < len(ratios[name]):
            spread += f" ({len(kept)} of {len(ratios[name])})"
        line = (f"{name:>14} {alone[name]:>10.4f} {float(np.median(raw[name])):>11.4f} {node_cpu:>9.4f}"
                f" {ratio:>8.2f}x {spread:>12}")  # fmt: skip
        if name in fixed:
            line += f" {fixed[name]:>16.4f} {node_cpu / fixed[name]:>9.2f}x"
        print(line)
    for name, node_cpu in in_node.items():
        print(f"{name:>14} {'-':>10} {'-':>11} {node_cpu:>9.4f}")
    verdict = worst <= TARGET_RATIO and not unmeasured
    missing = f"; not measured: {', '.join(unmeasured)}" if unmeasured else ""
    print(f"target: node within {TARGET_RATIO} x raw (median of the rounds): {'met' if verdict else 'MISSED'} "
          f"(worst {worst:.2f} x{missing})\n")  # fmt: skip
    return verdict


def robots_part(n: int, seconds: float, master, stack: str) -> bool:
    """Part 2 with one stack ("per-robot": base_driver, twist_mux and robot_state_publisher per robot;
    "fleet": one fleet_driver for all); whether its targets were met."""
    fleet = stack == "fleet"
    print(f"2. {n} robots, the simulator as fast as it can, {stack} stack")
    print(f"{'case':>36} {'RTF':>7} {'sim CPU/s':>10}")
    cases = [
        ("no sensors fitted", (), False),
        ("sensors fitted, none read", (), True),
        ("planar lidar, IMU, GNSS read", LIGHT, True),
        ("every sensor read", "all", True),
    ]
    results = {}
    for label, subscribe, fitted in cases:
        [(rtf, cpu, _, _)] = node_case(n, seconds, master, [subscribe], sensors=fitted, fleet_driver=fleet)
        results[label] = (rtf, cpu)
        print(f"{label:>36} {rtf:>6.2f}x {cpu:>9.3f}s", flush=True)
    bare, idle = results["no sensors fitted"][1], results["sensors fitted, none read"][1]
    per_sensor_idle = (idle - bare) / (6 * n) / bare
    light = results["planar lidar, IMU, GNSS read"][0]
    v1, v2 = light >= TARGET_RTF, per_sensor_idle < TARGET_IDLE
    print(f"target: lidar, IMU and GNSS read on {n} robots at least {TARGET_RTF:g} x real time: "
          f"{'met' if v1 else 'MISSED'} ({light:.2f} x)")  # fmt: skip
    print(f"target: an unread sensor under {TARGET_IDLE:.0%} of the simulator's CPU: "
          f"{'met' if v2 else 'MISSED'} ({per_sensor_idle:+.2%} each, {6 * n} sensors)\n")  # fmt: skip
    return v1 and v2


def _at_least_one(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value}: must be at least 1")
    return value


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seconds", type=float, default=10.0, help="simulated seconds measured per case")
    parser.add_argument("--robots", type=int, default=4)
    parser.add_argument("--rounds", type=_at_least_one, default=3, help="part 1: rounds per sensor (median kept)")
    parser.add_argument("--part", type=int, choices=(1, 2), help="only this part (default: both)")
    parser.add_argument("--raw", metavar="SENSOR", help=argparse.SUPPRESS)  # RawBeside's worker
    parser.add_argument(
        "--stack", choices=("per-robot", "fleet", "both"), default="both", help="the robots' stack in part 2"
    )
    args = parser.parse_args()
    if args.raw:
        return raw_worker(args.raw)
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))
    ok = True
    with ros_session("bench_sensors", core_only=True) as (master, _):
        if args.part in (None, 1):
            ok &= sensors_part(args.seconds, master, args.rounds)
        if args.part in (None, 2):
            for stack in ("per-robot", "fleet") if args.stack == "both" else (args.stack,):
                ok &= robots_part(args.robots, args.seconds, master, stack)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
