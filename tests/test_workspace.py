"""Workspace-level acceptance tests: the README's commands and the example robots end to end."""

import glob
import json
import os
import re
import subprocess

import pytest
import rosbag

from thorvald_testing import free_port

# the main job (the demo fixture) runs in its first test's set-up: about 3 minutes, 6 on a machine
# slowed by its neighbours (seen once in CI: past the suite's 300 s per test)
pytestmark = [pytest.mark.ros, pytest.mark.slow, pytest.mark.long(330), pytest.mark.timeout(660)]

WS = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
TOPICS = ("nav_vel", "twist_mux/cmd_vel", "odometry/base_raw", "odometry/gazebo", "base_state")
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
    packages = len(glob.glob(os.path.join(WS, "src", "*", "package.xml")))
    assert packages >= 11 and f"built ({packages} packages)" in proc.stdout


@pytest.fixture(scope="module")
def demo():
    """tools/demo (make demo without the set-up), run once for the tests below."""
    proc = run(["tools/demo"], timeout=600)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return proc.stdout


def test_main_job_checks_every_example_robot(demo):
    rows = [line.split() for line in demo.splitlines() if line.startswith("thorvald_ii_")]
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


def row(text, label):
    line = next(line for line in text.splitlines() if line.strip().startswith(label))
    return line.strip()[len(label) :].split()


def test_main_job_reproduces_the_papers_odometry_experiment_within_the_targets(demo):
    """The Figure 7 robot on tarmac_gravel, measured drives: lsq under 0.5 % and 1 m (the paper: 1.0 %, 2.2 m)."""
    assert "Odometry report: thorvald_ii_6wd6ws_asym" in demo
    truth, lsq, paper = (float(v) for v in row(demo, "distance [m]")[:3])
    # about 80 m, as the paper's 80.2 m; shorter if a loaded machine starved the commands (reported)
    assert 70.0 < truth < 82.0, demo
    assert float(row(demo, "distance by the manoeuvre's plan")[0]) == 80.0
    if "WARNING" not in demo:
        assert truth > 0.97 * 80.0, demo
    error_lsq, error_paper = (float(v) for v in row(demo, "distance error [%]")[1:3])
    assert abs(error_lsq) < 0.5, demo
    # recomputed from the distances as printed (to 0.01 m; the errors to 0.01 %), within that rounding
    rounding = 0.005 + 100 * 0.01 / truth
    assert error_lsq == pytest.approx((lsq - truth) / truth * 100, abs=rounding)
    assert error_paper == pytest.approx((paper - truth) / truth * 100, abs=rounding)
    assert float(row(demo, "end-point difference [m]")[1]) < 1.0, demo
    assert "targets for lsq: |distance error| < 0.5 %, end point < 1 m: met" in demo
    assert "80.2 / 81.0" in demo  # the paper's figures beside ours
    # base_driver's odometry is what the report's lsq replay recomputes from the recorded drive states
    # (exactly, unless a loaded machine dropped messages on their way to rosbag, which the report says)
    if "missing from the recording" not in demo:
        assert float(re.search(r"odometry/base_raw within ([0-9.]+) mm", demo).group(1)) < 1.0, demo


def test_main_job_records_a_real_bag_of_the_whole_drive_and_writes_figures_8_and_9(demo):
    out = os.path.join(WS, "build", "odometry_report")
    with rosbag.Bag(os.path.join(out, "odometry_report.bag")) as bag:
        info = bag.get_type_and_topic_info().topics
        span = bag.get_end_time() - bag.get_start_time()
    counts = {t: info[f"/thorvald_001/{t}"].message_count for t in TOPICS}
    assert float(re.search(r"drive: ([0-9.]+) s simulated", demo).group(1)) > 80.0 and span > 80.0
    for topic in ("odometry/base_raw", "odometry/gazebo", "base_state"):  # 50 Hz each
        assert counts[topic] > 45 * 80, counts
    assert counts["nav_vel"] > 15 * 80 and counts["twist_mux/cmd_vel"] > 15 * 80, counts  # 20 Hz
    for name in ("figure8_paths.png", "figure9_velocities.png"):
        png = os.path.join(out, name)
        with open(png, "rb") as f:
            assert f.read(8) == b"\x89PNG\r\n\x1a\n", name
        assert os.path.getsize(png) > 30000 and png in demo, name


