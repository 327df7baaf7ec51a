"""The balancing drive's decisions, without ROS: what each leg is driven with, and when the legs cannot
support a balance.

``balance_wheels`` measures each leg (the wheels' torques from their motor currents) and applies what
:class:`Balancer` says through base_driver's ``set_drive_params``; the simulator library's tests drive
the same decisions. The drive (:func:`thorvald_base.verification.balance_legs`): straight legs of the
radii, then on a steered robot the toe search's legs (:mod:`.toe_balance`) with the radii at the first
legs' fit, then legs of the radii again with the offsets found (:mod:`.torque_balance`).

A balance cannot diverge:

* every leg's radii are at most MAX_STEP (relative) from the last leg's;
* nothing is applied that the robot file's rules refuse (a radius the rules bound, wheels that would
  touch): the balance stops instead, with the rule;
* a fit is used only when the legs tell every radius to within MAX_SD (relative standard uncertainty)
  and puts none more than MAX_BALANCE from the radius the balance started with (the calibration from
  ground truth): a tyre's pressure and wear move its radius by a percent or two, more is another
  wheel, or a wheel whose torque does not follow its radius (on rigid tyres a frame of more than three
  wheels stands on three: the others turn almost free, their currents say nothing of their radii);
* the balance is kept only if its last leg fights less than the first.

A balance that stops says why (:attr:`Balancer.stopped`); the legs still to drive are driven with the
radii and offsets it started with, and nothing of it is kept: the calibration from ground truth stands.

Pure: numpy, no rospy, no messages.
"""

import math
from typing import List, Optional, Sequence, Tuple

import numpy as np

from thorvald_model import ConfigError, RobotConfig, with_drive_params

from ..errors import CalibrationError
from .toe_balance import ToeSearch, resistance
from .torque_balance import MAX_STEP, BalanceFit, Leg, fit_balance, next_radii

MAX_BALANCE = 0.03  # [1] of the radius the balance started with
MAX_SD = 0.003  # [1] a radius's relative standard uncertainty beyond which the legs do not tell it
RADII, TOE = "radii", "toe"  # the kinds of a balancing leg (thorvald_base.verification.BalanceWindow.kind)


