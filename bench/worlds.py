#!/usr/bin/env python3
"""What each shipped world costs a robot driving in it, against flat ground, side by side in one run.

    python bench/worlds.py [--rounds N]

The standard robot spawned at the origin of each world (the simulation core, no ROS), driving along
+x at 0.5 m/s (standing in the greenhouse: 2 m ahead are the pipes' ends); after half a simulated
second, the CPU time of this thread per physics step over 1 simulated second (other work on the
machine does not count), the best of three stretches, in rounds that alternate the worlds (a busy
spell hits them all alike); the figure per world is the median of the rounds. Printed: steps a
second and the ratio to flat ground. Target: every shipped world at least 0.3 of flat's steps a
second (plants, tunnels and walls are static bodies a robot pairs with only near them; a height
field costs bullet a triangle test per triangle under each wheel; rolling friction, as farm_track's
grass has, three more constraints a contact, about a fifth of the steps).

Also printed: what loading and building each world costs (CPU of this thread, the file read, checked
and built in a fresh pybullet client, the median of the rounds), against loading pybullet's own plane
in a fresh client; target: every world built within BUILD_TARGET seconds of CPU.
"""

import argparse
import os
import statistics
import sys
import time

from thorvald_model.description import generate_urdf
from thorvald_sim.bullet import pybullet as p
from thorvald_sim.physics.robot import Pose2D
from thorvald_sim.physics.scene import build_scene
from thorvald_sim.physics.simulation import Simulation
from thorvald_sim.world import load_world, resolve_world, shipped_worlds

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
STD = os.path.join(ROOT, "src", "thorvald_model", "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
TARGET = 0.3  # of flat's steps a second, at least
STEPS = 240  # a stretch: 1 s simulated
BUILD_TARGET = 1.5  # [s] of CPU to load and build a shipped world, at most


def build_cpu(name: str) -> float:
    """[s] of CPU to load a world's file and build it in a fresh client (name None: pybullet's plane)."""
    start = time.thread_time()
    client = p.connect(p.DIRECT)
    try:
        if name is None:
            import pybullet_data  # noqa: PLC0415 (the reference only)

            p.loadURDF(os.path.join(pybullet_data.getDataPath(), "plane.urdf"), physicsClientId=client)
        else:
            build_scene(client, load_world(resolve_world(name)))
        return time.thread_time() - start
    finally:
        p.disconnect(client)


def cpu_per_step(name: str, urdf: str) -> float:
    """[s] of CPU a step of a robot driving in the world (best of three stretches)."""
    client = p.connect(p.DIRECT)
    try:
        sim = Simulation(client, load_world(resolve_world(name)))
        robot = sim.spawn("r", urdf, Pose2D())
        if name != "greenhouse":
            robot.command([0.0] * len(robot.steering), [0.5] * len(robot.wheels))
        for _ in range(STEPS // 2):
            sim.step()
        best = float("inf")
        for _ in range(3):
            start = time.thread_time()
            for _ in range(STEPS):
                sim.step()
            best = min(best, (time.thread_time() - start) / STEPS)
        return best
    finally:
        p.disconnect(client)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=3, help="rounds over every world (default 3)")
    args = parser.parse_args()
    urdf = generate_urdf(STD)
    worlds = ["flat"] + [w for w in shipped_worlds() if w != "flat"]
    figures = {w: [] for w in worlds}
    builds = {w: [] for w in [None, *worlds]}
    for _ in range(args.rounds):
        for w in [None, *worlds]:
            builds[w].append(build_cpu(w))
        for w in worlds:
            figures[w].append(cpu_per_step(w, urdf))
    flat = statistics.median(figures["flat"])
    plane = statistics.median(builds[None])
    print(f"{'world':<15} {'steps/s':>9} {'vs flat':>8} {'build [ms]':>11} {'vs plane':>9}")
    missed, slow = [], []
    for w in worlds:
        per_step = statistics.median(figures[w])
        ratio = flat / per_step
        build = statistics.median(builds[w])
        print(f"{w:<15} {1.0 / per_step:9.0f} {ratio:8.2f} {1000 * build:11.1f} {build / plane:9.1f}")
        if ratio < TARGET:
            missed.append(w)
        if build > BUILD_TARGET:
            slow.append(w)
    print(f"(pybullet's plane.urdf in a fresh client: {1000 * plane:.1f} ms)")
    verdict = "missed by " + ", ".join(missed) if missed else "met"
    print(f"target: every world at least {TARGET} of flat's steps a second: {verdict}")
    verdict = "missed by " + ", ".join(slow) if slow else "met"
    print(f"target: every world loaded and built within {BUILD_TARGET} s of CPU: {verdict}")
    return 1 if missed or slow else 0


if __name__ == "__main__":
    sys.exit(main())
