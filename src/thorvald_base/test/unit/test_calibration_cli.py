"""``rosrun thorvald_base calibrate_odometry``: a bag written here (rosbag, no ROS master) with a
synthetic drive of the standard robot, read back, calibrated, printed and written as base_driver's
calibration file; and every way it refuses, one line and exit status 2."""

import json
import math
import os
import re
import subprocess

import genpy
import pytest
import rosbag
from base_test_helpers import EXAMPLE_ROBOTS
from calibration_test_helpers import MIXED, STRAIGHT, synthetic_drive
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu, NavSatFix

from thorvald_base.calibration import load_calibration
from thorvald_base.calibration.recording import WGS84_A, WGS84_E2
from thorvald_base.calibration_cli import main
from thorvald_base.kinematics import Twist
from thorvald_model import load_robot_config, with_drive_param
from thorvald_msgs.msg import BaseState

STD = next(p for p in EXAMPLE_ROBOTS if p.endswith("thorvald_ii_4wd4ws_std.yaml"))
RADII = (0.2016, 0.1990, 0.2006, 0.1981)
OFFSETS = (0.004, -0.006, 0.002, 0.007)
LAT0, LON0 = 53.268642, -0.524509  # [deg] the Riseholme datum


def write_bag(path, drive, *, ns="/robot_1", sim=True, gnss=False, states=True, lose=()):
    """The topics odometry_report records: base_state, odometry/gazebo, gps/fix, imu/data; lose:
    indices of base_state messages published (numbered, header.seq) and never recorded."""
    phi = math.radians(LAT0)
    w = 1.0 - WGS84_E2 * math.sin(phi) ** 2
    north_radius, east_radius = WGS84_A * (1 - WGS84_E2) / w**1.5, WGS84_A / math.sqrt(w) * math.cos(phi)
    with rosbag.Bag(str(path), "w") as bag:
        if states:
            rec = drive.recording
            for seq, (t, steering, speed) in enumerate(zip(rec.t, rec.steering, rec.speed)):
                if seq in lose:
                    continue
                msg = BaseState(steer_pos=list(steering), prop_speed=list(speed))
                msg.header.seq = seq
                msg.header.stamp = genpy.Time.from_sec(t)
                bag.write(ns + "/base_state", msg, msg.header.stamp)
        if sim:
            truth = drive.pose_truth
            for n, t in enumerate(truth.t):
                msg = Odometry()
                msg.header.stamp = genpy.Time.from_sec(t)
                msg.pose.pose.position.x, msg.pose.pose.position.y = truth.x[n], truth.y[n]
                msg.pose.pose.orientation.z = math.sin(truth.yaw[n] / 2)
                msg.pose.pose.orientation.w = math.cos(truth.yaw[n] / 2)
                msg.twist.twist.linear.x, msg.twist.twist.linear.y = truth.vx[n], truth.vy[n]
                msg.twist.twist.angular.z = truth.wz[n]
                bag.write(ns + "/odometry/gazebo", msg, msg.header.stamp)
        if gnss:
            g = drive.gnss_truth
            for t, east, north in zip(g.t_fix, g.east, g.north):
                msg = NavSatFix(latitude=LAT0 + math.degrees(north / north_radius))
                msg.longitude = LON0 + math.degrees(east / east_radius)
                msg.header.stamp = genpy.Time.from_sec(t)
                bag.write(ns + "/gps/fix", msg, msg.header.stamp)
            for t, yaw in zip(g.t_yaw, g.yaw):
                msg = Imu()
                msg.header.stamp = genpy.Time.from_sec(t)
                msg.orientation.z, msg.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
                bag.write(ns + "/imu/data", msg, msg.header.stamp)
    return str(path)


@pytest.fixture(scope="module")
def std():
    return load_robot_config(STD)


