"""The drives' one motor model (thorvald_model.motors): the winding current of an output torque when
motoring, braking and at standstill, its inverse, the power drawn, and the motors built from a drive's
keys. Pure."""

import math

import pytest
from hypothesis import given
from hypothesis import strategies as st

from thorvald_model import parse_robot_config
from thorvald_model.motors import (
    Motor,
    electrical_power,
    output_torque,
    propulsion_motor,
    steering_motor,
    winding_current,
)

KT, R, I0, G, ETA = 0.1, 0.2, 0.5, 30.0, 0.9
MOTOR = Motor(torque_constant=KT, resistance=R, no_load_current=I0, gear_ratio=G, gear_efficiency=ETA)


def test_motoring_the_motor_supplies_the_gears_loss_and_its_friction():
    # 12 N m at the output turning forward: tau_m = 12 / (30 x 0.9) = 0.444 N m, i = 4.444 + 0.5 A
    assert winding_current(MOTOR, 12.0, 3.0) == pytest.approx(12.0 / (G * ETA) / KT + I0)
    # backwards, the same: torque and turning have one sign
    assert winding_current(MOTOR, -12.0, -3.0) == pytest.approx(-(12.0 / (G * ETA) / KT + I0))


def test_braking_the_gear_passes_on_eta_and_the_friction_helps():
    # the load drives the output back (tau w < 0): tau_m = tau eta / G = -0.36 N m, i = -3.6 + 0.5 A
    assert winding_current(MOTOR, -12.0, 3.0) == pytest.approx(-12.0 * ETA / G / KT + I0)
    assert winding_current(MOTOR, 12.0, -3.0) == pytest.approx(12.0 * ETA / G / KT - I0)


def test_at_standstill_a_held_torque_counts_as_motoring_and_no_friction_current_flows():
    assert winding_current(MOTOR, 12.0, 0.0) == pytest.approx(12.0 / (G * ETA) / KT)
    assert winding_current(MOTOR, -12.0, 0.0) == pytest.approx(-12.0 / (G * ETA) / KT)
    assert winding_current(MOTOR, 0.0, 0.0) == 0.0
    assert output_torque(MOTOR, 4.0, 0.0) == pytest.approx(4.0 * KT * G * ETA)


def test_an_unloaded_turning_motor_draws_its_no_load_current():
    assert winding_current(MOTOR, 0.0, 5.0) == I0
    assert winding_current(MOTOR, 0.0, -5.0) == -I0
    assert output_torque(MOTOR, I0, 5.0) == 0.0


def test_less_than_the_no_load_current_while_turning_is_braking():
    # 0.3 A along the turning covers only 0.2 A of the friction's 0.5 A: the load turns the output on
    tau = output_torque(MOTOR, 0.3, 5.0)
    assert tau == pytest.approx(-(I0 - 0.3) * KT * G / ETA)
    assert winding_current(MOTOR, tau, 5.0) == pytest.approx(0.3)


def test_the_power_drawn_is_the_shaft_power_and_the_copper_loss():
    i = 12.0 / (G * ETA) / KT
    assert electrical_power(MOTOR, 12.0, 0.0) == pytest.approx(i * i * R)  # holding: the copper loss alone
    assert electrical_power(MOTOR, 0.0, 5.0) == pytest.approx(KT * G * 5.0 * I0 + I0 * I0 * R)
    # driven back hard, it generates: the shaft's power returned exceeds the copper loss
    i = -12.0 * ETA / G / KT + I0
    power = electrical_power(MOTOR, -12.0, 3.0)
    assert power == pytest.approx((KT * G * 3.0 + i * R) * i) and power < 0.0


@given(
    tau=st.floats(-500.0, 500.0, allow_nan=False),
    w=st.one_of(st.just(0.0), st.floats(-50.0, 50.0, allow_nan=False)),
)
def test_output_torque_inverts_the_winding_current(tau, w):
    i = winding_current(MOTOR, tau, w)
    assert output_torque(MOTOR, i, w) == pytest.approx(tau, rel=1e-9, abs=1e-9)


@given(
    i=st.floats(-200.0, 200.0, allow_nan=False),
    w=st.one_of(st.just(0.0), st.floats(-50.0, 50.0, allow_nan=False)),
)
def test_every_current_has_the_torque_that_draws_it(i, w):
    assert winding_current(MOTOR, output_torque(MOTOR, i, w), w) == pytest.approx(i, rel=1e-9, abs=1e-9)


def test_the_motors_are_built_from_a_drives_keys():
    raw = {
        "base_calculator": "pltf_clc_std::PltfClcStd",
        "motor_drives": {
            "drive0": {"node": 1, "x": 0.5, "y": 0.3, "prp_motor_kt": 0.2, "str_gear_eff": 0.8, "str_gr_rt": 40.0},
            "drive1": {"node": 2, "x": -0.5, "y": 0.3},
        },
    }
    d0, d1 = parse_robot_config(raw, "test").drives
    assert propulsion_motor(d0) == Motor(0.2, 0.25, 0.6, 42.0, 0.9)
    assert steering_motor(d0) == Motor(0.14, 0.4, 0.4, 40.0, 0.8)
    # the defaults: a Thorvald module's (values.Drive)
    assert propulsion_motor(d1) == Motor(d1.prp_motor_kt, d1.prp_motor_r, d1.prp_motor_i0, d1.prp_gr_rt, 0.9)
    assert steering_motor(d1).gear_ratio == pytest.approx(42.8571429)


def test_impossible_constants_are_refused_by_name():
    with pytest.raises(ValueError, match=r"motor: gear_efficiency 1.2: must be in \(0, 1\]"):
        Motor(KT, R, I0, G, 1.2)
    with pytest.raises(ValueError, match="torque_constant"):
        Motor(math.nan, R, I0, G, ETA)
