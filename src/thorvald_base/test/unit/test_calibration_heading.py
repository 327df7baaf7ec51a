"""Odometry's heading model (thorvald_base.calibration.heading): the wheels' weights in the calculator's
yaw rate, the correction in the calibration file, and the fit on synthetic drives with known answers.

The robot of most cases is a square of four steered drives at (+-1, +-1) m (base_test_helpers.four_ws),
so every expected number is a fraction: its plain least-squares fit gives each wheel's velocity the
weight 1/4 in vx and vy, and in wz the weights -y/8 (vx) and x/8 (vy) (sum J^T J = diag(4, 4, 8)). With
the weights 2, 0, 2, 0 (the diagonal pair of drives 0 and 2, at (-1, -1) and (1, 1)) the weighted
sum is diag(2+2, 2+2, 2*2+2*2) = diag(4, 4, 8) again, so the weighted wz weighs drive k's velocity by
w_k (-y_k/8, x_k/8): drive 0 by (1/4, -1/4), drive 2 by (-1/4, 1/4), drives 1 and 3 by nothing. Its
change from the plain fit, per drive: (1/8, -1/8), (-1/8, -1/8), (-1/8, 1/8), (1/8, 1/8)."""

import math
import re

import numpy as np
import pytest
from base_test_helpers import EXAMPLE_ROBOTS, four_ws, robot_config
from calibration_test_helpers import MIXED, synthetic_drive

from thorvald_base.calibration import DriveRecording, GnssTruth, PoseTruth
from thorvald_base.calibration.calibration_file import changes_yaml, parse_calibration_values, read_calibration
from thorvald_base.calibration.heading import HALF_BLOCK, MOTIONS, WINDOW, describe, heading_fit
from thorvald_base.calibration.odometry_error import imu_bias
from thorvald_base.errors import CalibrationError, KinematicsError
from thorvald_base.kinematics import DriveState, OdometryCorrection
from thorvald_base.kinematics.calculator import MAX_WEIGHTED_GAIN, weighted_gain_ratio, weighted_yaw_gains
from thorvald_base.lockstep import calibration_said
from thorvald_base.plugins import load_calculator
from thorvald_base.verification import commanded_path, plan_named
from thorvald_model import load_robot_config
from thorvald_model.errors import ConfigError

PAIR = (2.0, 0.0, 2.0, 0.0)  # the diagonal pair: drives 0 and 2
PAIR_GAINS = ((0.125, -0.125), (-0.125, -0.125), (-0.125, 0.125), (0.125, 0.125))


@pytest.fixture(scope="module")
def square():
    return four_ws(x=1.0, y=1.0)


@pytest.mark.parametrize("path", EXAMPLE_ROBOTS, ids=lambda p: p.split("/")[-1][:-5])
def test_weights_alike_change_nothing(path):
    calc = load_calculator(load_robot_config(path))
    n = len(calc.layout.drives)
    gains = weighted_yaw_gains(calc.layout, [1.0] * n)
    assert max(abs(g) for pair in gains for g in pair) < 1e-12
    assert weighted_gain_ratio(calc.layout, [1.0] * n) == pytest.approx(1.0)


def test_the_weighted_yaw_rate_of_the_diagonal_pair(square):
    layout = load_calculator(square).layout
    gains = weighted_yaw_gains(layout, PAIR)
    for got, expected in zip(gains, PAIR_GAINS):
        assert got == pytest.approx(expected, abs=1e-12)
    # a rigid motion moves no weighted fit: a turn about base_link gives wheel k (-y_k, x_k)
    turn = sum(gx * -y + gy * x for (gx, gy), x, y in zip(gains, layout.x, layout.y))
    assert turn == pytest.approx(0.0, abs=1e-12)
    # weights only matter relative to each other
    assert np.allclose(weighted_yaw_gains(layout, [w * 7.0 for w in PAIR]), gains, atol=1e-12)
    # the largest wheel gain: the pair's (1/4)*sqrt(2) against the plain fit's (1/8)*sqrt(2)
    assert weighted_gain_ratio(layout, PAIR) == pytest.approx(2.0)
    # one wheel alone cannot tell a turn
    assert weighted_yaw_gains(layout, (4.0, 0.0, 0.0, 0.0)) is None
    assert weighted_gain_ratio(layout, (4.0, 0.0, 0.0, 0.0)) == math.inf


