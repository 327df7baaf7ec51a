"""The radii's common factor from straight legs between standstills (thorvald_base.calibration.scale),
on synthetic drives of the straight manoeuvre with known tyres."""

import math

import numpy as np
import pytest
from base_test_helpers import four_ws, robot_config
from calibration_test_helpers import MIXED, synthetic_drive

from thorvald_base.calibration import common_scale
from thorvald_base.calibration.scale import STRAIGHT
from thorvald_base.errors import CalibrationError
from thorvald_base.kinematics import Twist
from thorvald_base.verification import plan_named

SIX = "thorvald_ii_6wd6ws_asym.yaml"


def straight_drive(config, radii, offsets=None, **kw):
    _, plan = plan_named("straight", config, side=4.0)
    offsets = offsets if offsets is not None else [d.steering_offset for d in config.drives]
    return synthetic_drive(config, [(s.duration, s.twist) for s in plan], radii, offsets, **kw)


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
