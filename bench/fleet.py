#!/usr/bin/env python3
"""Fleets in one simulation: the largest fleet this machine holds at real time, and where the CPU goes.

    python bench/fleet.py [--seconds 60] [--robots 4 8 12 16 20] [--lidar-robots 4 8 12]
                          [--stacks per-robot fleet] [--physics default fleet] [--plot docs/images/fleet/rtf.png]

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
``STACK+PRESET``.

Figures per case, over ``--seconds`` simulated seconds after 5 s of warm-up:
- real-time factor (simulated seconds per wall second); held: at least 0.95;
- the CPU per robot and simulated second [ms] of each part: pybullet's solver (the simulator's own
  /diagnostics: the thread CPU clock around stepSimulation), the simulator's ROS and Python work
  (its process's CPU less the solver), base_driver, twist_mux (or the fleet_driver holding both),
  robot_state_publisher, the ROS master, the rest (the world -> odom publishers); and the whole
  stack's against the solver's.

Targets (issue 24): the whole stack's CPU at most 3 times the solver's; 20 robots held at real
time; 12 robots with a lidar each held; the simulator node's own CPU at most 1.3 times its solver's.
Exits 1 when a target is missed; for each fleet that fell behind it prints why: the CPU the
simulator process needed per simulated second (one core at most: stepSimulation holds Python's
interpreter lock) and the whole stack's against the machine's cores.
"""

import argparse
import json
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
ROLES = ("solver", "simulator", "base_driver", "twist_mux", "fleet_driver", "robot_state_publisher", "master", "rest")
TARGET_STACK = 3.0
TARGET_FLEET = 20
TARGET_LIDAR_FLEET = 12
TARGET_SIMULATOR = 1.3


