#!/usr/bin/env python3
"""Fleets in one simulation: the largest fleet this machine holds at real time, and where the CPU goes.

    python bench/fleet.py [--seconds 60] [--robots 4 8 12 16 20] [--lidar-robots 4 8 12]
                          [--stacks per-robot fleet] [--physics default fleet] [--workers 1 2]
                          [--plot docs/images/fleet/rtf.png]

Each case is one roslaunch on the benchmark's own master: simulator.launch at real time
(real_time_factor 1) in the flat world, and N standard robots (thorvald_ii_4wd4ws_std) brought up
as multi_sim.launch brings them up (sim_robot_in_world.launch: the model, robot_state_publisher,
base_driver on drives measured from the simulated joints, twist_mux, the spawn, the world -> odom
transform), 6 m apart. Every robot gets its own twist on its nav_vel at 10 Hz (a circle of its
own: 0.30 to 0.38 m/s, +-0.3 rad/s). With ``--lidar-robots`` every robot also carries a planar
lidar of 720 beams at 10 Hz (bench/data/fleet_lidar.xacro, a gazebo_ros laser block), and each
scan is read (the simulator measures a sensor only while somebody reads it).

Stacks: ``per-robot`` is the stack as it is (base_driver and twist_mux processes per robot);
``fleet`` runs every robot's base_driver and twist_mux in one fleet_driver process
(``fleet_driver:=true``), the same topics, services and parameters per robot. ``--physics`` runs
each stack with each physics preset (simulator.launch's ``physics``: ``default``, or ``fleet``: 120
Hz, about half the solver's CPU); a stack on a preset other than the default is labelled
``STACK+PRESET``. ``--workers`` runs each of them with each number of physics worker processes
(simulator.launch's ``physics_workers``), labelled ``STACK+wN`` for N > 1. ``--fleet-topics on off``
runs the fleet stack with its drive topics on the simulator's fleet topics (fleet_driver.launch's
default, on) and on each robot's own (off, labelled ``STACK+own``).

Figures per case, over ``--seconds`` simulated seconds after 5 s of warm-up:
- real-time factor (simulated seconds per wall second); held: at least 0.95;
- the CPU per robot and simulated second [ms] of each part: pybullet's solver (the simulator's own
  /diagnostics: the thread CPU clock around stepSimulation, in every worker), the simulator's ROS
  and Python work (its process's CPU less the solver), its physics workers' other work (their
  processes' CPU less the solver), base_driver, twist_mux (or the fleet_driver holding both),
  robot_state_publisher, the ROS master, the rest (the world -> odom publishers); and the whole
  stack's against the solver's;
- raw pybullet beside it: the same number of standard robots on the same circles stepped by
  pybullet alone in this process (the simulator's Simulation class builds the world, then bare
  stepSimulation at the preset's rate, 10 simulated seconds), back to back and, at real time, at the
  node's pace (``raw_pybullet``); the simulator's CPU (node, workers, solver) and its solver against
  them (target: the solver at most 1.3 times the same steps raw).

A projection per stack: the fleet a machine of 8 and 16 cores would hold at real time, from the
largest fleet measured without lidars. Its assumptions: the CPU per robot of each part stays what
it was here; the simulator node's own thread (its ROS work, and the physics too without workers: one
core at most, Python's interpreter lock) and each process of the stack may use at most 0.9 of a
core; there are as many workers and fleet_drivers as needed; the whole stack fits in 0.9 of the
cores.

Targets (issue 24): the whole stack's CPU at most 3 times the solver's; 20 robots held at real
time; 12 robots with a lidar each held; the simulator node's own CPU at most 1.3 times its solver's.
Exits 1 when a target is missed; for each fleet that fell behind it prints why: the CPU the
simulator process needed per simulated second (one core at most: stepSimulation holds Python's
interpreter lock) and the whole stack's against the machine's cores.
"""

import argparse
import json
import math
import os
import re
import signal
import sys
import threading
import time

from base_driver import ros_session
from sim import case_launch, check