def test_the_calculator_turns_as_the_weighted_wheels_say_where_they_disagree(square):
    calc = load_calculator(square)
    # drive 1 rolls along x at 1 m/s, the others stand: the plain fit reads vx 1/4, wz -y1/8 = 1/8
    states = [DriveState(0.0, 0.0), DriveState(0.0, 1.0), DriveState(0.0, 0.0), DriveState(0.0, 0.0)]
    plain = calc.body_twist([s.steering for s in states], [s.speed for s in states])
    assert (plain.vx, plain.vy, plain.wz) == pytest.approx((0.25, 0.0, 0.125))
    calc.odometry_correction = OdometryCorrection(1.0, 0.0, 0.0, PAIR)
    # the pair carries the frame and stands: no turn (1/8 - 1/8), the translation kept
    weighted = calc.body_twist([s.steering for s in states], [s.speed for s in states])
    assert (weighted.vx, weighted.vy, weighted.wz) == pytest.approx((0.25, 0.0, 0.0), abs=1e-12)
    # wz' = m (wz + weighted) + b vx + c vy = 1.01 * 0 + 0.002 * 0.25 + 0.003 * 0
    calc.odometry_correction = OdometryCorrection(1.01, 0.002, 0.003, PAIR)
    assert calc.body_twist([0.0] * 4, [0.0, 1.0, 0.0, 0.0]).wz == pytest.approx(0.0005)
    # crabbing at 1 m/s along y: c vy
    assert calc.body_twist([math.pi / 2] * 4, [1.0] * 4).wz == pytest.approx(0.003)
    # integrated by calculate_odometry alike: 0.1 s at wz' 0.0005
    calc.calculate_odometry(states, 10.0)
    result = calc.calculate_odometry(states, 10.1)
    assert result.twist.wz == pytest.approx(0.0005) and result.pose.yaw == pytest.approx(0.00005)
    # a drive unheard: the heard drives' fit as it is (the weights are every wheel's). Drives 1 to 3 at
    # (1, -1), (1, 1), (-1, 1): sum J^T J = [[3, 0, -1], [0, 3, 1], [-1, 1, 6]], sum J^T v = (1, 0, 1), so
    # vx = 5/12, vy = -1/12, wz = 1/4, and wz' = 1.01 / 4 + 0.002 * 5/12 - 0.003 / 12
    unheard = [DriveState(0.0, 0.0, heard=False), *states[1:]]
    assert calc.calculate_odometry(unheard, 10.2).twist.wz == pytest.approx(1.01 / 4 + 0.002 * 5 / 12 - 0.003 / 12)


@pytest.mark.parametrize(
    "bad, said",
    [
        (OdometryCorrection(1.0, 0.0, 0.01), r"yaw_per_metre_sideways must be within \+-0\.005 rad/m, not 0\.01"),
        (OdometryCorrection(1.0, 0.0, 0.0, (1.0, -1.0, 2.0, 2.0)), "wheel_weights must each be a number >= 0"),
        (OdometryCorrection(1.0, 0.0, 0.0, (1.0, 1.0, 1.0, 2.0)), "wheel_weights must have the mean 1, not 1.25"),
        (OdometryCorrection(1.0, 0.0, 0.0, (1.0, 1.0)), r"one weight per drive \(4\), not 2"),
        (OdometryCorrection(1.0, 0.0, 0.0, (4.0, 0.0, 0.0, 0.0)), "do not determine the robot's motion"),
    ],
)
def test_the_calculator_refuses_a_correction_beyond_a_calibration(square, bad, said):
    calc = load_calculator(square)
    good = OdometryCorrection(1.0, 0.0, 0.0, PAIR)
    calc.odometry_correction = good
    with pytest.raises(KinematicsError, match=said):
        calc.odometry_correction = bad
    assert calc.odometry_correction == good  # the previous one stays


