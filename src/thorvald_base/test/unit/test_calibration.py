"""thorvald_base.calibration on synthetic drives with known as-built parameters.

Every drive is made with the workspace's own kinematics (calibration_test_helpers): the calculator
gives each wheel's true velocity for a twist, and base_driver's reading of a wheel that really rolls
with r_true and stands δ_true to the left of its reading is derived from it. Without noise the
least squares must give the parameters back to rounding; with noise each estimate must lie within 3
of its stated standard uncertainties, and those uncertainties must be what the estimates' spread is.
"""

import math

import numpy as np
import pytest
from base_test_helpers import diff, four_wd_two_ws, four_ws
from calibration_test_helpers import DEG, DIFF_DRIVE, MIXED, STRAIGHT, synthetic_drive

from thorvald_base.calibration import (
    GNSS,
    SIMULATOR,
    DriveRecording,
    as_read_with,
    calibrate,
    local_metres,
    odometry_error,
)
from thorvald_base.errors import CalibrationError
from thorvald_base.kinematics import Twist
from thorvald_model import with_drive_param

# the field profile's tolerances: radius +-1 %, steering +-0.5 deg
RADII = (0.2016, 0.1990, 0.2006, 0.1981)  # [m] true rolling radii (configured 0.2)
OFFSETS = (0.004, -0.006, 0.002, 0.007)  # [rad] true steering offsets (configured 0)
PSI = 0.3  # [rad] the IMU yaw's bias against east
ANTENNA = (0.2, 0.1)  # [m] the GNSS antenna in base_link
GROUND_TRUTHS = ("pose_truth", "gnss_truth")


def truth_values(p):
    return RADII[p.index] if p.key == "r_wheel" else OFFSETS[p.index]


def z_scores(calibration, truth=truth_values):
    return np.array([(p.value - truth(p)) / p.sd for p in calibration.parameters if p.excited])


@pytest.mark.parametrize("ground_truth", GROUND_TRUTHS)
def test_every_parameter_recovered_exactly_without_noise(ground_truth):
    config = four_ws()
    drive = synthetic_drive(config, MIXED, RADII, OFFSETS, heading_bias=PSI, antenna=ANTENNA)
    calibration = calibrate(config, drive.recording, getattr(drive, ground_truth))
    assert calibration.ground_truth == (GNSS if ground_truth == "gnss_truth" else SIMULATOR)
    assert [(p.drive, p.key) for p in calibration.parameters] == [
        (f"drive{i}", key) for i in range(4) for key in ("r_wheel", "steering_offset")
    ]
    assert calibration.not_excited == ()
    for p in calibration.parameters:
        assert p.value == pytest.approx(truth_values(p), rel=1e-9, abs=0), (p.drive, p.key)
        assert p.sd < 1e-12  # nothing left unexplained
    if ground_truth == "gnss_truth":
        assert calibration.heading_bias[0] == pytest.approx(PSI, rel=1e-9)
        # 28.04 s of fixes at 10 Hz, 281 of them, a window from each to the one 2 s (20 fixes) later
        assert calibration.observations == 261
    else:
        assert calibration.heading_bias is None
        assert calibration.observations == 1400  # the moving samples at 50 Hz
    assert calibration.turned == pytest.approx(6.7, abs=1e-9)  # 0.35*6 + 0.2*5 + 0.6*3 + 0.3*6 [rad]


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
@pytest.mark.parametrize("ground_truth", GROUND_TRUTHS)
def test_the_values_in_effect_are_where_the_estimates_start_from(ground_truth):
    """base_driver read the drive with drive1 at 0.205 m and drive2 homed 0.01 rad off: the estimates
    are still the true values, not corrections to them."""
    config = with_drive_param(with_drive_param(four_ws(), 1, "r_wheel", 0.205), 2, "steering_offset", 0.01)
    drive = synthetic_drive(config, MIXED, RADII, OFFSETS, heading_bias=PSI, antenna=ANTENNA)
    calibration = calibrate(config, drive.recording, getattr(drive, ground_truth))
    assert calibration.parameter("drive1", "r_wheel").in_effect == 0.205
    assert calibration.parameter("drive2", "steering_offset").in_effect == 0.01
    for p in calibration.parameters:
        assert p.value == pytest.approx(truth_values(p), rel=1e-9, abs=0), (p.drive, p.key)
    calibrated = calibration.calibrated(config)
    assert [d.r_wheel for d in calibrated.drives] == pytest.approx(RADII, rel=1e-9)
    assert [d.steering_offset for d in calibrated.drives] == pytest.approx(OFFSETS, rel=1e-9)


