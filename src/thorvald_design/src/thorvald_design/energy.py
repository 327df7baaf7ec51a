"""The energy a battery-electric robot uses: DC motors behind gears, a battery with internal
resistance, and what a run costs per kilometre, per hectare, in charge and in range.

The chain from a wheel to the battery: the output (wheel) torque and speed the simulator records,
through the gear to the motor shaft, through the motor's constants to the winding current and the
electrical power, summed with the hotel load (computers, sensors), and drawn from the battery,
whose internal resistance makes the current for a power higher than power / voltage.

The motor, its winding current and its power are the drives' one model (:mod:`thorvald_model.motors`;
``Motor`` is re-exported here); this module applies it to arrays and adds the battery and the run.

Pure: stdlib and numpy only; no rospy, no pybullet, no messages. SI units throughout (energy also
in Wh and charge in Ah, as batteries are rated).
"""

import math
from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from thorvald_model.motors import Motor, electrical_power, winding_current

from .errors import EnergyError

ArrayLike = Union[float, Sequence[float], np.ndarray]
SECONDS_PER_HOUR = 3600.0
# a run that used less than this fraction of the capacity used nothing (rounding of regeneration that gives
# back what was drawn): no range, rather than a range of 1e19 km
NOTHING_USED = 1e-9


@dataclass(frozen=True)
class Battery:
    """A battery: capacity_ah [Ah], voltage [V] open circuit (nominal), internal_resistance [ohm]."""

    capacity_ah: float
    voltage: float
    internal_resistance: float

    def __post_init__(self):
        rules = (
            ("capacity_ah", self.capacity_ah > 0.0, "> 0"),
            ("voltage", self.voltage > 0.0, "> 0"),
            ("internal_resistance", self.internal_resistance >= 0.0, ">= 0"),
        )
        for name, ok, rule in rules:
            if not (ok and math.isfinite(getattr(self, name))):
                raise EnergyError(f"battery: {name} {getattr(self, name)!r}: must be {rule}")

    @property
    def max_power(self) -> float:
        """The most power [W] it can deliver to a load: V^2 / (4 R_i) (inf for R_i = 0); see battery_current."""
        r = self.internal_resistance
        return math.inf if r == 0.0 else self.voltage**2 / (4.0 * r)


# the shared scalar model elementwise over broadcast arrays (the motor passed whole, not as an array)
_WINDING_CURRENT = np.vectorize(winding_current, otypes=[float], excluded={0})
_ELECTRICAL_POWER = np.vectorize(electrical_power, otypes=[float], excluded={0})


def _out(a: np.ndarray) -> Union[float, np.ndarray]:
    """A 0-d array as a float, others as they are."""
    return float(a) if np.ndim(a) == 0 else a


def motor_power(
    motor: Motor, output_torque: ArrayLike, output_speed: ArrayLike, regenerative: bool
) -> Tuple[Union[float, np.ndarray], Union[float, np.ndarray]]:
    """(electrical power [W] drawn, winding current [A]) of a motor whose gear output turns at
    output_speed w [rad/s] under output_torque tau [N m]; numpy arrays broadcast, floats give floats.

    Both are the drives' one motor model's (:mod:`thorvald_model.motors`): the winding current
    i = tau_m / k_t + sign(w_m) i_0, with the gear's loss taken the way the power flows
    (:func:`~thorvald_model.motors.winding_current`), and the power P = v i = k_t w_m i + i^2 R, the
    mechanical power at the shaft plus the copper loss (:func:`~thorvald_model.motors.electrical_power`).
    So holding a torque at standstill costs i^2 R = (tau / (G eta k_t))^2 R, and an unloaded motor at
    speed w costs k_e G w i_0 + i_0^2 R.

    P < 0 is a motor generating (its mechanical power returned exceeds its copper loss). With
    regenerative False the controller dissipates that (a braking resistor) and the power drawn is 0;
    with regenerative True it is negative: it charges the battery. The current returned is always the
    winding current i (for the motor's and the controller's ratings), whichever way the power goes."""
    tau = np.asarray(output_torque, dtype=float)
    w = np.asarray(output_speed, dtype=float)
    current = _WINDING_CURRENT(motor, tau, w)
    power = _ELECTRICAL_POWER(motor, tau, w)
    if not regenerative:
        power = np.maximum(power, 0.0)
    return _out(power), _out(current)


