"""The instants of a rate on simulated time: one grid for every periodic thing a simulation does.

The simulator's ``/clock``, ground truth and drive states, each sensor's readings and base_driver's
control cycle in lockstep all happen "at a rate" on a clock that advances in steps (the physics
step, or the simulator's clock ticks). :class:`RateGrid` says at which of those steps: at the first
step at or after each multiple of the period ``1 / rate``, a multiple counting as reached when a
step lies within half a step of it (the step nearest it, when steps are finer than the period).
So the instants are the same whenever the caller began to ask (two runs, two robots, a sensor
first read late all fall on the same grid), a multiple is served once, and one missed entirely (a
step longer than the period, or nobody asking for a while) is not made up later: no bursts.

Each served instant has an index, the multiple it serves (``period * index`` is its time), which
keys whatever must repeat with it (a sensor's noise). A rate of 0 means every step; its index is
then the step's (``round(now / step)``).

Pure: numbers in, booleans out; the caller's clock is whatever it passes.
"""

import math
from typing import Optional

EXACT = 1e-9  # [s] the tolerance of a clock without a step: its instants are exact multiples


class RateGrid:
    """The steps at which something of rate [Hz] is due, on a clock of step [s] (0: exact instants)."""

    def __init__(self, rate: float, step: float = 0.0):
        if not (rate >= 0.0 and math.isfinite(rate)):
            raise ValueError(f"rate {rate!r}: must be a finite number >= 0 [Hz]")
        if not (step >= 0.0 and math.isfinite(step)):
            raise ValueError(f"step {step!r}: must be a finite number >= 0 [s]")
        if rate == 0.0 and step == 0.0:
            raise ValueError("rate 0 (every step) needs the clock's step")
        self.period = 1.0 / rate if rate > 0.0 else 0.0  # [s]; 0: every step
        self.step = step
        self.tolerance = step / 2.0 if step > 0.0 else EXACT
        self.index: Optional[int] = None  # the multiple served last (None: none since the start or a pause)

    def due(self, now: float) -> bool:
        """Whether the step at now [s] is an instant of the grid; if so, ``index`` is the multiple it serves."""
        if self.period == 0.0:
            self.index = round(now / self.step)
            return True
        reached = math.floor((now + self.tolerance) / self.period)
        if self.index is None:
            # the first step asked (or the first after a pause): the multiples before it are not owed
            self.index = math.ceil((now - self.tolerance) / self.period) - 1
        if reached <= self.index:
            return False
        self.index = reached
        return True

    def pause(self) -> None:
        """Nobody asks for a while: the grid starts again at the next multiple after the next step asked."""
        self.index = None

    def time(self, index: Optional[int] = None) -> float:
        """The time [s] of a multiple (the last one served by default)."""
        k = self.index if index is None else index
        if k is None:
            raise ValueError("no instant served yet")
        return k * (self.period if self.period else self.step)
