"""The energy model (thorvald_design.energy) against closed forms: a motor holding a torque, turning
unloaded, motoring and generating with and without regeneration; the battery's current for a power
through its internal resistance; batteries in parallel; a run's energy, charge, state of charge and
range. Pure: numpy only."""

import math

import numpy as np
import pytest

from thorvald_design.energy import Battery, Motor, battery_current, energy_use, motor_power, parallel, trapezoid

KT, R, I0, G, ETA = 0.1, 0.2, 0.5, 30.0, 0.9
MOTOR = Motor(torque_constant=KT, resistance=R, no_load_current=I0, gear_ratio=G, gear_efficiency=ETA)
V, RI, CAP = 48.0, 0.05, 100.0
BATTERY = Battery(capacity_ah=CAP, voltage=V, internal_resistance=RI)


# --- motor -------------------------------------------------------------------------------------


@pytest.mark.parametrize("regenerative", [False, True])
def test_holding_a_torque_at_standstill_costs_the_copper_loss(regenerative):
    power, current = motor_power(MOTOR, 20.0, 0.0, regenerative)
    i = 20.0 / (G * ETA * KT)
    assert current == pytest.approx(i)
    assert power == pytest.approx(i * i * R)


@pytest.mark.parametrize("w", [5.0, -5.0])
def test_an_unloaded_motor_costs_its_friction_and_the_no_load_copper_loss(w):
    power, current = motor_power(MOTOR, 0.0, w, False)
    assert current == pytest.approx(math.copysign(I0, w))
    assert power == pytest.approx(KT * G * abs(w) * I0 + I0 * I0 * R)


def test_a_motoring_motor_draws_the_output_power_and_its_losses():
    tau, w = 10.0, 3.0
    i = tau / (G * ETA) / KT + I0
    power, current = motor_power(MOTOR, tau, w, False)
    assert current == pytest.approx(i)
    assert power == pytest.approx((KT * G * w + i * R) * i)
    assert power > tau * w  # the gear's, the friction's and the winding's losses on top


@pytest.mark.parametrize(("tau", "w"), [(-10.0, 3.0), (10.0, -3.0)])
def test_a_generating_motor_charges_only_with_regeneration(tau, w):
    # driven back: the gear passes on eta of the power, tau_m = tau eta / G
    i = tau * ETA / G / KT + math.copysign(I0, w)
    p = (KT * G * w + i * R) * i
    assert p < 0.0
    off, current_off = motor_power(MOTOR, tau, w, False)
    on, current_on = motor_power(MOTOR, tau, w, True)
    assert off == 0.0
    assert on == pytest.approx(p)
    assert current_off == current_on == pytest.approx(i)
    assert -on < -tau * w  # less comes back than the load put in


def test_motor_power_is_elementwise_over_arrays():
    tau = np.array([20.0, 0.0, 10.0, -10.0])
    w = np.array([0.0, 5.0, 3.0, 3.0])
    power, current = motor_power(MOTOR, tau, w, True)
    assert isinstance(power, np.ndarray) and power.shape == (4,)
    for k in range(4):
        p, i = motor_power(MOTOR, float(tau[k]), float(w[k]), True)
        assert (power[k], current[k]) == pytest.approx((p, i))
    power_off, _ = motor_power(MOTOR, tau, w, False)
    assert list(power_off == 0.0) == [False, False, False, True]


def test_motor_and_battery_refuse_impossible_constants():
    with pytest.raises(ValueError, match="gear_efficiency"):
        Motor(KT, R, I0, G, 1.2)
    with pytest.raises(ValueError, match="capacity_ah"):
        Battery(0.0, V, RI)


# --- battery -----------------------------------------------------------------------------------


@pytest.mark.parametrize("p", [1000.0, 5000.0, -800.0])
def test_battery_current_is_the_root_of_the_power_balance(p):
    i = battery_current(BATTERY, p)
    assert i == pytest.approx((V - math.sqrt(V * V - 4 * RI * p)) / (2 * RI))
    assert (V - RI * i) * i == pytest.approx(p)  # the terminals at V - R_i I deliver P
    assert math.copysign(1.0, i) == math.copysign(1.0, p)


def test_battery_current_without_internal_resistance_is_power_over_voltage():
    assert battery_current(Battery(CAP, V, 0.0), 1234.0) == pytest.approx(1234.0 / V)
    assert battery_current(Battery(CAP, V, 0.0), np.array([0.0, -96.0])) == pytest.approx([0.0, -2.0])


def test_battery_current_at_and_beyond_the_maximum_power():
    p_max = V * V / (4 * RI)  # 11520 W, at I = V / (2 R_i)
    assert battery_current(BATTERY, p_max) == pytest.approx(V / (2 * RI))
    with pytest.raises(ValueError, match="11520"):
        battery_current(BATTERY, [1000.0, p_max + 1.0])


