"""Wheels that fight, seen through their motors: each tyre's rolling radius relative to the others.

On a rigid frame whose wheels are speed controlled, a tyre that rolls on a larger radius than the one
base_driver uses turns its rim faster than the ground moves under it: it pushes, and the others brake
it. Ground truth sees only the frame's common motion (per-tyre radii are not observable from it, see
``docs/as-built.md``), but the motors see the fight. On a straight leg at a steady speed, each wheel's
torque is, to first order, a slip stiffness times its slip, and its slip is its rim's excess over the
common ground speed:

    tau_kL / v_L = C (ln rho_k - ln r_kL) - b_L

where rho_k is tyre k's true rolling radius, r_kL the radius in effect on leg L (the wheel turns at
v_L / r_kL), v_L the leg's rim speed (signed), C the tyres' slip stiffness (shared: alike tyres on
alike loads) and b_L the leg's common slip (the frame's resistance and the mean mismatch). One leg
gives one equation per wheel but not C; legs driven with different radii in effect give C too (how
much torque a known change of radius buys), and so the radii at which no wheel fights: rho_k up to a
common factor, which ground truth gives (:func:`thorvald_base.calibration.calibrate`).

The equations are linear in a_k = C ln rho_k, C and b_L, solved by least squares with the gauge
sum(a) = 0 (a common shift of every a_k is a shift of every b_L). :func:`fit_balance` does that;
:func:`next_radii` is one step of the balancing drive (``balance_wheels``): after a single leg a probe
along the torques' pattern (C is not known yet), then the fit of every leg so far. The legs must be
driven at one speed both ways (the stiffness of a real tyre is per unit of slip ratio, the
simulator's per unit of slip speed: at one speed they are the same) and slowly enough that no wheel
slides (its torque then stops growing with its slip).

Pure: numpy, no rospy, no messages.
"""

import math
from dataclasses import dataclass
from typing import Optional, Sequence, Tuple

import numpy as np

from thorvald_model.motors import Motor, electrical_power

from ..errors import CalibrationError

PROBE = 0.004  # rms of the first step's relative radius changes, along the torques' pattern
MAX_STEP = 0.03  # [1] largest relative radius change in one step
QUIET = 0.05  # [N m] internal torques below this rms are no fight (the probe has nothing to follow)


@dataclass(frozen=True)
class Leg:
    """One straight leg at a steady speed: the radii base_driver used [m] per drive, the rim speed
    [m/s] (negative backwards), each wheel's mean torque [N m] over the leg's steady part and its
    wheels' mean turning rates [rad/s], over duration [s] of samples."""

    radii: Tuple[float, ...]
    speed: float
    torques: Tuple[float, ...]
    rates: Tuple[float, ...] = ()
    duration: float = 0.0
    samples: int = 0

    def __post_init__(self):
        n = len(self.radii)
        if len(self.torques) != n or (self.rates and len(self.rates) != n):
            raise CalibrationError(f"a leg of {n} radii holds {len(self.torques)} torques and {len(self.rates)} rates")
        if not (abs(self.speed) > 0.0 and math.isfinite(self.speed)):
            raise CalibrationError(f"a leg's speed must be a non-zero rim speed [m/s], not {self.speed!r}")

    @property
    def internal(self) -> np.ndarray:
        """[N m] each wheel's torque beyond the mean: what it spends against the others."""
        tau = np.asarray(self.torques, dtype=float)
        return tau - tau.mean()

    @property
    def fight(self) -> float:
        """[N m] rms of the internal torques."""
        return float(np.sqrt(np.mean(self.internal**2)))


@dataclass(frozen=True)
class BalanceFit:
    """The radii [m] at which the wheels would not fight (their geometric mean: the first leg's), the
    slip stiffness C [N m s/m: torque over rim speed per unit of ln radius], each radius's standard
    uncertainty relative to the others [m], the rms misfit of the torques [N m], the legs used, and
    whether C came from the legs (False: from the prior given)."""

    radii: Tuple[float, ...]
    stiffness: float
    sd: Tuple[float, ...]
    residual: float
    legs: int
    identified: bool


