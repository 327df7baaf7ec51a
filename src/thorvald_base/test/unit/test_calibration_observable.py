"""thorvald_base.calibration.observable: which combinations of radii and steering offsets a drive
determines through the odometry, on synthetic drives with known as-built parameters
(calibration_test_helpers: the workspace's own kinematics make every reading).

The odometry is a rigid-body twist, three numbers a sample: a drive can only determine combinations
of the parameters that move those numbers. On four steered drives at the corners a straight line
moves vx by the common scale, vy by the common offset and wz by one mixture of the left-right radius
difference and the front-rear offset difference: three of eight. A drive that turns both ways,
crabs and spins adds three more; the two diagonal patterns (the front-left and rear-right radii
against the others, and so the offsets) would bend the frame and no rigid motion shows them: the
odometry never needs them, and the fit keeps them at the values in effect.
"""

import math

import numpy as np
import pytest
from base_test_helpers import diff, four_ws
from calibration_test_helpers import DIFF_DRIVE, MIXED, STRAIGHT, synthetic_drive

from thorvald_base.calibration import DriveRecording, as_read_with, odometry_error
from thorvald_base.calibration.observable import (
    DETERMINED,
    OFFSET_PRIOR,
    RADIUS_PRIOR,
    along_undetermined,
    observable_fit,
)
from thorvald_base.errors import CalibrationError
from thorvald_base.kinematics import Twist
from thorvald_model import with_drive_param

RADII = (0.2016, 0.1990, 0.2006, 0.1981)  # [m] true rolling radii (configured 0.2), the field's +-1 %
OFFSETS = (0.004, -0.006, 0.002, 0.007)  # [rad] true steering offsets (configured 0)


def vector(fit, weights):
    """A combination as a unit vector over fit.names, from {name: weight}."""
    v = np.array([weights.get(n, 0.0) for n in fit.names])
    return v / np.linalg.norm(v)


def in_priors(fit):
    """The fit's change from the values in effect in the model's own coordinates (each drive's
    m = k e^{i delta} = a + i b, against 1), in the priors' units."""
    out = []
    for name in fit.names:
        drive = name.split(".")[0]
        k = fit.value(f"{drive}.r_wheel") / fit.in_effect[fit.names.index(f"{drive}.r_wheel")]
        offset = f"{drive}.steering_offset"
        delta = fit.value(offset) - fit.in_effect[fit.names.index(offset)] if offset in fit.names else 0.0
        m = k * complex(math.cos(delta), math.sin(delta))
        out.append((m.real - 1.0) / RADIUS_PRIOR if name.endswith("r_wheel") else m.imag / OFFSET_PRIOR)
    return np.array(out)


def spans(fit, v, determined=True):
    """How much of v lies in the span of the (not) determined combinations (orthonormal already)."""
    basis = [np.array(c.vector) for c in fit.combinations if c.determined == determined]
    return float(np.linalg.norm(np.stack(basis) @ v)) if basis else 0.0


