"""Workspace-level acceptance tests: the README's commands and the example robots end to end."""

import glob
import os
import subprocess

WS = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
EXAMPLES = sorted(glob.glob(os.path.join(WS, "src", "thorvald_model", "config", "*", "*.yaml")))


def run(cmd, timeout=300):
    return subprocess.run(cmd, cwd=WS, capture_output=True, text=True, timeout=timeout)


def test_setup_rerun_has_nothing_to_do():
    """tools/setup is idempotent: a second run installs nothing and rebuilds nothing new."""
    proc = run(["tools/setup"])
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "all installed" in proc.stdout
    assert "    present" in proc.stdout
    assert "up to date" in proc.stdout
    assert "built (6 packages)" in proc.stdout


def test_main_job_checks_every_example_robot_and_drives_the_verification_manoeuvre():
    proc = run(["tools/demo"])
    assert proc.returncode == 0, proc.stdout + proc.stderr
    rows = [line.split() for line in proc.stdout.splitlines() if line.startswith("thorvald_ii_")]
    assert sorted(r[0] for r in rows) == sorted(os.path.basename(p)[:-5] for p in EXAMPLES)
    by_name = {r[0]: r for r in rows}
    # drives, steered, driven, passive as the paper's figures describe the robots
    assert by_name["thorvald_ii_4wd4ws_std"][1:5] == ["4", "4", "4", "0"]
    assert by_name["thorvald_ii_4wd2ws_tall"][1:3] == ["4", "2"]
    assert by_name["thorvald_ii_6wd6ws_susp"][1:3] == ["6", "6"]
    assert by_name["thorvald_ii_9wd9ws"][1:3] == ["9", "9"]
    assert by_name["thorvald_ii_2wd_diff"][1:5] == ["2", "0", "2", "2"]
    assert by_name["thorvald_ii_1wd1ws_rwd"][1:5] == ["1", "1", "1", "2"]
    assert by_name["thorvald_ii_1wd1ws_fwd"][-1] == "pltf_clc_1wd::PltfClc1WD"

    report = dict(
        line.strip().split("  ", 1)
        for line in proc.stdout.splitlines()
        if line.startswith("  ") and "  " in line.strip()
    )
    by_command = float(report["distance by command"].split()[0])
    by_odometry = float(report["distance by odometry"].split()[0])
    difference = float(report["end-point difference"].split()[0])
    # the plan: 4 legs of 10 m and two 20 m circles at 1 m/s
    assert by_command == 80.0
    # the simulated drives lag the commands (ramps, steering slew), but only a little
    assert abs(by_odometry - by_command) < 1.0
    assert difference < 0.5