def test_the_calibration_drive_calibrates_an_as_built_robot_from_what_it_determines(demo):
    """calibration_drive, as the main job ran it: the paper's six-wheeled robot as built (field:3)
    through the calibration manoeuvre in the simulator, recorded whole, calibrated from it: the drive
    determines 7 of its 12 combinations, and its own odometry after the calibration is closer to ground
    truth. Then its wheels balanced from their motor currents: they stop fighting, the steering offsets
    ground truth cannot see (the toe) found from the frame's resistance within a tenth of a degree,
    where ground truth left them 0.3 deg off, and each tyre's radius comes within half the issue's
    0.3 % of the as-built robot's, where ground truth left it 0.9 % off. Then straight legs at working
    speed with that in effect give the radii's common factor and odometry's yaw per metre, and the
    calibration reads their distance and heading right. Last, a drive of every motion (the calibration
    manoeuvre's, the straight legs, the field route's U turns) gives odometry's heading model: the
    yaw-rate multiplier, yaw per metre crabbing, and each wheel's weight in the yaw rate where the wheels
    disagree, the straight legs' yaw per metre kept. The main job then drives the field route with the
    calibration: within 0.2 % of distance and 0.5 m of end point, against ground truth and against
    RTK-GNSS."""
    out = os.path.join(WS, "build", "calibration_drive")
    with open(os.path.join(out, "result.json")) as f:
        text = f.read()
    result = json.loads(text[text.index("{") :])
    for manoeuvre in ("calibration", "balance", "straight", "heading"):
        assert f"through the {manoeuvre} manoeuvre" in text, manoeuvre
    assert sum(c["determined"] for c in result["combinations"]) == 7 and len(result["combinations"]) == 12
    before, after = result["before"], result["after"]
    assert before["end_point_m"] > 1.0 and abs(before["distance_error_percent"]) > 1.0  # tyres 2 % small
    assert after["end_point_m"] < 0.6 * before["end_point_m"]
    assert abs(after["distance_error_percent"]) < 0.5 * abs(before["distance_error_percent"])
    radii = [v["r_wheel"] for v in result["drives"].values()]
    assert all(0.19 < r < 0.2 for r in radii)  # loaded 1 to 3 % below the configured 0.2 m
    legs = result["balance"]["legs"]
    assert len(legs) == 8 + 36 + 4 and all(leg["samples"] >= 3 for leg in legs)  # radii, toe, radii again
    assert max(leg["fight_nm"] for leg in legs[-2:]) < 0.5 * legs[0]["fight_nm"]  # the wheels stopped fighting
    moves = result["balance"]["toe"]["moves"]
    assert moves[-1]["resistance_nm"][1] < 0.5 * moves[0]["resistance_nm"][1]  # the frame scrubs less
    tyres = result["tyres"]
    assert tyres["toe"]["ground_truth_deg"] > 0.2 and tyres["toe"]["balanced_deg"] < 0.1
    assert tyres["configured"]["largest_relative_percent"] > 1.0
    assert tyres["ground_truth"]["largest_relative_percent"] > 0.6
    assert tyres["balanced"]["largest_relative_percent"] < 0.1
    assert tyres["tyres"]["largest_percent"] < 0.3  # at the straight legs' common factor: 0.19 measured
    straight = result["straight"]
    assert [leg["straight"] for leg in straight["scale"]["legs"]] == [True] * 5
    assert 0.995 < straight["scale"]["factor"] < 1.01 and straight["scale"]["sd"] < 0.001
    assert abs(straight["after"]["distance_error_percent"]) < 0.05 < abs(straight["before"]["distance_error_percent"])
    assert os.path.samefile(straight["calibration_file"], os.path.join(out, "scaled_calibration.yaml"))
    heading = straight["scale"]["yaw_per_metre"]  # the turn odometry reads on a straight leg, taken out
    truth_turns = [leg["truth_turn_rad"] for leg in straight["scale"]["legs"] if leg["straight"]]
    errors = [t - a for t, a in zip(truth_turns, heading["odometry_turn_after_rad"])]
    assert abs(heading["value"]) < 0.005 and len(errors) == 5 and max(abs(e) for e in errors) < 0.003
    model = result["heading"]  # odometry's heading model from the heading drive, the straight legs' b kept
    assert model["yaw_rate_multiplier"]["in_effect"] == 1.0 and model["yaw_per_metre"]["kept"]
    assert model["yaw_per_metre"]["value"] == pytest.approx(heading["value"], rel=1e-6)
    multiplier = model["yaw_rate_multiplier"]["value"]
    assert 0.99 < multiplier < 1.01 and model["yaw_rate_multiplier"]["sd"] < 0.003
    # the wheels the frame turns as where they disagree: on field:3's soft tyres the weights fit each such
    # window better but leave more heading there in all, and are refused (all alike)
    weights = model["wheel_weights"]["value"]
    assert (len(weights) == 6 and sum(weights) == pytest.approx(6.0)) if model["wheel_weights"]["told"] else not weights
    motions = {m["motion"]: m for m in model["motions"]}
    assert {"straight", "crab", "spin", "arc", "re-steering"} <= set(motions)
    assert model["heading_rms_deg"]["after"] <= model["heading_rms_deg"]["before"]
    assert os.path.samefile(model["calibration_file"], os.path.join(out, "calibration.yaml"))
    names = ("calibration.yaml", "odometry_calibration.yaml", "balanced.yaml", "balanced_calibration.yaml")
    for name in (*names, "scaled_calibration.yaml", "calibration_drive.bag", "straight.bag", "heading.bag"):
        assert os.path.isfile(os.path.join(out, name)), name
    assert "field:3 on the field route against RTK-GNSS: uncalibrated" in demo
    # what the calibration applied, and how much of it the calibration drive determined
    determined = sum(1 for c in result["combinations"] if c["determined"])
    assert (
        f"applied build/calibration_drive/calibration.yaml: each drive's radius and steering offset from the "
        f"calibration drive ({determined} of 12 combinations determined; the other {12 - determined} from the balance"
    ) in demo
    # and what the heading drive determined (the multiplier from the windows, or from whole turns where
    # the windows left it within two of its uncertainties of 1), and what it kept
    said = "odometry's heading model from a drive of every motion (determined: "
    line = next(line for line in demo.splitlines() if said in line)
    if model["yaw_rate_multiplier"]["excited"]:
        assert f"the yaw-rate multiplier {multiplier:.5f}" in line
        turns = model["yaw_rate_multiplier"]["whole_turns"]
        assert (f"{multiplier:.5f} (from {turns} whole turns)" in line) == (turns > 0)
    else:
        assert "not determined: the yaw-rate multiplier (kept at 1)" in line
    assert ("each wheel's weight in the yaw rate" in line) == model["wheel_weights"]["told"]
    # validated on a different drive, the field route, within issue 34's targets against both
    with open(os.path.join(WS, "build", "field_route_calibrated", "figures.json")) as f:
        route = json.load(f)
    for against in ("against_truth", "against_rtk_gnss"):
        lsq = route[against]["odometry lsq"]
        assert abs(lsq["distance_error_percent"]) < 0.2 and lsq["end_point_m"] < 0.5, (against, lsq)


def test_verification_drive_on_base_drivers_own_simulated_drives():
    """verification_drive.launch: simple_sim, the node owning the clock, odometry against the command.

    At 4 times real time rather than the launch file's 8: the node paces /clock by the wall clock
    without waiting for base_driver, so on a loaded machine a driver that falls behind integrates
    late commands (a clean-clone CI once read a 0.68 m end-point difference at 8 times)."""
    port = free_port()
    env = dict(os.environ, ROS_MASTER_URI=f"http://localhost:{port}")
    proc = subprocess.run(
        ["roslaunch", "-p", str(port), "thorvald_bringup", "verification_drive.launch", "speedup:=4"],
        cwd=WS,
        capture_output=True,
        text=True,
        timeout=300,
        env=env,
    )
    assert "Verification drive of thorvald_ii_4wd4ws_std" in proc.stdout, proc.stdout[-3000:] + proc.stderr[-3000:]
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