def test_batteries_in_parallel():
    pack = parallel([BATTERY, BATTERY])
    assert pack.capacity_ah == pytest.approx(2 * CAP)
    assert pack.internal_resistance == pytest.approx(RI / 2)
    assert pack.voltage == pytest.approx(V)
    mixed = parallel([Battery(50.0, 50.0, 0.1), Battery(30.0, 46.0, 0.3)])
    # Thevenin: the voltage at which the two currents (V_k - V) / R_k cancel
    assert (50.0 - mixed.voltage) / 0.1 + (46.0 - mixed.voltage) / 0.3 == pytest.approx(0.0, abs=1e-9)
    assert mixed.internal_resistance == pytest.approx(0.1 * 0.3 / (0.1 + 0.3))
    assert mixed.capacity_ah == 80.0


# --- a run -------------------------------------------------------------------------------------


@pytest.mark.parametrize("start_soc", [1.0, 0.8])
def test_a_constant_power_for_an_hour(start_soc):
    t = np.linspace(0.0, 1800.0, 181)
    motors = {"drive0": np.full(t.size, 300.0), "drive1": np.full(t.size, 100.0)}
    report = energy_use(t, motors, 100.0, [BATTERY], distance_m=3000.0, area_ha=0.5, start_soc=start_soc)
    p, duration = 500.0, 1800.0
    i = (V - math.sqrt(V * V - 4 * RI * p)) / (2 * RI)
    ah = i * duration / 3600.0
    assert report.duration_s == duration
    assert report.energy_wh == pytest.approx(p * duration / 3600.0)
    assert dict(report.energy_by_motor_wh) == pytest.approx({"drive0": 150.0, "drive1": 50.0})
    assert report.hotel_wh == pytest.approx(50.0)
    assert report.mean_power_w == pytest.approx(p)
    assert report.wh_per_km == pytest.approx(250.0 / 3.0)
    assert report.wh_per_ha == pytest.approx(500.0)
    assert report.ah_used == pytest.approx(ah)
    assert report.peak_current_a == pytest.approx(i)
    assert report.rms_current_a == pytest.approx(i)
    assert report.peak_charge_current_a == 0.0
    assert report.end_soc == pytest.approx(start_soc - ah / CAP)
    assert report.range_km == pytest.approx(3.0 * start_soc * CAP / ah)


def test_two_batteries_in_parallel_double_the_range_and_halve_the_loss():
    t = np.array([0.0, 3600.0])
    one = energy_use(t, {"m": [2000.0, 2000.0]}, 0.0, [BATTERY], distance_m=5000.0)
    two = energy_use(t, {"m": [2000.0, 2000.0]}, 0.0, [BATTERY, BATTERY], distance_m=5000.0)
    i2 = (V - math.sqrt(V * V - 4 * (RI / 2) * 2000.0)) / (2 * (RI / 2))
    assert two.pack.capacity_ah == 2 * CAP
    assert two.ah_used == pytest.approx(i2) and two.ah_used < one.ah_used  # less lost inside
    assert two.range_km == pytest.approx(5.0 * 2 * CAP / i2)
    assert two.wh_per_ha is None


def test_a_ramp_of_power_and_regeneration():
    # P = 1 W/s * t - 300 W over 0..600 s: the trapezoid rule is exact for a line
    t = np.linspace(0.0, 600.0, 61)
    report = energy_use(t, {"m": t - 300.0}, 0.0, [Battery(CAP, V, 0.0)], distance_m=1000.0)
    assert report.energy_wh == pytest.approx(0.0, abs=1e-9)
    assert report.peak_current_a == pytest.approx(300.0 / V)
    assert report.peak_charge_current_a == pytest.approx(300.0 / V)
    # I = P / V: mean square of a line symmetric about 0 is (300 / V)^2 / 3
    assert report.rms_current_a == pytest.approx(300.0 / V / math.sqrt(3.0), rel=1e-3)
    assert report.range_km is None  # nothing used on balance


def test_a_run_beyond_the_pack_says_when():
    t = np.array([0.0, 1.0, 2.0])
    with pytest.raises(ValueError, match=r"t = 1\.000 s .*11520"):
        energy_use(t, {"m": [0.0, 12000.0, 0.0]}, 0.0, [BATTERY], distance_m=1.0)
    with pytest.raises(ValueError, match="3 times"):
        energy_use(t, {"m": [0.0, 1.0]}, 0.0, [BATTERY], distance_m=1.0)


def test_trapezoid():
    assert trapezoid([1.0, 3.0, 2.0], [0.0, 1.0, 3.0]) == pytest.approx(2.0 + 5.0)
