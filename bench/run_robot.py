#!/usr/bin/env python3
"""run_robot, the simulator without ROS: how fast one robot drives, against the ROS path, and how runs
in several processes scale with the cores.

    python bench/run_robot.py [--robot thorvald_ii_4wd4ws_std] [--world flat] [--physics default fleet]
                              [--processes 1 2]

The manoeuvre is the paper's verification manoeuvre for the robot (thorvald_base.verification's
plan, from 3 s on, as verification_drive drives it), about 85 simulated seconds.

1. run_robot in this process, on each physics preset: simulated seconds per wall second while
   driving (targets for the standard robot on one core: at least 45 on the default preset and 80 on
   the fleet preset), and its CPU time; beside each, raw pybullet: the same robot in the same world
   (the simulator's Simulation builds both) taking the steps run_robot took: given the motor commands
   run_robot gave at the same steps, the wheels ramping as Simulation.step ramps them, the thread's
   CPU clock around each bare stepSimulation; and run_robot's CPU against it.
2. The ROS path side by side, the same manoeuvre: ``odometry_report --world W`` (simulator, robot.launch
   in lockstep, base_driver on measured drives, rosbag), its drive's simulated and wall seconds as it
   reports them.
3. N runs at once in N processes (one pybullet DIRECT client each): simulated seconds per wall
   second over all of them, against N times one process's (pybullet's clients are independent, so
   the runs should scale with the cores).

Exits 1 when a target is missed.
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
from thorvald_sim.tools.runner import RunOptions, commands_from_plan, robot_urdf, run_robot

TARGETS = {"default": 45.0, "fleet": 80.0}  # simulated seconds per wall second driving, one robot, one core
START = 3.0  # [s] the manoeuvre's first command, as verification_drive's in a paused lockstep run


def commands_for(robot_file: str):
    return list(commands_from_plan(plan_for(load_robot_config(robot_file))[1], START))


def one_run(args):
    robot_file, world, physics = args
    commands = commands_for(robot_file)
    wall, cpu = time.monotonic(), time.process_time()
    run = run_robot(robot_file, commands, RunOptions(world=world, physics=physics))
    summary = run.summary
    return summary["simulated_s"], time.monotonic() - wall, time.process_time() - cpu, summary["drive_wall_s"]


def recorded_run(robot_file: str, world: str, physics: str):
    """one_run's figures, and every motor command run_robot gave the robot: (step, args) in order."""
    from thorvald_sim.physics.robot import SimRobot  # noqa: PLC0415
    from thorvald_sim.physics.simulation import Simulation  # noqa: PLC0415

    given, steps = [], [0]
    command, step = SimRobot.command, Simulation.step

    def recording_command(self, *args):
        given.append((steps[0], args))
        return command(self, *args)

    def counting_step(self):
        step(self)
        steps[0] += 1

    SimRobot.command, Simulation.step = recording_command, counting_step
    try:
        figures = one_run((robot_file, world, physics))
    finally:
        SimRobot.command, Simulation.step = command, step
    return figures, given


def raw_steps(robot_file: str, world: str, physics: str, given, simulated: float) -> float:
    """CPU [s] per simulated second of bare stepSimulation taking the steps run_robot took: the same
    robot spawned the same way in the same world, given the same motor commands at the same steps
    (and the wheels' ramps between, as Simulation.step gives them), the thread's CPU clock around
    each stepSimulation only."""
    from thorvald_sim.bullet import pybullet as p  # noqa: PLC0415
    from thorvald_sim.physics.presets import physics_settings  # noqa: PLC0415
    from thorvald_sim.physics.robot import Pose2D  # noqa: PLC0415
    from thorvald_sim.physics.simulation import Simulation  # noqa: PLC0415
    from thorvald_sim.world import load_world, resolve_world  # noqa: PLC0415

    settings = physics_settings(physics)
    options = RunOptions()
    client = p.connect(p.DIRECT)
    try:
        sim = Simulation(
            client, load_world(resolve_world(world)), settings.rate, solver_iterations=settings.solver_iterations
        )
        robot = sim.spawn(options.robot_name, robot_urdf(robot_file, options), Pose2D())
        cpu, k = 0.0, 1  # the first command was the spawn's own hold
        for n in range(round(simulated * settings.rate)):
            while k < len(given) and given[k][0] <= n:
                robot.command(*given[k][1])
                k += 1
            robot.before_step(sim.dt)
            t = time.thread_time()
            p.stepSimulation(physicsClientId=client)
            cpu += time.thread_time() - t
        return cpu / simulated
    finally:
        p.disconnect(client)


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
    parser.add_argument("--physics", nargs="+", default=["default", "fleet"], choices=sorted(TARGETS))
    parser.add_argument("--no-ros", action="store_true", help="leave out the ROS path")
    args = parser.parse_args()
    robot_file = package_file("config", args.robot, args.robot + ".yaml")
    print(f"{args.robot} on {args.world}, the verification manoeuvre ({os.cpu_count()} cores here)\n")

    met = True
    print("1. run_robot, one process, and raw pybullet through the same manoeuvre:")
    for physics in args.physics:
        (simulated, wall, cpu, driving), given = recorded_run(robot_file, args.world, physics)
        raw = raw_steps(robot_file, args.world, physics, given, simulated)
        rtf = simulated / driving
        target = TARGETS[physics]
        met &= rtf >= target
        print(
            f"   {physics}: {simulated:.1f} s simulated in {wall:.2f} s wall, {driving:.2f} s of it driving"
            f" ({wall - driving:.2f} s making the description, the world, the spawn)"
        )
        print(
            f"      driving {rtf:.1f} x real time (target {target:g}: {'met' if rtf >= target else 'MISSED'}),", end=" "
        )
        print(
            f"the whole call {simulated / wall:.1f} x; CPU {cpu / simulated * 1000:.1f} ms per simulated second,",
            end=" ",
        )
        print(f"raw pybullet {raw * 1000:.1f} ms ({cpu / simulated / raw:.2f} x raw)")
        if physics == args.physics[0]:
            first = (simulated, wall, driving)
    simulated, wall, driving = first
    rtf = simulated / driving
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
            results = pool.map(one_run, [(robot_file, args.world, args.physics[0])] * n)
            elapsed = time.monotonic() - start
        together = sum(r[0] for r in results) / elapsed
        processes = f"{n} process{'es' if n > 1 else ''}"
        print(f"   {processes}: {together:6.1f} x real time ({together / (simulated / wall):.2f} x one whole call)")
    print(f"\ntargets (one robot driving, one core): {'met' if met else 'MISSED'}")
    return 0 if met else 1


if __name__ == "__main__":
    sys.exit(main())