def test_weights_that_read_the_wheels_disagreement_too_strongly_are_refused():
    # four drives at (+-1, +-0.25): the plain fit's largest wheel gain on wz is |(-y, x)| / sum r^2 =
    # 1.0308 / 4.25 = 0.24254 per m/s. The front pair alone (weights 2, 2 at x = 1): sum w J^T J =
    # [[4, 0, 0], [0, 4, 4], [0, 4, 4.25]], whose inverse's wz row is (0, -4, 4), so each wheel's gain is
    # w (-y * 4, -4 + x * 4) = (-8 y, 0): 2 per m/s, a turn read from the pair's vx over their 0.5 m,
    # 2 / 0.24254 = 8.246 times as strongly
    config = four_ws(x=1.0, y=0.25)
    front = (0.0, 2.0, 2.0, 0.0)
    assert weighted_gain_ratio(load_calculator(config).layout, front) == pytest.approx(2 / (1.0625**0.5 / 4.25))
    assert weighted_gain_ratio(load_calculator(config).layout, front) > MAX_WEIGHTED_GAIN
    calc = load_calculator(config)
    with pytest.raises(KinematicsError, match=r"read it 8\.2 times as strongly .* lean on too few wheels"):
        calc.odometry_correction = OdometryCorrection(1.0, 0.0, 0.0, front)


def test_the_calibration_file_holds_the_heading_model_and_scales_the_weights(tmp_path, square):
    path = tmp_path / "calibration.yaml"
    correction = OdometryCorrection(1.002, -0.0004, 0.0012, PAIR)
    path.write_text(changes_yaml([(1, "r_wheel", 0.201)], "a header", odometry=correction))
    text = path.read_text()
    assert "  yaw_per_metre_sideways: 0.0012\n" in text
    assert "  wheel_weights:\n    drive0: 2.0\n    drive1: 0.0\n    drive2: 2.0\n    drive3: 0.0\n" in text
    values = read_calibration(str(path), square)
    assert values.odometry == correction and values.changes == ((1, "r_wheel", 0.201),)
    # base_driver's log line says all of it
    assert calibration_said(values) == (
        "drive1 r_wheel 0.201, odometry yaw_rate_multiplier 1.002, odometry yaw_per_metre -0.0004, "
        "odometry yaw_per_metre_sideways 0.0012, odometry wheel_weights 2 0 2 0"
    )
    # loads in newtons do: relative, scaled to the mean 1
    loads = parse_calibration_values(
        {"odometry": {"wheel_weights": {"drive0": 600, "drive1": 0, "drive2": 600, "drive3": 0}}}, square
    )
    assert loads.odometry == OdometryCorrection(1.0, 0.0, 0.0, PAIR)
    # a file without the new keys reads as before
    old = parse_calibration_values({"odometry": {"yaw_rate_multiplier": 1.003}}, square)
    assert old.odometry == OdometryCorrection(1.003) and old.wheel_weights is None


@pytest.mark.parametrize(
    "weights, path, rule",
    [
        ([1, 1], "odometry.wheel_weights", "must be a mapping of every drive of the robot"),
        ({"drive0": 1, "drive1": 1, "drive2": 1}, "odometry.wheel_weights.drive3", "is missing: weigh every drive"),
        ({"drive0": 1, "drive1": 1, "drive2": 1, "drive3": 1, "drive9": 1}, "odometry.wheel_weights.drive9",
         "is not a drive of the robot"),
        ({"drive0": -1, "drive1": 1, "drive2": 1, "drive3": 1}, "odometry.wheel_weights.drive0",
         "must be a number >= 0"),
        ({"drive0": "x", "drive1": 1, "drive2": 1, "drive3": 1}, "odometry.wheel_weights.drive0",
         "must be a number >= 0"),
        ({"drive0": 0, "drive1": 0, "drive2": 0, "drive3": 0}, "odometry.wheel_weights", "must not all be 0"),
        ({"drive0": 1, "drive1": 0, "drive2": 0, "drive3": 0}, "odometry.wheel_weights",
         "do not determine the robot's motion"),
    ],
)  # fmt: skip
def test_bad_weights_name_the_file_the_key_the_value_and_the_rule(tmp_path, square, weights, path, rule):
    import yaml  # noqa: PLC0415

    file = tmp_path / "calibration.yaml"
    file.write_text(yaml.safe_dump({"odometry": {"wheel_weights": weights, "yaw_per_metre_sideways": 0.1}}))
    with pytest.raises(ConfigError) as e:
        read_calibration(str(file), square)
    text = str(e.value)
    assert str(file) in text and path in text and rule in text
    assert "odometry.yaw_per_metre_sideways" in text and "must be within +-0.005 rad/m" in text  # every problem