from thorvald_testing import children, cmdline, cpu_seconds, poll

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
STD = os.path.join(ROOT, "src", "thorvald_model", "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
LIDAR = os.path.join(ROOT, "bench", "data", "fleet_lidar.xacro")
SPACING = 6.0  # [m] between robots: circles of 1 to 1.3 m radius never meet
HELD = 0.95
WARM_UP = 5.0  # [s] simulated
COMMAND_PERIOD = 0.1  # [s]
ROLES = (
    "solver",
    "simulator",
    "workers",
    "base_driver",
    "twist_mux",
    "fleet_driver",
    "robot_state_publisher",
    "master",
    "rest",
)
TARGET_STACK = 3.0
TARGET_FLEET = 20
TARGET_LIDAR_FLEET = 12
TARGET_SIMULATOR = 1.3
TARGET_WORKER_FLEET = 24  # with physics workers (issue 35)
TARGET_SOLVER_RAW = 1.3  # the solver inside the node against the same steps raw
PROJECTED_CORES = (8, 16)
CORE_USE = 0.9  # of a core a process, and of the machine the whole stack, in the projection
RAW_SECONDS = 10.0  # [s] simulated of raw pybullet per fleet size


def grid(k, n):
    side = max(1, round(n**0.5))
    return SPACING * (k % side), SPACING * (k // side)


def twist_of(k):
    """Robot k's own circle: (vx [m/s], wz [rad/s])."""
    return 0.30 + 0.02 * (k % 5), 0.3 if k % 2 else -0.3


def launch_file(
    n: int,
    lidar: bool,
    stack: str,
    rtf: float = 1.0,
    physics: str = "default",
    *,
    workers: int = 1,
    drivers: int = 1,
    fleet_topics: bool = True,
):
    extras = f'<arg name="model_extras" value="{LIDAR}"/>' if lidar else ""
    robots = "\n".join(
        f'  <include file="$(find thorvald_bringup)/launch/sim_robot_in_world.launch"><arg name="ns" value="r{k}"/>'
        f'<arg name="robot_model" value="{STD}"/><arg name="x" value="{grid(k, n)[0]}"/>'
        f'<arg name="y" value="{grid(k, n)[1]}"/><arg name="measured_drives" value="true"/>'
        f'<arg name="fleet_driver" value="{str(stack == "fleet").lower()}"/>{extras}</include>'
        for k in range(n)
    )
    fleet = "".join(  # the robots dealt over `drivers` fleet_driver processes
        '  <include file="$(find thorvald_bringup)/launch/fleet_driver.launch">'
        f'<arg name="name" value="{"fleet_driver" if d == 0 else f"fleet_driver_{d}"}"/>'
        f'<arg name="robots" value="{" ".join(f"r{k}" for k in range(d, n, drivers))}"/>'
        f'<arg name="fleet_topics" value="{"/simulator" if fleet_topics else ""}"/></include>\n'
        for d in range(drivers if stack == "fleet" else 0)
    )
    return (
        '<launch>\n  <include file="$(find thorvald_sim)/launch/simulator.launch">'
        f'<arg name="world" value="flat"/><arg name="real_time_factor" value="{rtf:g}"/>'
        f'<arg name="physics" value="{physics}"/><arg name="physics_workers" value="{workers}"/>'
        '<arg name="output" value="log"/>'
        f"</include>\n{robots}\n{fleet}</launch>\n"
    )


def role_of(pid: int, master_pid: int, parent: str = "") -> str:
    """A process's part: the node it is (its __name:=), the master, a physics worker (a process the
    simulator started), or the rest."""
    if pid == master_pid:
        return "master"
    match = re.search(r"__name:=(\S+)", cmdline(pid))
    name = match.group(1) if match else ""
    name = "fleet_driver" if name.startswith("fleet_driver_") else name  # a fleet split over processes
    if name in ROLES:
        return name
    return "workers" if parent in ("simulator", "workers") else "rest"


def processes(root: int, master_pid: int):
    """{pid: role} of every descendant of root (the launch) and the master."""
    roles = {master_pid: "master"}
    todo = [(pid, "") for pid in children(root)]
    while todo:
        pid, parent = todo.pop()
        roles[pid] = role_of(pid, master_pid, parent)
        todo += [(child, roles[pid]) for child in children(pid)]
    return roles


def cpu_by_role(roles):
    totals = dict.fromkeys(ROLES, 0.0)
    for pid, role in roles.items():
        totals[role] += cpu_seconds(pid, missing=0.0)
    return totals


def raw_pybullet(n: int, physics: str, seconds: float = RAW_SECONDS, paced: bool = False) -> float:
    """CPU [s] per robot and simulated second of bare pybullet stepping n standard robots (6 m apart)
    at the preset's rate and iterations, in this process: the world built by the simulator's
    Simulation class, each robot driving the circle the fleet's robot k drives (``twist_of``), its
    drives commanded as its base_driver commands them (the robot's own calculator).

    The same manoeuvre matters: a turning robot's wheels keep up to four contact points each in
    pybullet's contact manifolds (the points a wheel rolled over while it turned stay within
    pybullet's breaking distance), where a robot driving straight keeps one, and the solver's 50
    iterations run to the end instead of stopping early: the same robots on circles cost two to three
    times what they cost driving straight.

    paced: each step taken at its wall time at real time, as the node at real_time_factor 1 takes
    them, the thread sleeping in between; else back to back. The CPU is the thread's around each
    stepSimulation, as the node's solver figure is. A step after a pause costs more than one right
    after another (on this machine, in one process without ROS: 16 robots at the fleet preset 1.04
    times after pauses of 0.2 ms, 1.2 after 1 ms, 1.5 after 5 ms; busy-waiting the 5 ms instead of
    sleeping, 1.35), so the node at real time is compared with both."""
    from thorvald_base.kinematics.types import Twist  # noqa: PLC0415
    from thorvald_base.plugins import load_calculator  # noqa: PLC0415
    from thorvald_model import load_robot_config  # noqa: PLC0415
    from thorvald_model.description import generate_urdf  # noqa: PLC0415
    from thorvald_sim.bullet import pybullet as p  # noqa: PLC0415
    from thorvald_sim.physics.presets import physics_settings  # noqa: PLC0415
    from thorvald_sim.physics.robot import Pose2D  # noqa: PLC0415
    from thorvald_sim.physics.simulation import Simulation  # noqa: PLC0415
    from thorvald_sim.world import load_world, resolve_world  # noqa: PLC0415

    settings = physics_settings(physics, None, None)
    urdf = generate_urdf(STD)
    calculator = load_calculator(load_robot_config(STD))
    client = p.connect(p.DIRECT)
    try:
        sim = Simulation(
            client, load_world(resolve_world("flat")), settings.rate, solver_iterations=settings.solver_iterations
        )
        for k in range(n):
            vx, wz = twist_of(k)
            drives = calculator.calculate_command(Twist(vx, 0.0, wz)).commands
            robot = sim.spawn(f"r{k}", urdf, Pose2D(*grid(k, n), 0.0))
            robot.command([d.steering for d in drives], [d.speed for d in drives])
        for _ in range(round(2 * settings.rate)):  # under way, the steering turned
            sim.step()
        cpu, start, steps = 0.0, time.perf_counter(), round(seconds * settings.rate)
        for k in range(steps):
            if paced:
                time.sleep(max(0.0, start + k / settings.rate - time.perf_counter()))
            t = time.thread_time()
            p.stepSimulation(physicsClientId=client)
            cpu += time.thread_time() - t
        return cpu / seconds / n
    finally:
        p.disconnect(client)


def _ignore(_msg):
    pass


def case(
    n: int,
    lidar: bool,
    stack: str,
    seconds: float,
    *,
    master,
    rtf: float = 1.0,
    physics: str = "default",
    workers: int = 1,
    drivers: int = 1,
    fleet_topics: bool = True,
):
    """{figure: value} of one fleet, on the benchmark's master."""
    import rospy  # noqa: PLC0415
    from diagnostic_msgs.msg import DiagnosticArray  # noqa: PLC0415
    from geometry_msgs.msg import Twist  # noqa: PLC0415
    from nav_msgs.msg import Odometry  # noqa: PLC0415
    from rosgraph_msgs.msg import Clock  # noqa: PLC0415

    from thorvald_testing.topics import Latest  # noqa: PLC0415

    xml = launch_file(n, lidar, stack, rtf, physics, workers=workers, drivers=drivers, fleet_topics=fleet_topics)
    clock = Latest("/clock", Clock, queue_size=1)
    solver = []  # the simulator's figure per /diagnostics window while measuring [s per simulated s]
    measuring = threading.Event()

    def on_diagnostics(msg):
        for status in msg.status:
            if status.name.endswith(": simulation") and measuring.is_set():
                values = {kv.key: kv.value for kv in status.values}
                solver.append(float(values["solver CPU per simulated second [s]"]))

    diagnostics = rospy.Subscriber("/diagnostics", DiagnosticArray, on_diagnostics, queue_size=10)
    moving = set()
    odometry = [
        rospy.Subscriber(f"/r{k}/odometry/base_raw", Odometry, lambda m, k=k: moving.add(k), queue_size=1)
        for k in range(n)
    ]
    pubs = [rospy.Publisher(f"/r{k}/nav_vel", Twist, queue_size=1) for k in range(n)]
    # the simulator measures a sensor only while somebody reads it: each lidar gets a reader, which
    # takes the message's bytes without decoding them (its CPU, the benchmark's, is not counted)
    scans = [rospy.Subscriber(f"/r{k}/scan", rospy.AnyMsg, _ignore, queue_size=1) for k in range(n)] if lidar else []
    twists = []
    for k in range(n):
        twist = Twist()
        twist.linear.x, twist.angular.z = twist_of(k)
        twists.append(twist)
    stop = threading.Event()
    label = f"{n} robots{' with lidars' if lidar else ''}, {stack}"

    def command():  # 10 Hz of wall time: at real time, 10 Hz of simulated time
        next_at = time.monotonic()
        while not stop.is_set():
            for pub, twist in zip(pubs, twists):
                pub.publish(twist)
            next_at += COMMAND_PERIOD
            stop.wait(max(0.0, next_at - time.monotonic()))

    def now():
        return clock.get().clock.to_sec()

    try:
        with case_launch(xml, master, f"fleet_{n}_{'lidar_' if lidar else ''}{stack}") as launch:
            threading.Thread(target=command, daemon=True).start()
            retry = [time.monotonic() + 30]

            def all_moving():
                check(launch, label)
                missing = [k for k in range(n) if k not in moving]
                if missing and time.monotonic() > retry[0]:
                    # rospy gives up a connection that failed while the machine was swamped (a hundred
                    # processes starting): subscribe again to the robots not heard from
                    for k in missing:
                        odometry[k].unregister()
                        odometry[k] = rospy.Subscriber(
                            f"/r{k}/odometry/base_raw", Odometry, lambda m, k=k: moving.add(k), queue_size=1
                        )
                    retry[0] = time.monotonic() + 30
                return not missing and clock.get() is not None

            def not_moving():
                names = " ".join(f"r{k}" for k in range(n) if k not in moving)
                return f"{label}: odometry from every robot (none from {names or '-'}); see {launch.output}"

            poll(all_moving, 90 + 10 * n, not_moving, interval=0.5)
            for sub in odometry:
                sub.unregister()
            start = now()
            poll(lambda: check(launch, label) or now() - start >= WARM_UP, 20 * WARM_UP, f"{label}: the warm-up")
            roles = processes(launch.proc.pid, master.proc.pid)
            t0, w0, c0 = now(), time.perf_counter(), cpu_by_role(roles)
            measuring.set()
            while now() - t0 < seconds:
                check(launch, label)
                if time.perf_counter() - w0 > 20 * seconds:
                    raise RuntimeError(f"{label}: {now() - t0:.1f} simulated s in {20 * seconds:.0f} wall s")
                time.sleep(0.1)
            t1, w1, c1 = now(), time.perf_counter(), cpu_by_role(roles)
            measuring.clear()
            if not solver:
                raise RuntimeError(f"{label}: no /diagnostics from the simulator while measuring")
            simulated = t1 - t0
            per_robot = {role: (c1[role] - c0[role]) / simulated / n for role in ROLES}
            per_robot["solver"] = sum(solver) / len(solver) / n
            # the solver's CPU is in the processes that step: the simulator's, or its workers'
            per_robot["workers" if workers > 1 else "simulator"] -= per_robot["solver"]
            return {"rtf": simulated / (w1 - w0), "wall": w1 - w0, **per_robot}
    finally:
        stop.set()
        for endpoint in [clock.sub, diagnostics, *odometry, *pubs, *scans]:
            endpoint.unregister()


def simulator_cpu(r) -> float:
    """The simulator's whole CPU per robot and simulated second [s]: its node, its workers, the solver."""
    return r["solver"] + r["simulator"] + r.get("workers", 0.0)


def print_row(n, lidar, stack, r):
    ms = {role: 1000 * r.get(role, 0.0) for role in ROLES}
    total = sum(ms.values())
    raw = ""
    if "raw" in r:  # the same robots on the same circles, stepped raw: the simulator's and its solver's against it
        raw = f" {1000 * r['raw']:>7.1f} {simulator_cpu(r) / r['raw']:>7.2f}x {r['solver'] / r['raw']:>7.2f}x"
        if "raw_paced" in r:  # raw at the node's pace
            raw += f" {1000 * r['raw_paced']:>7.1f} {r['solver'] / r['raw_paced']:>7.2f}x"
    print(
        f"{n:>6} {'yes' if lidar else 'no':>5} {stack:>16} {r['rtf']:>6.2f}{'' if r['rtf'] >= HELD else '*':1}"
        + "".join(f" {ms[role]:>8.1f}" for role in ROLES)
        + f" {total:>7.1f} {total / ms['solver']:>7.1f}x {1000 * simulator_cpu(r) / ms['solver']:>7.2f}x{raw}",
        flush=True,
    )


def plot(results, path):
    import matplotlib  # noqa: PLC0415

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415

    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    for (lidar, stack), points in sorted(results.items()):
        xs = sorted(points)
        ax.plot(xs, [points[x]["rtf"] for x in xs], "o-", label=f"{describe(stack)}{', lidar each' if lidar else ''}")
    ax.axhline(HELD, color="grey", linestyle="--", linewidth=1)
    ax.text(ax.get_xlim()[0], HELD, " held at real time (0.95)", va="bottom", color="grey", fontsize=8)
    ax.set_xlabel("robots (thorvald_ii_4wd4ws_std, full stack each)")
    ax.set_ylabel("real-time factor")
    ax.set_ylim(0, 1.1)
    ax.legend(fontsize=8)
    ax.set_title("bench/fleet.py on 2 cores", fontsize=10)
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    fig.savefig(path, dpi=100)
    print(f"plot: {path}")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seconds", type=float, default=60.0, help="simulated seconds measured per case")
    parser.add_argument("--robots", type=int, nargs="*", default=[4, 8, 12, 16, 20], help="fleet sizes")
    parser.add_argument("--lidar-robots", type=int, nargs="*", default=[4, 8, 12], help="fleet sizes with a lidar each")
    parser.add_argument("--stacks", nargs="+", default=["per-robot", "fleet"], choices=["per-robot", "fleet"])
    parser.add_argument("--physics", nargs="+", default=["default"], choices=["default", "fleet"])
    parser.add_argument("--workers", type=int, nargs="+", default=[1], help="physics worker processes (1: none)")
    parser.add_argument(
        "--fleet-drivers", type=int, default=1, help="fleet_driver processes of the fleet stack (robots dealt)"
    )
    parser.add_argument(
        "--fleet-topics",
        nargs="+",
        default=["on"],
        choices=["on", "off"],
        help="the fleet stack's drive topics on the simulator's fleet topics (on), each robot's own (off), or both",
    )
    parser.add_argument(
        "--real-time-factor", type=float, default=1.0, help="the simulator's pace (1; 0: as fast as it can)"
    )
    parser.add_argument("--plot", help="save the real-time factor against fleet size as this PNG")
    parser.add_argument("--json", help="write every case's figures to this file")
    parser.add_argument("--merge", help="figures of earlier cases (a --json file) to plot and judge with these")
    args = parser.parse_args()
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))
    cases = [(n, False) for n in args.robots] + [(n, True) for n in args.lidar_robots]
    print("CPU per robot and simulated second [ms]; * below 0.95 of real time")
    print(
        f"{'robots':>6} {'lidar':>5} {'stack':>16} {'RTF':>7}"
        + "".join(f" {role[:8]:>8}" for role in ROLES)
        + f" {'total':>7} {'/solver':>8} {'sim/solv':>8} {'raw':>7} {'sim/raw':>8} {'solv/raw':>8}"
        + f" {'paced':>7} {'s/paced':>8}"
    )
    results = {}
    if args.merge:
        with open(args.merge) as f:
            for row in json.load(f):
                results.setdefault((row["lidar"], row["stack"]), {})[row["robots"]] = row["figures"]
                print_row(row["robots"], row["lidar"], row["stack"], row["figures"])
    raw = {}  # (robots, physics): raw pybullet's CPU per robot and simulated second
    with ros_session("bench_fleet", core_only=True) as (master, _):
        for n, lidar in cases:
            for stack in args.stacks:
                for physics in args.physics:
                    if not lidar and (n, physics) not in raw:  # between the launches: nothing else runs
                        raw[n, physics] = (
                            raw_pybullet(n, physics),
                            raw_pybullet(n, physics, paced=True) if args.real_time_factor == 1.0 else None,
                        )
                    topics_of = args.fleet_topics if stack == "fleet" else ["on"]
                    variants = [(w, t) for w in args.workers for t in topics_of]
                    for workers, topics in variants:
                        r = case(
                            n, lidar, stack, args.seconds, master=master, rtf=args.real_time_factor, physics=physics,
                            workers=workers, drivers=args.fleet_drivers, fleet_topics=topics == "on",
                        )  # fmt: skip
                        if not lidar:
                            r["raw"], paced = raw[n, physics]
                            if paced is not None:
                                r["raw_paced"] = paced
                        label = stack + (f"+{physics}" if physics != "default" else "")
                        label += f"+w{workers}" if workers > 1 else ""
                        label += f"+d{args.fleet_drivers}" if stack == "fleet" and args.fleet_drivers > 1 else ""
                        label += "+own" if topics == "off" else ""
                        results.setdefault((lidar, label), {})[n] = r
                        print_row(n, lidar, label, r)
    if args.json:
        rows = [
            {"robots": n, "lidar": lidar, "stack": stack, "figures": r}
            for (lidar, stack), points in sorted(results.items())
            for n, r in sorted(points.items())
        ]
        with open(args.json, "w") as f:
            json.dump(rows, f, indent=1)
    if args.plot:
        plot(results, args.plot)
    ok = verdicts(results)
    for line in projections(results):
        print(line)
    return 0 if ok else 1