def run(capsys, *args):
    status = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return status, out, err


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
def test_json_with_the_simulators_ground_truth(tmp_path, capsys, std):
    bag = write_bag(tmp_path / "drive.bag", synthetic_drive(std, MIXED, RADII, OFFSETS))
    status, out, err = run(capsys, bag, "--robot-model", STD, "--json")
    assert status == 0, err
    result = json.loads(out)
    assert result["ground_truth"] == "simulator"
    assert result["ground_truth_source"] == "the simulator's /robot_1/odometry/gazebo"
    for i, drive in enumerate(f"drive{i}" for i in range(4)):
        values = result["drives"][drive]
        assert values["r_wheel"] == pytest.approx(RADII[i], rel=1e-7)
        assert values["steering_offset"] == pytest.approx(OFFSETS[i], rel=1e-6)
        assert 0 <= values["r_wheel_sd"] < 1e-9 and 0 <= values["steering_offset_sd"] < 1e-9
    assert result["not_excited"] == []
    assert result["before"]["end_point_m"] > 0.02  # 4 cm after 20 m of MIXED
    assert result["after"]["end_point_m"] < 1e-6 and abs(result["after"]["distance_error_percent"]) < 1e-6
    # the file beside the bag, as base_driver reads it, and the call for a running robot
    assert result["calibration_file"] == str(tmp_path / "calibration.yaml")
    changes = load_calibration(result["calibration_file"], std)
    assert [(i, key) for i, key, _ in changes] == [(i, k) for i in range(4) for k in ("r_wheel", "steering_offset")]
    assert result["set_drive_params"].startswith(
        "rosservice call /robot_1/base_driver/set_drive_params \"params: [{index: 0, type: 'r_wheel', value: 0.2016"
    )


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
def test_it_says_what_the_drive_determines_through_the_odometry_and_fits_only_that(tmp_path, capsys, std):
    bag = write_bag(tmp_path / "straight.bag", synthetic_drive(std, STRAIGHT, RADII, OFFSETS))
    status, out, err = run(capsys, bag, "--robot-model", STD)
    assert status == 0, err
    assert "what the drive determines through the odometry: 3 of 8 combinations" in out
    assert out.count("(determined)") == 3 and out.count("(kept at the values in effect)") == 5
    status, out, err = run(capsys, bag, "--robot-model", STD, "--fit", "odometry", "--json")
    assert status == 0, err
    result = json.loads(out)
    assert result["fit"] == "odometry" and sum(c["determined"] for c in result["combinations"]) == 3
    strongest = result["combinations"][0]["parts"]  # the common scale: every radius alike
    assert sorted(strongest) == [f"drive{i}.r_wheel" for i in range(4)]
    assert max(abs(w) for w in strongest.values()) - min(abs(w) for w in strongest.values()) < 0.05
    # the odometry is right after it, though no single radius is each tyre's
    assert result["after"]["end_point_m"] < 1e-3 < result["before"]["end_point_m"]
    assert len(load_calibration(result["calibration_file"], std)) == 8
    # GNSS has no body twist to compare at every instant: refused, one line
    gnss = write_bag(tmp_path / "gnss.bag", synthetic_drive(std, STRAIGHT, RADII, OFFSETS), sim=False, gnss=True)
    status, out, err = run(capsys, gnss, "--robot-model", STD, "--fit", "odometry")
    assert status == 2 and err.count("\n") == 1 and "needs the simulator's ground truth" in err


