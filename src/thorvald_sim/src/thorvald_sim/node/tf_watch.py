"""Whether another node publishes a transform the simulator publishes: ``/tf`` read raw, without ROS.

The simulator publishes each robot's ``<prefix>odom -> <prefix>base_link`` from ground truth, as
users of the Gazebo plugin had it. A robot whose base_driver publishes that transform as well
(``enable_odom_tf``), or a robot_localization node in the odom frame, would make the tree flicker
between the two: tf2 keeps the newest of either. :class:`TfWatch` finds such a publisher from the
messages on ``/tf``, so the simulator can leave the transform to it while it publishes, and take it
back when it stops (a base_driver that died, one that publishes only until ground truth reaches it).

Reading ``/tf`` costs the simulator a message from every transform publisher, robot_state_publisher's
at 50 Hz per robot included, so it reads only while a publisher it has not judged yet is there: a
publisher is judged after ``JUDGE_AFTER`` messages (a node that publishes a transform at all
publishes it in each message of its cycle) or when it shows a conflict; a robot that had a conflict
keeps /tf read, to see its other publisher stop or come back. The node asks
:meth:`TfWatch.listening` after every look at the master's list of ``/tf`` publishers and
subscribes or unsubscribes accordingly. Frames compare as tf2 compares them: a leading slash dropped.
"""

import struct
import threading
from dataclasses import dataclass
from typing import Dict, Iterable, List, Set, Tuple

from ..errors import MalformedTf

JUDGE_AFTER = 20  # messages of a publisher read before it is known not to publish a watched transform
STALE = 2.0  # [s] without the other publisher's transform before the simulator publishes it again

_UINT32 = struct.Struct("<I")
_STAMP = 12  # bytes of a header's seq, secs and nsecs
_TRANSFORM = 56  # bytes of a Transform: 7 float64


def tf_frame(name: str) -> str:
    """A frame id as tf2 keys it: without leading slashes."""
    return name.lstrip("/")


def transform_frames(buff: bytes) -> List[Tuple[str, str]]:
    """(parent, child) of each transform of a serialised tf2_msgs/TFMessage, in order; frames as tf2 keys them."""
    view = memoryview(buff)
    end = len(view)
    try:
        (count,) = _UINT32.unpack_from(view, 0)
        at = 4
        frames = []
        for _ in range(count):
            at += _STAMP
            (n,) = _UINT32.unpack_from(view, at)
            parent = bytes(view[at + 4 : at + 4 + n])
            at += 4 + n
            (n,) = _UINT32.unpack_from(view, at)
            child = bytes(view[at + 4 : at + 4 + n])
            at += 4 + n + _TRANSFORM
            if at > end:
                raise MalformedTf(f"a TFMessage of {count} transforms ends after {end} bytes")
            frames.append((tf_frame(parent.decode("utf-8", "replace")), tf_frame(child.decode("utf-8", "replace"))))
    except struct.error:
        raise MalformedTf(f"a TFMessage cut short at {end} bytes") from None
    return frames


@dataclass(frozen=True)
class Conflict:
    """Another publisher of a transform whose child frame the simulator publishes for a robot."""

    robot: str
    publisher: str  # its node name (the connection's callerid)
    parent: str
    child: str


class TfWatch:
    """Which robots' transforms another node publishes too; thread-safe (the master poll, rospy's readers).

    A robot whose transform another node publishes is yielded to it (the simulator stops publishing
    that robot's) for as long as that node goes on: after ``stale`` seconds without it, the robot is
    handed back (:meth:`resumed`), and /tf is read for it still, so the other node's return is seen
    at its first message. Time is the caller's (wall, monotonic).
    """

    def __init__(self, own_name: str, judge_after: int = JUDGE_AFTER, stale: float = STALE):
        self.own = own_name
        self.judge_after = judge_after
        self.stale = stale
        self._lock = threading.Lock()
        self._watched: Dict[str, str] = {}  # child frame -> robot, for robots the simulator publishes
        self._yielded: Dict[str, Tuple[Conflict, float]] = {}  # robot -> (its conflict, when last seen)
        self._conflicted: Set[str] = set()  # robots that had a conflict once: /tf is read for them
        self._publishers: Set[str] = set()  # the /tf publishers the master lists, but us
        self._seen: Dict[str, int] = {}  # publisher -> messages read since the watched frames last changed
        self._judged: Set[str] = set()

    def watch(self, robot: str, child: str) -> None:
        """From now on, another publisher of child is robot's conflict; every publisher is judged again."""
        with self._lock:
            self._watched[tf_frame(child)] = robot
            self._judged.clear()
            self._seen.clear()

    def forget(self, robot: str) -> None:
        with self._lock:
            self._watched = {c: r for c, r in self._watched.items() if r != robot}
            self._yielded.pop(robot, None)
            self._conflicted.discard(robot)

    def publishers(self, names: Iterable[str]) -> None:
        """The master's current list of /tf publishers (the simulator itself is left out)."""
        with self._lock:
            self._publishers = {n for n in names if n != self.own}
            self._judged &= self._publishers

    def listening(self) -> bool:
        """Whether /tf must be read: a watched frame and a publisher not judged yet, or a robot that had
        a conflict (its other publisher may stop, or come back)."""
        with self._lock:
            return bool(self._conflicted) or (bool(self._watched) and bool(self._publishers - self._judged))

    def message(self, publisher: str, buff: bytes, now: float) -> List[Conflict]:
        """A /tf message of publisher's (its raw bytes) read at now [s]: the robots it takes the transform
        of (each once, until handed back)."""
        with self._lock:
            if publisher == self.own:
                return []
            yielded = {c.child: c for c, _ in self._yielded.values() if c.publisher == publisher}
            if (publisher in self._judged or not self._watched) and not yielded:
                return []
            watched = dict(self._watched)
        try:
            frames = transform_frames(buff)
        except MalformedTf:
            frames = []
        found: Dict[str, Conflict] = {}
        with self._lock:
            for parent, child in frames:
                if child in yielded:
                    self._yielded[yielded[child].robot] = (yielded[child], now)
                elif child in watched and self._watched.get(child) == watched[child]:
                    found[child] = Conflict(watched[child], publisher, parent, child)
            for conflict in found.values():
                del self._watched[conflict.child]
                self._yielded[conflict.robot] = (conflict, now)
                self._conflicted.add(conflict.robot)
            seen = self._seen.get(publisher, 0) + 1
            self._seen[publisher] = seen
            if seen >= self.judge_after:
                self._judged.add(publisher)
        return list(found.values())

    def resumed(self, now: float) -> List[Conflict]:
        """The conflicts whose other publisher has been silent for ``stale`` seconds at now: their robots
        are handed back to the simulator (and watched again)."""
        with self._lock:
            back = [c for c, last in self._yielded.values() if now - last >= self.stale]
            for conflict in back:
                del self._yielded[conflict.robot]
                self._watched[conflict.child] = conflict.robot
                self._judged.discard(conflict.publisher)
                self._seen.pop(conflict.publisher, None)
        return back