def grid(k, n):
    side = max(1, round(n**0.5))
    return SPACING * (k % side), SPACING * (k // side)


def twist_of(k):
    """Robot k's own circle: (vx [m/s], wz [rad/s])."""
    return 0.30 + 0.02 * (k % 5), 0.3 if k % 2 else -0.3


def launch_file(n: int, lidar: bool, stack: str, rtf: float = 1.0, physics: str = "default"):
    extras = f'<arg name="model_extras" value="{LIDAR}"/>' if lidar else ""
    robots = "\n".join(
        f'  <include file="$(find thorvald_bringup)/launch/sim_robot_in_world.launch"><arg name="ns" value="r{k}"/>'
        f'<arg name="robot_model" value="{STD}"/><arg name="x" value="{grid(k, n)[0]}"/>'
        f'<arg name="y" value="{grid(k, n)[1]}"/><arg name="measured_drives" value="true"/>'
        f'<arg name="fleet_driver" value="{str(stack == "fleet").lower()}"/>{extras}</include>'
        for k in range(n)
    )
    fleet = (
        '  <include file="$(find thorvald_bringup)/launch/fleet_driver.launch">'
        f'<arg name="robots" value="{" ".join(f"r{k}" for k in range(n))}"/></include>\n'
        if stack == "fleet"
        else ""
    )
    return (
        '<launch>\n  <include file="$(find thorvald_sim)/launch/simulator.launch">'
        f'<arg name="world" value="flat"/><arg name="real_time_factor" value="{rtf:g}"/>'
        f'<arg name="physics" value="{physics}"/><arg name="output" value="log"/>'
        f"</include>\n{robots}\n{fleet}</launch>\n"
    )


def role_of(pid: int, master_pid: int) -> str:
    if pid == master_pid:
        return "master"
    match = re.search(r"__name:=(\S+)", cmdline(pid))
    name = match.group(1) if match else ""
    if name in ROLES:
        return name
    return "rest"


def cpu_by_role(pids, master_pid):
    totals = dict.fromkeys(ROLES, 0.0)
    for pid in pids:
        totals[role_of(pid, master_pid)] += cpu_seconds(pid, missing=0.0)
    return totals


def _ignore(_msg):
    pass


def case(n: int, lidar: bool, stack: str, seconds: float, *, master, rtf: float = 1.0, physics: str = "default"):
    """{figure: value} of one fleet, on the benchmark's master."""
    import rospy  # noqa: PLC0415
    from diagnostic_msgs.msg import DiagnosticArray  # noqa: PLC0415
    from geometry_msgs.msg import Twist  # noqa: PLC0415
    from nav_msgs.msg import Odometry  # noqa: PLC0415
    from rosgraph_msgs.msg import Clock  # noqa: PLC0415

    from thorvald_testing.topics import Latest  # noqa: PLC0415

    xml = launch_file(n, lidar, stack, rtf, physics)
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
            pids = [*children(launch.proc.pid), master.proc.pid]
            t0, w0, c0 = now(), time.perf_counter(), cpu_by_role(pids, master.proc.pid)
            measuring.set()
            while now() - t0 < seconds:
                check(launch, label)
                if time.perf_counter() - w0 > 20 * seconds:
                    raise RuntimeError(f"{label}: {now() - t0:.1f} simulated s in {20 * seconds:.0f} wall s")
                time.sleep(0.1)
            t1, w1, c1 = now(), time.perf_counter(), cpu_by_role(pids, master.proc.pid)
            measuring.clear()
            if not solver:
                raise RuntimeError(f"{label}: no /diagnostics from the simulator while measuring")
            simulated = t1 - t0
            per_robot = {role: (c1[role] - c0[role]) / simulated / n for role in ROLES}
            per_robot["solver"] = sum(solver) / len(solver) / n
            per_robot["simulator"] -= per_robot["solver"]  # the simulator process's CPU less its solver
            return {"rtf": simulated / (w1 - w0), "wall": w1 - w0, **per_robot}
    finally:
        stop.set()
        for endpoint in [clock.sub, diagnostics, *odometry, *pubs, *scans]:
            endpoint.unregister()


def print_row(n, lidar, stack, r):
    ms = {role: 1000 * r[role] for role in ROLES}
    total = sum(ms.values())
    print(
        f"{n:>6} {'yes' if lidar else 'no':>5} {stack:>13} {r['rtf']:>6.2f}{'' if r['rtf'] >= HELD else '*':1}"
        + "".join(f" {ms[role]:>8.1f}" for role in ROLES)
        + f" {total:>7.1f} {total / ms['solver']:>7.1f}x {(ms['simulator'] + ms['solver']) / ms['solver']:>7.2f}x",
        flush=True,
    )


def plot(results, path):
    import matplotlib  # noqa: PLC0415

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # noqa: PLC0415

    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    for (lidar, stack), points in sorted(results.items()):
        xs = sorted(points)
        ax.plot(xs, [points[x]["rtf"] for x in xs], "o-", label=f"{stack} stack{', lidar each' if lidar else ''}")
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
        f"{'robots':>6} {'lidar':>5} {'stack':>13} {'RTF':>7}"
        + "".join(f" {role[:8]:>8}" for role in ROLES)
        + f" {'total':>7} {'/solver':>8} {'sim/solv':>8}"
    )
    results = {}
    if args.merge:
        with open(args.merge) as f:
            for row in json.load(f):
                results.setdefault((row["lidar"], row["stack"]), {})[row["robots"]] = row["figures"]
                print_row(row["robots"], row["lidar"], row["stack"], row["figures"])
    with ros_session("bench_fleet", core_only=True) as (master, _):
        for n, lidar in cases:
            for stack in args.stacks:
                for physics in args.physics:
                    r = case(n, lidar, stack, args.seconds, master=master, rtf=args.real_time_factor, physics=physics)
                    label = stack if physics == "default" else f"{stack}+{physics}"
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
    return 0 if verdicts(results) else 1


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
        sim_ratio = max((r["simulator"] + r["solver"]) / r["solver"] for r in every)
        held, held_lidar = largest_held(False, stack), largest_held(True, stack)
        checks = [
            (f"whole stack's CPU at most {TARGET_STACK:g} x the solver's", stack_ratio <= TARGET_STACK, stack_ratio),
            (f"{TARGET_FLEET} robots held at real time", held >= TARGET_FLEET, held),
            (f"{TARGET_LIDAR_FLEET} robots with a lidar each held", held_lidar >= TARGET_LIDAR_FLEET, held_lidar),
            (
                f"simulator node's CPU at most {TARGET_SIMULATOR:g} x its solver's",
                sim_ratio <= TARGET_SIMULATOR,
                sim_ratio,
            ),
        ]
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


def why_not_held(n: int, lidar: bool, r) -> str:
    """What a fleet that fell behind real time needed: the simulator process alone (pybullet's
    stepSimulation holds the interpreter lock, so the process steps on one core at a time), and the
    whole stack against the machine's cores."""
    simulator = n * (r["solver"] + r["simulator"])
    stack = n * sum(r[role] for role in ROLES)
    cores = os.cpu_count() or 1
    return (
        f"{n} robots{' with lidars' if lidar else ''} at {r['rtf']:.2f}: per simulated second the simulator process "
        f"needs {simulator:.2f} s of one core (solver {n * r['solver']:.2f} s), the whole stack {stack:.2f} s "
        f"of {cores} cores"
    )


if __name__ == "__main__":
    sys.exit(main())