def test_a_recording_that_lost_drive_states_is_refused(tmp_path, capsys, std):
    bag = write_bag(tmp_path / "lost.bag", synthetic_drive(std, MIXED, RADII, OFFSETS), lose=(100,))
    status, out, err = run(capsys, bag, "--robot-model", STD)
    assert status == 2 and out == ""
    assert "the recording is incomplete (/robot_1/base_state: 1 lost, the first seq 100)" in err


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
def test_text_with_gnss_on_a_straight_line_refuses_the_offsets(tmp_path, capsys, std):
    drive = synthetic_drive(std, STRAIGHT, RADII, OFFSETS, heading_bias=1.2, antenna=(0.3, 0.0))
    bag = write_bag(tmp_path / "straight.bag", drive, ns="", gnss=True)
    out_file = tmp_path / "cal" / "straight.yaml"
    out_file.parent.mkdir()
    status, out, err = run(
        capsys, bag, "--robot-model", STD, "--ground-truth", "gnss", "--antenna", 0.3, 0, "--out", out_file
    )
    assert status == 0, err
    lines = out.splitlines()
    assert lines[0].startswith("ground truth: GNSS /gps/fix (301 fixes) and the IMU's yaw /imu/data")
    assert lines[1].split() == ["drive", "r_wheel", "[m]", "steering_offset", "[rad]"]
    assert lines[2].startswith("drive0   0.20160 ± 0.0000") and "(was 0.2)" in lines[2]
    assert lines[2].endswith("0 (not excited)")
    refused = [line for line in lines if line.startswith("not excited:")]
    assert len(refused) == 4
    assert refused[0].startswith("not excited: drive0 steering_offset (left at 0): a straight line cannot tell")
    assert any(line.startswith("IMU yaw bias against east: +1.20") for line in lines)
    assert f"wrote {out_file}" in lines
    assert lines[-1].startswith("apply it to the running robot: rosservice call /base_driver/set_drive_params")
    data = out_file.read_text()
    assert "steering_offset" not in data.split("motor_drives:")[1]  # only what was estimated


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
def test_a_calibration_in_effect_is_where_it_starts_and_what_it_keeps(tmp_path, capsys, std):
    earlier = tmp_path / "earlier.yaml"
    earlier.write_text("motor_drives:\n  drive1: {r_wheel: 0.205}\n  drive2: {steering_offset: 0.01}\n")
    in_effect = with_drive_param(with_drive_param(std, 1, "r_wheel", 0.205), 2, "steering_offset", 0.01)
    drive = synthetic_drive(in_effect, STRAIGHT, RADII, OFFSETS, heading_bias=0.4)
    bag = write_bag(tmp_path / "d.bag", drive, gnss=True, sim=False)  # a real robot's bag: no simulator
    status, out, err = run(capsys, bag, "--robot-model", STD, "--calibration", earlier, "--json")
    assert status == 0, err
    result = json.loads(out)
    assert result["ground_truth"] == "gnss"  # the only ground truth in the bag
    assert result["drives"]["drive1"]["r_wheel"] == pytest.approx(RADII[1], rel=1e-4)
    assert {(p["drive"], p["key"], p["value_in_effect"]) for p in result["not_excited"]} == {
        ("drive0", "steering_offset", 0.0),
        ("drive1", "steering_offset", 0.0),
        ("drive2", "steering_offset", 0.01),
        ("drive3", "steering_offset", 0.0),
    }
    written = load_calibration(result["calibration_file"], std)
    assert (2, "steering_offset", 0.01) in written  # kept from the calibration in effect
    assert [v for i, k, v in written if (i, k) == (1, "r_wheel")] == [pytest.approx(RADII[1], rel=1e-4)]
    assert "kept from" in (tmp_path / "calibration.yaml").read_text()


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
def test_fit_scale_takes_the_radii_common_factor_from_straight_legs_over_the_calibration_in_effect(
    tmp_path, capsys, std
):
    from thorvald_base.verification import plan_named  # noqa: PLC0415

    earlier = tmp_path / "earlier.yaml"
    earlier.write_text("motor_drives:\n  drive1: {r_wheel: 0.205, steering_offset: 0.01}\n")
    in_effect = with_drive_param(with_drive_param(std, 1, "r_wheel", 0.205), 1, "steering_offset", 0.01)
    truth = [d.r_wheel * 1.003 for d in in_effect.drives]  # every tyre 0.3 % larger than in effect
    offsets = [d.steering_offset for d in in_effect.drives]
    plan = [(s.duration, s.twist) for s in plan_named("straight", std, side=3.0)[1]]
    bag = write_bag(tmp_path / "straight.bag", synthetic_drive(in_effect, plan, truth, offsets))
    status, out, err = run(capsys, bag, "--robot-model", STD, "--calibration", earlier, "--fit", "scale")
    assert status == 0, err
    assert "5 straight legs between standstills" in out
    # noise-free legs: the factor exact, its uncertainty rounding's (shown to two significant digits)
    factor = r"the radii's common factor: 1\.00300 ± ([0-9.e+-]+) \(\+0\.300 %\), ground truth's 24\.00 m"
    found = re.search(factor, out)
    assert found and float(found.group(1)) < 1e-9, out
    assert "not excited" not in out and out.count("(kept)") == 4
    assert re.search(r"before -0\.299 % of 24\.00 m, end point 0\.000 m; after [+-]0\.000 %", out), out
    written = dict(((i, k), v) for i, k, v in load_calibration(str(tmp_path / "calibration.yaml"), std))
    assert written[(1, "steering_offset")] == 0.01  # kept from the calibration in effect
    assert [written[(i, "r_wheel")] for i in range(4)] == [pytest.approx(r, rel=1e-9) for r in truth]
    # without --calibration the factor is the same (the bag holds rim speeds) but applies to the file's radii
    status, out, err = run(capsys, bag, "--robot-model", STD, "--fit", "scale", "--json")
    assert status == 0, err
    result = json.loads(out)
    assert result["scale"]["factor"] == pytest.approx(1.003, rel=1e-9) and len(result["scale"]["legs"]) == 5
    assert result["drives"]["drive1"]["r_wheel"] == pytest.approx(0.2 * 1.003, rel=1e-9)
    # a drive of turns has no straight leg; --balance is for the other fits
    turning = write_bag(tmp_path / "mixed.bag", synthetic_drive(std, MIXED, RADII, OFFSETS))
    for extra, message in (([], "no straight leg"), (["--balance", earlier], "--balance goes with")):
        status, out, err = run(capsys, turning, "--robot-model", STD, "--fit", "scale", *extra)
        assert status == 2 and err.count("\n") == 1 and message in err, err


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
def test_fit_straight_also_takes_odometrys_yaw_per_metre_from_the_legs_heading(tmp_path, capsys, std):
    from thorvald_base.calibration.calibration_file import read_calibration  # noqa: PLC0415
    from thorvald_base.verification import plan_named  # noqa: PLC0415

    truth = [d.r_wheel * math.exp(0.002 * d.y) for d in std.drives]  # the left tyres 0.18 % larger
    plan = [(s.duration, s.twist) for s in plan_named("straight", std, side=3.0)[1]]
    bag = write_bag(tmp_path / "straight.bag", synthetic_drive(std, plan, truth, [0.0] * 4))
    earlier = tmp_path / "earlier.yaml"
    earlier.write_text("odometry: {yaw_rate_multiplier: 1.004}\n")
    status, out, err = run(capsys, bag, "--robot-model", STD, "--fit", "straight", "--calibration", earlier, "--json")
    assert status == 0, err
    heading = json.loads(out)["scale"]["yaw_per_metre"]
    assert heading["value"] == heading["added"] and 1e-4 < abs(heading["value"]) < 1e-3
    assert max(abs(t) for t in heading["odometry_turn_after_rad"]) < 1e-5
    values = read_calibration(str(tmp_path / "calibration.yaml"), std)  # the multiplier in effect kept
    assert values.odometry.yaw_rate_multiplier == 1.004
    assert values.odometry.yaw_per_metre == pytest.approx(heading["value"], rel=1e-6)
    status, out, err = run(capsys, bag, "--robot-model", STD, "--fit", "straight")
    assert status == 0, err
    assert re.search(r"odometry's yaw per metre along x: [+-]0\.000[0-9]+ rad/m \([+-]0\.0[0-9]+ ± 0\.0000 deg/m", out)
    assert "each leg's heading change [deg], ground truth / odometry before / after: +0.00 / " in out


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
def test_fit_turns_takes_the_yaw_rate_multiplier_from_the_turns_over_the_calibration_in_effect(tmp_path, capsys, std):
    from calibration_test_helpers import with_turn_slip  # noqa: PLC0415

    from thorvald_base.calibration.calibration_file import read_calibration  # noqa: PLC0415
    from thorvald_base.verification import plan_named  # noqa: PLC0415

    earlier = tmp_path / "earlier.yaml"
    earlier.write_text("motor_drives:\n  drive1: {r_wheel: 0.205}\nodometry: {yaw_rate_multiplier: 1.002}\n")
    in_effect = with_drive_param(std, 1, "r_wheel", 0.205)
    plan = [(s.duration, s.twist) for s in plan_named("turns", std, side=3.0)[1]]
    radii = [d.r_wheel for d in in_effect.drives]
    drive = with_turn_slip(synthetic_drive(in_effect, plan, radii, [0.0] * 4), left=1.005, right=1.005)
    bag = write_bag(tmp_path / "turns.bag", drive, gnss=True)
    status, out, err = run(capsys, bag, "--robot-model", STD, "--calibration", earlier, "--fit", "turns")
    assert status == 0, err
    assert "ground truth: the simulator's /robot_1/odometry/gazebo; 8 turns" in out
    assert out.count(" % short)") == 8 and "(+0.30 % short)" in out  # 1.005 slip against 1.002 in effect
    assert "odometry's yaw-rate multiplier: 1.00500 ± 0.00000 (was 1.002;" in out
    assert re.search(
        r"before [+-]0\.000 % of [0-9.]+ m, end point 0\.[0-9]{3} m; after [+-]0\.000 %, end point 0\.000", out
    )
    values = read_calibration(str(tmp_path / "calibration.yaml"), std)
    assert values.changes == ((1, "r_wheel", 0.205),)  # the drives' values kept
    assert values.yaw_rate_multiplier == pytest.approx(1.005, abs=1e-6) and values.yaw_per_metre == 0.0
    # from the IMU's yaw, as JSON
    status, out, err = run(capsys, bag, "--robot-model", STD, "--fit", "turns", "--ground-truth", "gnss", "--json")
    assert status == 0, err
    result = json.loads(out)
    assert result["fit"] == "turns" and len(result["turns"]) == 8
    assert result["yaw_rate_multiplier"]["value"] == pytest.approx(1.005, abs=1e-6)
    assert result["yaw_rate_multiplier"]["in_effect"] == 1.0 and result["yaw_per_metre"] == 0.0
    # a drive without turns, and --balance, are refused in one line
    straight = write_bag(tmp_path / "straight.bag", synthetic_drive(std, STRAIGHT, RADII, OFFSETS))
    for bag_, extra, message in (
        (straight, [], "drive the turns manoeuvre"),
        (bag, ["--balance", earlier], "goes with"),
    ):
        status, out, err = run(capsys, bag_, "--robot-model", STD, "--fit", "turns", *extra)
        assert status == 2 and err.count("\n") == 1 and message in err, err