def _ln_radii(legs: Sequence[Leg]) -> np.ndarray:
    return np.log(np.asarray([leg.radii for leg in legs], dtype=float))


def stiffness_identified(legs: Sequence[Leg], tolerance: float = 1e-5) -> bool:
    """Whether the legs tell C: the radii's pattern (beyond a common factor) differs between legs by
    more than tolerance (relative, rms)."""
    if len(legs) < 2:
        return False
    pattern = _ln_radii(legs)
    pattern = pattern - pattern.mean(axis=1, keepdims=True)
    return float(np.sqrt(np.mean((pattern - pattern.mean(axis=0)) ** 2))) > tolerance


def fit_balance(legs: Sequence[Leg], stiffness_prior: Optional[float] = None) -> BalanceFit:
    """The radii at which the wheels of these legs would not fight; CalibrationError if the legs do
    not tell the slip stiffness and no prior is given, or if it comes out not positive (the wheels
    do not push back as slip grows: sliding, or torques that are not the wheels').

    Each wheel has a stiffness of its own (a wheel carrying more of the frame grips harder):
    tau_kL / v_L = C_k (x_k - ln r_kL - s_L), solved by alternating least squares (x and s for given
    stiffnesses, a linear problem with the gauge sum(x) = 0; then each C_k for given x and s), from
    the one shared stiffness's solution. The stiffness reported is the wheels' mean."""
    if not legs:
        raise CalibrationError("no leg to balance the wheels on")
    n = len(legs[0].radii)
    if any(len(leg.radii) != n for leg in legs):
        raise CalibrationError("the legs hold different numbers of drives")
    identified = stiffness_identified(legs)
    if not identified and stiffness_prior is None:
        raise CalibrationError(
            "the legs were all driven with the same radii (up to a common factor): they do not tell how much "
            "torque a change of radius buys; drive legs with other radii, or give the slip stiffness"
        )
    m = len(legs)
    ln_r = _ln_radii(legs)  # (m, n)
    y = np.asarray([[t / leg.speed for t in leg.torques] for leg in legs], dtype=float)  # (m, n)
    if identified:
        c = _shared_stiffness(ln_r, y)
        if not (c > 0.0 and math.isfinite(c)):
            raise CalibrationError(
                f"the wheels' torques do not grow with their slip (slip stiffness {c:.4g}): a wheel slid, or the "
                "torques are not the wheels' (motor currents of another drive, or of no load)"
            )
    else:
        c = float(stiffness_prior)
    stiffness = np.full(n, c)
    x, s = _offsets(ln_r, y, stiffness)
    if identified:
        for _ in range(ALS_ITERATIONS):
            z = x[None, :] - ln_r - s[:, None]
            zz = np.sum(z * z, axis=0)
            fitted = np.where(zz > 1e-14, np.sum(y * z, axis=0) / np.maximum(zz, 1e-300), stiffness)
            stiffness = np.where(fitted > 0.0, fitted, stiffness)
            x_new, s = _offsets(ln_r, y, stiffness)
            moved = float(np.max(np.abs(x_new - x)))
            x = x_new
            if moved < 1e-9:
                break
    keep = float(ln_r[0].mean())
    radii = np.exp(x - x.mean() + keep)
    residuals = (stiffness[None, :] * (x[None, :] - ln_r - s[:, None]) - y) * np.abs([[leg.speed] for leg in legs])
    residual = float(np.sqrt(np.mean(residuals**2)))
    # each x_k's uncertainty from its own equations: the torque misfit over its stiffness and speed
    dof = max(m * n - (n - 1) - m - (n if identified else 0), 1)
    sigma = float(np.sqrt(np.sum(residuals**2) / dof))
    speed = float(np.sqrt(np.mean([leg.speed**2 for leg in legs])))
    sd = sigma / (stiffness * speed * math.sqrt(m)) * radii
    return BalanceFit(tuple(float(r) for r in radii), float(stiffness.mean()), tuple(float(v) for v in sd), residual,
                      m, identified)  # fmt: skip


ALS_ITERATIONS = 200