def test_the_heading_manoeuvre_drives_the_calibration_the_straight_legs_and_the_turns_in_turn():
    config = robot_config("thorvald_ii_6wd6ws_asym.yaml")
    description, plan = plan_named("heading", config, side=4.0)
    parts = [plan_named(name, config, side=4.0)[1] for name in ("calibration", "straight", "turns")]
    assert plan == parts[0] + parts[1] + parts[2]
    assert description.startswith("heading: every motion the robot makes") and "8 headland U turns" in description
    end, _ = commanded_path(plan)  # the turns end a row ahead of the start; the rest comes back to it
    assert math.hypot(end.x - 4.0, end.y) < 1e-6


RATE = 50.0


def drawn_drive(config, seconds=120.0, seed=1, disagree=0.3):
    """Drive states of a robot whose wheels follow smoothly varying body twists (vx, vy, wz drawn as sums
    of slow sines, forwards and crabbing and turning both ways) and, on drives 1 and 3, a disagreement of
    up to ``disagree`` m/s along x (what re-steering wheels give): (recording, plain twists, wheel
    velocities)."""
    rng = np.random.default_rng(seed)
    t = 50.0 + np.arange(int(seconds * RATE)) / RATE

    def slow(scale):
        return scale * sum(np.sin(2 * np.pi * f * t + rng.uniform(0, 2 * np.pi)) for f in rng.uniform(0.02, 0.2, 3)) / 3

    vx, vy, wz = slow(1.0), slow(0.6), slow(0.8)
    calc = load_calculator(config)
    xs, ys = np.asarray(calc.layout.x), np.asarray(calc.layout.y)
    wx = vx[:, None] - wz[:, None] * ys
    wy = vy[:, None] + wz[:, None] * xs
    wx[:, 1] += slow(disagree)
    wx[:, 3] -= slow(disagree)
    steering, speed = np.arctan2(wy, wx), np.hypot(wx, wy)
    return DriveRecording(t, steering, speed), calc


def truth_of(recording, calc, model, *, bias=0.0, noise=0.0, seed=2):
    """Ground truth whose yaw rate is the model's (an OdometryCorrection), held over the interval before each
    sample as base_driver integrates; the translation odometry's (the model corrects the yaw alone)."""
    calc.odometry_correction = model
    rates = np.array([calc.body_twist(a, s).wz for a, s in zip(recording.steering, recording.speed)])
    dt = np.diff(recording.t, prepend=recording.t[0])
    yaw = 0.3 + np.cumsum(rates * dt)
    zero = np.zeros_like(yaw)
    pose = PoseTruth(recording.t, zero, zero, yaw, zero, zero, rates)
    rng = np.random.default_rng(seed)
    t_imu = np.arange(recording.t[0], recording.t[-1], 0.01)
    imu = np.interp(t_imu, recording.t, yaw) - bias + rng.normal(0.0, noise, len(t_imu))
    gnss = GnssTruth(recording.t[::5], zero[::5], zero[::5], t_imu, imu)
    return pose, gnss


@pytest.mark.slow  # a fit over two minutes of samples
def test_the_fit_recovers_the_multiplier_the_yaw_per_metre_both_ways_and_the_weights(square):
    recording, calc = drawn_drive(square)
    pose, _ = truth_of(recording, calc, OdometryCorrection(1.006, -0.0008, 0.0015, PAIR))
    fit = heading_fit(square, [(recording, pose)])
    c = fit.correction
    # the weights' prior (all alike) holds the two that weigh nothing at about 0.005 instead of 0, which
    # leaves a trace in the rest: m, b and c to 3e-5 of their values' scale
    assert c.yaw_rate_multiplier == pytest.approx(1.006, abs=1e-4)
    assert c.yaw_per_metre == pytest.approx(-0.0008, abs=5e-5)
    assert c.yaw_per_metre_sideways == pytest.approx(0.0015, abs=5e-5)
    assert c.wheel_weights == pytest.approx(PAIR, abs=0.05) and max(c.wheel_weights[1::2]) < 0.01
    assert fit.excited == (True, True, True) and fit.weights_told
    assert fit.rms_after < 0.01 * fit.rms_before
    assert fit.windows == pytest.approx(120.0 / WINDOW, abs=2)
    assert {m.motion for m in fit.motions} <= set(MOTIONS)
    assert sum(m.windows for m in fit.motions) == fit.windows