NOISE = {
    # the simulator's twist, jittering with contacts [m/s, rad/s]; what the drives read [m/s, rad]
    "pose_truth": dict(twist=0.01, speed=0.002, steering=0.001),
    # an RTK fix with 2 cm noise at 10 Hz, an IMU's yaw with 0.001 rad
    "gnss_truth": dict(fix=0.02, yaw=0.001),
}


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
@pytest.mark.parametrize("ground_truth", GROUND_TRUTHS)
def test_with_noise_every_estimate_lies_within_three_standard_uncertainties(ground_truth):
    config = four_ws()
    drive = synthetic_drive(
        config, MIXED, RADII, OFFSETS, heading_bias=PSI, antenna=ANTENNA, noise=NOISE[ground_truth], seed=4
    )
    calibration = calibrate(config, drive.recording, getattr(drive, ground_truth))
    assert calibration.not_excited == ()
    z = z_scores(calibration)
    assert len(z) == 8 and np.all(np.abs(z) < 3.0), z
    radius_sd = [p.sd / p.value for p in calibration.parameters if p.key == "r_wheel"]
    offset_sd = [p.sd for p in calibration.parameters if p.key == "steering_offset"]
    if ground_truth == "pose_truth":
        # 1400 samples: the radii to about 0.04 %, the offsets to about 0.02 deg
        assert max(radius_sd) < 5e-4 and max(offset_sd) < 0.04 * DEG
    else:
        # 281 fixes with 2 cm of noise: the radii to about 0.07 %, the offsets to about 0.08 deg (the
        # issue's targets for the field robot are 0.2 % and 0.1 deg)
        assert max(radius_sd) < 1e-3 and max(offset_sd) < 0.1 * DEG
        assert abs(calibration.heading_bias[0] - PSI) < 3 * calibration.heading_bias[1]


@pytest.mark.parametrize("ground_truth", GROUND_TRUTHS)
@pytest.mark.slow  # many calibrations of noisy drives
def test_the_stated_uncertainties_are_the_spread_of_the_estimates(ground_truth):
    """Over 20 seeds, the estimates' errors in units of their stated standard uncertainty have an
    RMS near 1: the uncertainties are neither optimistic nor so wide that 'within 3' says nothing."""
    config = four_ws()
    z = []
    for seed in range(20):
        drive = synthetic_drive(
            config, MIXED, RADII, OFFSETS, heading_bias=PSI, antenna=ANTENNA, noise=NOISE[ground_truth], seed=seed
        )
        z.extend(z_scores(calibrate(config, drive.recording, getattr(drive, ground_truth))))
    rms = math.sqrt(np.mean(np.square(z)))
    assert 0.8 < rms < 1.3, rms
    assert np.mean(np.abs(z) < 2.0) > 0.85


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
def test_a_straight_line_with_gnss_refuses_the_steering_offsets():
    """A straight line cannot tell a steering offset from a heading: δ_i + c and ψ − c fit alike."""
    config = four_ws()
    for noise in (None, NOISE["gnss_truth"]):
        drive = synthetic_drive(config, STRAIGHT * 3, RADII, OFFSETS, heading_bias=PSI, antenna=ANTENNA, noise=noise)
        calibration = calibrate(config, drive.recording, drive.gnss_truth)
        refused = calibration.not_excited
        assert [(p.drive, p.key) for p in refused] == [(f"drive{i}", "steering_offset") for i in range(4)]
        for p in refused:
            assert "a straight line cannot tell a steering offset from a heading" in p.reason
            assert (p.value, p.in_effect) == (0.0, 0.0) and math.isnan(p.sd)  # left at its value in effect
        radii = [p for p in calibration.parameters if p.key == "r_wheel"]
        assert all(p.excited for p in radii)
        if noise is None:
            # the radii are still told: fitted with every offset at 0 (ψ taking their mean), each wheel's
            # rolling direction is off by ε, its offset less the mean, which costs its radius the
            # factor cos ε (drive1: ε = -0.00775 rad, 3.0e-5)
            eps = np.subtract(OFFSETS, np.mean(OFFSETS))
            assert [p.value for p in radii] == pytest.approx(RADII * np.cos(eps), rel=1e-7)
            # the IMU's bias then takes the offsets' common part: their mean, weighted by how far each
            # wheel rolled (all alike here)
            assert calibration.heading_bias[0] == pytest.approx(PSI + np.mean(OFFSETS), abs=1e-6)
        else:
            # within 3 uncertainties of 0.4 % or better
            assert all(p.sd / p.value < 0.004 for p in radii)
            assert np.all(np.abs(z_scores(calibration)) < 3.0)
    # ... which the simulator's true heading can: there the same drive gives the offsets
    exact = calibrate(config, drive.recording, drive.pose_truth)
    assert exact.not_excited == ()