def battery_current(battery: Battery, power_w: ArrayLike) -> Union[float, np.ndarray]:
    """The current [A] a battery delivers to a load of power_w [W] (negative: charging); arrays
    elementwise, a float for a float.

    The battery is an open-circuit voltage V behind an internal resistance R_i: its terminals stand
    at V - R_i I, so a load of power P takes P = (V - R_i I) I, i.e. R_i I^2 - V I + P = 0, whose
    root on the working branch (the one that goes to 0 with P) is
    I = (V - sqrt(V^2 - 4 R_i P)) / (2 R_i). Multiplied through by (V + sqrt(...)) it is
    I = 2 P / (V + sqrt(V^2 - 4 R_i P)), the form computed: free of the cancellation for small R_i P,
    and P / V at R_i = 0 exactly. The square root is real only for P <= V^2 / (4 R_i), the most the
    battery can deliver (at I = V / (2 R_i), half its voltage lost inside): a larger load cannot be
    supplied, EnergyError with the figures. For P < 0 the same formula gives the charging current
    I < 0 (the charger must push the terminals above V)."""
    p = np.asarray(power_w, dtype=float)
    v, r = battery.voltage, battery.internal_resistance
    too_much = p > battery.max_power
    if np.any(too_much):
        worst = float(np.max(p[too_much]))
        raise EnergyError(
            f"battery: a load of {worst:.1f} W is more than the battery can deliver: "
            f"V^2 / (4 R_i) = {v:.2f}^2 / (4 * {r:.4f}) = {battery.max_power:.1f} W"
        )
    current = 2.0 * p / (v + np.sqrt(np.maximum(v * v - 4.0 * r * p, 0.0)))
    return _out(current)


def parallel(batteries: Sequence[Battery]) -> Battery:
    """Batteries connected in parallel as one battery.

    Capacities add. Each is a source V_k behind R_k; in parallel they are (Thevenin) one source of
    V = sum(V_k / R_k) / sum(1 / R_k) behind R = 1 / sum(1 / R_k): n equal batteries give the same
    voltage and R_k / n. Batteries of R_k = 0 are ideal sources and set the voltage alone (all of them
    must have the same one) with R = 0."""
    batteries = list(batteries)
    if not batteries:
        raise EnergyError("parallel: no batteries")
    capacity = sum(b.capacity_ah for b in batteries)
    ideal = [b for b in batteries if b.internal_resistance == 0.0]
    if ideal:
        voltages = sorted({b.voltage for b in ideal})
        if len(voltages) > 1:
            raise EnergyError(f"parallel: ideal batteries (R_i = 0) of different voltages {voltages} V short-circuit")
        return Battery(capacity, voltages[0], 0.0)
    conductance = sum(1.0 / b.internal_resistance for b in batteries)
    voltage = sum(b.voltage / b.internal_resistance for b in batteries) / conductance
    return Battery(capacity, voltage, 1.0 / conductance)


def trapezoid(y: ArrayLike, t: ArrayLike) -> float:
    """The integral of samples y over times t by the trapezoid rule: sum of (y_i + y_i+1) / 2 (t_i+1 - t_i).
    (numpy's own is np.trapz before 2.0 and np.trapezoid from 2.0: neither is in both.)"""
    y = np.asarray(y, dtype=float)
    t = np.asarray(t, dtype=float)
    return float(np.sum((y[1:] + y[:-1]) * np.diff(t)) / 2.0)


@dataclass(frozen=True)
class EnergyReport:
    """What a run cost.

    duration_s [s]; energy_wh [Wh] delivered to the loads (motors and hotel load; what the battery
    loses inside itself is in the charge, not here); energy_by_motor_wh: (name, Wh) per motor, in the
    order given, and hotel_wh; mean_power_w [W]; wh_per_km, wh_per_ha (None without a distance or an
    area); ah_used [Ah] the charge drawn (integral of the battery current); peak_current_a [A] the
    largest current drawn, peak_charge_current_a [A] the largest charging current (0 without
    regeneration); rms_current_a [A] (what heats cables and cells); end_soc the state of charge left,
    start_soc - ah_used / capacity (below 0: the pack would have run flat); range_km [km] the distance
    the usable charge would cover at this rate (None when no charge was used); the pack as one
    battery."""

    duration_s: float
    energy_wh: float
    energy_by_motor_wh: Tuple[Tuple[str, float], ...]
    hotel_wh: float
    mean_power_w: float
    wh_per_km: Optional[float]
    wh_per_ha: Optional[float]
    ah_used: float
    peak_current_a: float
    peak_charge_current_a: float
    rms_current_a: float
    end_soc: float
    range_km: Optional[float]
    pack: Battery


