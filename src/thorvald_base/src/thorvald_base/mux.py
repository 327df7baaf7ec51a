"""Twist multiplexer logic, with the semantics of the ROS ``twist_mux`` package.

Inputs and locks each have a name, a topic, a timeout [s] and a priority (0..255):

- an input *expires* when its last message is older than its timeout; a timeout of 0 never
  expires (so such an input counts as live even before its first message, as in twist_mux);
- a lock is *locked* while its last message said true, or while it has expired: a lock with a
  timeout is therefore locked until its first message arrives, and locked again when its
  publisher goes quiet;
- an input is *masked* when it has expired or its priority is below the highest priority of the
  locked locks;
- a message is relayed exactly as received when its input is the highest-priority unmasked one.

Pure Python: the node converts messages and clock readings to these calls.
"""

from dataclasses import dataclass
from typing import Any, Dict, List, Mapping, Optional, Sequence

from .errors import ParameterError


@dataclass(frozen=True)
class Source:
    """One input topic or lock of the multiplexer."""

    name: str
    topic: str
    timeout: float  # [s]; 0 = never expires
    priority: int  # 0..255


def parse_sources(value: Any, param: str) -> List[Source]:
    """Reads ``~topics`` or ``~locks`` in twist_mux's format: a list of entries, or a mapping from
    name to entry; each entry has ``topic``, ``timeout`` and ``priority`` (and ``name`` in a list).
    Every problem is collected before raising one ParameterError."""
    if value is None:
        return []
    if isinstance(value, Mapping):
        items = [(str(name), entry) for name, entry in value.items()]
    elif isinstance(value, (list, tuple)):
        items = [(entry.get("name") if isinstance(entry, Mapping) else None, entry) for entry in value]
    else:
        raise ParameterError(f"{param}: {value!r}: must be a list of {{name, topic, timeout, priority}} entries")
    sources, problems = [], []
    for i, (name, entry) in enumerate(items):
        where = f"{param}[{i}]" if name is None else f"{param}.{name}"
        before = len(problems)
        if not isinstance(entry, Mapping):
            problems.append(f"{where}: {entry!r}: must be a mapping with topic, timeout and priority")
            continue
        if not isinstance(name, str) or not name:
            problems.append(f"{where}.name: {name!r}: must be a non-empty string")
        topic = entry.get("topic")
        if not isinstance(topic, str) or not topic:
            problems.append(f"{where}.topic: {topic!r}: must be a topic name")
        timeout = entry.get("timeout")
        if isinstance(timeout, bool) or not isinstance(timeout, (int, float)) or not timeout >= 0:
            problems.append(f"{where}.timeout: {timeout!r}: must be a number of seconds >= 0 (0 = never expires)")
        priority = entry.get("priority")
        if isinstance(priority, bool) or not isinstance(priority, int) or not 0 <= priority <= 255:
            problems.append(f"{where}.priority: {priority!r}: must be an integer in 0..255")
        unknown = sorted(set(entry) - {"name", "topic", "timeout", "priority", "short_desc"})
        if unknown:
            problems.append(f"{where}: unknown key(s) {', '.join(unknown)}: known are name, topic, timeout, priority")
        if len(problems) == before:
            sources.append(Source(name, topic, float(timeout), int(priority)))
    names = [s.name for s in sources]
    for name in sorted({n for n in names if names.count(n) > 1}):
        problems.append(f"{param}: name {name!r} appears more than once")
    if problems:
        raise ParameterError("\n".join(problems))
    return sources


class TwistMux:
    """Decides which input's messages pass. Times are in seconds on any one clock."""

    def __init__(self, inputs: Sequence[Source], locks: Sequence[Source] = ()):
        self.inputs = {s.name: s for s in inputs}
        self.locks = {s.name: s for s in locks}
        # Never heard from: an input or lock with a timeout starts expired.
        self._input_stamp: Dict[str, Optional[float]] = {name: None for name in self.inputs}
        self._lock_stamp: Dict[str, Optional[float]] = {name: None for name in self.locks}
        self._lock_state: Dict[str, bool] = {name: False for name in self.locks}

    @staticmethod
    def _expired(source: Source, stamp: Optional[float], now: float) -> bool:
        if source.timeout <= 0.0:
            return False
        # a stamp more than a timeout ahead of now: time moved backwards (a simulation reset), and
        # nothing heard since is fresh
        return stamp is None or abs(now - stamp) > source.timeout

    def lock_priority(self, now: float) -> int:
        """Highest priority among the locked locks; -1 when none is locked."""
        locked = [
            s.priority
            for name, s in self.locks.items()
            if self._lock_state[name] or self._expired(s, self._lock_stamp[name], now)
        ]
        return max(locked, default=-1)

    def masked(self, name: str, now: float) -> bool:
        source = self.inputs[name]
        return self._expired(source, self._input_stamp[name], now) or source.priority < self.lock_priority(now)

    def selected(self, now: float) -> Optional[str]:
        """The input whose messages pass now, or None."""
        best, best_priority = None, -1
        for name, source in self.inputs.items():
            if not self.masked(name, now) and source.priority > best_priority:
                best, best_priority = name, source.priority
        return best

    def on_input(self, name: str, now: float) -> bool:
        """Records a message of input ``name``; True if it is to be relayed."""
        self._input_stamp[name] = now
        return self.selected(now) == name

    def on_lock(self, name: str, locked: bool, now: float) -> None:
        self._lock_stamp[name] = now
        self._lock_state[name] = bool(locked)

    def status(self, now: float) -> Dict[str, Any]:
        """State for diagnostics: per input its age [s] and mask, per lock its state, the selection."""

        def age(stamp: Optional[float]) -> Optional[float]:
            return None if stamp is None else now - stamp

        return {
            "selected": self.selected(now),
            "lock_priority": self.lock_priority(now),
            "inputs": [
                {
                    "name": s.name,
                    "topic": s.topic,
                    "priority": s.priority,
                    "age": age(self._input_stamp[s.name]),
                    "masked": self.masked(s.name, now),
                }
                for s in self.inputs.values()
            ],
            "locks": [
                {
                    "name": s.name,
                    "topic": s.topic,
                    "priority": s.priority,
                    "age": age(self._lock_stamp[s.name]),
                    "locked": self._lock_state[s.name] or self._expired(s, self._lock_stamp[s.name], now),
                }
                for s in self.locks.values()
            ],
        }
