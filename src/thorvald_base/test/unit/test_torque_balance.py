"""The torque-balance term (thorvald_base.calibration.torque_balance) on synthetic legs: wheels of known
radii on a rigid frame, each pushing with its own slip stiffness, as the simulator's were measured."""

import math

import numpy as np
import pytest

from thorvald_base.calibration.torque_balance import (
    MAX_STEP,
    Leg,
    fit_balance,
    next_radii,
    relative_errors,
    stiffness_identified,
)
from thorvald_base.errors import CalibrationError

CONFIGURED = (0.2,) * 6
TRUTH = (0.1953, 0.1958, 0.1968, 0.1944, 0.1954, 0.1983)  # field:3's tyres [m]
STIFFNESS = (2600.0, 5200.0, 7000.0, 4300.0, 4500.0, 6900.0)  # [N m s/m] per wheel: they carry different loads


def drive_leg(radii, speed, *, truth=TRUTH, stiffness=STIFFNESS, noise=0.0, rng=None, resistance=0.0):
    """A straight leg on a rigid frame: the frame's common slip s is where the wheels' forces balance the
    resistance; each wheel's torque is its stiffness times its slip, times the speed (the simulator's
    friction grows with slip speed)."""
    c = np.asarray(stiffness)
    mismatch = np.log(np.asarray(truth) / np.asarray(radii))
    s = (np.sum(c * mismatch) - resistance / speed) / np.sum(c)
    torques = c * (mismatch - s) * speed
    if noise:
        torques = torques + rng.normal(0.0, noise, len(torques))
    return Leg(tuple(radii), speed, tuple(float(t) for t in torques))


def balance(truth=TRUTH, legs=6, speed=0.2, **kwargs):
    radii, done = CONFIGURED, []
    for i in range(legs):
        done.append(drive_leg(radii, speed if i % 2 == 0 else -speed, truth=truth, **kwargs))
        radii = next_radii(done)
    return done, radii


def test_one_leg_does_not_tell_the_stiffness():
    leg = drive_leg(CONFIGURED, 0.2)
    assert not stiffness_identified([leg])
    with pytest.raises(CalibrationError, match="same radii"):
        fit_balance([leg])
    # driving the same radii again both ways tells nothing more
    assert not stiffness_identified([leg, drive_leg(CONFIGURED, -0.2)])


def test_the_first_step_probes_along_the_fight():
    leg = drive_leg(CONFIGURED, 0.2)
    probe = np.log(np.asarray(next_radii([leg])) / np.asarray(CONFIGURED))
    internal = leg.internal
    # a pushing wheel (its tyre larger than base_driver thinks) gets a larger radius
    assert np.all(np.sign(probe[np.abs(internal) > 0.5]) == np.sign(internal[np.abs(internal) > 0.5]))
    assert float(np.sqrt(np.mean((probe - probe.mean()) ** 2))) == pytest.approx(0.004, rel=1e-6)


def test_balancing_recovers_each_tyres_radius_up_to_the_common_factor():
    before = relative_errors(CONFIGURED, TRUTH)
    assert np.max(np.abs(before)) > 0.01  # the configuration is 1 % off on one tyre
    legs, radii = balance()
    after = relative_errors(radii, TRUTH)
    assert np.max(np.abs(after)) < 1e-6
    assert legs[-1].fight < 1e-3 * legs[0].fight  # the wheels no longer fight
    # the common factor is left to ground truth: the geometric mean stays the configured one
    assert math.exp(np.mean(np.log(radii))) == pytest.approx(0.2, rel=1e-9)


def test_the_fit_of_every_leg_gives_the_radii_and_the_stiffnesses():
    legs, _ = balance(legs=4)
    fit = fit_balance(legs)
    assert fit.identified and fit.legs == 4
    assert np.max(np.abs(relative_errors(fit.radii, TRUTH))) < 2e-5  # alternating least squares: 0.002 %
    assert fit.stiffness == pytest.approx(np.mean(STIFFNESS), rel=1e-2)
    assert fit.residual < 0.01  # [N m]


def test_noisy_torques_give_radii_within_their_uncertainty():
    rng = np.random.default_rng(7)
    legs, _ = balance(legs=8, noise=0.2, rng=rng)  # 0.2 N m of noise on each leg's mean torque
    fit = fit_balance(legs)
    errors = relative_errors(fit.radii, TRUTH)
    sd = np.asarray(fit.sd) / np.asarray(fit.radii)
    assert np.max(np.abs(errors)) < 0.003  # the 0.3 %
    assert np.all(np.abs(errors) < 4.0 * sd + 1e-5)
    assert 0.05 < fit.residual < 0.5


def test_rolling_resistance_shared_by_stiffness_does_not_move_the_radii():
    _, radii = balance(resistance=3.0)  # [N m] the frame's resistance, shared as the wheels' grip
    assert np.max(np.abs(relative_errors(radii, TRUTH))) < 1e-6


def test_a_prior_stiffness_steps_at_once_and_no_step_is_too_large():
    leg = drive_leg(CONFIGURED, 0.2)
    radii = next_radii([leg], stiffness_prior=float(np.mean(STIFFNESS)))
    step = np.log(np.asarray(radii) / np.asarray(CONFIGURED))
    assert np.max(np.abs(step)) <= MAX_STEP + 1e-12
    assert np.max(np.abs(relative_errors(radii, TRUTH))) < np.max(np.abs(relative_errors(CONFIGURED, TRUTH)))


def test_torques_that_do_not_grow_with_slip_are_refused():
    legs, _ = balance(legs=3)
    flipped = [Leg(leg.radii, leg.speed, tuple(-t for t in leg.torques)) for leg in legs]
    with pytest.raises(CalibrationError, match="do not grow with their slip"):
        fit_balance(flipped)


def test_bad_legs_are_refused():
    with pytest.raises(CalibrationError, match="non-zero rim speed"):
        Leg(CONFIGURED, 0.0, (0.0,) * 6)
    with pytest.raises(CalibrationError, match="6 radii holds 5 torques"):
        Leg(CONFIGURED, 0.2, (0.0,) * 5)
    with pytest.raises(CalibrationError, match="no leg"):
        fit_balance([])
