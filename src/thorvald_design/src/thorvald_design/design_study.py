"""``rosrun thorvald_design design_study STUDY.yaml --out DIR [--jobs N] [--resume]``: a design study
run from the command line.

The study file is read and checked first (every problem with its key path, value and rule; exit 2,
no traceback). Every candidate's robot file is written to ``DIR/candidates/``; the runs (one a
candidate and scenario) go to N worker processes (default: the machine's cores), each its own
pybullet client, a progress bar on the terminal saying which candidate and scenario run; each run's
result lands in ``DIR/results.json`` as it ends (so nothing is lost to an interruption, and
``--resume`` skips the runs already there), and at the end ``DIR/results.csv`` and a table on the
terminal. Anything else the package refuses (:class:`thorvald_design.errors.DesignError`) ends the
command with one line and exit 2, as does a file it cannot write; a run never does (what breaks in
it is its result, ``"failed: ..."``).

No ROS master: the runs use the simulator library's runner.
"""

import argparse
import os
import sys
import time
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from multiprocessing import get_context
from typing import Dict, List, Optional, Set, Tuple

from tqdm import tqdm

from thorvald_model import load_robot_config
from thorvald_model.errors import ThorvaldModelError

from .errors import DesignError, StudyError
from .report import write_report
from .report.table import results_table, write_csv
from .runs import (
    TIMING,
    Job,
    done,
    empty_results,
    longest_first,
    merge,
    prepare,
    read_results,
    read_timing,
    run_one,
    write_json,
    write_results,
)
from .search import run_search, search_table
from .study import load_study


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="design_study",
        description="Compare robot designs in simulation: candidates through scenarios, metrics from ground truth.",
    )
    p.add_argument("study", help="the study file (YAML: candidates and scenarios; docs/design-studies.md)")
    p.add_argument("--out", required=True, metavar="DIR", help="where results.json, results.csv and the rest go")
    p.add_argument("--jobs", type=int, default=0, metavar="N", help="worker processes (default: the cores)")
    p.add_argument("--resume", action="store_true", help="keep the results already in DIR; run only the rest")
    p.add_argument(
        "--scheduler",
        metavar="ADDRESS",
        help="run on a Dask distributed scheduler (tcp://HOST:8786) instead of local worker processes",
    )
    p.add_argument(
        "--scheduler-timeout",
        type=float,
        default=SCHEDULER_TIMEOUT,
        metavar="S",
        help=f"with --scheduler: how long to try reaching it before giving up (default {SCHEDULER_TIMEOUT:g} s)",
    )
    p.add_argument("--optimise", action="store_true", help="run the study's optimise: search instead of its candidates")
    p.add_argument(
        "--against-sweep",
        action="store_true",
        help="with --optimise: also run the full sweep of the same space and compare the fronts and runs",
    )
    return p


def main(argv: Optional[List[str]] = None) -> int:
    args = build_parser().parse_args(argv)
    if args.jobs < 0:
        print("design_study: --jobs must be >= 0 (0: the cores)", file=sys.stderr)
        return 2
    try:
        return _study(args)
    except StudyError as e:  # every problem of the file, a line each (the robot files' format)
        print(e, file=sys.stderr)
    except DesignError as e:
        print(f"design_study: {_one_line(e)}", file=sys.stderr)
    except OSError as e:  # DIR or a file in it that cannot be written
        print(f"design_study: {e.filename or args.out}: {e.strerror or _one_line(e)}", file=sys.stderr)
    return 2


def _one_line(e: BaseException) -> str:
    return " ".join(str(e).split()) or type(e).__name__


def _study(args) -> int:
    """The study of the command line: its runs, results, table and report; the exit code."""
    study = load_study(args.study)
    if args.optimise:
        if study.optimise is None:
            print(f"{args.study}: --optimise needs an optimise: section (docs/design-studies.md)", file=sys.stderr)
            return 2
        print(search_table(run_search(study, args.out, against_sweep=args.against_sweep)))
        return 0
    os.makedirs(args.out, exist_ok=True)
    jobs = prepare(study, args.out)
    results = empty_results(study)
    old = read_results(args.out) if args.resume else None
    if old is not None:
        for name in results["candidates"]:
            kept = old.get("candidates", {}).get(name, {})
            for scenario, result in kept.get("scenarios", {}).items():
                if scenario in dict(study.scenarios):
                    merge(results, {"candidate": name, "scenario": scenario, "mass_kg": kept.get("mass_kg"),
                                    "result": result}, study)  # fmt: skip
    todo = longest_first([job for job in jobs if not done(results, job)], read_timing(args.out), drive_counts(jobs))
    write_results(args.out, results)
    skipped = len(jobs) - len(todo)
    try:
        executor, workers, where = _executor(args, len(todo))
    except (OSError, ValueError, TimeoutError) as e:
        print(f"design_study: cannot reach the scheduler {args.scheduler}: {e}", file=sys.stderr)
        return 2
    print(
        f"design_study: {counted(len(study.candidates), 'candidate')} x {counted(len(study.scenarios), 'scenario')} = "
        f"{counted(len(jobs), 'run')}" + (f" ({skipped} already in {args.out})" if skipped else "") + f", {where}",
        file=sys.stderr,
    )
    started = time.monotonic()
    timing: List[dict] = []
    drawn: Set[Tuple[str, str]] = set()  # the runs whose tracks plot their worker drew
    with executor:
        _run(todo, executor, workers, results=results, study=study, out_dir=args.out, timing=timing, drawn=drawn)
    wall = time.monotonic() - started
    write_json(
        os.path.join(args.out, TIMING),
        {"workers": workers, "wall_s": round(wall, 3), "simulated_s": round(sum(r["simulated_s"] for r in timing), 3),
         "runs": timing},
    )  # fmt: skip
    write_results(args.out, results)
    write_csv(os.path.join(args.out, "results.csv"), results, study)
    print(results_table(results, study))
    page = write_report(args.out, results, study, pareto=study.pareto, drawn=drawn)
    print(f"design_study: the report: {page}", file=sys.stderr)
    print(
        f"design_study: {len(todo)} runs in {time.monotonic() - started:.1f} s; results in {args.out}", file=sys.stderr
    )
    failed = [n for n, c in results["candidates"].items() if c["status"] != "ok"]
    return 1 if failed and len(failed) == len(results["candidates"]) else 0


