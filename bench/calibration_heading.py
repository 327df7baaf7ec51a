#!/usr/bin/env python3
"""Odometry calibration beyond the profile it was built on: three robots of different layouts, as built
from two profiles, each calibrated as a real robot is and validated on two drives it never saw.

    python bench/calibration_heading.py [--robots R ...] [--profiles field workshop [rigid]] [--seed 4] [--out DIR]

For each robot (default: the paper's Figure 7 robot thorvald_ii_6wd6ws_asym, the standard 4WD4WS, the
2WD differential robot) and profile (``field``: tyres loaded and soft, +-1 % each, homing within +-0.5
degrees, encoders counting; ``workshop``: pneumatic tyres within +-0.85 %, homing within +-0.3 degrees), as a
user types it:

1. ``calibration_drive --as-built PROFILE:SEED --ground-truth gnss``: the calibration manoeuvre against
   the simulated RTK-GNSS and IMU, as a real robot is calibrated; the balance of the motor currents
   where the wheels can fight; the straight legs; the heading manoeuvre and odometry's heading model
   (``calibration.yaml``);
2. ``odometry_report --manoeuvre field`` (five 15 m rows and headland U turns, 84 m) and ``--manoeuvre
   paper`` (the paper-like drive: 80 m of translation in x and y with crab legs, spins on the spot both
   ways between them, a circle and a circle crabbing; a robot that cannot crab drives out and back with
   half turns on the spot about its axle line, twice, and a stadium), uncalibrated and with
   ``calibration.yaml``. Neither is a drive the calibration saw.

Prints the table (lsq odometry against the simulator's ground truth, and in brackets against RTK-GNSS
with the IMU's yaw) and exits 1 when a calibrated drive misses a target: the distance within 0.2 % of
ground truth's and the end point within 0.5 m. A robot whose calibration fails is a miss, with the
reason. One seed a robot and profile (default 4: a seed not looked at while the model was developed).
Every drive runs in lockstep with a ROS master of its own, so ``--jobs 2`` runs two robots at once. Two
runs are not identical: recording starts and stops on wall time (the straight legs held 574 and 611 GNSS
fixes), the radii then differ by 1e-5, and whatever a fit does with that shows (a heading model's wheel
weights, before they had to be told twice). Then, from the bags, how each kind of whole turn reads
(``turns.drive_turns``, the multiplier 1 and the rest of the calibration applied, against the simulator's
ground truth): a spin (under 0.2 m/s of translation while turning), a wide arc (under 0.7 m/s^2 across:
circles, a stadium, a slow robot's U turns) or a tight arc (headland U turns and corners at 1 m/s): what
a yaw-rate multiplier per kind of motion would take up. ``--out DIR`` keeps every bag and report and
runs only what is missing there (a run that stopped resumes; with nothing missing it prints both tables
at once). It prints its wall time: 11 to 12 minutes with ``--jobs 2`` on a 2-core machine with nothing
beside it, 16 to 18 beside other tests.
"""

import argparse
import dataclasses
import json
import os
import subprocess
import sys
import tempfile
import time
from collections import defaultdict
from concurrent.futures import ThreadPoolExecutor

import numpy as np

from thorvald_base.calibration.calibration_file import read_calibration
from thorvald_base.calibration.turns import TURNING, drive_turns
from thorvald_base.calibration_cli import read_bag
from thorvald_base.kinematics.calculator import NO_CORRECTION
from thorvald_model import load_robot_config, with_drive_params
from thorvald_model.description import package_file

DISTANCE, END = 0.2, 0.5  # [%], [m]: issue 46's targets
ROBOTS = ("thorvald_ii_6wd6ws_asym", "thorvald_ii_4wd4ws_std", "thorvald_ii_2wd_diff")
PROFILES = ("field", "workshop")
MANOEUVRES = ("field", "paper")
SPIN = 0.2  # [m/s] of translation while turning: less is a spin
TIGHT = 0.7  # [m/s^2] of lateral acceleration while turning: more is a tight arc
KINDS = ("spin", "wide arc", "tight arc")
DRIVES = (("heading", "calibration/heading.bag"), ("field", "field/calibrated/odometry_report.bag"),
          ("paper", "paper/calibrated/odometry_report.bag"))  # fmt: skip


def kind_of(truth, start: float, end: float) -> str:
    pick = (truth.t >= start) & (truth.t <= end) & (np.abs(truth.wz) > TURNING)
    if not np.any(pick):
        return "spin"
    speed = np.hypot(truth.vx[pick], truth.vy[pick])
    if np.mean(speed) < SPIN:
        return "spin"
    return "tight arc" if np.mean(speed * np.abs(truth.wz[pick])) >= TIGHT else "wide arc"


