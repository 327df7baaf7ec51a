"""The radii's common factor from straight legs between standstills (thorvald_base.calibration.scale),
on synthetic drives of the straight manoeuvre with known tyres."""

import math

import numpy as np
import pytest
from base_test_helpers import four_ws, robot_config
from calibration_test_helpers import MIXED, synthetic_drive

from thorvald_base.calibration import common_scale, replay
from thorvald_base.calibration.scale import STRAIGHT
from thorvald_base.errors import CalibrationError
from thorvald_base.kinematics import OdometryCorrection, Twist
from thorvald_base.verification import plan_named

SIX = "thorvald_ii_6wd6ws_asym.yaml"


def straight_drive(config, radii, offsets=None, **kw):
    _, plan = plan_named("straight", config, side=4.0)
    offsets = offsets if offsets is not None else [d.steering_offset for d in config.drives]
    return synthetic_drive(config, [(s.duration, s.twist) for s in plan], radii, offsets, **kw)


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
def test_tyres_all_larger_by_one_factor_give_that_factor_and_the_offsets_are_kept():
    config = robot_config(SIX)
    radii = [d.r_wheel * 1.0042 for d in config.drives]
    drive = straight_drive(config, radii)
    fit = common_scale(config, drive.recording, drive.pose_truth)
    assert fit.factor == pytest.approx(1.0042, abs=1e-9)
    assert len(fit.legs) == len(fit.used) == 5  # every leg between the six stops
    # the robot drove the plan's 32 m; its odometry, reading wheels 0.42 % larger than it thinks, less
    assert sum(leg.truth_m for leg in fit.used) == pytest.approx(8 * 4.0, rel=1e-9)
    assert sum(leg.odometry_m for leg in fit.used) == pytest.approx(8 * 4.0 / 1.0042, rel=1e-9)
    calibration = fit.calibration(config)
    for drive_config, p in zip(config.drives, [p for p in calibration.parameters if p.key == "r_wheel"]):
        assert p.excited and p.value == pytest.approx(drive_config.r_wheel * 1.0042, rel=1e-9)
    offsets = [p for p in calibration.parameters if p.key == "steering_offset"]
    assert offsets and not any(p.excited for p in offsets)


def test_from_gnss_with_noise_the_standstills_average_it_out():
    config = four_ws()
    radii = [d.r_wheel * 0.996 for d in config.drives]
    drive = straight_drive(config, radii, noise={"fix": 0.02}, antenna=(0.3, 0.2), heading_bias=0.4, seed=3)
    fit = common_scale(config, drive.recording, drive.gnss_truth)
    assert fit.ground_truth == "gnss"
    # 2 cm fixes, 20 per standstill half: about 0.006 m per leg end, 0.2 % of a 4 m leg, 0.06 % of all
    assert fit.factor == pytest.approx(0.996, abs=0.0006)
    assert 0.0 < fit.sd < 0.001 and abs(fit.factor - 0.996) < 4 * fit.sd


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
def test_different_tyres_give_their_common_motion_and_a_turning_drive_is_refused():
    config = robot_config(SIX)
    radii = [d.r_wheel * f for d, f in zip(config.drives, (1.01, 0.99, 1.0, 1.003, 0.997, 1.002))]
    drive = straight_drive(config, radii)
    fit = common_scale(config, drive.recording, drive.pose_truth)
    # what the odometry reads of wheels that read differently on a straight leg: their speeds' mean
    mean_read = np.mean([1.0 / f for f in (1.01, 0.99, 1.0, 1.003, 0.997, 1.002)])
    assert fit.factor == pytest.approx(1.0 / mean_read, rel=1e-6)
    turning = synthetic_drive(config, MIXED, [d.r_wheel for d in config.drives], [0.0] * 6)
    with pytest.raises(CalibrationError, match="no straight leg"):
        common_scale(config, turning.recording, turning.pose_truth)


