"""The simulator node's lock, with turns: the loop holds it for each step and, between steps, lets the
threads that wait for it in before it takes it again.

CPython's locks are not fair. A loop that releases its lock and takes it again at once, as the
simulator's does when it runs flat out (``~real_time_factor: 0``), kept a waiting service thread out
for many steps: a ``/gazebo`` request that costs a millisecond took 100 to 160 ms to be answered beside
20 robots. With :class:`TurnLock` the loop calls :meth:`TurnLock.let_waiters_in` between its steps: the
threads waiting at that moment have the lock, one after the other, before the loop's next step. Free
when nobody waits.

The loop's steps are C calls that keep CPython's interpreter lock, and a request passes through
several of rospy's threads, each waiting for that lock: :data:`SWITCH_INTERVAL` shortens each of
those waits (CPython's default is 5 ms; :func:`sys.setswitchinterval`, set by the node's ``main``).

Pure: threading only, tested with threads of its own.
"""

import threading

TURN_TIMEOUT = 0.5  # [s] of wall time the loop waits at most for the threads waiting to have their turn
SWITCH_INTERVAL = 0.0005  # [s] a thread waits for the interpreter before the running one must let go


class TurnLock:
    """A reentrant lock (``with lock:``) whose owner loop lets waiting threads in between its turns."""

    def __init__(self, timeout: float = TURN_TIMEOUT):
        self.timeout = timeout
        self._lock = threading.RLock()
        self._count = threading.Condition(threading.Lock())
        self._waiting = 0  # threads blocked in acquire
        self._served = 0  # threads that had to wait and then got the lock

    def acquire(self) -> bool:
        if self._lock.acquire(blocking=False):  # free, or this thread's already
            return True
        with self._count:
            self._waiting += 1
        try:
            self._lock.acquire()
        finally:
            with self._count:
                self._waiting -= 1
                self._served += 1
                self._count.notify_all()
        return True

    def release(self) -> None:
        self._lock.release()

    __enter__ = acquire

    def __exit__(self, *_exc) -> None:
        self._lock.release()

    def let_waiters_in(self) -> None:
        """Called by the loop between its turns, without the lock: returns once every thread that waits
        for the lock now has had it (or after the timeout)."""
        if not self._waiting:
            return
        with self._count:
            goal = self._served + self._waiting
            self._count.wait_for(lambda: self._served >= goal, self.timeout)


__all__ = ["SWITCH_INTERVAL", "TURN_TIMEOUT", "TurnLock"]
