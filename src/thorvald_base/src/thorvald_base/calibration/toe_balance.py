"""Steering offsets that do not scrub, seen through the wheels' motors: the toe the odometry cannot see.

A steering module homed off by a fraction of a degree rolls at that angle to the others. On a rigid
frame the wheels cannot all roll where they point: they scrub sideways, and the frame's resistance
grows, which the propulsion motors pay for. Ground truth sees only the frame's motion, and a frame
whose wheels toe in or out drives as straight as one whose wheels do not: the toe pattern is not
observable from it (``calibrate_odometry`` leaves it at the configured values). Two toe patterns
cost nothing: every steered wheel turned alike (the frame crabs) and turned in proportion to its x
(the frame drives an arc). Ground truth sees both, so they keep the calibration's values.

The toe costs the balance of the radii too: with a wheel scrubbing, the radii at which no wheel
fights are off by a few tenths of a percent (:mod:`.torque_balance`).

:class:`ToeSearch` finds the offsets at which the frame's resistance is least, by straight legs at a
steady speed, alternately forwards and back, each measured through its wheels' mean torque against
the travel (:func:`resistance`): for one steered drive at a time, a leg with its offset step higher
and one step lower, then the offset at the vertex of the V the three legs give (a scrubbing wheel's
cost grows with the size of its toe, either way), and a leg there, which is the next drive's start.
Each round goes once through every steered drive and the step shrinks by TOE_SHRINK for a drive
whose vertex lay inside its step. At the end the offsets' crab and arc are put back as they started
(:func:`toe_gauge`).

Drive it with the radii balanced first: wheels that fight longitudinally push the frame with a force
that does not turn round with the travel, and the resistance then reads it.

Pure: numpy, no rospy, no messages.
"""

import math
from dataclasses import dataclass
from typing import List, Sequence, Tuple

import numpy as np

from thorvald_model import RobotConfig
from thorvald_model.layout import axle_lines

from ..errors import CalibrationError
from .torque_balance import Leg

TOE_STEP = math.radians(0.3)  # [rad] the first round's step (a field robot's modules home within +-0.5 deg)
TOE_ROUNDS = 2
TOE_SHRINK = 0.4  # each round's step, of the last one's, for a drive whose vertex lay inside its step


def resistance(leg: Leg) -> float:
    """[N m] the wheels' mean torque against the leg's travel: what they spend pushing the frame."""
    return float(np.mean(leg.torques)) * math.copysign(1.0, leg.speed)


def toe_gauge(config: RobotConfig) -> np.ndarray:
    """(drives, m) orthonormal columns: the steering offsets' patterns a rigid frame follows without a
    wheel scrubbing, alpha_k = b + c x_k over the steered drives (a crab and an arc), those of them
    whose turning centre lies on the axle line of the wheels that cannot steer (drives and fixed passive
    wheels), if there are any. Ground truth sees these; the motors do not."""
    drives = config.drives
    steered = np.array([d.steerable for d in drives], dtype=bool)
    x = np.array([d.x for d in drives], dtype=float)
    basis = np.stack([np.ones(len(drives)), x], axis=1)  # (b, c) -> alpha
    fixed = np.array([[1.0, line.x] for line in axle_lines(drives, config.passive_wheels)]).reshape(-1, 2)
    if len(fixed):
        _, s, vt = np.linalg.svd(fixed)
        rank = int(np.sum(s > 1e-9 * max(1.0, float(s[0]))))
        combos = vt[rank:].T  # (2, 2 - rank)
    else:
        combos = np.eye(2)
    patterns = (basis @ combos) * steered[:, None]
    if not patterns.size:
        return np.zeros((len(drives), 0))
    u, s, _ = np.linalg.svd(patterns, full_matrices=False)
    return u[:, s > 1e-9 * max(1.0, float(s[0]) if len(s) else 1.0)]


def searched(config: RobotConfig) -> Tuple[int, ...]:
    """The drives whose offsets the search moves: every steered drive, when the steered drives have a
    toe pattern beyond the gauge's (none for a differential robot, or a robot of one steered drive)."""
    steered = tuple(k for k, d in enumerate(config.drives) if d.steerable)
    return steered if len(steered) > toe_gauge(config).shape[1] else ()