def turn_kinds(base: str):
    """(the calibration's multiplier, {kind: {drive: [short % per turn]}}) of one robot as built (its
    directory of bags): each whole turn replayed with the calibration but the multiplier 1, by kind."""
    robot = os.path.basename(base).rsplit("_", 1)[0]
    config = load_robot_config(package_file("config", robot, robot + ".yaml"))
    values = read_calibration(os.path.join(base, "calibration", "calibration.yaml"), config)
    config = with_drive_params(config, values.changes)
    model = values.odometry or NO_CORRECTION
    multiplier = model.yaw_rate_multiplier
    unit = dataclasses.replace(model, yaw_rate_multiplier=1.0)
    found = defaultdict(lambda: defaultdict(list))
    for drive, path in DRIVES:
        recording, truth, _, _ = read_bag(os.path.join(base, path), len(config.drives), "sim")
        for turn in drive_turns(config, recording, truth, unit):
            found[kind_of(truth, turn.start, turn.end)][drive].append(turn.short_percent)
    return multiplier, found


def call(cmd, log: str, errors: str = "") -> int:
    with open(log, "w") as f, open(errors or os.devnull, "w") as e:
        return subprocess.run(cmd, stdout=f, stderr=e if errors else subprocess.STDOUT).returncode


def calibrate(robot: str, spec: str, out: str) -> dict:
    """calibration_drive's JSON, or {"error": its last line} when it gives no calibration."""
    path = os.path.join(out, "calibration.json")
    if not os.path.isfile(os.path.join(out, "calibration.yaml")):
        cmd = ["rosrun", "thorvald_bringup", "calibration_drive", "--robot", robot, "--as-built", spec]
        cmd += ["--ground-truth", "gnss", "--out", out, "--json"]
        os.makedirs(out, exist_ok=True)
        call(cmd, path, os.path.join(out, "calibration.err"))
    with open(path) as f:
        text = f.read()
    if not os.path.isfile(os.path.join(out, "calibration.yaml")):
        with open(os.path.join(out, "calibration.err")) as f:
            lines = [line for line in (f.read() + text).splitlines() if line.strip()]
        return {"error": lines[0] if lines else "no output"}
    return json.loads(text[text.index("{") :])


def report(robot: str, spec: str, manoeuvre: str, out: str, calibration: str = "") -> dict:
    """odometry_report's lsq figures against ground truth and against RTK-GNSS."""
    figures = os.path.join(out, "figures.json")
    if not os.path.isfile(figures):
        cmd = ["rosrun", "thorvald_bringup", "odometry_report", "--robot", robot, "--as-built", spec]
        cmd += ["--manoeuvre", manoeuvre, "--out", out, "--json", figures]
        cmd += ["--calibration", calibration] if calibration else []
        os.makedirs(out, exist_ok=True)
        if call(cmd, os.path.join(out, "report.txt")) != 0 or not os.path.isfile(figures):
            with open(os.path.join(out, "report.txt")) as f:
                lines = [line for line in f.read().splitlines() if line.strip()]
            return {"error": "odometry_report: " + (lines[-1] if lines else "no output")}
    with open(figures) as f:
        g = json.load(f)
    return {k: g[k]["odometry lsq"] for k in ("against_truth", "against_rtk_gnss") if k in g}


def cell(f: dict) -> str:
    if not f or "error" in f:
        return "-"
    truth, rtk = f["against_truth"], f.get("against_rtk_gnss")
    text = f"{truth['distance_error_percent']:+.2f} %, {truth['end_point_m']:.2f} m"
    if rtk:
        text += f" ({rtk['distance_error_percent']:+.2f} %, {rtk['end_point_m']:.2f} m)"
    return text


def met(f: dict) -> bool:
    truth = f.get("against_truth") if f else None
    return bool(truth) and abs(truth["distance_error_percent"]) <= DISTANCE and truth["end_point_m"] <= END


def model(result: dict) -> str:
    """What the calibration's heading model came to, in a few words."""
    heading = result.get("heading") or {}
    if "error" in result:
        return "no calibration"
    if not heading or "error" in heading:
        return "no heading model"
    weights = heading["wheel_weights"]["value"]
    said = f"m {heading['yaw_rate_multiplier']['value']:.4f}, b {heading['yaw_per_metre']['value']:+.5f}"
    said += f", c {heading['yaw_per_metre_sideways']['value']:+.5f}"
    return said + (", weights " + " ".join(f"{w:.2f}" for w in weights) if weights else "")


