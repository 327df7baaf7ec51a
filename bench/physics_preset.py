#!/usr/bin/env python3
"""The fleet physics preset against the default, side by side in one run: what it costs, what it changes.

    python bench/physics_preset.py [--robots 16] [--seconds 3] [--repeats 3]

Cost: N standard robots on the flat world, driving (wheels turned 0.3 rad, 0.5 m/s), set up by the
simulator's Simulation class; CPU per robot and simulated second of Simulation.step (the solver and
the wheels' ramps in Python) and of bare pybullet.stepSimulation, each preset in turn, repeated and
interleaved (the median is printed: this machine is noisy).

What it changes: every example robot drives the paper's verification manoeuvre (about 80 m) on
tarmac_gravel through the simulator library (thorvald_sim.tools.runner: base_driver's core in lockstep,
no ROS), with each preset: odometry's distance error and end point against ground truth, and how far
the fleet preset's true path strays from the default's (the largest distance at one instant).

About 2 minutes here.
"""

import argparse
import math
import os
import statistics
import sys
import time

import numpy as np

from thorvald_base.verification import plan_for
from thorvald_model import load_robot_config
from thorvald_model.description import generate_urdf
from thorvald_sim.bullet import pybullet as p
from thorvald_sim.physics.presets import PRESETS
from thorvald_sim.physics.robot import Pose2D
from thorvald_sim.physics.simulation import Simulation
from thorvald_sim.tools.runner import RunOptions, commands_from_plan, run_robot
from thorvald_sim.world import load_world, resolve_world

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
CONFIGS = os.path.join(ROOT, "src", "thorvald_model", "config")
STD = os.path.join(CONFIGS, "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")


def cost(preset: str, n: int, seconds: float):
    """(Simulation.step, bare stepSimulation) CPU [ms] per robot and simulated second."""
    physics = PRESETS[preset]
    urdf = generate_urdf(STD)
    c = p.connect(p.DIRECT)
    try:
        world = load_world(resolve_world("flat"))
        sim = Simulation(c, world, physics.rate, solver_iterations=physics.solver_iterations)
        for k in range(n):
            sim.spawn(f"r{k}", urdf, Pose2D(6.0 * (k % 4), 6.0 * (k // 4), 0.0)).command([0.3] * 4, [0.5] * 4)
        for _ in range(round(physics.rate)):  # under way
            sim.step()
        steps = round(seconds * physics.rate)
        cpu = time.process_time()
        for _ in range(steps):
            sim.step()
        core = time.process_time() - cpu
        cpu = time.process_time()
        for _ in range(steps):
            p.stepSimulation(physicsClientId=c)
        raw = time.process_time() - cpu
    finally:
        p.disconnect(c)
    return 1000.0 * core / seconds / n, 1000.0 * raw / seconds / n


def paper(robot: str, preset: str):
    commands = commands_from_plan(plan_for(load_robot_config(robot))[1], 1.0)
    cpu = time.process_time()
    run = run_robot(robot, commands, RunOptions(world="tarmac_gravel", physics=preset))
    return run, time.process_time() - cpu


def stray(a, b) -> float:
    """The largest distance [m] between two true paths at one instant (b interpolated to a's times)."""
    tb = np.array([s.t for s in b])
    xb, yb = np.array([s.x for s in b]), np.array([s.y for s in b])
    return max(math.hypot(s.x - np.interp(s.t, tb, xb), s.y - np.interp(s.t, tb, yb)) for s in a)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robots", type=int, default=16)
    parser.add_argument("--seconds", type=float, default=3.0)
    parser.add_argument("--repeats", type=int, default=3)
    args = parser.parse_args()
    names = tuple(PRESETS)
    costs = {name: [] for name in names}
    for _ in range(args.repeats):
        for name in names:
            costs[name].append(cost(name, args.robots, args.seconds))
    print(f"{args.robots} standard robots driving on flat ground, CPU [ms] per robot and simulated second (median):")
    print("| preset | rate [Hz] | solver iterations | Simulation.step | bare stepSimulation |")
    print("|---|---|---|---|---|")
    median = {}
    for name in names:
        step = statistics.median(c[0] for c in costs[name])
        raw = statistics.median(c[1] for c in costs[name])
        median[name] = step
        physics = PRESETS[name]
        print(f"| {name} | {physics.rate:g} | {physics.solver_iterations} | {step:.2f} | {raw:.2f} |")
    print(f"fleet / default: {median['fleet'] / median['default']:.2f}")
    print()
    print("The paper's verification manoeuvre on tarmac_gravel (lsq odometry against ground truth):")
    print("| robot | default: distance, end | fleet: distance, end | fleet's path from default's [m] | run CPU [s] |")
    print("|---|---|---|---|---|")
    for name in sorted(os.listdir(CONFIGS)):
        robot = os.path.join(CONFIGS, name, name + ".yaml")
        if not os.path.isfile(robot):
            continue
        cells, runs, cpus = [], [], []
        for preset in ("default", "fleet"):
            run, cpu = paper(robot, preset)
            s = run.summary
            error = 100.0 * (s["distance_odometry_m"] / s["distance_truth_m"] - 1.0)
            cells.append(f"{error:+.2f} %, {s['end_point_difference_m']:.2f} m")
            runs.append(run)
            cpus.append(cpu)
        apart = stray(runs[1].ground_truth, runs[0].ground_truth)
        print(f"| {name} | {cells[0]} | {cells[1]} | {apart:.2f} | {cpus[0]:.1f} / {cpus[1]:.1f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
