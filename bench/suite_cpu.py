#!/usr/bin/env python3
"""Where the test suite's time goes: CPU seconds per test file, the test's process and its children.

    python bench/suite_cpu.py [--top 25] [--workers 2] [PYTEST_ARGS...]

Runs the parallel stage of ``make test`` (pytest, ``-n 2 --dist loadfile -m "not solo"``, or the
pytest arguments given after ``--``) with a plugin that reads ``getrusage`` of the worker and of the
children it waited for (subprocesses, roslaunch and every node it started and stopped) around every
test, then prints per file: CPU seconds (user and system), wall seconds, tests, and the running share.
A test stage on this 2-core machine is bound by its CPU seconds, not by any one test's wall time: a
cut in the suite is a cut in this table. Needs the workspace sourced; takes as long as the stage.
"""

import argparse
import collections
import glob
import json
import os
import subprocess
import sys
import tempfile
import time

PLUGIN = """
import json, os, resource, time
import pytest

def _cpu():
    own, children = resource.getrusage(resource.RUSAGE_SELF), resource.getrusage(resource.RUSAGE_CHILDREN)
    return own.ru_utime + own.ru_stime + children.ru_utime + children.ru_stime

_rows = []

@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    cpu, wall = _cpu(), time.time()
    yield
    _rows.append((item.nodeid, time.time() - wall, _cpu() - cpu))

def pytest_sessionfinish(session):
    with open(os.path.join(os.environ["SUITE_CPU_OUT"], f"{os.getpid()}.json"), "w") as f:
        json.dump(_rows, f)
"""


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--top", type=int, default=25, help="files to print (default 25)")
    parser.add_argument("--workers", type=int, default=2, help="pytest-xdist workers (default 2)")
    parser.add_argument("pytest_args", nargs="*", help="pytest's arguments (after --) in place of the stage's")
    args = parser.parse_args(argv)
    ws = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
    with tempfile.TemporaryDirectory() as tmp:
        with open(os.path.join(tmp, "suite_cpu_plugin.py"), "w") as f:
            f.write(PLUGIN)
        out = os.path.join(tmp, "rows")
        os.mkdir(out)
        env = dict(os.environ, SUITE_CPU_OUT=out, PYTHONPATH=tmp + os.pathsep + os.environ.get("PYTHONPATH", ""))
        # tools/run-tests' parallel stage, unless pytest's arguments were given
        stage = args.pytest_args or [
            "-n",
            str(args.workers),
            "--dist",
            "loadfile",
            "--no-loadscope-reorder",
            "-m",
            "not solo",
        ]
        cmd = [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "-p", "suite_cpu_plugin", *stage]
        started = time.time()
        before = os.times()
        done = subprocess.run(cmd, cwd=ws, env=env)
        after = os.times()
        wall = time.time() - started
        rows = []
        for path in glob.glob(os.path.join(out, "*.json")):
            with open(path) as f:
                rows += json.load(f)
    by_file = collections.defaultdict(lambda: [0.0, 0.0, 0])
    for node, seconds, cpu in rows:
        entry = by_file[node.split("::")[0]]
        entry[0] += cpu
        entry[1] += seconds
        entry[2] += 1
    total = sum(e[0] for e in by_file.values())
    stage_cpu = (after.children_user - before.children_user) + (after.children_system - before.children_system)
    print(f"\n{len(rows)} tests in {wall:.0f} s of wall time; {stage_cpu:.0f} CPU seconds in all "
          f"({stage_cpu / wall:.2f} cores busy on average), {total:.0f} of them inside tests")  # fmt: skip
    print(f"{'CPU s':>7} {'wall s':>7} {'tests':>6} {'share':>6}  file")
    running = 0.0
    for name, (cpu, seconds, count) in sorted(by_file.items(), key=lambda kv: -kv[1][0])[: args.top]:
        running += cpu
        print(f"{cpu:7.1f} {seconds:7.1f} {count:6d} {100 * running / total:5.0f}%  {name}")
    return done.returncode


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