def test_a_differential_robot_gets_its_radii_only():
    config = diff()  # two type-1 drives on one axle and a caster
    radii = (0.202, 0.197)
    drive = synthetic_drive(config, DIFF_DRIVE, radii, (0.0, 0.0), heading_bias=-1.0, antenna=ANTENNA)
    for truth in (drive.pose_truth, drive.gnss_truth):
        calibration = calibrate(config, drive.recording, truth)
        assert [(p.drive, p.key) for p in calibration.parameters] == [("drive0", "r_wheel"), ("drive1", "r_wheel")]
        assert [p.value for p in calibration.parameters] == pytest.approx(radii, rel=1e-9)
    assert calibration.heading_bias[0] == pytest.approx(-1.0, rel=1e-9)
    # with noise on the simulator's twist, within 3 uncertainties
    noisy = synthetic_drive(config, DIFF_DRIVE, radii, (0.0, 0.0), noise=NOISE["pose_truth"], seed=2)
    z = z_scores(calibrate(config, noisy.recording, noisy.pose_truth), lambda p: radii[p.index])
    assert len(z) == 2 and np.all(np.abs(z) < 3.0), z


def test_a_robot_with_steered_and_fixed_drives_gets_offsets_for_the_steered_ones():
    config = four_wd_two_ws()  # drive0, drive1 steer; drive2, drive3 on a fixed rear axle
    offsets = (0.004, -0.003, 0.0, 0.0)
    segments = ((5.0, Twist(0.8, 0.0, 0.0)), (6.0, Twist(0.6, 0.0, 0.4)), (6.0, Twist(0.7, 0.0, -0.3)))
    drive = synthetic_drive(config, segments, RADII, offsets)
    calibration = calibrate(config, drive.recording, drive.pose_truth)
    keys = [(p.drive, p.key) for p in calibration.parameters]
    assert keys == [
        ("drive0", "r_wheel"),
        ("drive0", "steering_offset"),
        ("drive1", "r_wheel"),
        ("drive1", "steering_offset"),
        ("drive2", "r_wheel"),
        ("drive3", "r_wheel"),
    ]
    values = {k: p.value for k, p in zip(keys, calibration.parameters)}
    assert values[("drive0", "steering_offset")] == pytest.approx(0.004, rel=1e-9)
    assert values[("drive1", "steering_offset")] == pytest.approx(-0.003, rel=1e-9)
    assert values[("drive3", "r_wheel")] == pytest.approx(RADII[3], rel=1e-9)


def test_a_drive_that_excites_nothing_is_refused():
    config = four_ws()
    standing = synthetic_drive(config, ((10.0, Twist()),), RADII, OFFSETS, heading_bias=PSI)
    for truth in (standing.pose_truth, standing.gnss_truth):
        with pytest.raises(CalibrationError, match="the recorded drive excites nothing"):
            calibrate(config, standing.recording, truth)
    # a creep of 1 mm/s for 10 s: moving, but not enough to tell anything through 2 cm of GNSS noise
    creeping = synthetic_drive(
        config, ((10.0, Twist(0.001, 0.0, 0.0)),), RADII, OFFSETS, noise=NOISE["gnss_truth"], antenna=ANTENNA
    )
    with pytest.raises(CalibrationError, match=r"excites nothing: drive0 r_wheel: its standard uncertainty") as info:
        calibrate(config, creeping.recording, creeping.gnss_truth)
    assert "it rolled 0.01 m" in str(info.value)