def one_robot(robot: str, profile: str, seed: int, root: str):
    """(rows, misses) of one robot as built from one profile: its calibration and its four drives."""
    spec = f"{profile}:{seed}"
    base = os.path.join(root, f"{robot}_{profile}{seed}")
    result = calibrate(robot, spec, os.path.join(base, "calibration"))
    final = os.path.join(base, "calibration", "calibration.yaml")
    rows, missed = [], []
    for manoeuvre in MANOEUVRES:
        before = report(robot, spec, manoeuvre, os.path.join(base, manoeuvre, "uncalibrated"))
        after = (
            report(robot, spec, manoeuvre, os.path.join(base, manoeuvre, "calibrated"), final)
            if "error" not in result
            else {}
        )
        rows.append((robot, spec, manoeuvre, before, after, model(result)))
        if not met(after):
            why = f": {result['error']}" if "error" in result else (f": {after['error']}" if "error" in after else "")
            missed.append(f"{robot} {spec} {manoeuvre} {cell(after)}{why}")
    print(f"{robot} {spec} done", file=sys.stderr, flush=True)
    return rows, missed


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--robots", nargs="+", default=list(ROBOTS))
    parser.add_argument("--profiles", nargs="+", default=list(PROFILES), choices=(*PROFILES, "rigid"))
    parser.add_argument("--seed", type=int, default=4)
    parser.add_argument("--jobs", type=int, default=1, help="robots calibrated and driven at once (default 1)")
    parser.add_argument("--out", metavar="DIR", help="keep everything here and run only what is missing")
    parser.add_argument("--json", metavar="FILE", help="also write every figure as JSON to FILE")
    args = parser.parse_args()
    start = time.monotonic()
    with tempfile.TemporaryDirectory() as tmp:
        root = os.path.abspath(args.out) if args.out else tmp
        tasks = [(robot, profile) for robot in args.robots for profile in args.profiles]
        with ThreadPoolExecutor(max(1, args.jobs)) as pool:
            done = list(pool.map(lambda task: one_robot(*task, args.seed, root), tasks))
        bases = [(robot, profile, os.path.join(root, f"{robot}_{profile}{args.seed}")) for robot, profile in tasks]
        kinds = [
            (robot, profile, turn_kinds(base))
            for robot, profile, base in bases
            if os.path.isfile(os.path.join(base, "calibration", "calibration.yaml"))
        ]
    rows = [row for part, _ in done for row in part]
    missed = [miss for _, part in done for miss in part]
    print("lsq odometry against ground truth (in brackets against RTK-GNSS and the IMU's yaw), calibrated with")
    print(f"calibration_drive --ground-truth gnss; targets: distance within {DISTANCE} %, end point within {END} m")
    print("| robot | as built | manoeuvre | uncalibrated | calibrated | the heading model |")
    print("|---|---|---|---|---|---|")
    for robot, spec, manoeuvre, before, after, said in rows:
        mark = "" if met(after) else " **missed**"
        print(f"| {robot} | {spec} | {manoeuvre} | {cell(before)} | {cell(after)}{mark} | {said} |")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(
                [
                    {"robot": r, "as_built": s, "manoeuvre": m, "uncalibrated": b, "calibrated": a, "model": d}
                    for r, s, m, b, a, d in rows
                ],
                f,
                indent=1,
            )
    # how each kind of whole turn reads (the bags of every robot calibrated)
    print("\nwhole turns read short [%] with the yaw-rate multiplier 1, the rest of the calibration applied: mean")
    print("(min to max) over N turns of the heading drive and the two calibrated drives")
    print("| robot | as built | m determined | " + " | ".join(KINDS) + " |")
    print("|---|---|---|" + "---|" * len(KINDS))
    for robot, profile, (multiplier, found) in kinds:
        cells = []
        for kind in KINDS:
            values = [v for drive in found[kind].values() for v in drive]
            cells.append(
                f"{np.mean(values):+.2f} ({min(values):+.1f} to {max(values):+.1f}) over {len(values)}"
                if values
                else "-"
            )
        print(f"| {robot} | {profile}:{args.seed} | {multiplier:.4f} | " + " | ".join(cells) + " |")
    wall = time.monotonic() - start
    if missed:
        print("targets missed: " + "; ".join(missed))
    else:
        print("every target met")
    print(f"{len(rows)} drives validated in {wall / 60:.1f} minutes of wall time (--jobs {args.jobs})")
    return 1 if missed else 0


if __name__ == "__main__":
    sys.exit(main())
