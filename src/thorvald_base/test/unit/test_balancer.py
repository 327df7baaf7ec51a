"""The balancing drive's decisions (thorvald_base.calibration.balancer) on synthetic legs: a balance
that finds the radii where it can, and stops with the reason where the legs cannot support one, never
sending what the robot file's rules refuse nor moving a radius more than a step a leg."""

import math

import numpy as np
import pytest
import yaml
from base_test_helpers import EXAMPLE_ROBOTS, diff
from test_torque_balance import STIFFNESS, TRUTH, drive_leg

from thorvald_base.calibration.balancer import MAX_BALANCE, RADII, TOE, Balancer
from thorvald_base.calibration.toe_balance import toe_legs
from thorvald_base.calibration.torque_balance import MAX_STEP, Leg, relative_errors
from thorvald_base.errors import CalibrationError
from thorvald_base.verification import BALANCE_AGAIN, BALANCE_LEGS
from thorvald_model import ConfigError, load_robot_config, parse_robot_config, with_drive_param

ASYM = next(p for p in EXAMPLE_ROBOTS if p.endswith("thorvald_ii_6wd6ws_asym.yaml"))
SPEED = 0.2  # [m/s]


def kinds(config):
    """The balance manoeuvre's legs: the radii, the toe search's (steered robots), the radii again."""
    toe = toe_legs(config)
    return [RADII] * BALANCE_LEGS + ([TOE] * toe + [RADII] * BALANCE_AGAIN if toe else [])


def drive(balancer, truth=TRUTH, stiffness=STIFFNESS, noise=0.0):
    """Every leg of the drive, each with what the balancer set, its torques with noise [N m] rms; the
    radii of each leg, in order."""
    driven, rng = [], np.random.default_rng(5)
    for k in range(len(balancer.kinds)):
        driven.append(balancer.radii)
        speed = SPEED if k % 2 == 0 else -SPEED
        balancer.record(drive_leg(balancer.radii, speed, truth=truth, stiffness=stiffness, noise=noise, rng=rng))
        balancer.next()
    return driven


def assert_steps_bounded(driven):
    for a, b in zip(driven, driven[1:]):
        assert np.max(np.abs(np.log(np.asarray(b) / np.asarray(a)))) <= MAX_STEP + 1e-12


@pytest.mark.slow  # a fit or a replay of a whole synthetic drive
def test_a_balance_finds_each_tyres_radius_and_drives_only_bounded_steps():
    config = load_robot_config(ASYM)
    balancer = Balancer(config, kinds(config))
    driven = drive(balancer, noise=0.05)
    fit = balancer.result()
    assert balancer.stopped is None
    assert np.max(np.abs(relative_errors(fit.radii, TRUTH))) < 3e-4
    assert_steps_bounded(driven)
    assert balancer.legs[-1].fight < 0.05 * balancer.legs[0].fight


def test_wheels_whose_torque_does_not_follow_their_radius_stop_the_balance():
    """Rigid tyres: the frame stands on four wheels of six, the other two turn almost free (a stiffness a
    thousandth of the others'), and every torque reads 0.05 N m of noise (the simulator's legs: about
    that). The free wheels' radii are not told: the balance stops at the first fit, with the reason,
    and drives the rest with the radii and offsets it started with."""
    config = load_robot_config(ASYM)
    balancer = Balancer(config, kinds(config))
    free = tuple(c * (1e-3 if k in (0, 4) else 1.0) for k, c in enumerate(STIFFNESS))
    driven = drive(balancer, stiffness=free, noise=0.05)
    assert "do not tell every tyre's radius (drive0" in balancer.stopped and "drive4" in balancer.stopped
    assert_steps_bounded(driven[: balancer.kinds.index(TOE) + 1])
    assert driven[-1] == balancer.start_radii and balancer.offsets == balancer.start_offsets
    with pytest.raises(CalibrationError, match="the balance stopped: the motor currents do not tell"):
        balancer.result()


def test_a_balance_beyond_a_tyres_pressure_and_wear_stops():
    """A tyre 8 % smaller than the others (a flat one): no balance moves a radius that far."""
    config = diff()
    balancer = Balancer(config, [RADII] * BALANCE_LEGS)
    truth = (0.2 * 0.92, 0.2)
    drive(balancer, truth=truth, stiffness=(5000.0, 5000.0))
    with pytest.raises(CalibrationError, match=f"beyond \\+-{100 * MAX_BALANCE:g} % of the calibration's"):
        balancer.result()


def test_nothing_the_robot_files_rules_refuse_is_sent():
    """Two drives whose wheels just clear each other when they turn: a larger radius would make them
    touch, and the balance stops with the robot file's rule instead of sending it."""
    with open(ASYM, encoding="utf-8") as f:
        data = yaml.safe_load(f)
    d0, d1 = load_robot_config(ASYM).drives[:2]
    # drive1 moved along x towards drive0 to the smallest gap (to 2 mm) the rules take with these radii
    for gap in np.arange(0.40, 1.2, 0.002):
        data["motor_drives"]["drive1"].update(x=float(d0.x + math.copysign(gap, d1.x - d0.x)), y=d0.y)
        try:
            config = parse_robot_config(data, "tight")
            break
        except ConfigError:  # the rules refuse gaps this small
            continue
    balancer = Balancer(config, [RADII] * BALANCE_LEGS)
    # every tyre larger than configured, drive0 the most: the balance would grow its radius
    truth = tuple(r * (1.03 if k == 0 else 1.0) for k, r in enumerate(balancer.start_radii))
    driven = drive(balancer, truth=truth, stiffness=(5000.0,) * len(truth))
    if balancer.stopped is None:  # the step that would touch never came: the test's geometry is wrong
        pytest.fail(f"no refusal: {driven[-1]}")
    assert "the robot file's rules refuse what the balance would set" in balancer.stopped
    for radii in driven:  # everything driven is what the rules take
        for k, r in enumerate(radii):
            with_drive_param(config, k, "r_wheel", r)


def test_a_balance_that_does_not_reduce_the_fight_is_not_kept():
    """Torques that follow nothing the radii do (a constant pattern): the fit cannot make them fight less."""
    config = diff()
    balancer = Balancer(config, [RADII] * BALANCE_LEGS)
    for k in range(BALANCE_LEGS):
        speed = SPEED if k % 2 == 0 else -SPEED
        balancer.record(Leg(balancer.radii, speed, (2.0, -2.0)))
        balancer.next()
    with pytest.raises(CalibrationError, match="the balance stopped"):
        balancer.result()