def energy_use(
    t: ArrayLike,
    powers_by_motor: Dict[str, ArrayLike],
    hotel_load_w: ArrayLike,
    batteries: List[Battery],
    *,
    distance_m: float,
    area_ha: Optional[float] = None,
    start_soc: float = 1.0,
) -> EnergyReport:
    """The energy, charge and range of a run: times t [s] (at least 2, not decreasing), the electrical
    power [W] of each motor at those times (motor_power), the hotel load [W] (a constant or one per
    time), the batteries (in parallel: parallel()), the distance [m] driven and optionally the area
    [ha] worked, and the state of charge (0..1] at the start.

    - energy_wh = integral of P dt / 3600 (trapezoid rule over t), P = sum of the motors + hotel;
    - the battery current I(t) = battery_current(pack, P(t)) and ah_used = integral of I dt / 3600:
      charge, not energy, is what empties a battery, and it includes the internal loss;
    - rms_current_a = sqrt(integral of I^2 dt / duration);
    - end_soc = start_soc - ah_used / capacity;
    - range_km: the run drew ah_used for distance_m, so the usable charge start_soc * capacity lasts
      range = distance_m / 1000 * start_soc * capacity / ah_used (None when ah_used is at most
      NOTHING_USED * capacity: nothing was used, or regeneration gave back as much as was drawn)."""
    t = np.asarray(t, dtype=float).reshape(-1)
    if t.size < 2:
        raise EnergyError(f"energy_use: {t.size} times; integrating needs at least 2")
    if np.any(np.diff(t) < 0.0):
        raise EnergyError("energy_use: times must not decrease")
    duration = float(t[-1] - t[0])
    if duration <= 0.0:
        raise EnergyError("energy_use: the times span no time")
    if not 0.0 < start_soc <= 1.0:
        raise EnergyError(f"energy_use: start_soc {start_soc}: must be in (0, 1]")
    if distance_m < 0.0:
        raise EnergyError(f"energy_use: distance_m {distance_m}: must be >= 0")
    if area_ha is not None and area_ha <= 0.0:
        raise EnergyError(f"energy_use: area_ha {area_ha}: must be > 0 (or None)")
    pack = parallel(batteries)

    def series(name: str, values: ArrayLike) -> np.ndarray:
        a = np.asarray(values, dtype=float)
        try:
            return np.broadcast_to(a, t.shape)
        except ValueError:
            raise EnergyError(f"energy_use: {name} has {a.size} values for {t.size} times") from None

    motors = [(name, series(f"motor {name!r}", p)) for name, p in powers_by_motor.items()]
    hotel = series("hotel_load_w", hotel_load_w)
    total = hotel + sum((p for _, p in motors), np.zeros_like(t))
    too_much = total > pack.max_power
    if np.any(too_much):
        i = int(np.argmax(too_much))
        raise EnergyError(
            f"energy_use: at t = {t[i]:.3f} s the load is {total[i]:.1f} W, more than the pack can deliver "
            f"({pack.voltage:.2f} V, {pack.internal_resistance:.4f} ohm: at most {pack.max_power:.1f} W)"
        )
    current = np.asarray(battery_current(pack, total))
    energy_wh = trapezoid(total, t) / SECONDS_PER_HOUR
    ah_used = trapezoid(current, t) / SECONDS_PER_HOUR
    km = distance_m / 1000.0
    return EnergyReport(
        duration_s=duration,
        energy_wh=energy_wh,
        energy_by_motor_wh=tuple((name, trapezoid(p, t) / SECONDS_PER_HOUR) for name, p in motors),
        hotel_wh=trapezoid(hotel, t) / SECONDS_PER_HOUR,
        mean_power_w=energy_wh * SECONDS_PER_HOUR / duration,
        wh_per_km=energy_wh / km if km > 0.0 else None,
        wh_per_ha=energy_wh / area_ha if area_ha is not None else None,
        ah_used=ah_used,
        peak_current_a=max(float(np.max(current)), 0.0),
        peak_charge_current_a=max(-float(np.min(current)), 0.0),
        rms_current_a=math.sqrt(trapezoid(current * current, t) / duration),
        end_soc=start_soc - ah_used / pack.capacity_ah,
        range_km=km * start_soc * pack.capacity_ah / ah_used if ah_used > NOTHING_USED * pack.capacity_ah else None,
        pack=pack,
    )
