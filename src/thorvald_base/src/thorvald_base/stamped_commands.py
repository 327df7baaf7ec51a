"""Velocity commands stamped with the instant they hold from, for base_driver in lockstep (pure).

A lockstep run repeats only if every cycle of base_driver commands the same in every run. A
``cmd_vel`` Twist carries no instant: which one a cycle uses depends on when it arrived, which
depends on the machine's load. A command source that knows its commands ahead (verification_drive,
a replayed plan) publishes them as TwistStamped on ``cmd_vel_stamped``, each before the instant
in its stamp. base_driver in lockstep then, at its cycle at instant t, waits until it holds a
command stamped after t (so that the one holding at t is known for certain) and applies the last
one stamped at or before t; twist_mux's ``cmd_vel`` is ignored while it follows such a stream.
"""

import bisect
from typing import List, Optional, Tuple

Twist3 = Tuple[float, float, float]  # vx [m/s], vy [m/s], wz [rad/s]
SAME_INSTANT = 1e-6  # [s]: stamps this close are one instant (a stamp travels as whole nanoseconds, truncated)
# in every warning of a node in lockstep that gave up waiting (the simulator for a driver's answer,
# base_driver for its stamped commands): from there on the run depends on timing; a report reading the log says so
LOCKSTEP_BROKEN = "lockstep broken"


class StampedCommands:
    """The stamped commands received and not yet passed, in the order of their stamps."""

    def __init__(self):
        self.stamps: List[float] = []
        self.twists: List[Twist3] = []
        self.holding: Optional[Twist3] = None  # the last command taken by at()

    @property
    def active(self) -> bool:
        """Whether a stream is being followed (a command came and the stream was not let go)."""
        return bool(self.stamps) or self.holding is not None

    def add(self, stamp: float, twist: Twist3) -> None:
        """A command holding from stamp [s] on. A stamp before the last one starts a new stream (the
        source started again, or simulated time was reset)."""
        if self.stamps and stamp < self.stamps[-1]:
            self.clear()
        self.stamps.append(stamp)
        self.twists.append(twist)

    def begun(self, t: float) -> bool:
        """Whether the stream holds at t: a command stamped at or before t has come."""
        return self.holding is not None or bool(self.stamps and self.stamps[0] <= t + SAME_INSTANT)

    def known(self, t: float) -> bool:
        """Whether the command holding at t is known: a command stamped after t has come."""
        return bool(self.stamps) and self.stamps[-1] > t + SAME_INSTANT

    def at(self, t: float) -> Optional[Twist3]:
        """The command holding at t (the last stamped at or before it); earlier ones are dropped."""
        k = bisect.bisect_right(self.stamps, t + SAME_INSTANT)
        if k:
            self.holding = self.twists[k - 1]
            del self.stamps[:k], self.twists[:k]
        return self.holding

    def clear(self) -> None:
        """Let the stream go: base_driver follows cmd_vel again until the next stamped command."""
        self.stamps.clear()
        self.twists.clear()
        self.holding = None
