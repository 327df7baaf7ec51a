#!/usr/bin/env python3
"""Where the field route's end point goes when nothing is left to calibrate: the headland turns.

    python bench/turn_slip.py [--seeds 2 4] [--robot NAME] [--gains 1 1.002 1.004 1.006 1.008 1.01]

For each seed, the as-built robot (``field:SEED``) drives the field route (odometry_report
``--manoeuvre field``) with its own radii and steering offsets in effect (bench/calibration_field.py's
floor: no per-drive calibration can do better). The route's heading error is then split into its
parts (straight rows, headland U turns of 0.75 m radius: where the simulator's ground truth turns
faster than 0.2 rad/s), and the end point is recomputed as if odometry's yaw rate were multiplied by
each gain: every step's displacement in base_link kept, its heading scaled from the start (what a
yaw-rate multiplier in the estimator would give, to within the arcs' shape inside one 20 ms step).

It answers whether a yaw-rate correction for turns, calibrated on turns of the working radius,
could bring the end point within issue 34's 0.5 m where the floor misses it (field:2 and field:4).
About 40 s of wall time a seed.
"""

import argparse
import math
import os
import subprocess
import sys
import tempfile

import numpy as np
from calibration_field import as_built_file

TURNING = 0.2  # [rad/s] of ground truth's yaw rate: a turn


def drive(robot: str, seed: int, out: str) -> str:
    """The field route's bag, the as-built robot's own radii and offsets in effect."""
    os.makedirs(out, exist_ok=True)
    own = as_built_file(robot, seed, os.path.join(out, "own.yaml"))
    cmd = ["rosrun", "thorvald_bringup", "odometry_report", "--robot", robot, "--as-built", f"field:{seed}"]
    cmd += ["--manoeuvre", "field", "--out", out, "--calibration", own]
    done = subprocess.run(cmd, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"{' '.join(cmd)} failed:\n{done.stdout[-2000:]}\n{done.stderr[-2000:]}")
    return os.path.join(out, "odometry_report.bag")


def parts(truth, odometry):
    """[(kind, seconds from the start, ground truth's turn [deg], odometry's heading error made [deg])]."""
    t = np.array(truth.t)
    yaw_truth = np.unwrap(np.array(truth.yaw))
    yaw_odom = np.interp(t, np.array(odometry.t), np.unwrap(np.array(odometry.yaw)))
    error = (yaw_odom - yaw_odom[0]) - (yaw_truth - yaw_truth[0])
    turning = np.abs(np.array(truth.wz)) > TURNING
    bounds = [0, *(np.flatnonzero(np.diff(turning.astype(int))) + 1), len(t) - 1]
    return [
        (
            "turn" if turning[a] else "row",
            t[a] - t[0],
            math.degrees(yaw_truth[b] - yaw_truth[a]),
            math.degrees(error[b] - error[a]),
        )
        for a, b in zip(bounds, bounds[1:])
    ]


def end_point(truth, odometry, gain: float) -> float:
    """[m] between ground truth's end and odometry's, each relative to its own start pose, odometry's
    yaw rate multiplied by gain."""
    t, x, y = np.array(odometry.t), np.array(odometry.x), np.array(odometry.y)
    yaw = np.unwrap(np.array(odometry.yaw))
    end = min(t[-1], truth.t[-1])
    keep = t <= end
    t, x, y, yaw = t[keep], x[keep], y[keep], yaw[keep]
    # each step's displacement in base_link, turned by the scaled heading
    dx, dy = np.diff(x), np.diff(y)
    bx = np.cos(yaw[:-1]) * dx + np.sin(yaw[:-1]) * dy
    by = -np.sin(yaw[:-1]) * dx + np.cos(yaw[:-1]) * dy
    scaled = yaw[0] + gain * (yaw[:-1] - yaw[0])
    ex = np.sum(np.cos(scaled) * bx - np.sin(scaled) * by)
    ey = np.sum(np.sin(scaled) * bx + np.cos(scaled) * by)
    odom_end = relative(ex, ey, yaw[0])
    tt = np.array(truth.t)
    xt, yt, yawt = (np.interp([t[0], end], tt, np.array(v)) for v in (truth.x, truth.y, np.unwrap(truth.yaw)))
    truth_end = relative(xt[1] - xt[0], yt[1] - yt[0], yawt[0])
    return math.hypot(odom_end[0] - truth_end[0], odom_end[1] - truth_end[1])


def relative(dx: float, dy: float, yaw: float):
    return math.cos(yaw) * dx + math.sin(yaw) * dy, -math.sin(yaw) * dx + math.cos(yaw) * dy


def main() -> int:
    from thorvald_bringup.report_bag import read_recording  # noqa: PLC0415

    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, nargs="+", default=[2, 4])
    parser.add_argument("--robot", default="thorvald_ii_6wd6ws_asym")
    parser.add_argument("--gains", type=float, nargs="+", default=[1.0, 1.002, 1.004, 1.006, 1.008, 1.01])
    args = parser.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for seed in args.seeds:
            recording = read_recording(drive(args.robot, seed, os.path.join(tmp, f"field{seed}")))
            truth, odometry = recording.truth, recording.odometry
            print(f"field:{seed}, the field route with the as-built robot's own radii and offsets (lsq):")
            for kind, start, turned, made in parts(truth, odometry):
                if kind == "turn":
                    print(
                        f"  U turn at {start:5.1f} s: ground truth {turned:+8.2f} deg, odometry's heading "
                        f"{made:+6.2f} deg off (it reads the turn {-100 * made / turned:+.2f} % short)"
                    )
            rows.append((seed, [end_point(truth, odometry, g) for g in args.gains]))
    print("\nend point [m] with odometry's yaw rate multiplied by:")
    print("| seed | " + " | ".join(f"{g:g}" for g in args.gains) + " |")
    print("|---|" + "---|" * len(args.gains))
    for seed, ends in rows:
        print(f"| field:{seed} | " + " | ".join(f"{e:.2f}" for e in ends) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
