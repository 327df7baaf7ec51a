#!/usr/bin/env python3
"""run_robot, the simulator without ROS: how fast one robot drives, against the ROS path, and how runs
in several processes scale with the cores.

    python bench/run_robot.py [--robot thorvald_ii_4wd4ws_std] [--world flat] [--processes 1 2]

The manoeuvre is the paper's verification manoeuvre for the robot (thorvald_base.verification's
plan, from 3 s on, as verification_drive drives it), about 85 simulated seconds.

1. run_robot in this process: simulated seconds per wall second (target: at least 30 for the
   standard robot on one core), and its CPU time.
2. The ROS path side by side, the same manoeuvre: ``odometry_report --world W`` (simulator, robot.launch
   in lockstep, base_driver on measured drives, rosbag), its drive's simulated and wall seconds as it
   reports them.
3. N runs at once in N processes (one pybullet DIRECT client each): simulated seconds per wall
   second over all of them, against N times one process's (pybullet's clients are independent, so
   the runs should scale with the cores).

Exits 1 when the 30 x target is missed.
"""

import argparse
import multiprocessing
import os
import re
import subprocess
import sys
import tempfile
import time

from thorvald_base.verification import plan_for
from thorvald_model import load_robot_config
from thorvald_model.description import package_file
from thorvald_sim.tools.runner import RunOptions, commands_from_plan, run_robot

TARGET = 30.0  # simulated seconds per wall second, one robot, one core
START = 3.0  # [s] the manoeuvre's first command, as verification_drive's in a paused lockstep run


def commands_for(robot_file: str):
    return list(commands_from_plan(plan_for(load_robot_config(robot_file))[1], START))


def one_run(args):
    robot_file, world = args
    commands = commands_for(robot_file)
    wall, cpu = time.monotonic(), time.process_time()
    run = run_robot(robot_file, commands, RunOptions(world=world))
    summary = run.summary
    return summary["simulated_s"], time.monotonic() - wall, time.process_time() - cpu, summary["drive_wall_s"]


def ros_path(robot: str, world: str):
    with tempfile.TemporaryDirectory(prefix="bench_run_robot_") as out:
        proc = subprocess.run(
            ["rosrun", "thorvald_bringup", "odometry_report", "--robot", robot, "--world", world, "--out", out],
            capture_output=True,
            text=True,
            timeout=1800,
        )
    m = re.search(r"drive: ([0-9.]+) s simulated in ([0-9.]+) s wall", proc.stdout)
    if m is None:
        raise RuntimeError("odometry_report printed no drive line:\n" + proc.stdout[-2000:] + proc.stderr[-2000:])
    return float(m.group(1)), float(m.group(2))


def main() -> int:
    parser = argparse.ArgumentParser(prog="run_robot", description=__doc__.split("\n")[0])
    parser.add_argument("--robot", default="thorvald_ii_4wd4ws_std")
    parser.add_argument("--world", default="flat")
    parser.add_argument("--processes", type=int, nargs="*", default=[1, 2])
    parser.add_argument("--no-ros", action="store_true", help="leave out the ROS path")
    args = parser.parse_args()
    robot_file = package_file("config", args.robot, args.robot + ".yaml")
    print(f"{args.robot} on {args.world}, the verification manoeuvre ({os.cpu_count()} cores here)\n")

    simulated, wall, cpu, driving = one_run((robot_file, args.world))
    rtf = simulated / driving
    print(
        f"1. run_robot, one process: {simulated:.1f} s simulated in {wall:.2f} s wall, {driving:.2f} s of it driving"
        f" ({wall - driving:.2f} s making the description, the world, the spawn)"
    )
    print(f"   driving {rtf:.1f} x real time, the whole call {simulated / wall:.1f} x;", end=" ")
    print(f"CPU {cpu:.2f} s ({cpu / simulated * 1000:.1f} ms per simulated second)")
    if not args.no_ros:
        ros_simulated, ros_wall = ros_path(args.robot, args.world)
        ros_rtf = ros_simulated / ros_wall
        print(
            f"2. the ROS path (odometry_report, lockstep): {ros_simulated:.1f} s simulated in {ros_wall:.1f} s wall:"
            f" {ros_rtf:.1f} x real time; run_robot drives {rtf / ros_rtf:.1f} x as fast"
        )
    print("3. runs in parallel processes (simulated seconds per wall second, all runs together):")
    for n in args.processes:
        with multiprocessing.get_context("spawn").Pool(n) as pool:
            start = time.monotonic()
            results = pool.map(one_run, [(robot_file, args.world)] * n)
            elapsed = time.monotonic() - start
        together = sum(r[0] for r in results) / elapsed
        processes = f"{n} process{'es' if n > 1 else ''}"
        print(f"   {processes}: {together:6.1f} x real time ({together / (simulated / wall):.2f} x one whole call)")
    met = rtf >= TARGET
    verdict = "met" if met else "MISSED"
    print(f"\ntarget: one robot driving at least {TARGET:g} x real time on one core: {verdict} ({rtf:.1f})")
    return 0 if met else 1


if __name__ == "__main__":
    sys.exit(main())