@pytest.mark.slow  # fits and replays of whole synthetic drives
def test_fit_heading_takes_odometrys_heading_model_from_several_drives_over_the_calibration_in_effect(
    tmp_path, capsys, std
):
    from calibration_test_helpers import with_turn_slip  # noqa: PLC0415

    from thorvald_base.calibration.calibration_file import read_calibration  # noqa: PLC0415
    from thorvald_base.verification import plan_named  # noqa: PLC0415

    earlier = tmp_path / "earlier.yaml"
    earlier.write_text("motor_drives:\n  drive1: {r_wheel: 0.205}\nodometry: {yaw_per_metre: 0.0004}\n")
    in_effect = with_drive_param(std, 1, "r_wheel", 0.205)
    radii = [d.r_wheel for d in in_effect.drives]
    bags = []
    for name in ("calibration", "turns"):  # two drives with the calibration in effect, turning 0.6 % more
        plan = [(s.duration, s.twist) for s in plan_named(name, std, side=3.0)[1]]
        drive = with_turn_slip(synthetic_drive(in_effect, plan, radii, [0.0] * 4), left=1.006, right=1.006)
        bags.append(write_bag(tmp_path / f"{name}.bag", drive, gnss=True))
    common = ["--robot-model", STD, "--calibration", earlier, "--fit", "heading", "--keep-yaw-per-metre"]
    status, out, err = run(capsys, *bags, *common)
    assert status == 0, err
    assert "heading error (ground truth less odometry) by motion, over" in out
    assert "  m (yaw-rate multiplier)      1.00600" in out
    assert "  b (yaw per metre along x)    +0.000400 rad/m (kept: the straight legs') (was 0.0004)" in out
    assert "wheel weights (mean 1)       all alike (kept: not told apart: the wheels never disagreed" in out
    assert out.count("odometry against ground truth on ") == 2
    values = read_calibration(str(tmp_path / "calibration.yaml"), std)
    assert values.changes == ((1, "r_wheel", 0.205),)  # the drives' values kept
    # with_turn_slip's truth turns each twist's wz 1.006 times as fast, translation kept: exactly the model
    assert values.yaw_rate_multiplier == pytest.approx(1.006, abs=1e-6) and values.yaw_per_metre == 0.0004
    # from the IMU's yaw, as JSON, b fitted too (the slip is all m's, b 0). The IMU's yaw is averaged over
    # 0.05 s either side of each window's ends, which is exact where the heading changes linearly and off
    # by up to a quarter of that times the rate's jump where a synthetic drive steps from one twist to
    # the next (a real drive ramps): m and b to a few parts in a thousand
    status, out, err = run(capsys, *bags, *common[:-1], "--ground-truth", "gnss", "--json")
    assert status == 0, err
    result = json.loads(out)
    assert result["fit"] == "heading" and len(result["drives"]) == 2 and not result["wheel_weights"]["told"]
    assert result["yaw_rate_multiplier"]["value"] == pytest.approx(1.006, abs=3e-3)
    assert result["yaw_per_metre"]["value"] == pytest.approx(0.0, abs=1e-3) and not result["yaw_per_metre"]["kept"]
    assert not result["yaw_rate_multiplier"]["undetermined"]  # 1.006 is many of its uncertainties from 1
    assert result["after"]["end_point_m"] < result["before"]["end_point_m"]
    # another fit takes one bag
    status, out, err = run(capsys, *bags, "--robot-model", STD, "--fit", "turns")
    assert status == 2 and err.count("\n") == 1 and "--fit turns takes one bag, not 2" in err, err