def toe_legs(config: RobotConfig, rounds: int = TOE_ROUNDS) -> int:
    """How many legs the search drives on this robot: three per steered drive and round."""
    return 3 * rounds * len(searched(config))


@dataclass(frozen=True)
class ToeMove:
    """One drive's step of the search: the resistance [N m] at its offset minus, at and plus step
    [rad], and the move [rad] to the vertex."""

    drive: int
    round: int
    step: float
    minus: float
    at: float
    plus: float
    move: float


def vertex(minus: float, at: float, plus: float, step: float) -> float:
    """[rad] where a V through (-step, minus), (0, at), (step, plus) has its vertex, within +-step:
    the slope from the three and the vertex from the difference of the sides. No V (the middle not
    below the sides' line): the lower of the sides, or no move."""
    slope = (plus + minus - 2.0 * at + abs(plus - minus)) / (2.0 * step)
    if not (slope > 0.0 and math.isfinite(slope)):
        if min(plus, minus) < at:
            return step if plus < minus else -step
        return 0.0
    return float(np.clip(-(plus - minus) / (2.0 * slope), -step, step))


class ToeSearch:
    """The search, one leg at a time: :meth:`offsets` are the steering offsets [rad, every drive's] to
    drive the next leg with, :meth:`record` takes that leg's :func:`resistance`; when :attr:`done`,
    :attr:`result` holds the offsets found (their gauge patterns as they started) and :attr:`moves`
    each step."""

    def __init__(
        self,
        config: RobotConfig,
        offsets: Sequence[float],
        *,
        step: float = TOE_STEP,
        rounds: int = TOE_ROUNDS,
        shrink: float = TOE_SHRINK,
    ):
        n = len(config.drives)
        if len(offsets) != n:
            raise CalibrationError(f"{len(offsets)} steering offsets for a robot of {n} drives")
        if not (step > 0.0 and math.isfinite(step)) or rounds < 1 or not 0.0 < shrink <= 1.0:
            raise CalibrationError(
                f"a toe search needs a positive step, rounds and shrink, not {step}, {rounds}, {shrink}"
            )
        self.drives = searched(config)
        if not self.drives:
            raise CalibrationError("this robot has no toe to search: fewer steered drives than the frame follows")
        self.gauge = toe_gauge(config)
        self.start = np.asarray(offsets, dtype=float)
        self.current = self.start.copy()
        self.steps = {k: float(step) for k in self.drives}
        self.rounds, self.shrink = rounds, shrink
        self.legs = 3 * rounds * len(self.drives)
        self.moves: List[ToeMove] = []
        self._queue = [(r, k) for r in range(rounds) for k in self.drives]
        self._measured: List[float] = []  # this drive's resistances: at, plus, minus
        self._at = None  # the resistance at the current offsets, once measured

    @property
    def done(self) -> bool:
        return not self._queue

    def offsets(self) -> Tuple[float, ...]:
        if self.done:
            return self.result
        _, k = self._queue[0]
        o = self.current.copy()
        if self._at is not None:
            o[k] += self.steps[k] if len(self._measured) == 0 else -self.steps[k]
        return tuple(float(v) for v in o)

    def record(self, value: float) -> None:
        if self.done:
            raise CalibrationError("the toe search is done: no leg to record")
        if not math.isfinite(value):
            raise CalibrationError(f"a toe leg's resistance is {value!r}")
        if self._at is None:
            self._at = float(value)
            return
        self._measured.append(float(value))
        if len(self._measured) < 2:
            return
        plus, minus = self._measured
        rnd, k = self._queue.pop(0)
        h = self.steps[k]
        d = vertex(minus, self._at, plus, h)
        self.moves.append(ToeMove(k, rnd, h, minus, self._at, plus, d))
        self.current[k] += d
        if abs(d) < 0.999 * h:
            self.steps[k] = h * self.shrink
        self._measured = []
        self._at = None

    @property
    def result(self) -> Tuple[float, ...]:
        """The offsets found, with the gauge's patterns (crab, arc) put back as they started."""
        g = self.gauge
        o = self.current + g @ (g.T @ (self.start - self.current))
        return tuple(float(v) for v in o)


__all__ = [
    "TOE_ROUNDS",
    "TOE_SHRINK",
    "TOE_STEP",
    "ToeMove",
    "ToeSearch",
    "resistance",
    "searched",
    "toe_gauge",
    "toe_legs",
    "vertex",
]