def _shared_stiffness(ln_r: np.ndarray, y: np.ndarray) -> float:
    """C of the one-stiffness model, linear in a_k = C x_k, C and b_L = C s_L (gauge sum(a) = 0)."""
    m, n = ln_r.shape
    columns = n + 1 + m
    rows = []
    for li in range(m):
        for k in range(n):
            row = np.zeros(columns)
            row[k] = 1.0
            row[n] = -ln_r[li, k]
            row[n + 1 + li] = -1.0
            rows.append(row)
    gauge = np.zeros(columns)
    gauge[:n] = 1.0
    a = np.vstack([np.asarray(rows), gauge])
    target = np.concatenate([y.reshape(-1), [0.0]])
    solution, *_ = np.linalg.lstsq(a, target, rcond=None)
    return float(solution[n])


def _offsets(ln_r: np.ndarray, y: np.ndarray, stiffness: np.ndarray) -> Tuple[np.ndarray, np.ndarray]:
    """(x, s) for given stiffnesses: y_kL = C_k (x_k - ln r_kL - s_L) in torque units, sum(x) = 0."""
    m, n = ln_r.shape
    rows, target = [], []
    for li in range(m):
        for k in range(n):
            row = np.zeros(n + m)
            row[k] = stiffness[k]
            row[n + li] = -stiffness[k]
            rows.append(row)
            target.append(y[li, k] + stiffness[k] * ln_r[li, k])
    gauge = np.zeros(n + m)
    gauge[:n] = float(np.mean(stiffness))
    solution, *_ = np.linalg.lstsq(np.vstack([np.asarray(rows), gauge]), np.asarray([*target, 0.0]), rcond=None)
    return solution[:n], solution[n:]


def next_radii(legs: Sequence[Leg], probe: float = PROBE, stiffness_prior: Optional[float] = None) -> Tuple[float, ...]:
    """The radii to drive the next leg with, from the legs so far: the fitted balance when the legs
    tell the stiffness (or one is given), else a probe, a change of probe rms along the last leg's
    internal torques (a pushing wheel rolls on more than base_driver thinks: its radius grows), with
    no wheel changed by more than MAX_STEP from the last leg's radii."""
    last = np.asarray(legs[-1].radii, dtype=float)
    if stiffness_identified(legs) or stiffness_prior is not None:
        target = np.asarray(fit_balance(legs, stiffness_prior).radii)
    else:
        internal = legs[-1].internal
        rms = float(np.sqrt(np.mean(internal**2)))
        direction = internal / rms if rms > QUIET else np.zeros_like(internal)
        if not direction.any():  # nothing pushes: probe along a fixed pattern, to learn the stiffness
            direction = np.where(np.arange(len(last)) % 2 == 0, 1.0, -1.0)
        target = last * np.exp(probe * (direction - direction.mean()))
    step = np.clip(np.log(target / last), -MAX_STEP, MAX_STEP)
    return tuple(float(r) for r in last * np.exp(step))


def fight_power(leg: Leg, motors: Sequence[Motor]) -> float:
    """[W] the electrical power the leg's propulsion motors drew beyond what they would have drawn with
    every wheel carrying the mean torque: what the fight cost. A braking motor's power is not counted
    back (its controller burns it), as on a base without regeneration."""
    rates = leg.rates or tuple(leg.speed / r for r in leg.radii)
    tau = np.asarray(leg.torques, dtype=float)
    even = float(tau.mean())

    def drawn(torques) -> float:
        return sum(max(electrical_power(m, float(t), w), 0.0) for m, t, w in zip(motors, torques, rates))

    return drawn(tau) - drawn([even] * len(tau))


def relative_errors(radii: Sequence[float], truth: Sequence[float]) -> np.ndarray:
    """Each radius's error relative to the truth once the common factor is removed (what a balance
    can tell) [1]: ln(r_k / rho_k) minus its mean."""
    e = np.log(np.asarray(radii, dtype=float) / np.asarray(truth, dtype=float))
    return e - e.mean()


__all__ = [
    "MAX_STEP",
    "PROBE",
    "BalanceFit",
    "Leg",
    "fight_power",
    "fit_balance",
    "next_radii",
    "relative_errors",
    "stiffness_identified",
]