@pytest.mark.slow  # a fit over two minutes of samples
def test_the_straight_legs_yaw_per_metre_can_be_kept(square):
    recording, calc = drawn_drive(square)
    pose, _ = truth_of(recording, calc, OdometryCorrection(1.006, -0.0008, 0.0015, PAIR))
    fit = heading_fit(square, [(recording, pose)], OdometryCorrection(1.0, -0.0007), keep_yaw_per_metre=True)
    assert fit.correction.yaw_per_metre == -0.0007 and fit.kept_yaw_per_metre and not fit.excited[1]
    assert fit.correction.yaw_rate_multiplier == pytest.approx(1.006, abs=2e-3)  # m, c and the weights take the rest


@pytest.mark.slow  # a fit over two minutes of samples
def test_the_imus_bias_does_not_matter_and_its_noise_averages_out(square):
    recording, calc = drawn_drive(square, seed=3)
    _, gnss = truth_of(recording, calc, OdometryCorrection(0.995, 0.0006, -0.001, PAIR), bias=1.5, noise=0.004)
    fit = heading_fit(square, [(recording, gnss)])
    c = fit.correction
    # 0.004 rad a sample (an IMU's orientation noise of 0.002 per quaternion component), 11 samples
    # averaged at each end of 240 windows: each within 3 of its stated uncertainties (0.0007 for m, about
    # 0.0006 and 0.0009 rad/m for b and c)
    for value, truth, sd in zip(
        (c.yaw_rate_multiplier, c.yaw_per_metre, c.yaw_per_metre_sideways), (0.995, 0.0006, -0.001), fit.sd
    ):
        assert abs(value - truth) < 3 * sd < 0.003
    assert max(c.wheel_weights[1::2]) < 0.05  # what the drive tells: drives 1 and 3 carry nothing


@pytest.mark.slow  # a fit over two minutes of samples
def test_what_the_drive_moves_less_than_two_standard_uncertainties_stays_as_in_effect(square):
    # the IMU's noise five times as large as above: m, b and c move by less than twice their uncertainties
    # (0.0033, 0.0027 and 0.0044) from the values in effect, and stay there; the weights, which the
    # windows where the wheels disagree tell, are fitted
    recording, calc = drawn_drive(square, seed=3)
    _, gnss = truth_of(recording, calc, OdometryCorrection(0.995, 0.0006, -0.001, PAIR), bias=1.5, noise=0.02)
    in_effect = OdometryCorrection(1.0, 0.0, 0.0)
    fit = heading_fit(square, [(recording, gnss)], in_effect)
    c = fit.correction
    assert fit.undetermined == (True, True, True) and fit.excited == (False, False, False)
    assert (c.yaw_rate_multiplier, c.yaw_per_metre, c.yaw_per_metre_sideways) == (1.0, 0.0, 0.0)
    assert fit.weights_told and max(c.wheel_weights[1::2]) < 0.05
    assert all(0.002 < sd < 0.006 for sd in fit.sd)
    text = "\n".join(describe(fit))
    assert "  c (yaw per metre along y)    +0.000000 rad/m (not determined: within 2 of its ± 0.0044" in text


@pytest.mark.slow  # a fit over a minute of samples
def test_wheels_that_never_disagree_keep_their_weights_and_a_robot_that_never_crabs_its_sideways_term():
    config = robot_config("thorvald_ii_2wd_diff.yaml")
    calc = load_calculator(config)
    t = 50.0 + np.arange(int(60 * RATE)) / RATE
    vx, wz = 0.8 + 0.2 * np.sin(0.3 * t), 0.5 * np.sin(0.1 * t)
    speed = np.stack([vx - wz * y for y in calc.layout.y], axis=1)
    recording = DriveRecording(t, np.zeros_like(speed), speed)
    pose, _ = truth_of(recording, calc, OdometryCorrection(1.004, 0.001))
    fit = heading_fit(config, [(recording, pose)], OdometryCorrection(1.0, 0.0, 0.002))
    c = fit.correction
    assert c.yaw_rate_multiplier == pytest.approx(1.004, abs=1e-6) and c.yaw_per_metre == pytest.approx(0.001)
    assert not fit.excited[2] and c.yaw_per_metre_sideways == 0.002  # kept as in effect
    assert not fit.weights_told and c.wheel_weights == ()


