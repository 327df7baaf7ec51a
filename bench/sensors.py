#!/usr/bin/env python3
"""What simulated sensors cost, side by side in one run: each sensor in the simulator node against raw
pybullet doing the same rays or renders, and four robots carrying sensors, subscribed and not.

    python bench/sensors.py [--seconds S] [--robots N]

Sensors (bench/data/bench_sensors.xacro on the standard robot): planar lidar 720 beams at 40 Hz,
IMU 100 Hz, RTK-GNSS 10 Hz, RGB-D camera 320 x 240 at 10 Hz, 16 x 440 3D lidar at 10 Hz, p3d 50 Hz.

1. Per sensor: raw is pybullet alone, in this process, casting the same rays (rayTestBatch, the
   same beams from the same mount) or rendering the same image (getCameraImage, tiny renderer) at
   the sensor's rate between the physics steps of a simulated second (240 steps: a ray test right
   after a step finds the collision structures as the simulator's does, not hot in the cache from
   the last ray test), CPU of the rays or renders per simulated second; node is the simulator's own
   figure for that sensor (its /diagnostics: CPU spent measuring, converting and publishing, per
   simulated second) while it is the one sensor read (the IMU and GNSS: with all read). Target:
   node within 1.3 times raw.
2. N robots (4) with these sensors, the simulator as fast as it can: real-time factor and the
   simulator's CPU per simulated second with no sensor subscribed, with the planar lidar, IMU and
   GNSS of every robot subscribed, and with everything subscribed; and the same robots without
   sensors. Targets: with lidar, IMU and GNSS subscribed at least 2 times real time; an unsubscribed
   sensor costs under 1 % of the simulator's CPU.
"""

import argparse
import functools
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time

import numpy as np
from base_driver import Processes, cpu_seconds, free_port, start_master
from sim import children, cmdline, fleet_launch, stop_launch

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
    "rgbd": ("rgb/image_raw", "depth/image_raw", "depth/points"),
}


# ---------------------------------------------------------------------------------------------
# 1. raw pybullet, no ROS
# ---------------------------------------------------------------------------------------------
def raw_costs(seconds: float):
    """{sensor name: CPU [s] per simulated second} of raw pybullet doing each sensor's work at its rate,
    on the standard robot with the bench sensors in the flat world."""
    import pybullet as p  # noqa: PLC0415

    from thorvald_model.description import generate_urdf  # noqa: PLC0415
    from thorvald_sim.robot import Pose2D  # noqa: PLC0415
    from thorvald_sim.simulation import Simulation  # noqa: PLC0415
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
            if spec.kind not in ("laser", "multilayer", "camera", "depth"):
                continue
            origin, quat = sensor.pose()  # the same mount, computed once: raw does nothing else
            readings = max(1, round(seconds * spec.rate))
            steps = max(1, round(PHYSICS_RATE / spec.rate))  # physics steps between two readings
            if spec.kind in ("laser", "multilayer"):
                m = np.asarray(p.getMatrixFromQuaternion(quat)).reshape(3, 3)
                d = sensor.directions.reshape(-1, 3) @ m.T
                starts = (np.asarray(origin) + d * spec.config.range_min).tolist()
                ends = (np.asarray(origin) + d * spec.config.range_max).tolist()
                work = functools.partial(p.rayTestBatch, starts, ends, physicsClientId=c)

            else:
                cfg = spec.config
                view = p.computeViewMatrix(origin, np.add(origin, (1.0, 0.0, 0.0)).tolist(), (0, 0, 1))
                work = functools.partial(
                    p.getCameraImage, cfg.width, cfg.height, view, sensor.projection,
                    renderer=p.ER_TINY_RENDERER, flags=p.ER_NO_SEGMENTATION_MASK, physicsClientId=c,
                )  # fmt: skip

            spent = 0.0
            for _ in range(readings):
                for _ in range(steps):
                    p.stepSimulation(physicsClientId=c)
                start = time.thread_time()
                work()
                spent += time.thread_time() - start
            out[spec.name] = spent / (readings / spec.rate)
        return out
    finally:
        p.disconnect(c)


