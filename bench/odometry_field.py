#!/usr/bin/env python3
"""The paper's odometry experiment on as-built robots: five field robots, and what each imperfection
contributes, against RTK-GNSS as the paper measured and against the simulator's true pose.

    python bench/odometry_field.py [--seeds 1 2 3 4 5] [--ablation-seed 3] [--robot NAME]

1. For each seed, ``odometry_report --as-built field:SEED`` on tarmac_gravel (the paper's six-wheeled
   robot by default): odometry's (lsq) distance error and end-point difference against RTK-GNSS.
   Target: the paper's range over five seeds, distance error 0.5 to 2 % and end point 1 to 4 m.
2. Ablation, on one seed's draw: the ideal robot on flat ground; each imperfection of that draw alone
   on flat ground (each tyre's own radius, the load's common radius, the steering offsets, the
   encoders' counts, the tyres' softness, and each tyre's own radius on soft tyres); the ideal robot
   on tarmac_gravel (the terrain alone); and everything on tarmac_gravel.

Each run is a simulation of about 90 s, as fast as the machine can (about 30 s of wall time here),
in lockstep: a seed gives the same figures on every run. Exit status 1 when the target is missed.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile

import yaml

from thorvald_model import load_robot_config
from thorvald_sim.physics.as_built import draw_as_built

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
CONFIGS = os.path.join(ROOT, "src", "thorvald_model", "config")
DISTANCE_RANGE = (0.5, 2.0)  # [%] the paper's range (its robot: +1.0 %)
END_POINT_RANGE = (1.0, 4.0)  # [m] (its robot: 2.2 m)


def run(robot: str, as_built: str, world: str, out: str) -> dict:
    """One odometry_report: its figures (the --json file)."""
    figures = os.path.join(out, "figures.json")
    cmd = ["rosrun", "thorvald_bringup", "odometry_report", "--robot", robot, "--world", world, "--out", out]
    cmd += ["--json", figures] + (["--as-built", as_built] if as_built else [])
    result = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if not os.path.isfile(figures):
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{result.stdout[-3000:]}")
    with open(figures) as f:
        return json.load(f)


def lsq(figures: dict, against: str = "against_rtk_gnss") -> dict:
    return figures[against]["odometry lsq"]


def only(built, what: str) -> dict:
    """An as-built file's contents keeping one kind of imperfection of a draw: ``radius`` (each tyre's
    own, without the load), ``loaded`` (the load's common radius, every tyre alike), ``steering``,
    ``encoders``, ``tyres`` (soft: their deflection under the load), ``radius+tyres``; rigid tyres but
    for the last two."""
    data = {"encoders": what == "encoders"}
    if what in ("tyres", "radius+tyres"):
        data["tyre_deflection"] = built.tyre_deflection
    if what in ("radius", "radius+tyres"):
        data["motor_drives"] = {d.name: {"r_wheel": d.r_wheel / (1.0 - built.loaded)} for d in built.drives}
    elif what == "loaded":
        data["motor_drives"] = {
            d.name: {"r_wheel": r * (1.0 - built.loaded)} for d, r in zip(built.drives, built.configured)
        }
    elif what == "steering":
        data["motor_drives"] = {d.name: {"steering_offset": d.steering_offset} for d in built.drives}
    return data


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3, 4, 5])
    parser.add_argument("--ablation-seed", type=int, default=3)
    parser.add_argument("--robot", default="thorvald_ii_6wd6ws_asym", help="an example robot (the paper's)")
    args = parser.parse_args()
    config = load_robot_config(os.path.join(CONFIGS, args.robot, args.robot + ".yaml"))
    work = tempfile.mkdtemp(prefix="odometry_field_")
    print(f"odometry_report on {args.robot}, as built field:SEED, tarmac_gravel (runs in {work})\n")
    print("1. five field robots: odometry (lsq) against RTK-GNSS, and against the true pose")
    print(f"{'seed':>6} {'error vs GNSS':>14} {'end vs GNSS':>12} {'error vs truth':>15} {'end vs truth':>13}")
    inside = 0
    for seed in args.seeds:
        f = run(args.robot, f"field:{seed}", "tarmac_gravel", os.path.join(work, f"seed{seed}"))
        g, t = lsq(f), lsq(f, "against_truth")
        ok = DISTANCE_RANGE[0] <= abs(g["distance_error_percent"]) <= DISTANCE_RANGE[1]
        ok &= END_POINT_RANGE[0] <= g["end_point_m"] <= END_POINT_RANGE[1]
        inside += ok
        print(
            f"{seed:>6} {g['distance_error_percent']:>+13.2f}% {g['end_point_m']:>11.2f}m "
            f"{t['distance_error_percent']:>+14.2f}% {t['end_point_m']:>12.2f}m",
            flush=True,
        )
    verdict = inside == len(args.seeds)
    print(
        f"target: every seed in the paper's range (|error| {DISTANCE_RANGE[0]:g} to {DISTANCE_RANGE[1]:g} %, end "
        f"point {END_POINT_RANGE[0]:g} to {END_POINT_RANGE[1]:g} m): {'met' if verdict else 'MISSED'} "
        f"({inside} of {len(args.seeds)})\n"
    )

    built = draw_as_built(f"field:{args.ablation_seed}", config)
    print(f"2. ablation, field:{args.ablation_seed}'s imperfections one at a time (odometry lsq against RTK-GNSS)")
    print(f"{'case':>38} {'error':>8} {'end point':>10} {'heading':>9}")
    cases = [("ideal robot, flat ground", "", "flat")]
    for what in ("radius", "loaded", "steering", "encoders", "tyres", "radius+tyres"):
        path = os.path.join(work, f"only_{what}.yaml")
        with open(path, "w") as f:
            yaml.safe_dump(only(built, what), f)
        cases.append((f"{what} only, flat ground", path, "flat"))
    cases += [
        ("ideal robot, tarmac_gravel (terrain)", "", "tarmac_gravel"),
        ("everything, tarmac_gravel", f"field:{args.ablation_seed}", "tarmac_gravel"),
    ]
    for k, (label, as_built, world) in enumerate(cases):
        g = lsq(run(args.robot, as_built, world, os.path.join(work, f"case{k}")))
        print(
            f"{label:>38} {g['distance_error_percent']:>+7.2f}% {g['end_point_m']:>9.2f}m {g['heading_deg']:>+8.2f}d",
            flush=True,
        )
    return 0 if verdict else 1


if __name__ == "__main__":
    sys.exit(main())
