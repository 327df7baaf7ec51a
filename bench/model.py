#!/usr/bin/env python3
"""Time to generate URDFs: every example robot, and how the time grows with the number of drives.

    python bench/model.py [--repeat N]

1. Each example robot: the median of N in-process runs of thorvald_model.description.generate_urdf
   (xacro with the shared loader) after one warm-up run that also pays the imports ("warm"), and a
   fresh process running the CLI as a launch file's command does ("cold"). Target: 9WD9WS cold
   under 1 s.
2. Growth: grid robots of N type-0 drives 0.6 m apart (nodes 1..N) with the standard robot's other
   sections (batteries, corners, pipes, beams), N = 10, 20, 40, 80, 100, 120, measured in this one
   run. Target: the time per drive at 100 drives at most 1.5 times the time per drive at 10 drives
   (linear growth; the recursion over names[1:] this replaced was quadratic from about 20 drives).
3. Bad input: a "billion laughs" (9 levels of 10 aliases, 10^9 values in about 450 bytes) refused by
   the shared loader (thorvald_model.schema.load_yaml), against yaml.safe_load of the standard
   robot's file, the median of N each. Target: refused in less time than a robot file takes to load
   (the bound stops it after 10^5 values, before levels f to i are composed).
"""

import argparse
import glob
import math
import os
import statistics
import subprocess
import sys
import tempfile
import time

import yaml

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
PKG = os.path.join(ROOT, "src", "thorvald_model")
sys.path.insert(0, os.path.join(PKG, "src"))

from thorvald_model.description import generate_urdf  # noqa: E402
from thorvald_model.errors import YamlBoundError  # noqa: E402
from thorvald_model.schema import load_yaml  # noqa: E402

TARGET_9WD9WS = 1.0  # [s], cold
TARGET_GROWTH = 1.5  # time per drive at 100 drives / at 10 drives
GROWTH_SIZES = (10, 20, 40, 80, 100, 120)
STANDARD = os.path.join(PKG, "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
SPACING = 0.6  # [m] between neighbouring drives of a grid robot


def grid_robot(n: int) -> dict:
    """The standard robot's file with its drives replaced by n type-0 drives on a square grid."""
    with open(STANDARD) as f:
        data = yaml.safe_load(f)
    cols = math.ceil(math.sqrt(n))
    data["motor_drives"] = {
        f"drive{k}": {"node": k + 1, "x": SPACING * (k % cols), "y": SPACING * (k // cols), "type": 0} for k in range(n)
    }
    return data


def timed(path: str, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        start = time.perf_counter()
        generate_urdf(path)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def example_robots(repeat: int) -> float:
    robots = sorted(glob.glob(os.path.join(PKG, "config", "*", "*.yaml")))
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([os.path.join(PKG, "src"), os.environ.get("PYTHONPATH", "")]))
    print(f"{'robot':<30} {'links':>5} {'joints':>6} {'warm [s]':>9} {'cold [s]':>9}")
    worst = 0.0
    for path in robots:
        name = os.path.splitext(os.path.basename(path))[0]
        urdf = generate_urdf(path)
        warm = timed(path, repeat)
        start = time.perf_counter()
        subprocess.run(
            [sys.executable, "-m", "thorvald_model.generate_urdf", path], env=env, check=True, stdout=subprocess.DEVNULL
        )
        cold = time.perf_counter() - start
        print(f"{name:<30} {urdf.count('<link '):>5} {urdf.count('<joint '):>6} {warm:>9.3f} {cold:>9.3f}")
        if "9wd9ws" in name:
            worst = max(worst, cold)
    return worst


def growth(repeat: int) -> dict:
    print(f"\n{'drives':>6} {'links':>6} {'joints':>6} {'time [s]':>9} {'per drive [ms]':>15} {'vs 10 drives':>13}")
    per_drive = {}
    with tempfile.TemporaryDirectory() as tmp:
        for n in GROWTH_SIZES:
            path = os.path.join(tmp, f"grid_{n}.yaml")
            with open(path, "w") as f:
                yaml.safe_dump(grid_robot(n), f)
            urdf = generate_urdf(path)
            seconds = timed(path, max(1, repeat // 2) if n > 40 else repeat)
            per_drive[n] = seconds / n
            ratio = per_drive[n] / per_drive[GROWTH_SIZES[0]]
            print(
                f"{n:>6} {urdf.count('<link '):>6} {urdf.count('<joint '):>6} {seconds:>9.3f}"
                f" {1000 * per_drive[n]:>15.1f} {ratio:>13.2f}"
            )
    return per_drive


def bomb(levels: int = 9, fan: int = 10) -> str:
    """Level a holds fan scalars, each next level fan aliases of the one before: fan^levels values."""
    names = "abcdefghijklmnopqrstuvwxyz"[:levels]
    lines = [f"  a: &a [{', '.join(['lol'] * fan)}]"]
    for prev, name in zip(names, names[1:]):
        lines.append(f"  {name}: &{name} [{', '.join(['*' + prev] * fan)}]")
    return "lol:\n" + "\n".join(lines) + "\n"


def bad_input(repeat: int) -> float:
    """(bomb refused, robot file loaded) [s], medians; prints both and their ratio."""
    text = bomb()
    std = os.path.join(PKG, "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
    with open(std) as f:
        robot = f.read()
    refused, loaded = [], []
    for _ in range(repeat):
        start = time.perf_counter()
        try:
            load_yaml(text)
        except YamlBoundError:
            refused.append(time.perf_counter() - start)
        else:
            raise SystemExit("the bomb was not refused")
        start = time.perf_counter()
        yaml.safe_load(robot)
        loaded.append(time.perf_counter() - start)
    bomb_s, robot_s = statistics.median(refused), statistics.median(loaded)
    print(f"\nbad input: a {len(text)}-byte billion laughs refused in {1000 * bomb_s:.2f} ms; "
          f"the standard robot's file loads in {1000 * robot_s:.2f} ms ({bomb_s / robot_s:.2f} x)")  # fmt: skip
    return bomb_s / robot_s


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeat", type=int, default=5)
    args = parser.parse_args()
    worst = example_robots(args.repeat)
    per_drive = growth(args.repeat)
    ratio = per_drive[100] / per_drive[10]
    bomb_ratio = bad_input(args.repeat)
    ok_cold = worst < TARGET_9WD9WS
    ok_growth = ratio <= TARGET_GROWTH
    print(
        f"\ntarget: 9WD9WS under {TARGET_9WD9WS:.1f} s including process start: "
        f"{'met' if ok_cold else 'MISSED'} ({worst:.3f} s)"
    )
    print(
        f"target: time per drive at 100 drives at most {TARGET_GROWTH} x that at 10: "
        f"{'met' if ok_growth else 'MISSED'} ({ratio:.2f} x)"
    )
    ok_bomb = bomb_ratio < 1.0
    print(f"target: the bomb refused in less time than the robot file loads: {'met' if ok_bomb else 'MISSED'}")
    return 0 if ok_cold and ok_growth and ok_bomb else 1


if __name__ == "__main__":
    sys.exit(main())