def test_a_leg_that_turned_is_left_out():
    config = four_ws()
    stop, leg = (2.0, Twist()), (4.0, Twist(1.0, 0.0, 0.0))
    arc = (4.0, Twist(1.0, 0.0, 0.4))
    drive = synthetic_drive(config, [stop, leg, stop, arc, stop, leg, stop], [d.r_wheel * 1.01 for d in config.drives],
                            [0.0] * 4)  # fmt: skip
    fit = common_scale(config, drive.recording, drive.pose_truth)
    assert [leg.straight for leg in fit.legs] == [True, False, True]
    assert fit.legs[1].path_m > fit.legs[1].odometry_m * (1 + STRAIGHT)
    assert fit.factor == pytest.approx(1.01, abs=1e-9) and math.isfinite(fit.sd)


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
def test_radii_that_differ_side_to_side_read_a_turn_on_straight_legs_which_yaw_per_metre_takes_out():
    config = robot_config(SIX)
    lateral = np.array([d.y for d in config.drives])
    radii = [d.r_wheel * 1.001 * math.exp(0.003 * (y - lateral.mean())) for d, y in zip(config.drives, lateral)]
    drive = straight_drive(config, radii)
    plain = common_scale(config, drive.recording, drive.pose_truth)
    assert plain.yaw_per_metre is None and plain.correction == OdometryCorrection()
    # odometry reads each leg turning, one way forwards, the other way back; ground truth drives straight
    turns = [leg.odometry_turn for leg in plain.used]
    assert all(abs(t) > math.radians(0.05) for t in turns) and turns[0] * turns[1] < 0
    assert all(abs(leg.truth_turn) < 1e-9 for leg in plain.used)
    forward = [leg.forward_m for leg in plain.used]  # odometry's, of tyres 0.1 % larger than it thinks
    assert forward == [pytest.approx(4.0 / 1.001 * s, rel=1e-4) for s in (1, -2, 2, -2, 1)]
    fit = common_scale(config, drive.recording, drive.pose_truth, heading=True)
    assert fit.factor == pytest.approx(plain.factor)
    per_metre = -turns[0] * 1.001 / 4.0  # the first leg's turn, undone over its 4 m
    assert fit.yaw_per_metre == pytest.approx(per_metre, rel=1e-3) and fit.yaw_per_metre_sd < 1e-6
    assert max(abs(t) for t in fit.odometry_turns_after) < math.radians(0.001)
    # the radii are the factor's alone: the correction is the odometry's, base_driver's commands unchanged
    fitted = [p.value for p in fit.calibration(config).parameters if p.key == "r_wheel"]
    assert fitted == [pytest.approx(d.r_wheel * fit.factor) for d in config.drives]
    # a correction in effect: the legs are replayed with it, and what they ask is added to it
    again = common_scale(config, drive.recording, drive.pose_truth, heading=True, in_effect=fit.correction)
    assert abs(again.yaw_per_metre) < 1e-6 and again.correction.yaw_per_metre == pytest.approx(per_metre, rel=1e-3)
    # and odometry of the whole drive, replayed with the correction, reads no turn at any instant
    _, _, _, yaw = replay(config, drive.recording, correction=fit.correction)
    _, _, _, uncorrected = replay(config, drive.recording)
    assert np.max(np.abs(uncorrected - uncorrected[0])) > math.radians(0.05)
    assert np.max(np.abs(yaw - yaw[0])) < math.radians(0.002)


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
def test_yaw_per_metre_from_the_imus_yaw_and_one_beyond_a_calibration_is_refused():
    config = four_ws()
    lateral = [d.y for d in config.drives]
    radii = [d.r_wheel * math.exp(-0.004 * y) for d, y in zip(config.drives, lateral)]
    drive = straight_drive(config, radii, antenna=(0.3, 0.2), heading_bias=0.4)
    sim = common_scale(config, drive.recording, drive.pose_truth, heading=True)
    gnss = common_scale(config, drive.recording, drive.gnss_truth, heading=True)
    assert gnss.yaw_per_metre == pytest.approx(sim.yaw_per_metre, rel=1e-3) and abs(sim.yaw_per_metre) > 1e-4
    far = [d.r_wheel * math.exp(0.1 * y) for d, y in zip(config.drives, lateral)]
    drive = straight_drive(config, far)
    with pytest.raises(CalibrationError, match=r"yaw per metre, beyond \+-0\.005: more than a calibration"):
        common_scale(config, drive.recording, drive.pose_truth, heading=True)