def test_a_recording_of_another_robot_is_refused():
    config = four_ws()
    drive = synthetic_drive(diff(), DIFF_DRIVE, (0.2, 0.2), (0.0, 0.0))
    with pytest.raises(CalibrationError, match="the recording holds 2 drives, the robot file 4"):
        calibrate(config, drive.recording, drive.pose_truth)
    with pytest.raises(CalibrationError, match=r"holds 2 steering angles and 2 rim speeds for a robot of 4 drives"):
        DriveRecording.from_samples([(0.0, (0.0, 0.0), (0.1, 0.1))], 4)


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
def test_odometry_error_before_and_after_on_a_straight_drive_with_larger_wheels():
    """Every wheel 1 % larger than configured: odometry reads 1/1.01 of the distance, -0.990 %, and
    the end point falls short by 0.0099 of the 30 m; calibrated, it reads the distance exactly."""
    config = four_ws()
    drive = synthetic_drive(config, STRAIGHT, [0.202] * 4, [0.0] * 4)
    calibration = calibrate(config, drive.recording, drive.pose_truth)
    assert [p.value for p in calibration.parameters if p.key == "r_wheel"] == pytest.approx([0.202] * 4, rel=1e-9)
    before = odometry_error(config, drive.recording, drive.pose_truth)
    assert before.truth_distance_m == pytest.approx(30.0, rel=1e-12)
    assert before.distance_error_percent == pytest.approx((1 / 1.01 - 1) * 100, rel=1e-9)
    assert before.end_point_m == pytest.approx(30.0 * (1 - 1 / 1.01), rel=1e-9)
    calibrated = calibration.calibrated(config)
    after = odometry_error(calibrated, as_read_with(drive.recording, config, calibrated), drive.pose_truth)
    assert abs(after.distance_error_percent) < 1e-9 and after.end_point_m < 1e-9


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
@pytest.mark.parametrize("ground_truth", GROUND_TRUTHS)
def test_the_calibrated_odometry_follows_ground_truth(ground_truth):
    config = four_ws()
    drive = synthetic_drive(config, MIXED, RADII, OFFSETS, heading_bias=PSI, antenna=ANTENNA)
    truth = getattr(drive, ground_truth)
    calibration = calibrate(config, drive.recording, truth)
    bias = calibration.heading_bias[0] if calibration.heading_bias else 0.0
    before = odometry_error(config, drive.recording, truth, bias)
    calibrated = calibration.calibrated(config)
    after = odometry_error(calibrated, as_read_with(drive.recording, config, calibrated), truth, bias)
    # offsets of up to 0.4 deg and radii 1 % off put the uncalibrated end point 0.3 m off after 20 m
    assert before.end_point_m > 0.2 and abs(before.distance_error_percent) > 0.05
    assert after.end_point_m < 1e-9 and abs(after.distance_error_percent) < 1e-9


def test_as_read_with_the_calibrated_configuration():
    config = four_ws()
    calibrated = with_drive_param(with_drive_param(config, 0, "r_wheel", 0.21), 2, "steering_offset", 0.02)
    recording = DriveRecording(np.array([0.0, 0.02]), np.full((2, 4), 0.1), np.full((2, 4), 0.5))
    read = as_read_with(recording, config, calibrated)
    assert read.speed[0] == pytest.approx([0.5 * 0.21 / 0.2, 0.5, 0.5, 0.5])  # wheel turns x the new radius
    assert read.steering[1] == pytest.approx([0.1, 0.1, 0.12, 0.1])  # reading + the new offset


def test_local_metres_of_a_fix_use_the_wgs84_radii():
    # a thousandth of a degree: 111.132 m north and 78.847 m east at 45 deg, 111.412 m and 55.800 m
    # at 60 deg (the lengths of a degree of latitude and longitude, WGS84)
    for lat, north, east in ((45.0, 111.132, 78.847), (60.0, 111.412, 55.800)):
        e, n = local_metres([lat, lat + 0.001, lat], [10.0, 10.0, 10.001])
        assert (e[0], n[0]) == (0.0, 0.0)
        assert n[1] == pytest.approx(north, abs=1e-3) and e[1] == pytest.approx(0.0, abs=1e-12)
        assert e[2] == pytest.approx(east, abs=1e-3) and n[2] == pytest.approx(0.0, abs=1e-12)
