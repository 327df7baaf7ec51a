"""Odometry's yaw-rate multiplier from turns of the working radius (thorvald_base.calibration.turns), the
turns manoeuvre, and the multiplier in the calculator, the calibration file and base_driver's core."""

import math

import numpy as np
import pytest
from base_test_helpers import four_ws, robot_config
from calibration_test_helpers import STRAIGHT, synthetic_drive, with_turn_slip

from thorvald_base.calibration import odometry_error
from thorvald_base.calibration.calibration_file import changes_yaml, parse_calibration_values, read_calibration
from thorvald_base.calibration.turns import turn_fit
from thorvald_base.errors import CalibrationError, KinematicsError
from thorvald_base.kinematics import DriveState, OdometryCorrection, Twist
from thorvald_base.plugins import load_calculator
from thorvald_base.verification import ROW_SPACING, commanded_path, plan_named
from thorvald_model.errors import ConfigError

SIX = "thorvald_ii_6wd6ws_asym.yaml"
DIFF = "thorvald_ii_2wd_diff.yaml"


def turns_drive(config, side=4.0):
    _, plan = plan_named("turns", config, side=side)
    radii = [d.r_wheel for d in config.drives]
    offsets = [d.steering_offset for d in config.drives]
    return synthetic_drive(config, [(s.duration, s.twist) for s in plan], radii, offsets)


@pytest.mark.parametrize("name", [SIX, DIFF])
def test_the_turns_manoeuvre_turns_u_turns_of_the_field_routes_radius_both_ways_and_ends_a_row_on(name):
    config = robot_config(name)
    description, plan = plan_named("turns", config, side=4.0)
    turns = [s for s in plan if s.label.startswith("headland U turn")]
    assert [s.label[-5:].strip() for s in turns] == ["left", "left", "right", "right"] * 2
    for s in turns:  # half a circle each, about a point half a row spacing to the side
        assert abs(s.twist.wz) * s.duration == pytest.approx(math.pi)
    assert "8 headland U turns" in description and "0.75 m" in description
    end, _ = commanded_path(plan)
    assert math.hypot(end.x - 4.0, end.y) < 1e-6 and abs(math.remainder(end.yaw, 2 * math.pi)) < 1e-6
    if name == SIX:  # every wheel steers: base_link's own circle is the row spacing's half
        assert all(abs(s.twist.vx / s.twist.wz) == pytest.approx(ROW_SPACING / 2) for s in turns)


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
def test_the_multiplier_is_ground_truths_turn_over_odometrys_and_the_turns_both_ways_average():
    config = robot_config(SIX)
    drive = with_turn_slip(turns_drive(config), left=1.004, right=1.008)
    fit = turn_fit(config, drive.recording, drive.pose_truth)
    assert len(fit.turns) == 8
    left = [turn for turn in fit.turns if turn.truth > 0]
    assert len(left) == 4
    for turn in fit.turns:  # each turn read short by its slip
        slip = 1.004 if turn.truth > 0 else 1.008
        assert turn.short_percent == pytest.approx((1 - 1 / slip) * 100, abs=0.01)
        assert abs(turn.odometry) == pytest.approx(math.pi, rel=5e-3)  # half a circle, to the 20 ms step
    assert fit.multiplier == pytest.approx(1.006, abs=2e-4)
    # the two ways differ by 0.4 %: their scatter (0.2 % a turn) over the eight turns is the uncertainty
    assert fit.multiplier_sd == pytest.approx(0.002 / math.sqrt(7), rel=0.02)
    # with the multiplier in effect the turns read right and the fit says so: no further gain
    again = turn_fit(config, drive.recording, drive.pose_truth, in_effect=fit.correction)
    assert again.gain == pytest.approx(1.0, abs=1e-6) and again.multiplier == pytest.approx(fit.multiplier)
    # the drive's end point comes in as far as one multiplier for both ways can bring it; the distance stays
    before = odometry_error(config, drive.recording, drive.pose_truth)
    after = odometry_error(config, drive.recording, drive.pose_truth, correction=fit.correction)
    assert before.end_point_m > 0.1 and after.end_point_m < before.end_point_m * 0.75
    assert after.distance_error_percent == pytest.approx(before.distance_error_percent, abs=1e-5)
    # where both ways slip alike, it takes the end point to where the 20 ms steps leave it
    alike = with_turn_slip(turns_drive(config), left=1.006, right=1.006)
    fit = turn_fit(config, alike.recording, alike.pose_truth)
    assert fit.multiplier == pytest.approx(1.006, abs=1e-6)
    before = odometry_error(config, alike.recording, alike.pose_truth)
    after = odometry_error(config, alike.recording, alike.pose_truth, correction=fit.correction)
    assert before.end_point_m > 0.1 and after.end_point_m < 1e-3


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
def test_the_imus_yaw_is_ground_truth_enough_and_a_drive_without_turns_is_refused():
    config = four_ws()
    drive = with_turn_slip(turns_drive(config), left=1.005, right=1.005)
    fit = turn_fit(config, drive.recording, drive.gnss_truth)
    assert fit.multiplier == pytest.approx(1.005, abs=1e-4) and fit.gain_sd < 1e-4
    straight = synthetic_drive(config, STRAIGHT, [d.r_wheel for d in config.drives], [0.0] * 4)
    with pytest.raises(CalibrationError, match=r"holds 0 turns.*drive the turns manoeuvre"):
        turn_fit(config, straight.recording, straight.pose_truth)
    apart = with_turn_slip(turns_drive(config), left=0.97, right=1.05)  # a multiplier of 1.01 fits neither way
    with pytest.raises(CalibrationError, match=r"the turns disagree \(the multiplier 1\.01.* no multiplier fits them"):
        turn_fit(config, apart.recording, apart.pose_truth)
    absurd = with_turn_slip(turns_drive(config), left=1.3, right=1.3)
    with pytest.raises(CalibrationError, match=r"multiplier of 1\.30.*beyond \[0\.9, 1\.1\]"):
        turn_fit(config, absurd.recording, absurd.pose_truth)