BAD_BAGS = [
    (lambda p, d: p.write_text("not a bag") or str(p), [], "cannot read the bag"),
    (lambda p, d: str(p) + ".missing", [], "cannot read the bag"),
    (lambda p, d: write_bag(p, d, states=False), [], "no topic ending in base_state (the bag has: "),
    (lambda p, d: write_bag(p, d, sim=False), [], "no ground truth: no topic ending in odometry/gazebo"),
    (write_bag, ["--ground-truth", "gnss"], "no topic ending in gps/fix and imu/data"),
]


@pytest.mark.parametrize("case", BAD_BAGS, ids=["not a bag", "missing", "no base_state", "no ground truth", "no gnss"])
def test_a_bag_that_cannot_calibrate_is_one_line_and_status_2(tmp_path, capsys, std, case):
    make, extra, message = case
    drive = synthetic_drive(std, STRAIGHT, RADII, OFFSETS)
    bag = make(tmp_path / "x.bag", drive)
    status, out, err = run(capsys, bag, "--robot-model", STD, *extra)
    assert status == 2 and out == ""
    assert err.startswith(f"calibrate_odometry: {bag}: ") and message in err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert not (tmp_path / "calibration.yaml").exists()


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
def test_a_drive_that_excites_nothing_and_a_bad_robot_file_are_refused(tmp_path, capsys, std):
    standing = write_bag(tmp_path / "s.bag", synthetic_drive(std, ((5.0, Twist()),), RADII, OFFSETS))
    status, out, err = run(capsys, standing, "--robot-model", STD)
    assert status == 2 and out == "" and err.startswith("calibrate_odometry: the recorded drive excites nothing")
    assert err.count("\n") == 1 and not (tmp_path / "calibration.yaml").exists()
    bad = tmp_path / "robot.yaml"
    bad.write_text("motor_drives: {drive0: {node: 1, x: 0, y: 0, r_wheel: -1}}\n")
    status, _, err = run(capsys, standing, "--robot-model", bad)
    assert status == 2 and f"{bad}: invalid robot configuration" in err and "motor_drives.drive0.r_wheel" in err
    another = tmp_path / "other.bag"
    write_bag(another, synthetic_drive(load_robot_config(_diff_file(tmp_path)), STRAIGHT, (0.2, 0.2), (0, 0)))
    status, _, err = run(capsys, another, "--robot-model", STD)
    assert status == 2 and "holds 2 steering angles and 2 rim speeds for a robot of 4 drives" in err


def _diff_file(tmp_path):
    path = tmp_path / "diff.yaml"
    path.write_text(
        "base_calculator: pltf_clc_2wdiff::PltfClc2WDiff\n"
        "motor_drives:\n  drive0: {node: 1, x: 0, y: -0.3, type: 1}\n  drive1: {node: 1, x: 0, y: 0.3, type: 1}\n"
        "passive_wheels:\n  passive0: {type: caster, x: -0.5, y: 0}\n"
    )
    return str(path)


@pytest.mark.slow  # a process per case: the command as a user types it
def test_rosrun_runs_it_and_refuses_without_a_traceback(tmp_path):
    not_a_bag = tmp_path / "notes.bag"
    not_a_bag.write_text("a drive, in words")
    proc = subprocess.run(
        ["rosrun", "thorvald_base", "calibrate_odometry", str(not_a_bag), "--robot-model", STD],
        capture_output=True,
        text=True,
        timeout=60,
        env=dict(os.environ),
    )
    assert proc.returncode == 2, proc.stderr
    assert proc.stderr.startswith(f"calibrate_odometry: {not_a_bag}: cannot read the bag")
    assert "Traceback" not in proc.stderr and proc.stdout == ""
