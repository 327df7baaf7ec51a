"""A drive's motors: a DC motor behind a gear, and the winding current that carries an output torque.

One model for every part that turns a joint's torque into a motor current or a current back into a
torque: the simulator reports each drive's currents as its motor controllers would measure them
(thorvald_sim), base_driver's measured drives read the torque back from them (the motor controllers'
relative power), and the energy model (thorvald_design.energy) and the calibration add the power the
motors draw (:func:`electrical_power`).

The motors' constants are robot-file keys of each drive (``prp_motor_kt``, ``prp_motor_r``,
``prp_motor_i0``, ``prp_gr_rt``, ``prp_gear_eff`` and the ``str_`` ones, :class:`~thorvald_model.values.Drive`):
:func:`propulsion_motor` and :func:`steering_motor` build the motors from them.

Pure: stdlib only (scalars; thorvald_design.energy applies it elementwise to arrays). SI units.
"""

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class Motor:
    """One DC motor (a brushless one modelled as DC) with its gear.

    torque_constant k_t [N m/A], in SI equal to the back-EMF constant k_e [V s/rad]: the power
    conversion k_t i w = k_e w i balances only when they are the same number; resistance R [ohm] of
    the winding; no_load_current i_0 [A], the current that turns the unloaded motor (its friction
    torque is k_t i_0); gear_ratio G, motor turns per output turn; gear_efficiency eta in (0, 1]."""

    torque_constant: float
    resistance: float
    no_load_current: float
    gear_ratio: float
    gear_efficiency: float

    def __post_init__(self):
        rules = (
            ("torque_constant", self.torque_constant > 0.0, "> 0"),
            ("resistance", self.resistance >= 0.0, ">= 0"),
            ("no_load_current", self.no_load_current >= 0.0, ">= 0"),
            ("gear_ratio", self.gear_ratio > 0.0, "> 0"),
            ("gear_efficiency", 0.0 < self.gear_efficiency <= 1.0, "in (0, 1]"),
        )
        for name, ok, rule in rules:
            if not (ok and math.isfinite(getattr(self, name))):
                raise ValueError(f"motor: {name} {getattr(self, name)!r}: must be {rule}")


# A drive's keys (robot file, values.Drive) that make each of its motors, in the order of Motor's fields.
PROPULSION_KEYS = ("prp_motor_kt", "prp_motor_r", "prp_motor_i0", "prp_gr_rt", "prp_gear_eff")
STEERING_KEYS = ("str_motor_kt", "str_motor_r", "str_motor_i0", "str_gr_rt", "str_gear_eff")


def propulsion_motor(drive) -> Motor:
    """A drive's propulsion motor and gear, from its keys ``prp_motor_kt``, ``prp_motor_r``,
    ``prp_motor_i0``, ``prp_gr_rt`` and ``prp_gear_eff`` (drive: anything that has them as attributes,
    a :class:`~thorvald_model.values.Drive` as a rule)."""
    return Motor(*(getattr(drive, k) for k in PROPULSION_KEYS))


def steering_motor(drive) -> Motor:
    """A drive's steering motor and gear, from its keys ``str_motor_kt``, ``str_motor_r``,
    ``str_motor_i0``, ``str_gr_rt`` and ``str_gear_eff`` (a drive that does not steer has them too,
    with their defaults: nothing reads them)."""
    return Motor(*(getattr(drive, k) for k in STEERING_KEYS))


def _sign(x: float) -> float:
    """-1, 0 or 1 (NaN for NaN, as numpy's sign)."""
    if x > 0.0:
        return 1.0
    if x < 0.0:
        return -1.0
    return 0.0 if x == 0.0 else math.nan


def winding_current(motor: Motor, output_torque: float, output_speed: float) -> float:
    """The winding current i [A] of a motor whose gear output turns at output_speed w [rad/s] under
    output_torque tau [N m] (what the motor applies to its load: positive turns it the positive way).

    Gear: the motor turns at w_m = G w. Power flows through the gear with loss eta the way it flows:
    when the output delivers power to the load (tau w >= 0, motoring, holding at standstill
    included) the motor supplies more than arrives, tau_m w_m = tau w / eta, so tau_m = tau / (G eta);
    when the load drives the output back (tau w < 0, braking, going downhill) the motor receives less
    than was put in, tau_m w_m = eta tau w, so tau_m = tau eta / G.

    Motor: torque needs current, tau_m = k_t i, and the motor's own friction k_t i_0 opposes its
    turning, so i = tau_m / k_t + sign(w_m) i_0 (sign(w_m) = sign(w); i_0 only while turning: at
    standstill i = tau_m / k_t)."""
    g, eta = motor.gear_ratio, motor.gear_efficiency
    tau, w = output_torque, output_speed
    # signs compared, not the product tau w, which underflows to 0 for tiny ones: the inverse must agree
    s = _sign(w)
    tau_m = tau / (g * eta) if _sign(tau) * s >= 0.0 else tau * eta / g
    return tau_m / motor.torque_constant + s * motor.no_load_current


def electrical_power(motor: Motor, output_torque: float, output_speed: float) -> float:
    """The electrical power P [W] a motor draws whose gear output turns at output_speed w [rad/s]
    under output_torque tau [N m] (negative: it generates).

    The winding's voltage is the back-EMF plus the resistive drop, v = k_e w_m + i R (k_e = k_t in SI,
    w_m = G w, i the :func:`winding_current`), and P = v i = k_t w_m i + i^2 R: the mechanical power
    at the shaft plus the copper loss. So holding a torque at standstill costs i^2 R =
    (tau / (G eta k_t))^2 R, and an unloaded motor at speed w costs k_e G w i_0 + i_0^2 R. P < 0 is
    a motor generating: the mechanical power it gets back exceeds its copper loss."""
    current = winding_current(motor, output_torque, output_speed)
    voltage = motor.torque_constant * (motor.gear_ratio * output_speed) + current * motor.resistance
    return voltage * current


def output_torque(motor: Motor, current: float, output_speed: float) -> float:
    """The output torque tau [N m] a winding current [A] carries at output_speed w [rad/s]: the inverse
    of :func:`winding_current`, so output_torque(m, winding_current(m, tau, w), w) == tau (to rounding).

    The motor's torque is what the current gives beyond its friction, tau_m = k_t (i - sign(w) i_0);
    tau_m and tau have one sign (G, eta > 0), so tau_m w >= 0 is motoring, tau = tau_m G eta, and
    tau_m w < 0 braking, tau = tau_m G / eta. At standstill that is motoring (a held torque), as
    winding_current has it.

    A current along the turning but smaller than i_0 (0 < sign(w) i < i_0) is braking too, not 0: the
    current covers only part of the motor's friction k_t i_0 and the load turns the output for the
    rest, tau = -sign(w) k_t (i_0 - |i|) G / eta. That is the inverse winding_current takes: for a
    given w, i(tau) rises strictly and continuously over every current (both branches meet at tau = 0,
    i = sign(w) i_0), so each current has one torque; clamping such currents to tau = 0 would not
    round-trip."""
    g, eta = motor.gear_ratio, motor.gear_efficiency
    s = _sign(output_speed)
    tau_m = motor.torque_constant * (current - s * motor.no_load_current)
    return tau_m * (g * eta) if _sign(tau_m) * s >= 0.0 else tau_m * g / eta


__all__ = [
    "PROPULSION_KEYS",
    "STEERING_KEYS",
    "Motor",
    "electrical_power",
    "output_torque",
    "propulsion_motor",
    "steering_motor",
    "winding_current",
]
