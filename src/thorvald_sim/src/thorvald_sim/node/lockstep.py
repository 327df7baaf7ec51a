"""Lockstep: the world steps past an instant only when every robot in lockstep has answered it.

In lockstep the simulator publishes each robot's drive states of an instant and waits, before its
next step, until each robot's driver has answered them with a command stamped for that instant
(or later). A robot is in lockstep from the first drive states it publishes to a reader (so the
steps before its first answer do not depend on how soon that answer came) or from its first
command; one that has not answered for ``timeout`` seconds of wall time (its driver died, stopped,
or reads drive states without being in lockstep) is let go, and the others go on; it joins again
with its next command. In its first STARTUP_SPAN of simulated time after joining, a robot has
``startup_timeout`` instead: a driver just started does its first cycles while its process still
imports and connects, and on a loaded machine that took more than 2 s (a run that broke lockstep
there, 0.05 s in, did not repeat to the bit). See the simulator node's docstring for the whole contract.

Pure bookkeeping, thread-safe: the node's loop calls :meth:`Lockstep.published` and
:meth:`Lockstep.wait`; the command callbacks call :meth:`Lockstep.answered`. The wall clock and
the wait on the condition are the caller's, so tests run it on a clock of their own.
"""

import threading
import time
from dataclasses import dataclass
from typing import Callable, Dict, List, Optional

TIMEOUT = 2.0  # [s] of wall time a robot in lockstep may leave an instant unanswered before it is let go
STARTUP_TIMEOUT = 10.0  # [s] of wall time instead, for the instants of a robot's first STARTUP_SPAN in lockstep
STARTUP_SPAN = 1.0  # [s] of simulated time from the instant a robot joined
SAME_INSTANT = 1e-9  # [s]: a command stamped this close before an instant answers it (stamps are ns)
POLL = 0.1  # [s] the longest a wait sleeps before it looks at the clock again


@dataclass
class _Robot:
    in_lockstep: bool = False  # it answers: joined, and not let go since
    joined: bool = False  # it was awaited once (a robot let go joins again by a command only)
    awaiting: Optional[float] = None  # [s] the instant of drive states it has not answered yet
    since: float = 0.0  # [s] the instant it joined (again)


class Lockstep:
    """Which robots the world waits for, and for which instant."""

    def __init__(
        self,
        timeout: float = TIMEOUT,
        clock: Callable[[], float] = time.monotonic,
        wait: Optional[Callable[[threading.Condition, float], None]] = None,
        startup_timeout: float = STARTUP_TIMEOUT,
    ):
        self.timeout = timeout
        self.startup_timeout = max(startup_timeout, timeout)
        self.clock = clock
        self._wait = wait or (lambda condition, seconds: condition.wait(seconds))
        self.condition = threading.Condition()
        self._robots: Dict[str, _Robot] = {}

    def _robot(self, name: str) -> _Robot:
        return self._robots.setdefault(name, _Robot())

    def published(self, name: str, instant: float) -> bool:
        """Robot name's drive states of instant [s] went to a reader; whether it joined with them."""
        with self.condition:
            robot = self._robot(name)
            joined = not robot.joined
            if joined:
                robot.joined = robot.in_lockstep = True
                robot.since = instant
            if robot.in_lockstep:
                robot.awaiting = instant
            return joined

    def answered(self, name: str, stamp: float) -> bool:
        """Robot name sent a command stamped for stamp [s]; whether it joined (again) with it."""
        with self.condition:
            robot = self._robot(name)
            joined = not robot.in_lockstep
            if joined:
                robot.joined = robot.in_lockstep = True
                robot.since = stamp
            if robot.awaiting is not None and stamp >= robot.awaiting - SAME_INSTANT:
                robot.awaiting = None
            self.condition.notify_all()
            return joined

    def restart(self) -> None:
        """Time went back to zero (the Gazebo API's reset_simulation): no robot owes an answer for an
        instant of the old time; each is awaited again from its next drive states."""
        with self.condition:
            for robot in self._robots.values():
                robot.awaiting = None
            self.condition.notify_all()

    def forget(self, name: str) -> None:
        with self.condition:
            self._robots.pop(name, None)
            self.condition.notify_all()

    def waiting(self) -> List[str]:
        """The robots in lockstep whose last instant is not answered yet."""
        with self.condition:
            return [n for n, r in self._robots.items() if r.in_lockstep and r.awaiting is not None]

    def allowed(self, name: str) -> float:
        """[s] of wall time robot name may leave its awaited instant unanswered."""
        with self.condition:
            return self._allowed(self._robot(name))

    def _allowed(self, robot: _Robot) -> float:
        starting = robot.awaiting is not None and robot.awaiting - robot.since < STARTUP_SPAN
        return self.startup_timeout if starting else self.timeout

    def wait(self, stop: Callable[[], bool] = lambda: False) -> List[str]:
        """Holds until every robot in lockstep answered its last instant, each at most its allowed wall
        time (:meth:`allowed`); returns the robots let go for not answering (each joins again with its
        next command)."""
        started = self.clock()
        let_go: List[str] = []
        with self.condition:
            while not stop():
                allowed = {
                    n: self._allowed(r) for n, r in self._robots.items() if r.in_lockstep and r.awaiting is not None
                }
                if not allowed:
                    return let_go
                waited = self.clock() - started
                late = [n for n, seconds in allowed.items() if waited >= seconds]
                for name in late:
                    robot = self._robots[name]
                    robot.in_lockstep, robot.awaiting = False, None
                let_go += late
                if len(late) == len(allowed):
                    return let_go
                left = min(seconds for n, seconds in allowed.items() if n not in late) - waited
                self._wait(self.condition, min(left, POLL))
        return let_go