SCHEDULER_TIMEOUT = 10.0  # [s] to reach a Dask scheduler


def drive_counts(jobs: List[Job]) -> Dict[str, int]:
    """Each candidate's number of drives (how long its runs take grows with it); a candidate whose file
    cannot be read is left out (its runs fail at once)."""
    counts: Dict[str, int] = {}
    for job in jobs:
        if job.candidate not in counts:
            try:
                counts[job.candidate] = len(load_robot_config(job.robot_file).drives)
            except ThorvaldModelError:
                continue
    return counts


def counted(n: int, one: str, many: str = "") -> str:
    """n and the noun, plural unless n is 1: '1 scenario', '3 runs'."""
    return f"{n} {one if n == 1 else (many or one + 's')}"


def _executor(args, runs: int):
    """(a concurrent.futures executor, its workers, what it is): local worker processes (one pybullet
    client each, started fresh: spawn), or a Dask distributed scheduler's workers (its
    ``Client.get_executor()``), whose machines have the workspace installed and sourced."""
    if args.scheduler:
        from distributed import Client  # noqa: PLC0415 (only a study run on a cluster needs it)

        client = Client(args.scheduler, timeout=args.scheduler_timeout)
        workers = max(1, sum(w.get("nthreads", 1) for w in client.scheduler_info()["workers"].values()))
        return _DaskExecutor(client), workers, f"{workers} Dask workers at {args.scheduler}"
    workers = min(args.jobs or os.cpu_count() or 1, max(runs, 1))
    pool = ProcessPoolExecutor(max_workers=workers, mp_context=get_context("spawn"))
    return pool, workers, counted(workers, "worker process", "worker processes")


class _DaskExecutor:
    """A Dask client's executor, closing the client with it."""

    def __init__(self, client):
        self.client = client
        self.executor = client.get_executor(pure=False)

    def submit(self, fn, *args):
        return self.executor.submit(fn, *args)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.executor.shutdown(wait=True)
        self.client.close()


def _run(
    todo: List[Job],
    pool,
    workers: int,
    *,
    results,
    study,
    out_dir: str,
    timing: List[dict],
    drawn: Set[Tuple[str, str]],
) -> None:
    """Submits every run to the pool and gathers each result into results.json as it ends; the
    progress bar names the runs that are running (a line a run without a terminal)."""
    if not todo:
        return
    bar = tqdm(total=len(todo), unit="run", file=sys.stderr, dynamic_ncols=True, disable=None)
    try:
        pending = {pool.submit(run_one, job): job for job in todo}
        finished_runs = 0  # (a disabled bar counts nothing)
        running = list(todo[: min(workers, len(todo))])
        bar.set_postfix_str(", ".join(j.label for j in running))
        while pending:
            finished, _ = wait(pending, return_when=FIRST_COMPLETED)
            for future in finished:
                job = pending.pop(future)
                run = future.result()
                if "timing" in run:
                    timing.append({"run": job.label, **run["timing"]})
                if run.get("drawn"):
                    drawn.add((job.candidate, job.scenario))
                merge(results, run, study)
                write_results(out_dir, results)
                bar.update(1)
                finished_runs += 1
                if bar.disable:  # no terminal: a line a run
                    print(f"[{finished_runs}/{len(todo)}] {job.label}: {_outcome(run)}", file=sys.stderr, flush=True)
                running = [j for j in running if j != job]
                waiting = [j for j in pending.values() if j not in running]
                running += waiting[: max(0, min(workers, len(pending)) - len(running))]
                bar.set_postfix_str(", ".join(j.label for j in running))
    finally:
        bar.close()


def _outcome(run) -> str:
    result = run["result"]
    return result if isinstance(result, str) else "ok"
