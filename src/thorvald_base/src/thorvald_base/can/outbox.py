"""Frames waiting for a bus that refused a write: bounded in number and in age, the newest command first.

A write that a full buffer or a write timeout refuses (an SLCAN adapter's serial port whose reader
is slow, a SocketCAN transmit queue, python-can's ``virtual`` queue) is not a broken bus: the bus is
kept, reading goes on, and the frames wait here for the next write (the handle's next poll of the
bus: two or three a cycle). A command or mode frame to a motor controller replaces the one to the
same identifier still waiting, in its place, so a slow link delays the newest command instead of
piling up stale ones; every other frame (setups, IO commands, relayed frames) keeps its turn. A frame waits at most
MAX_WAIT: older ones are dropped, as are the oldest beyond LIMIT, and both are counted.

:func:`write_refused` tells a refused write (try again) from a broken port (shut it and reopen).

No bus here: the handle writes what :meth:`Outbox.waiting` gives and says how many went
(:meth:`Outbox.sent`). Times are seconds of the caller's clock (base_driver's cycle time).
"""

import errno
import queue
from collections import OrderedDict
from dataclasses import dataclass, replace
from typing import Callable, Dict, Hashable, Iterable, List, Optional

try:  # python-can's serial interfaces (slcan, serial) raise it from their write; pyserial is theirs
    from serial import SerialTimeoutException
except ImportError:  # pragma: no cover  (no serial interface without pyserial)
    SerialTimeoutException = ()  # type: ignore[assignment,misc]

LIMIT = 256  # frames waiting at most: a 9-drive robot's commands (27 ids) and a cycle's 100 relayed frames
# [s] the longest a frame waits: base_driver's ~command_timeout (0.5 s) stops the wheels on a velocity
# command that old, so a frame later than that would drive on what the base itself calls stale
MAX_WAIT = 0.5

# errno values of a write the buffer refused for now: EAGAIN/EWOULDBLOCK (a non-blocking port or
# socket), ENOBUFS (SocketCAN's transmit queue full), EINTR (a signal)
REFUSED_ERRNOS = frozenset((errno.EAGAIN, errno.EWOULDBLOCK, errno.ENOBUFS, errno.EINTR))
# what python-can's interfaces say when their transmit buffer is full (lower case): socketcan's
# select timed out, virtual's receiver queue (rx_queue_size) full, pyserial's write timeout, and
# the vendors' "transmit buffer/queue full" wordings
REFUSED_WORDS = (
    "transmit buffer full",
    "buffer is full",
    "queue full",
    "queue is full",
    "could not send message to one or more recipients",
    "write timeout",
)


def write_refused(error: BaseException) -> bool:
    """Whether a failed write was refused for now (a full buffer, a write timeout): the bus is fine.

    Anything else (EIO, a closed port, a device gone) is a broken bus. python-can wraps the
    interface's own error (``CanOperationError("Could not write to serial device")`` for a full
    serial buffer and for an unplugged adapter alike), so the cause chain decides.
    """
    seen = set()
    e: Optional[BaseException] = error
    while e is not None and id(e) not in seen:
        seen.add(id(e))
        if isinstance(e, (BlockingIOError, InterruptedError, queue.Full, SerialTimeoutException)):
            return True
        code = getattr(e, "error_code", None)  # python-can's CanError
        if code is None:
            code = getattr(e, "errno", None)  # OSError
        if code in REFUSED_ERRNOS:
            return True
        if any(words in str(e).lower() for words in REFUSED_WORDS):
            return True
        e = e.__cause__ or e.__context__
    return False


@dataclass(frozen=True)
class Waiting:
    """A frame given to the bus and not written yet."""

    can_id: int
    data: bytes
    extended: bool = False
    remote: bool = False
    since: Optional[float] = None  # [s] when it was given; None: before the caller's clock was known
    deferred: bool = False  # it missed the write it was given for
    relayed: bool = False  # from an implement (can_frames_device_t), not the base's own


@dataclass
class OutboxCounters:
    """What the outbox did, for /diagnostics."""

    deferred: int = 0  # frames that missed the write they were given for and waited for a later one
    superseded: int = 0  # waiting commands replaced by a newer one to the same identifier
    dropped: int = 0  # frames never written: waited longer than MAX_WAIT, or beyond LIMIT
    worst_latency: float = 0.0  # [s] the longest a written frame waited


class Outbox:
    """The frames to write, in order; a keyed frame replaces the waiting one with its key, in place."""

    def __init__(self, limit: int = LIMIT, max_wait: float = MAX_WAIT):
        self.limit = limit
        self.max_wait = max_wait
        self.counters = OutboxCounters()
        self._frames: Dict[Hashable, Waiting] = OrderedDict()
        self._serial = 0  # keys of the frames nothing replaces

    def __len__(self) -> int:
        return len(self._frames)

    def put(self, frame: Waiting, key: Optional[Hashable] = None) -> None:
        """Queues a frame; one with a key replaces the waiting frame with the same key (keeping its turn)."""
        if key is not None:
            if ("key", key) in self._frames:
                self.counters.superseded += 1
            self._frames[("key", key)] = frame
        else:
            self._serial += 1
            self._frames[("frame", self._serial)] = frame
        while len(self._frames) > self.limit:
            # the oldest frame nothing replaces goes first: commands stay (each is only the newest)
            oldest = next((k for k in self._frames if k[0] == "frame"), next(iter(self._frames)))
            del self._frames[oldest]
            self.counters.dropped += 1

    def extend(self, frames: Iterable[Waiting], keys: Iterable[Optional[Hashable]]) -> None:
        for frame, key in zip(frames, keys):
            self.put(frame, key)

    def waiting(self, time: Optional[float]) -> List[Waiting]:
        """The frames to write now, in order, after dropping those that waited longer than max_wait."""
        if time is not None:
            for key, f in list(self._frames.items()):
                if f.since is None or f.since > time:  # given before the clock was known, or it went back
                    self._frames[key] = replace(f, since=time)
                elif time - f.since > self.max_wait:
                    del self._frames[key]
                    self.counters.dropped += 1
        return list(self._frames.values())

    def sent(self, count: int, time: Optional[float]) -> None:
        """The first count frames of :meth:`waiting` were written at time; the rest missed this write."""
        for _ in range(min(count, len(self._frames))):
            _, f = self._frames.popitem(last=False)  # type: ignore[call-arg]
            if time is not None and f.since is not None:
                self.counters.worst_latency = max(self.counters.worst_latency, time - f.since)
        for key, f in list(self._frames.items()):
            if not f.deferred:
                self._frames[key] = replace(f, deferred=True)
                self.counters.deferred += 1

    def discard(self, which: Callable[[Waiting], bool]) -> None:
        """Forgets the waiting frames which(frame) is true of (not counted as dropped: nobody wants them)."""
        for key in [k for k, f in self._frames.items() if which(f)]:
            del self._frames[key]

    def clear(self) -> None:
        self._frames.clear()
