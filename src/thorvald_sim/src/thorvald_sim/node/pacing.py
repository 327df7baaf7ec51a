"""Real-time pacing of a simulation: how long to wait after a step so that simulated time keeps
``real_time_factor`` times the pace of the wall clock.

The pace counts from an anchor, a (wall, simulated) pair of times: after each step the simulation
waits until the wall clock reaches ``anchor_wall + (simulated - anchor_simulated) / factor``. A
simulation that falls behind by more than ``catch_up`` seconds of wall time (a stall, a busy
machine) takes a new anchor instead of racing to catch up, since a burst faster than asked would
read as faster than asked to everything that runs on its clock. A pause drops the anchor too. A
factor of 0 means as fast as the machine can: no waiting at all.

Pure: the clock and the sleep are the caller's (``time.monotonic`` and ``time.sleep`` by default),
so tests drive it with a clock of their own.
"""

import math
import time
from typing import Callable, List, Optional, Tuple

CATCH_UP = 0.05  # [s] of wall time behind the pace after which the pace starts again from now


class Pacer:
    """Waits after each step so that simulated time runs real_time_factor times the wall clock."""

    def __init__(
        self,
        real_time_factor: float,
        catch_up: float = CATCH_UP,
        clock: Callable[[], float] = time.monotonic,
        sleep: Callable[[float], None] = time.sleep,
    ):
        if not (real_time_factor >= 0.0 and math.isfinite(real_time_factor)):
            raise ValueError(f"real_time_factor {real_time_factor!r}: must be a finite number >= 0")
        self.factor = real_time_factor
        self.catch_up = catch_up
        self.clock = clock
        self.sleep = sleep
        self.anchor: Optional[Tuple[float, float]] = None  # (wall, simulated) times the pace counts from
        self.restarts = 0  # new anchors taken because the simulation fell behind

    def stepped(self, simulated: float) -> float:
        """After a step that brought simulated time [s] to simulated: waits as long as the pace asks;
        returns the wait [s] (0 when behind, or as fast as possible)."""
        if self.factor == 0.0:
            return 0.0
        wall = self.clock()
        if self.anchor is None:
            self.anchor = (wall, simulated)
        ahead = self.anchor[0] + (simulated - self.anchor[1]) / self.factor - wall
        if ahead > 0.0:
            self.sleep(ahead)
            return ahead
        if ahead < -self.catch_up:  # too slow to keep up: do not race to catch up afterwards
            self.anchor = None
            self.restarts += 1
        return 0.0

    def paused(self) -> None:
        """The simulation is paused: the pace starts again from the first step after it."""
        self.anchor = None


MAX_WAIT = 0.5  # [s] wall: the longest a simulation waits at once for robots that lag


class FollowerWait:
    """Holds a simulation (without lockstep) while robots' commands lag behind simulated time, for at
    most max_wait [s] of wall time at once: a busy machine slows the simulation instead of letting
    robots drive on stale commands, and a robot that cannot keep up does not stop it for long."""

    def __init__(
        self,
        max_wait: float = MAX_WAIT,
        clock: Callable[[], float] = time.monotonic,
        sleep: Callable[[float], None] = time.sleep,
        poll: float = 0.0005,
    ):
        self.max_wait = max_wait
        self.clock = clock
        self.sleep = sleep
        self.poll = poll

    def wait(
        self, lagging: Callable[[], List[str]], first: Callable[[], None], stop: Callable[[], bool] = lambda: False
    ) -> List[str]:
        """Waits while lagging() names robots; first() is called once when the wait begins (the lagging
        drivers run on the clock it publishes). Returns the robots given up on after max_wait ([] when
        none lag any more, or stop() said so)."""
        deadline = None
        while not stop():
            names = lagging()
            if not names:
                return []
            if deadline is None:
                first()
                deadline = self.clock() + self.max_wait
            elif self.clock() > deadline:
                return names
            self.sleep(self.poll)
        return []