def verdicts(results) -> bool:
    ok = True

    def largest_held(lidar, stack):
        points = results.get((lidar, stack), {})
        held = [n for n, r in points.items() if r["rtf"] >= HELD]
        return max(held, default=0)

    print()
    for stack in sorted({s for _, s in results}):
        every = [r for (_, s), points in results.items() if s == stack for r in points.values()]
        stack_ratio = max(sum(r[role] for role in ROLES) / r["solver"] for r in every)
        sim_ratio = max(simulator_cpu(r) / r["solver"] for r in every)
        own_thread = [r for r in every if "+w" not in stack]  # the solver in the node's own thread
        solver_raw = [r["solver"] / r["raw"] for r in own_thread if "raw" in r]
        solver_paced = [r["solver"] / r["raw_paced"] for r in own_thread if "raw_paced" in r]
        held, held_lidar = largest_held(False, stack), largest_held(True, stack)
        fleet = TARGET_WORKER_FLEET if "+w" in stack else TARGET_FLEET
        checks = [
            (f"whole stack's CPU at most {TARGET_STACK:g} x the solver's", stack_ratio <= TARGET_STACK, stack_ratio),
            (f"{fleet} robots held at real time", held >= fleet, held),
            (f"{TARGET_LIDAR_FLEET} robots with a lidar each held", held_lidar >= TARGET_LIDAR_FLEET, held_lidar),
            (
                f"simulator node's CPU at most {TARGET_SIMULATOR:g} x its solver's",
                sim_ratio <= TARGET_SIMULATOR,
                sim_ratio,
            ),
        ]
        for ratios, how in ((solver_raw, "back to back"), (solver_paced, "at the node's pace")):
            if ratios:
                what = f"solver in the node at most {TARGET_SOLVER_RAW:g} x the same steps raw, {how}"
                checks.append((what, max(ratios) <= TARGET_SOLVER_RAW, max(ratios)))
        for what, met, figure in checks:
            ok &= met
            figure = f"{figure:.2f} x" if isinstance(figure, float) else figure
            figure = f"largest held {figure}" if isinstance(figure, int) else figure
            print(f"{stack} stack: {what}: {'met' if met else 'MISSED'} ({figure})")
        for (lidar, s), points in sorted(results.items()):
            if s == stack:
                for n, r in sorted(points.items()):
                    if r["rtf"] < HELD:
                        print(f"  {why_not_held(n, lidar, r)}")
    return ok