def test_the_calculator_corrects_odometrys_yaw_rate_and_keeps_its_translation():
    config = four_ws()
    calc = load_calculator(config)
    command = calc.calculate_command(Twist(0.75, 0.0, 1.0)).commands
    states = [DriveState(c.steering, c.speed) for c in command]
    plain = calc.calculate_odometry(states, 0.0).twist
    correction = OdometryCorrection(1.006, 0.002)
    calc.odometry_correction = correction
    fixed = calc.calculate_odometry(states, 0.02)
    assert fixed.twist.wz == pytest.approx(plain.wz * 1.006 + 0.002 * 0.75)
    assert (fixed.twist.vx, fixed.twist.vy) == pytest.approx((plain.vx, plain.vy))
    assert fixed.pose.yaw == pytest.approx(0.02 * (1.006 + 0.0015))  # integrated with it
    twist = calc.body_twist([s.steering for s in states], [s.speed for s in states])
    assert twist.wz == pytest.approx(1.006 + 0.0015)
    calc.set_params(config.drives)  # a new radius at run time keeps it
    assert calc.odometry_correction == correction
    cases = [
        (OdometryCorrection(1.2), r"yaw_rate_multiplier must be in \[0\.9, 1\.1\], not 1\.2"),
        (OdometryCorrection(float("nan")), "yaw_rate_multiplier must be in"),
        (OdometryCorrection(True), "yaw_rate_multiplier must be in"),
        (OdometryCorrection(1.0, 0.01), r"yaw_per_metre must be within \+-0\.005 rad/m, not 0\.01"),
        (OdometryCorrection(1.0, "0"), "yaw_per_metre must be within"),
    ]
    for bad, said in cases:
        with pytest.raises(KinematicsError, match=said):
            calc.odometry_correction = bad
    assert calc.odometry_correction == correction


def test_the_calibration_file_carries_the_multiplier_and_names_a_bad_one(tmp_path):
    config = four_ws()
    path = tmp_path / "calibration.yaml"
    path.write_text(
        changes_yaml([(1, "r_wheel", 0.201)], "a header", odometry=OdometryCorrection(1.00612345678, -2e-4))
    )
    assert "odometry:\n  yaw_rate_multiplier: 1.00612346\n  yaw_per_metre: -0.0002\n" in path.read_text()
    values = read_calibration(str(path), config)
    assert values.changes == ((1, "r_wheel", 0.201),) and values.odometry == OdometryCorrection(1.00612346, -2e-4)
    assert parse_calibration_values({"motor_drives": {}}, config).odometry is None
    alone = parse_calibration_values({"odometry": {"yaw_per_metre": 0.001}}, config)
    assert (alone.yaw_rate_multiplier, alone.odometry) == (None, OdometryCorrection(1.0, 0.001))
    cases = [
        ({"odometry": {"yaw_rate_multiplier": 1.5}}, "odometry.yaw_rate_multiplier: 1.5: must be in [0.9, 1.1]"),
        ({"odometry": {"yaw_rate": 1.0}}, "odometry.yaw_rate: 1.0: unknown key"),
        ({"odometry": [1.0]}, "odometry: [1.0]: must be a mapping of keys"),
        ({"odometry": {"yaw_rate_multiplier": "fast"}}, "odometry.yaw_rate_multiplier: 'fast'"),
        ({"odometry": {"yaw_per_metre": -0.02}}, "odometry.yaw_per_metre: -0.02: must be within +-0.005 rad/m"),
    ]
    for data, said in cases:
        with pytest.raises(ConfigError) as e:
            parse_calibration_values(data, config, "mine.yaml")
        assert said in str(e.value) and "mine.yaml" in str(e.value)


def test_base_drivers_core_applies_the_files_multiplier_to_its_odometry(tmp_path):
    from thorvald_base.bases.simulated import SimulatedBase  # noqa: PLC0415
    from thorvald_base.core import BaseDriverCore  # noqa: PLC0415
    from thorvald_base.lockstep import apply_calibration, calibration_said  # noqa: PLC0415

    config = four_ws()
    core = BaseDriverCore(config, load_calculator(config), SimulatedBase(config))
    path = tmp_path / "calibration.yaml"
    path.write_text("motor_drives:\n  drive0: {r_wheel: 0.201}\nodometry: {yaw_rate_multiplier: 0.997}\n")
    values = apply_calibration(core, str(path))
    assert core.calculator.odometry_correction == OdometryCorrection(0.997, 0.0)
    assert core.config.drives[0].r_wheel == 0.201
    assert calibration_said(values) == "drive0 r_wheel 0.201, odometry yaw_rate_multiplier 0.997"
    assert np.isfinite(core.step(0.0).odometry.twist.wz)