RADIUS = [f"drive{i}.r_wheel" for i in range(4)]
OFFSET = [f"drive{i}.steering_offset" for i in range(4)]
# four_ws: drive0 rear right, drive1 front right, drive2 front left, drive3 rear left
SCALE = dict.fromkeys(RADIUS, 1.0)
CRAB = dict.fromkeys(OFFSET, 1.0)
FRONT_REAR = {"drive1.r_wheel": 1.0, "drive2.r_wheel": 1.0, "drive0.r_wheel": -1.0, "drive3.r_wheel": -1.0}
DIAGONAL_RADII = {"drive0.r_wheel": 1.0, "drive2.r_wheel": 1.0, "drive1.r_wheel": -1.0, "drive3.r_wheel": -1.0}
DIAGONAL_OFFSETS = {n.replace("r_wheel", "steering_offset"): w for n, w in DIAGONAL_RADII.items()}


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
def test_a_straight_line_determines_the_common_scale_the_crab_and_one_mixture_of_the_rest():
    config = four_ws()
    drive = synthetic_drive(config, STRAIGHT, RADII, OFFSETS)
    fit = observable_fit(config, drive.recording, drive.pose_truth)
    assert len(fit.names) == 8 and len(fit.determined) == 3
    strongest = fit.combinations[0]
    assert strongest.determined and abs(vector(fit, SCALE) @ np.array(strongest.vector)) > 0.999
    assert spans(fit, vector(fit, CRAB)) > 0.999  # vy: ground truth's heading sees a crab
    # front against rear radii only scale vx alike: not determined, left where they were
    assert spans(fit, vector(fit, FRONT_REAR)) < 0.01
    for c in fit.combinations:  # the fit moved along the determined ones only
        if not c.determined:
            assert abs(np.array(c.vector) @ in_priors(fit)) < 1e-9
    for c in fit.combinations[3:]:
        assert c.strength < 1e-9 and c.sd == pytest.approx(1.0)


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
def test_a_drive_that_turns_crabs_and_spins_determines_all_but_the_frames_diagonals():
    config = four_ws()
    drive = synthetic_drive(config, MIXED, RADII, OFFSETS)
    fit = observable_fit(config, drive.recording, drive.pose_truth)
    assert len(fit.determined) == 6
    for diagonal in (DIAGONAL_RADII, DIAGONAL_OFFSETS):
        assert spans(fit, vector(fit, diagonal), determined=False) > 0.99
    for c in fit.combinations[6:]:  # kept at the values in effect, not left to drift
        assert not c.determined and abs(np.array(c.vector) @ in_priors(fit)) < 1e-9
    # what is determined is what the odometry needs: replayed, the calibrated drive is ground truth
    calibrated = config
    for index, key, value in fit.changes():
        calibrated = with_drive_param(calibrated, index, key, value)
    before = odometry_error(config, drive.recording, drive.pose_truth)
    after = odometry_error(calibrated, as_read_with(drive.recording, config, calibrated), drive.pose_truth)
    assert before.end_point_m > 0.1 and after.end_point_m < 1e-6
    # and the true values agree with the fit along every determined combination
    truth = np.array([(r / 0.2 - 1.0) / RADIUS_PRIOR for r in RADII] + [o / OFFSET_PRIOR for o in OFFSETS])
    order = [fit.names.index(n) for n in RADIUS + OFFSET]
    found = in_priors(fit)[order]
    for c in fit.determined:
        v = np.array(c.vector)[order]
        assert v @ found == pytest.approx(v @ truth, abs=0.02)  # first order in the priors' units


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
def test_a_differential_robot_has_no_offsets_and_a_straight_line_determines_both_radii():
    config = diff()
    drive = synthetic_drive(config, DIFF_DRIVE[:1], (0.202, 0.199), (0.0, 0.0))
    fit = observable_fit(config, drive.recording, drive.pose_truth)
    assert fit.names == ("drive0.r_wheel", "drive1.r_wheel")
    assert len(fit.determined) == 2  # the sum in vx, the difference in wz
    assert fit.value("drive0.r_wheel") == pytest.approx(0.202, rel=1e-6)
    assert fit.value("drive1.r_wheel") == pytest.approx(0.199, rel=1e-6)


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
def test_noise_leaves_a_stated_uncertainty_and_a_weak_combination_partly_at_its_prior():
    config = four_ws()
    noise = {"twist": 0.02, "speed": 0.005, "steering": 0.002}
    fits = [
        observable_fit(config, d.recording, d.pose_truth)
        for d in (synthetic_drive(config, MIXED, RADII, OFFSETS, noise=noise, seed=s) for s in range(8))
    ]
    for fit in fits:
        assert 0.005 < fit.sigma < 0.05  # the noise's, not the floor
        for c in fit.combinations:
            assert 0.0 < c.sd <= 1.0
            assert c.determined == (c.sd < DETERMINED)
        assert all(sd > 0.0 for sd in fit.sd)
    # the common scale is pinned far below its prior (1 %) by 1400 samples
    scale = [np.mean([f.value(n) for n in RADIUS]) for f in fits]
    assert np.std(scale) < 0.0005 and abs(np.mean(scale) - np.mean(RADII)) < 0.0005


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
def test_a_drive_that_never_moves_or_of_another_robot_is_refused():
    config = four_ws()
    still = synthetic_drive(config, ((5.0, Twist()),), RADII, OFFSETS)
    with pytest.raises(CalibrationError, match="no moving sample"):
        observable_fit(config, still.recording, still.pose_truth)
    drive = synthetic_drive(config, STRAIGHT, RADII, OFFSETS)
    other = DriveRecording(drive.recording.t, drive.recording.steering[:, :2], drive.recording.speed[:, :2])
    with pytest.raises(CalibrationError, match="2 drives, the robot 4"):
        observable_fit(config, other, drive.pose_truth)
    assert math.isfinite(observable_fit(config, drive.recording, drive.pose_truth).sigma)


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
def test_a_fit_that_moves_parameters_far_beyond_their_priors_says_so():
    config = four_ws()
    drive = synthetic_drive(config, MIXED, RADII, OFFSETS)
    assert observable_fit(config, drive.recording, drive.pose_truth).far() == []  # within the field's +-1 %
    # ground truth 20 % slower than the wheels turn (a robot slipping all the way): 20 priors of scale
    t = drive.pose_truth
    slipping = type(t)(t.t, t.x, t.y, t.yaw, 0.8 * t.vx, 0.8 * t.vy, t.wz)
    far = dict(observable_fit(config, drive.recording, slipping).far())
    assert set(RADIUS) <= set(far) and all(far[n] < -10 for n in RADIUS)


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
def test_the_balance_moves_the_fit_only_along_what_the_drive_did_not_determine():
    """along_undetermined: the fit moved towards the balance's radii and, after a toe search, its steering
    offsets, along the combinations the drive did not determine: every determined one keeps the fit's
    value; the frame's diagonals (which no rigid motion shows) take the balance's."""
    config = four_ws()
    drive = synthetic_drive(config, MIXED, RADII, OFFSETS)
    fit = observable_fit(config, drive.recording, drive.pose_truth)
    values = fit.values
    unit = np.array([RADIUS_PRIOR if n.endswith("r_wheel") else OFFSET_PRIOR for n in fit.names])

    def in_units(moved):
        return (
            np.array([math.log(m / v) if n.endswith("r_wheel") else m - v for n, m, v in zip(fit.names, moved, values)])
            / unit
        )

    radii = [0.2 * (1 + 0.004 * s) for s in (1, -1, 1, -1)]  # the diagonal pattern of the radii
    offsets = [math.radians(0.2) * s for s in (1, -1, 1, -1)]  # and of the offsets
    for toe in (None, offsets):
        moved = along_undetermined(fit, values, radii, toe)
        change = in_units(moved)
        for c in fit.determined:  # what ground truth saw stays as it saw it
            assert abs(np.array(c.vector) @ change) < 1e-9
        assert spans(fit, change, determined=False) == pytest.approx(np.linalg.norm(change), rel=1e-9)
        assert np.linalg.norm(change) > 0.2  # the diagonals taken from the balance
    without, with_toe = (in_units(along_undetermined(fit, values, radii, toe)) for toe in (None, offsets))
    diagonal = vector(fit, DIAGONAL_OFFSETS)
    assert abs(diagonal @ with_toe) > abs(diagonal @ without) + 0.1  # the offsets' diagonal follows the toe search
    assert along_undetermined(fit, values, [values[fit.names.index(n)] for n in RADIUS]) == pytest.approx(values)
