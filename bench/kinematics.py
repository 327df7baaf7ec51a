#!/usr/bin/env python3
"""Kinematics core benchmark: time per control cycle, and odometry accuracy under noise and slip.

    python3 bench/kinematics.py [--cycles N] [--samples N]

1. Time per control cycle (calculate_command + drive layer + calculate_odometry) for robots with 1,
   4, 9 and 20 drives, with each estimator. Target: under 200 us for 9 drives.
2. Accuracy of both estimators on the same generated data (fixed seed) on a 6-drive robot: drive
   states from a true twist, steering encoder noise (0.5 to 2 degrees, Gaussian sd) and wheel slip
   (1 to 5 %, Gaussian sd of the relative speed error). Error = RMS over the samples of the body
   velocity error |v_est - v_true| [m/s] and of the yaw rate error [rad/s]. Target: least squares
   at most a fifth of the paper method's velocity error.
"""

import argparse
import glob
import math
import os
import random
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
for sub in ("thorvald_base", "thorvald_model"):
    path = os.path.join(HERE, "..", "src", sub, "src")
    if path not in sys.path:
        sys.path.insert(0, path)

from thorvald_base.kinematics import DriveLayer, DriveState, PltfClc1WD, PltfClcStd, Twist  # noqa: E402
from thorvald_model import load_robot_config, parse_robot_config  # noqa: E402

SEED = 20240601


def ring(n, radius):
    drives = {}
    for k in range(n):
        a = 2 * math.pi * k / n
        drives[f"drive{k}"] = {"node": k + 1, "x": radius * math.cos(a) + 0.1, "y": radius * math.sin(a)}
    return parse_robot_config({"motor_drives": drives}, f"ring of {n}")


def tricycle():
    return parse_robot_config(
        {
            "base_calculator": "pltf_clc_1wd::PltfClc1WD",
            "motor_drives": {"drive0": {"node": 1, "x": 0.8, "y": 0.0}},
            "passive_wheels": {
                "passive0": {"type": "fixed", "x": 0.0, "y": 0.4},
                "passive1": {"type": "fixed", "x": 0.0, "y": -0.4},
            },
        },
        "tricycle",
    )


def timing_robots():
    return [
        (1, tricycle(), PltfClc1WD),
        (4, ring(4, 0.7), PltfClcStd),
        (9, ring(9, 1.5), PltfClcStd),
        (20, ring(20, 3.5), PltfClcStd),
    ]


def time_cycle(config, cls, estimator, cycles, repeats=3):
    calc = cls.from_config(config, estimator=estimator, seed=SEED)
    layer = DriveLayer(config.drives)
    rng = random.Random(SEED)
    twists = [Twist(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-0.5, 0.5)) for _ in range(64)]
    measured = [0.0] * len(config.drives)
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        for k in range(cycles):
            result = calc.calculate_command(twists[k & 63])
            out = layer.apply(result.commands, measured)
            states = [DriveState(c.steering, c.speed) for c in out.commands]
            calc.calculate_odometry(states, k * 0.02)
            measured = [c.steering for c in out.commands]
        best = min(best, (time.perf_counter() - t0) / cycles)
    return best


def six_drive_robot():
    files = sorted(glob.glob(os.path.join(HERE, "..", "src", "thorvald_model", "config", "*6wd6ws*", "*.yaml")))
    if files:
        return load_robot_config(files[0]), os.path.basename(files[0])
    return ring(6, 1.0), "ring of 6 (no 6wd6ws example robot found)"


def generate(config, samples, rng):
    """True twists: a quarter pure translations (the paper method's special case), the rest arcs."""
    data = []
    for k in range(samples):
        vx, vy = rng.uniform(-1, 1), rng.uniform(-1, 1)
        wz = 0.0 if k % 4 == 0 else rng.uniform(-0.6, 0.6)
        data.append((vx, vy, wz, [rng.gauss(0, 1) for _ in config.drives], [rng.gauss(0, 1) for _ in config.drives]))
    return data


def accuracy(config, data, steer_sd, slip_sd, estimator):
    calc = PltfClcStd.from_config(config, estimator=estimator, seed=SEED)
    ev = ew = 0.0
    for vx, vy, wz, n_steer, n_slip in data:
        states = []
        for d, ns, nv in zip(config.drives, n_steer, n_slip):
            wvx, wvy = vx - wz * d.y, vy + wz * d.x
            states.append(DriveState(math.atan2(wvy, wvx) + steer_sd * ns, math.hypot(wvx, wvy) * (1.0 + slip_sd * nv)))
        est = calc.calculate_odometry(states, 0.0).twist
        ev += (est.vx - vx) ** 2 + (est.vy - vy) ** 2
        ew += (est.wz - wz) ** 2
    return math.sqrt(ev / len(data)), math.sqrt(ew / len(data))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cycles", type=int, default=3000)
    parser.add_argument("--samples", type=int, default=2000)
    args = parser.parse_args(argv)

    print(f"Python {sys.version.split()[0]}; time per control cycle (command + drive layer + odometry), best of 3")
    print(f"{'drives':>6} {'lsq [us]':>10} {'paper [us]':>11}")
    for n, config, cls in timing_robots():
        lsq = time_cycle(config, cls, "lsq", args.cycles) * 1e6
        paper = time_cycle(config, cls, "paper", args.cycles) * 1e6
        print(f"{n:>6} {lsq:>10.1f} {paper:>11.1f}")

    config, name = six_drive_robot()
    if config.base_calculator != "pltf_clc_std::PltfClcStd":
        config = ring(6, 1.0)
        name = "ring of 6"
    data = generate(config, args.samples, random.Random(SEED))
    print()
    print(f"Odometry accuracy on {name} ({len(config.drives)} drives), {args.samples} samples, seed {SEED}")
    print("RMS velocity error [m/s] and yaw rate error [rad/s] vs the true twist; ratio = paper / lsq (velocity)")
    print(f"{'steer sd':>8} {'slip sd':>7} {'lsq v':>9} {'paper v':>9} {'ratio':>7} {'lsq wz':>9} {'paper wz':>9}")
    for deg in (0.5, 1.0, 2.0):
        for slip in (0.01, 0.03, 0.05):
            lv, lw = accuracy(config, data, math.radians(deg), slip, "lsq")
            pv, pw = accuracy(config, data, math.radians(deg), slip, "paper")
            print(f"{deg:>6.1f}deg {slip * 100:>6.0f}% {lv:>9.4f} {pv:>9.4f} {pv / lv:>7.1f} {lw:>9.4f} {pw:>9.4f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