@pytest.mark.slow  # a fit over two minutes of samples
def test_weights_that_fit_each_window_but_leave_more_heading_in_all_are_refused(square):
    """The wheels' weights act where the wheels disagree; they are used only where they leave less heading
    error in all over those windows, not only a better fit of each (heading.py's docstring). Drives 1 and 3
    toe by 0.03 m/s and a 0.1 m/s swing along x (a 12 s period) on twists of whole periods over the drive's
    120 s (so vx, vy and wz each sum to about 0 and m, b and c cannot take up a steady turn), and ground
    truth turns by the diagonal pair's weighted change less its mean: each window's shape is the weights',
    the steady part the opposite of theirs. Fitting the weights to the swing takes most of each window's
    squared error off, and adds their steady part to the sum over the disagreeing windows."""
    calc = load_calculator(square)
    t = 50.0 + np.arange(int(120 * RATE)) / RATE
    s = t - t[0]
    vx, vy, wz = 0.8 * np.sin(2 * np.pi * s / 20), 0.5 * np.sin(2 * np.pi * s / 30), 0.6 * np.sin(2 * np.pi * s / 15)
    xs, ys = np.asarray(calc.layout.x), np.asarray(calc.layout.y)
    wx, wy = vx[:, None] - wz[:, None] * ys, vy[:, None] + wz[:, None] * xs
    toe = 0.03 + 0.1 * np.sin(2 * np.pi * s / 12)
    wx[:, 1] += toe
    wx[:, 3] -= toe
    recording = DriveRecording(t, np.arctan2(wy, wx), np.hypot(wx, wy))

    def rates(model):
        calc.odometry_correction = model
        return np.array([calc.body_twist(a, v).wz for a, v in zip(recording.steering, recording.speed)])

    plain = rates(OdometryCorrection())
    change = rates(OdometryCorrection(1.0, 0.0, 0.0, PAIR)) - plain
    # the pair's change: drive 1's toe by -1/8 and drive 3's by -1/8 (PAIR_GAINS), a mean of -0.0075 rad/s
    assert np.mean(change) == pytest.approx(-0.0075, abs=1e-6)
    rate = plain + change - np.mean(change)
    yaw = np.cumsum(rate * np.diff(t, prepend=t[0]))
    zero = np.zeros_like(yaw)
    fit = heading_fit(square, [(recording, PoseTruth(t, zero, zero, yaw, zero, zero, rate))])
    assert not fit.weights_told and fit.correction.wheel_weights == ()
    said = fit.weights_said
    assert said.startswith("refused: they fit each window where the wheels disagree better, but leave more heading")
    free, kept = (float(v) for v in re.findall(r"([0-9.]+) against ([0-9.]+) degrees without them", said)[0])
    assert free > kept
    assert fit.correction.yaw_rate_multiplier == pytest.approx(1.0, abs=0.005)  # nothing else to take up


@pytest.mark.slow  # three fits over two minutes of samples
def test_weights_the_drive_does_not_tell_twice_are_refused(square):
    """The weights are used only where each half of the drive (its windows in alternate blocks of 10 s)
    tells weights that leave less heading where the wheels disagree on the other half. A frame that stands
    on the diagonal pair in the even blocks and on all four wheels alike in the odd ones: the whole drive
    tells weights, but those of the odd half are none, and the even half's leave more heading on the odd
    half's re-steering windows than weights alike; a frame on the pair throughout is told twice."""
    recording, calc = drawn_drive(square, seed=1, disagree=0.05)
    odd = np.floor((recording.t - recording.t[0]) / HALF_BLOCK).astype(int) % 2 == 1

    def truth(weights_odd):
        rates = {}
        for name, weights in (("even", PAIR), ("odd", weights_odd)):
            calc.odometry_correction = OdometryCorrection(1.0, 0.0, 0.0, weights)
            rates[name] = np.array([calc.body_twist(a, v).wz for a, v in zip(recording.steering, recording.speed)])
        rate = np.where(odd, rates["odd"], rates["even"])
        yaw = np.cumsum(rate * np.diff(recording.t, prepend=recording.t[0]))
        zero = np.zeros_like(yaw)
        return PoseTruth(recording.t, zero, zero, yaw, zero, zero, rate)

    fit = heading_fit(square, [(recording, truth((1.0, 1.0, 1.0, 1.0)))])
    assert not fit.weights_told and fit.correction.wheel_weights == ()
    assert fit.weights_said.startswith("not told twice: fitted on half the drive (alternate 10 s), they leave more")
    fit = heading_fit(square, [(recording, truth(PAIR))])
    assert fit.weights_told and fit.correction.wheel_weights == pytest.approx(PAIR, abs=0.1)


