"""A robot's drive commands as the simulator takes them: checked, kept until the loop applies them,
and a stop when they stop coming. No ROS here: the node hands each message's values in and applies
what :meth:`CommandSlot.take` gives back; tests drive it with a clock of their own.

* A command for another number of drives, or with a value that is not finite, is refused with the
  reason (:func:`command_problem`; the node warns, throttled).
* The loop applies the latest command once, before the next step (:meth:`CommandSlot.take`); a robot
  whose commands stopped for ``timeout`` seconds of simulated time is held (its wheels stop), once.
* Without lockstep, the simulator waits for a robot whose command stream is alive (a command came
  within ``STREAM_ALIVE`` seconds of wall time) but lags more than ``max_lag`` behind simulated time
  (:meth:`CommandSlot.lagging`, :class:`thorvald_sim.node.pacing.FollowerWait`).
"""

import math
import threading
import time
from typing import Callable, List, Optional, Sequence, Tuple

STREAM_ALIVE = 1.0  # [s] wall: a robot whose commands stopped this long ago is not waited for

Command = Tuple[List[float], List[float], Optional[List[float]]]  # (steering [rad], speeds, max steering speeds)
APPLY, HOLD = "apply", "hold"


def command_problem(drives: int, steering: Sequence[float], speeds: Sequence[float], limits: Sequence[float]) -> str:
    """Why a command (steering positions, propulsion speeds, steering speed limits) cannot be applied to
    a robot of that many drives ("" if it can)."""
    if len(steering) != drives or len(speeds) != drives:
        return f"a command for {len(steering)}/{len(speeds)} drives ignored; the robot has {drives}"
    if not all(math.isfinite(v) for v in (*steering, *speeds, *limits)):
        return "a non-finite command ignored"
    return ""


class CommandSlot:
    """The latest command of one robot of that many drives: written by its subscriber's thread
    (:meth:`put`), taken by the simulation's loop (:meth:`take`). clock: the wall clock (``time.monotonic``)."""

    def __init__(self, drives: int, clock: Callable[[], float] = time.monotonic):
        self.drives = drives
        self.clock = clock
        self.lock = threading.Lock()
        self.command: Optional[Command] = None
        self.time: Optional[float] = None  # [s] simulated time the latest command arrived (None: held since)
        self.stamp: Optional[float] = None  # [s] simulated time the latest command is for (its stamp)
        self.wall: Optional[float] = None  # [s] wall time it arrived
        self.fresh = False

    def put(self, steering, speeds, limits, now: float, stamp: float) -> str:
        """A command arrived at simulated time now, stamped stamp; "" if kept, else why it was refused."""
        drives = self.drives
        problem = command_problem(drives, steering, speeds, limits)
        if problem:
            return problem
        command = (list(steering), list(speeds), list(limits) if len(limits) == drives else None)
        with self.lock:
            self.command, self.time, self.stamp, self.wall, self.fresh = command, now, stamp, self.clock(), True
        return ""

    def take(self, now: float, timeout: float) -> Tuple[Optional[str], Optional[Command]]:
        """Before a step at simulated time now: (APPLY, the command) once for each new one, (HOLD, None)
        once when none came for timeout [s], else (None, None)."""
        with self.lock:
            if self.fresh:
                self.fresh = False
                return APPLY, self.command
            if self.time is not None and now - self.time > timeout:
                self.time = None
                return HOLD, None
        return None, None

    def restart_time(self) -> None:
        """Simulated time went back to zero: the latest command counts as come at 0 (the timeout
        runs from there), and no stamp of the old time is behind or ahead of the new."""
        with self.lock:
            if self.time is not None:
                self.time = 0.0
            self.stamp = None

    def lagging(self, now: float, max_lag: float) -> bool:
        """Whether the command stream is alive but more than max_lag [s] behind simulated time now."""
        with self.lock:
            stamp, wall = self.stamp, self.wall
        return stamp is not None and self.clock() - wall < STREAM_ALIVE and now - stamp > max_lag