# ---------------------------------------------------------------------------------------------
# 2. the simulator node
# ---------------------------------------------------------------------------------------------
def node_case(n: int, seconds: float, port: int, phases, sensors: bool = True):
    """One launch of n robots, measured in phases one after the other, each reading its own topics:
    per phase (real-time factor, simulator CPU [s] per simulated second, {sensor: node CPU per
    simulated second} of robot r0). A phase: topic suffixes to read on every robot, "all", or ()."""
    import rospy  # noqa: PLC0415
    from diagnostic_msgs.msg import DiagnosticArray  # noqa: PLC0415
    from rosgraph_msgs.msg import Clock  # noqa: PLC0415
    from rospy import AnyMsg  # noqa: PLC0415

    env = dict(os.environ, ROS_MASTER_URI=f"http://localhost:{port}")
    extras = f'<arg name="model_extras" value="{EXTRAS}"/>' if sensors else ""
    launch = fleet_launch([(SPACING * k, 0) for k in range(n)], robot_args=extras)
    clock = {"t": None}
    sub = rospy.Subscriber("/clock", Clock, lambda m: clock.__setitem__("t", m.clock.to_sec()))
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
    output = tempfile.NamedTemporaryFile("w", prefix="bench_sensors_", suffix=".log", delete=False)
    proc = subprocess.Popen(["roslaunch", launch.name], env=env, stdout=output, stderr=subprocess.STDOUT,
                            start_new_session=True)  # fmt: skip
    results = []
    try:
        deadline = time.time() + 120 + 20 * n
        while time.time() < deadline and clock["t"] is None:
            if proc.poll() is not None:
                raise RuntimeError(f"the launch stopped; see {output.name}")
            time.sleep(0.2)
        time.sleep(5.0)  # every robot spawned
        sim_pid = [pid for pid in children(proc.pid) if "/simulator" in cmdline(pid).split(" __")[0]]
        for subscribe in phases:
            if subscribe == "all":
                topics = [t for t, _ in rospy.get_published_topics() if t.startswith("/r") and _sensor_topic(t)]
            else:
                topics = [f"/r{k}/{s}" for k in range(n) for s in subscribe]
            readers = [rospy.Subscriber(t, AnyMsg, lambda _m: None, queue_size=1) for t in topics]
            time.sleep(3.0)
            per_sensor.clear()
            t0, w0, c0 = clock["t"], time.perf_counter(), sum(cpu_seconds(p, 0.0) for p in sim_pid)
            measuring.set()
            while clock["t"] - t0 < seconds and time.perf_counter() - w0 < 40 * seconds and proc.poll() is None:
                time.sleep(0.1)
            measuring.clear()
            t1, w1, c1 = clock["t"], time.perf_counter(), sum(cpu_seconds(p, 0.0) for p in sim_pid)
            simulated = t1 - t0
            if simulated <= 0:
                raise RuntimeError(f"simulated time stood still; see {output.name}")
            sensors_cpu = {k: float(np.median(v)) for k, v in per_sensor.items()}
            results.append((simulated / (w1 - w0), (c1 - c0) / simulated, sensors_cpu))
            for r in readers:
                r.unregister()
            readers = []
        return results
    finally:
        for r in readers:
            r.unregister()
        sub.unregister()
        diagnostics.unregister()
        stop_launch(proc)
        os.unlink(launch.name)
        output.close()


def _sensor_topic(topic: str) -> bool:
    return any(topic.endswith(s) for s in ("scan", "imu/data", "gps/fix", "velodyne_points", "image_raw", "points"))


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seconds", type=float, default=10.0, help="simulated seconds measured per case")
    parser.add_argument("--robots", type=int, default=4)
    args = parser.parse_args()
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))
    procs = Processes()
    log = open(os.devnull, "w")
    ok = True
    try:
        port = free_port(11411)
        start_master(procs, log, port, "bench_sensors", master_only=True)
        raw = raw_costs(args.seconds)
        in_node = {}
        for _, _, cpu in node_case(1, args.seconds, port, [SENSOR_TOPICS[name] for name in raw] + ["all"]):
            for key, value in cpu.items():  # each sensor from its own phase (read alone); the rest from "all"
                in_node.setdefault(key, value)
        print("1. each sensor: CPU per simulated second, raw pybullet and in the simulator node (one robot)")
        print(f"{'sensor':>14} {'raw [s]':>9} {'node [s]':>9} {'node/raw':>9}")
        worst = 0.0
        for name, raw_cpu in raw.items():
            node_cpu = next((v for k, v in in_node.items() if k.split(" ", 1)[1] == name), float("nan"))
            ratio = node_cpu / raw_cpu
            worst = max(worst, ratio)
            print(f"{name:>14} {raw_cpu:>9.4f} {node_cpu:>9.4f} {ratio:>8.2f}x")
        for key, node_cpu in in_node.items():
            if key.split(" ", 1)[1] not in raw:
                print(f"{key.split(' ', 1)[1]:>14} {'-':>9} {node_cpu:>9.4f}")
        verdict = worst <= TARGET_RATIO
        ok &= verdict
        print(f"target: node within {TARGET_RATIO} x raw: {'met' if verdict else 'MISSED'} (worst {worst:.2f} x)\n")

        n = args.robots
        print(f"2. {n} robots, the simulator as fast as it can")
        print(f"{'case':>36} {'RTF':>7} {'sim CPU/s':>10}")
        cases = [
            ("no sensors fitted", (), False),
            ("sensors fitted, none read", (), True),
            ("planar lidar, IMU, GNSS read", LIGHT, True),
            ("every sensor read", "all", True),
        ]
        results = {}
        for label, subscribe, fitted in cases:
            [(rtf, cpu, _)] = node_case(n, args.seconds, port, [subscribe], sensors=fitted)
            results[label] = (rtf, cpu)
            print(f"{label:>36} {rtf:>6.2f}x {cpu:>9.3f}s", flush=True)
        bare, idle = results["no sensors fitted"][1], results["sensors fitted, none read"][1]
        per_sensor_idle = (idle - bare) / (6 * n) / bare
        light = results["planar lidar, IMU, GNSS read"][0]
        v1, v2 = light >= TARGET_RTF, per_sensor_idle < TARGET_IDLE
        ok &= v1 and v2
        print(f"target: lidar, IMU and GNSS read on {n} robots at least {TARGET_RTF:g} x real time: "
              f"{'met' if v1 else 'MISSED'} ({light:.2f} x)")  # fmt: skip
        print(f"target: an unread sensor under {TARGET_IDLE:.0%} of the simulator's CPU: "
              f"{'met' if v2 else 'MISSED'} ({per_sensor_idle:+.2%} each, {6 * n} sensors)")  # fmt: skip
    finally:
        import rospy  # noqa: PLC0415

        rospy.signal_shutdown("done")
        procs.stop_all()
        log.close()
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