def projections(results) -> list:
    """Lines: for each stack, the fleet a machine of PROJECTED_CORES would hold at real time, from its
    largest fleet measured without lidars (see the module's docstring)."""
    lines = []
    for (lidar, stack), points in sorted(results.items()):
        if lidar or not points:
            continue
        held = [k for k, r in points.items() if r["rtf"] >= HELD]
        n = max(held or points)  # the largest held: a fleet that fell behind measures a saturated machine
        r = points[n]
        per_robot = sum(r.get(role, 0.0) for role in ROLES)
        workers = "+w" in stack
        # the node's own thread: its ROS messages and loop, and the physics too unless workers step it
        node = r["simulator"] if workers else r["simulator"] + r["solver"]
        physics = r["solver"] + r.get("workers", 0.0) if workers else 0.0
        driver = r.get("fleet_driver", 0.0)
        lines.append(
            f"projection from {stack}, {n} robots at {r['rtf']:.2f} of real time ({1000 * per_robot:.1f} ms a robot "
            f"and simulated second: node {1000 * node:.1f}, physics {1000 * physics:.1f}, fleet_driver "
            f"{1000 * driver:.1f}):"
        )
        by_node = CORE_USE / node
        for cores in PROJECTED_CORES:
            by_cores = CORE_USE * cores / per_robot
            robots = int(min(by_node, by_cores))
            bound = "the simulator node's thread" if by_node < by_cores else f"{cores} cores"
            count = math.ceil(robots * physics / CORE_USE)
            needed = f"{count} worker{'s' if count != 1 else ''}" if workers else "the physics in the node"
            drivers = math.ceil(robots * driver / CORE_USE) if driver else 0
            lines.append(
                f"  {cores} cores: about {robots} robots, with {needed}"
                + (f" and {drivers} fleet_driver process{'es' if drivers != 1 else ''}" if drivers else "")
                + f" (bound: {bound})"
            )
    return lines


