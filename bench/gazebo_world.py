#!/usr/bin/env python3
"""A large farm world in Gazebo's format: 10,000 plants, instances of one mesh, loaded, built and driven.

    python bench/gazebo_world.py [--plants 10000] [--seconds 10]

Writes a Gazebo world into a temporary folder: Gazebo's sun and ground plane, and a ``<population>``
of a crop model found through ``model://`` on GAZEBO_MODEL_PATH (its collision an OBJ mesh of 64
triangles, a plant 0.3 m wide and 0.4 m tall), as a grid of rows 0.75 m apart, plants 0.2 m apart in
a row. Then measures: reading the world (``load_world``: CPU of this thread), building it with
the standard robot and a planar lidar (721 beams at 20 Hz, at the plants' height) in a
``RobotSession`` (wall time), and driving along the rows at 0.5 m/s for --seconds simulated seconds,
the lidar read as the simulator reads it: the real-time factor (simulated seconds per wall second).
Beside it, in the same run, the same robot and lidar driving on the flat world. Targets (issue 49):
loaded in under 10 s, driven at real time or better.
"""

import argparse
import math
import os
import sys
import tempfile
import time

from thorvald_sim.tools.runner import RobotSession, RunOptions
from thorvald_sim.world import load_world

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
STD = os.path.join(ROOT, "src", "thorvald_model", "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
LIDAR = os.path.join(ROOT, "src", "thorvald_sim", "test", "data", "row_lidar.xacro")
ROW_SPACING = 0.75  # [m]
PLANT_SPACING = 0.2  # [m]

WORLD = """<?xml version="1.0"?>
<sdf version="1.6">
  <world name="field">
    <include><uri>model://sun</uri></include>
    <include><uri>model://ground_plane</uri></include>
    <population name="lettuce">
      <model name="lettuce"><include><uri>model://crop</uri></include></model>
      <pose>{x} {y} 0 0 0 0</pose>
      <box><size>{length} {width} 0.01</size></box>
      <distribution>
        <type>grid</type><rows>{rows}</rows><cols>{cols}</cols><step>{step_x} {step_y} 0</step>
      </distribution>
    </population>
  </world>
</sdf>
"""
CONFIG = '<?xml version="1.0"?><model><name>crop</name><sdf version="1.6">model.sdf</sdf></model>\n'
MODEL = """<?xml version="1.0"?><sdf version="1.6"><model name="crop"><static>true</static><link name="link">
<collision name="collision"><geometry><mesh><uri>model://crop/meshes/plant.obj</uri></mesh></geometry></collision>
<visual name="visual"><geometry><mesh><uri>model://crop/meshes/plant.obj</uri></mesh></geometry></visual>
</link></model></sdf>
"""


def plant_obj(sides=16, radius=0.15, height=0.4) -> str:
    """A plant: a closed cone-topped prism of sides sides (64 triangles at 16), base on z = 0."""
    lines, top = [], 0.6 * height
    for k in range(sides):
        a = 2 * math.pi * k / sides
        lines.append(f"v {radius * math.cos(a):.4f} {radius * math.sin(a):.4f} 0")
        lines.append(f"v {radius * math.cos(a):.4f} {radius * math.sin(a):.4f} {top:.4f}")
    lines += ["v 0 0 0", f"v 0 0 {height:.4f}"]
    bottom, apex = 2 * sides + 1, 2 * sides + 2
    for k in range(sides):
        a0, a1 = 2 * k + 1, 2 * k + 2
        b0, b1 = 2 * ((k + 1) % sides) + 1, 2 * ((k + 1) % sides) + 2
        lines += [f"f {a0} {b0} {b1}", f"f {a0} {b1} {a1}", f"f {a1} {b1} {apex}", f"f {a0} {bottom} {b0}"]
    return "\n".join(lines) + "\n"


def write_world(folder: str, plants: int) -> str:
    crop = os.path.join(folder, "models", "crop")
    os.makedirs(os.path.join(crop, "meshes"))
    with open(os.path.join(crop, "model.config"), "w") as f:
        f.write(CONFIG)
    with open(os.path.join(crop, "model.sdf"), "w") as f:
        f.write(MODEL)
    with open(os.path.join(crop, "meshes", "plant.obj"), "w") as f:
        f.write(plant_obj())
    rows = 20
    cols = max(1, plants // rows)
    length, width = cols * PLANT_SPACING, rows * ROW_SPACING
    # the rows along x, starting 2 m ahead of the robot, the robot between the two middle rows
    text = WORLD.format(
        x=2.0 + length / 2, y=0.0, length=length, width=width, rows=rows, cols=cols,
        step_x=PLANT_SPACING, step_y=ROW_SPACING,
    )  # fmt: skip
    path = os.path.join(folder, "field.world")
    with open(path, "w") as f:
        f.write(text)
    os.environ["GAZEBO_MODEL_PATH"] = os.path.join(folder, "models")
    return path


def drive(world, seconds: float):
    """(build wall [s], real-time factor) of the standard robot with the lidar in world (a WorldConfig or a name)."""
    named = isinstance(world, str)
    options = RunOptions(model_extras=LIDAR, record_sensors=True, **({"world": world} if named else {}))
    started = time.perf_counter()
    session = RobotSession(STD, options, world=None if named else world)
    with session:
        built = time.perf_counter() - started
        started = time.perf_counter()
        session.run(seconds, lambda t: (0.5, 0.0, 0.0))
        wall = time.perf_counter() - started
    return built, seconds / wall


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--plants", type=int, default=10_000)
    parser.add_argument("--seconds", type=float, default=10.0)
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as folder:
        path = write_world(folder, args.plants)
        started = time.thread_time()
        world = load_world(path)  # the budgets the simulator holds every world to
        read = time.thread_time() - started
        print(f"{len(world.models)} plants in {os.path.basename(path)}: read in {read:.2f} s of CPU")
        built, rtf = drive(world, args.seconds)
        print(f"built with the robot and its lidar in {built:.2f} s; driven {args.seconds:g} s: {rtf:.2f} x real time")
        flat_built, flat_rtf = drive("flat", args.seconds)
        print(f"beside it, the flat world: built in {flat_built:.2f} s, driven at {flat_rtf:.2f} x real time")
        print(f"targets: loaded (read and built) in under 10 s: {read + built:.1f} s; real time: {rtf:.2f}")
    return 0 if read + built < 10.0 and rtf >= 1.0 else 1


if __name__ == "__main__":
    sys.exit(main())