def headland_drive(rocking: float):
    """A differential robot's rows at 1 m/s and U turns at 1.2 rad/s for 2.6 s, both ways, 23 of them in
    240 s; ground truth turns 2 % more than the wheels say, and its frame rocks by ``rocking`` rad at 0.83 Hz
    (what scatters a real robot's windows: the frame lagging and catching up): (config, recording, truth)."""
    config = robot_config("thorvald_ii_2wd_diff.yaml")
    calc = load_calculator(config)
    t = 50.0 + np.arange(int(240 * RATE)) / RATE
    wz = np.zeros_like(t)
    for k, start in enumerate(np.arange(55.0, 285.0, 10.0)):
        wz[(t >= start) & (t < start + 2.6)] = 1.2 * (-1) ** k
    speed = np.stack([1.0 - wz * y for y in calc.layout.y], axis=1)
    recording = DriveRecording(t, np.zeros_like(speed), speed)
    yaw = 0.3 + np.cumsum(1.02 * wz / RATE) + rocking * np.sin(2 * np.pi * 0.83 * t)
    zero = np.zeros_like(t)
    return config, recording, PoseTruth(t, zero, zero, yaw, zero, zero, zero)


@pytest.mark.slow  # two fits over four minutes of samples
def test_where_the_windows_scatter_the_multiplier_comes_from_whole_turns():
    # rocking by 0.06 rad: the 0.5 s windows leave m within two of their uncertainty of 1, the 23 U turns,
    # each read whole, tell it; rocking by 0.03 the windows tell it themselves
    config, recording, truth = headland_drive(0.06)
    fit = heading_fit(config, [(recording, truth)])
    m, sd = fit.correction.yaw_rate_multiplier, fit.sd[0]
    assert len(fit.turns) == 23 and fit.excited[0] and not fit.undetermined[0]
    assert abs(m - 1.02) < 2.5 * sd < 0.01
    assert "from 23 whole turns: the windows' scatter left it within 2 sd" in "\n".join(describe(fit))
    config, recording, truth = headland_drive(0.03)
    fit = heading_fit(config, [(recording, truth)])
    assert fit.turns == () and fit.excited[0] and abs(fit.correction.yaw_rate_multiplier - 1.02) < 2.5 * fit.sd[0]


@pytest.mark.slow  # a fit over a minute of samples
def test_a_fit_beyond_a_calibration_or_a_drive_too_short_is_refused(square):
    recording, calc = drawn_drive(square, seconds=60.0, disagree=0.0)
    pose, _ = truth_of(recording, calc, OdometryCorrection())
    turning = PoseTruth(pose.t, pose.x, pose.y, 1.2 * pose.yaw, pose.vx, pose.vy, pose.wz)  # 20 % more
    with pytest.raises(CalibrationError, match=r"more than a calibration explains \(yaw_rate_multiplier must be in"):
        heading_fit(square, [(recording, turning)])
    short = DriveRecording(recording.t[:400], recording.steering[:400], recording.speed[:400])
    with pytest.raises(CalibrationError, match="at least 20 are needed: drive the heading manoeuvre"):
        heading_fit(square, [(short, pose)])


@pytest.mark.slow  # a replay of a whole synthetic drive
def test_the_imus_bias_against_east_from_the_fixes_and_odometrys_translation():
    # an IMU reading 0.7 rad less than the heading (a hector GNSS puts the simulator's x north: 90 degrees)
    config = four_ws()
    radii, offsets = [d.r_wheel for d in config.drives], [d.steering_offset for d in config.drives]
    drive = synthetic_drive(config, MIXED, radii, offsets, heading_bias=0.7)
    assert imu_bias(config, drive.recording, drive.gnss_truth) == pytest.approx(0.7, abs=1e-6)