class Balancer:
    """One balancing drive's decisions: ``record`` each leg as it is measured, ask ``next`` what the
    following leg is driven with, and ``result`` at the end.

    config: the robot file with the calibration in effect (its radii and offsets are where the balance
    starts); kinds: every leg's kind in order (RADII or TOE)."""

    def __init__(self, config: RobotConfig, kinds: Sequence[str]):
        self.config = config
        self.kinds = tuple(kinds)
        self.start_radii: Tuple[float, ...] = tuple(d.r_wheel for d in config.drives)
        self.start_offsets: Tuple[float, ...] = tuple(d.steering_offset for d in config.drives)
        self.radii, self.offsets = self.start_radii, self.start_offsets
        self.legs: List[Leg] = []
        self.first: Optional[BalanceFit] = None  # the first legs' fit, once the toe search starts
        self.toe: Optional[ToeSearch] = None
        if TOE in self.kinds:
            self.toe = ToeSearch(config, self.start_offsets)
            if self.toe.legs != self.kinds.count(TOE):
                raise CalibrationError("the balance manoeuvre's toe legs are not the toe search's")
        self.stopped: Optional[str] = None  # why the balance stopped, if it did

    # ---- the drive ---------------------------------------------------------------------------
    def record(self, leg: Leg) -> None:
        """The next leg, measured (driven with self.radii and self.offsets)."""
        kind = self.kinds[len(self.legs)]
        self.legs.append(leg)
        if kind == TOE and self.stopped is None:
            self.toe.record(resistance(leg))

    def next(self) -> Tuple[Optional[Tuple[float, ...]], Optional[Tuple[float, ...]]]:
        """(radii, offsets) to drive the next leg with, each None where it stays as it is."""
        if self.stopped is not None or len(self.legs) >= len(self.kinds):
            return None, None
        try:
            return self._set(*self._next(self.kinds[len(self.legs)]))
        except CalibrationError as e:
            return self.stop(str(e))

    def _next(self, kind: str):
        if kind == TOE:
            radii = None
            if self.first is None:  # the toe search starts with the radii balanced: the first legs' fit
                self.first = self.checked(fit_balance(self.radii_legs(0)))
                radii = self.stepped(self.first.radii)
            return radii, self.toe.offsets()
        if self.first is None:
            return self.stepped(next_radii(self.radii_legs(0))), None
        offsets = self.toe.result if self.offsets != self.toe.result else None
        again = self.radii_legs(1)
        if again:  # the stiffness known from the first legs: every leg after the search gives the radii
            return self.stepped(next_radii(again, stiffness_prior=self.first.stiffness)), offsets
        return (self.stepped(self.first.radii) if self.radii != self.first.radii else None), offsets

    def stop(self, reason: str):
        """Stops balancing: the rest of the drive goes with the radii and offsets it started with."""
        self.stopped = reason
        return self._set(self.start_radii, self.start_offsets)

    def _set(self, radii, offsets):
        radii = None if radii is None or tuple(radii) == self.radii else tuple(float(r) for r in radii)
        offsets = None if offsets is None or tuple(offsets) == self.offsets else tuple(float(o) for o in offsets)
        if radii is not None or offsets is not None:
            self.allowed(radii or self.radii, offsets or self.offsets)
            self.radii, self.offsets = radii or self.radii, offsets or self.offsets
        return radii, offsets

    # ---- the guards --------------------------------------------------------------------------
    def stepped(self, target: Sequence[float]) -> Tuple[float, ...]:
        """target, each radius at most MAX_STEP (relative) from the last leg's."""
        last = np.asarray(self.radii, dtype=float)
        step = np.clip(np.log(np.asarray(target, dtype=float) / last), -MAX_STEP, MAX_STEP)
        return tuple(float(r) for r in last * np.exp(step))

    def allowed(self, radii: Sequence[float], offsets: Sequence[float]) -> None:
        """CalibrationError with the rule if the robot file's rules refuse these radii and offsets."""
        changes = []
        for k, (r, o) in enumerate(zip(radii, offsets)):
            changes.append((k, "r_wheel", r))
            if self.config.drives[k].steerable:
                changes.append((k, "steering_offset", o))
        try:
            with_drive_params(self.config, changes)
        except ConfigError as e:
            raise CalibrationError(
                "the robot file's rules refuse what the balance would set: " + str(e).replace("\n", " ")
            ) from None

    def checked(self, fit: BalanceFit) -> BalanceFit:
        """fit, if the legs tell every radius (MAX_SD) and none is beyond MAX_BALANCE; CalibrationError why not."""
        names = [d.name for d in self.config.drives]
        vague = [(n, sd / r) for n, r, sd in zip(names, fit.radii, fit.sd) if not sd / r <= MAX_SD]
        if vague:
            told = ", ".join(f"{n} +-{100 * s:.3g} %" for n, s in vague)
            raise CalibrationError(
                f"the motor currents do not tell every tyre's radius ({told}; a balance needs +-{100 * MAX_SD:g} "
                "%): those wheels' torques do not follow their radii (rigid tyres: a frame of more than three "
                "wheels stands on three, and the others turn almost free)"
            )
        # the fit keeps the radii's geometric mean; the start's may be another, which is not the balance's
        ratio = np.log(np.asarray(fit.radii) / np.asarray(self.start_radii))
        ratio -= ratio.mean()
        far = [(n, r) for n, r in zip(names, ratio) if abs(r) > MAX_BALANCE]
        if far:
            told = ", ".join(f"{n} {100 * math.expm1(r):+.2f} %" for n, r in far)
            raise CalibrationError(
                f"the balance would move a radius beyond +-{100 * MAX_BALANCE:g} % of the calibration's ({told}): "
                "more than a tyre's pressure and wear, so not what the currents measure"
            )
        return fit

    # ---- the result --------------------------------------------------------------------------
    def radii_legs(self, part: int) -> List[Leg]:
        """The legs of the radii before the toe search (part 0) or after it (1)."""
        kinds = self.kinds[: len(self.legs)]
        first_toe = kinds.index(TOE) if TOE in kinds else len(kinds)
        pairs = list(zip(kinds, self.legs))
        return [leg for kind, leg in (pairs[first_toe:] if part else pairs[:first_toe]) if kind == RADII]

    def result(self) -> BalanceFit:
        """The balance: the fit of the last part's legs of the radii (with the first part's stiffness after
        a toe search); CalibrationError (self.stopped) when the legs cannot support one."""
        if self.stopped is None:
            try:
                if self.first is None:
                    fit = self.checked(fit_balance(self.radii_legs(0)))
                else:
                    fit = self.checked(fit_balance(self.radii_legs(1), stiffness_prior=self.first.stiffness))
                self.allowed(fit.radii, self.toe.result if self.toe is not None else self.offsets)
                first, last = self.legs[0].fight, self.legs[-1].fight
                if not last < first:
                    raise CalibrationError(
                        f"the balance did not reduce the wheels' fight ({first:.2f} N m on the first leg, "
                        f"{last:.2f} N m on the last)"
                    )
                return fit
            except CalibrationError as e:
                self.stopped = str(e)
        raise CalibrationError(f"the balance stopped: {self.stopped}")


__all__ = ["MAX_BALANCE", "MAX_SD", "RADII", "TOE", "Balancer"]