def why_not_held(n: int, lidar: bool, r) -> str:
    """What a fleet that fell behind real time needed: the simulator node's process (pybullet's
    stepSimulation holds the interpreter lock, so the process steps on one core at a time; with
    workers, the physics is theirs), and the whole stack against the machine's cores."""
    stack = n * sum(r.get(role, 0.0) for role in ROLES)
    cores = os.cpu_count() or 1
    if r.get("workers", 0.0) > 0.0:
        node = (
            f"the simulator node needs {n * r['simulator']:.2f} s of one core, its workers "
            f"{n * (r['solver'] + r['workers']):.2f} s (solver {n * r['solver']:.2f} s)"
        )
    else:
        node = (
            f"the simulator process needs {n * (r['solver'] + r['simulator']):.2f} s of one core "
            f"(solver {n * r['solver']:.2f} s)"
        )
    return (
        f"{n} robots{' with lidars' if lidar else ''} at {r['rtf']:.2f}: per simulated second {node}, "
        f"the whole stack {stack:.2f} s of {cores} cores"
    )


def describe(label: str) -> str:
    """A stack's label (STACK[+PRESET][+wN]) in words, for the plot."""
    stack, *rest = label.split("+")
    words = [f"{stack} stack"]
    for part in rest:
        if part == "own":
            words.append("each robot's own drive topics")
        elif part[:1] in "wd" and part[1:].isdigit():
            words.append(f"{part[1:]} {'physics workers' if part[0] == 'w' else 'fleet_drivers'}")
        else:
            words.append(f"{part} physics")
    return ", ".join(words)


if __name__ == "__main__":
    sys.exit(main())
