#!/usr/bin/env python3
"""Design studies: how fast the runs go, per worker, and how they scale from 1 to 2 worker processes.

    python bench/design_study.py [--study src/thorvald_design/studies/example_robots.yaml] [--jobs 1 2]

Runs the study (by default the example robots through every scenario) once with each number of
worker processes, as a user types it (``rosrun thorvald_design design_study STUDY --out DIR --jobs N``),
and prints side by side: the wall time, the simulated seconds of every run (the study's timing.json),
simulated seconds per wall second per worker, and the speed-up against one worker. The results of
every run must be the same whatever the workers (checked: results.json to the byte). Beside them,
how well the runs were spread over the workers (the runs' wall time against the sum of every run's
own over the workers: the runs start longest first) and what the rest of the call took (starting,
the workers, the report).

Target (issue 33): the example robots through every scenario in under 10 minutes on this machine
with its cores; exits 1 when missed.
"""

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

TARGET = 600.0  # [s] the example robots through every scenario, all the machine's cores
HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT = os.path.join(HERE, "..", "src", "thorvald_design", "studies", "example_robots.yaml")


def run(study: str, out: str, jobs: int) -> dict:
    started = time.monotonic()
    done = subprocess.run(
        ["rosrun", "thorvald_design", "design_study", study, "--out", out, "--jobs", str(jobs)],
        capture_output=True,
        text=True,
    )
    wall = time.monotonic() - started
    if done.returncode != 0:
        sys.exit(f"design_study --jobs {jobs} failed:\n{done.stderr[-3000:]}")
    with open(os.path.join(out, "timing.json"), encoding="utf-8") as f:
        timing = json.load(f)
    with open(os.path.join(out, "results.json"), "rb") as f:
        results = f.read()
    return {"jobs": jobs, "wall": wall, "simulated": timing["simulated_s"], "runs": len(timing["runs"]),
            "runs_wall": timing["wall_s"], "run_sum": sum(r["wall_s"] for r in timing["runs"]),
            "results": results}  # fmt: skip


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--study", default=os.path.normpath(DEFAULT))
    parser.add_argument("--jobs", type=int, nargs="+", default=[1, 2])
    args = parser.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for jobs in args.jobs:
            rows.append(run(args.study, os.path.join(tmp, f"jobs{jobs}"), jobs))
    base = rows[0]
    print(f"study: {args.study}, {base['runs']} runs, {base['simulated']:.0f} simulated seconds")
    print(
        f"{'workers':>8} {'wall [s]':>9} {'sim s / wall s':>15} {'per worker':>11} {'speed-up':>9}"
        f" {'runs [s]':>9} {'sum / N':>8} {'runs / (sum / N)':>17} {'the rest [s]':>13}"
    )
    for r in rows:
        rate = r["simulated"] / r["wall"]
        share = r["run_sum"] / r["jobs"]  # the runs' wall time over the workers: what perfect scheduling gives
        print(
            f"{r['jobs']:>8} {r['wall']:>9.1f} {rate:>15.1f} {rate / r['jobs']:>11.1f} {base['wall'] / r['wall']:>9.2f}"
            f" {r['runs_wall']:>9.1f} {share:>8.1f} {r['runs_wall'] / share:>17.2f} {r['wall'] - r['runs_wall']:>13.1f}"
        )
    print(
        "(runs: from the first run's start to the last one's end; sum / N: every run's own wall time over the"
        " workers; the rest: starting, the workers, the report)"
    )
    same = all(r["results"] == base["results"] for r in rows)
    print(f"results.json the same for every number of workers: {same}")
    fastest = min(r["wall"] for r in rows)
    verdict = "met" if fastest < TARGET else "MISSED"
    print(f"target: under {TARGET:.0f} s with the machine's cores: {fastest:.0f} s ({verdict})")
    return 0 if same and fastest < TARGET else 1


if __name__ == "__main__":
    sys.exit(main())
