"""The Linux joystick API (``/dev/input/jsN``) without ROS: events, the joystick's state, when to publish it.

A joystick device gives ``struct js_event`` records of 8 bytes, little-endian: ``u32 time`` [ms],
``s16 value``, ``u8 type``, ``u8 number``. ``type`` is ``JS_EVENT_BUTTON`` or ``JS_EVENT_AXIS``, or'ed
with ``JS_EVENT_INIT`` for the events that describe the initial state right after the device opens.

The behaviour is that of the ROS ``joy`` package's ``joy_node`` (joystick_drivers, ROS 1):

- axes are ``-value / 32767`` (the joy package's sign: pushing a stick up or left gives a positive
  value, as REP 103's x forward and y left expect), with the dead zone cut out of the middle and the
  rest rescaled so the output is continuous: ``(|v| - dz) / (32767 - dz)`` beyond it, 0 inside it;
  clamped to -1..1 (-32768 would otherwise give slightly more than 1);
- buttons are 0 or 1; the arrays grow to the highest axis and button number seen;
- initial-state axis events size the axes but leave their value 0 unless ``default_trig_val`` is set,
  as the joy package does (the kernel may report the state of when the device was last closed, and a
  stick held at plug-in should not move the robot before it is moved);
- a button change is published at once, axis changes and initial-state events are merged for
  ``coalesce_interval`` seconds; while nothing changes the last state is repeated at ``autorepeat_rate``.

:class:`JoystickReader` opens a device (or a FIFO standing in for one) non-blocking and reads its
events; a missing or unplugged device (open fails, ``ENODEV``, end of file) raises
:class:`DeviceUnavailable`. A FIFO without a writer reads end of file, so it counts as unplugged.
"""

import errno
import os
import struct
from typing import List, NamedTuple, Optional, Tuple

from .errors import DeviceUnavailable

JS_EVENT_BUTTON = 0x01
JS_EVENT_AXIS = 0x02
JS_EVENT_INIT = 0x80
EVENT_SIZE = 8
AXIS_MAX = 32767.0
MAX_DEADZONE = 0.9

_EVENT = struct.Struct("<IhBB")
assert _EVENT.size == EVENT_SIZE


class JsEvent(NamedTuple):
    """One ``struct js_event``."""

    time: int  # [ms], the driver's clock
    value: int  # -32767..32767 for an axis (-32768 possible), 0 or 1 for a button
    type: int  # JS_EVENT_BUTTON or JS_EVENT_AXIS, or'ed with JS_EVENT_INIT for the initial state
    number: int  # the axis or button number

    @property
    def is_init(self) -> bool:
        return bool(self.type & JS_EVENT_INIT)

    @property
    def is_button(self) -> bool:
        return self.type & ~JS_EVENT_INIT == JS_EVENT_BUTTON

    @property
    def is_axis(self) -> bool:
        return self.type & ~JS_EVENT_INIT == JS_EVENT_AXIS


def pack_event(time: int, value: int, type_: int, number: int) -> bytes:
    """The 8 bytes of one js_event (what the kernel writes; the tests' devices use it)."""
    return _EVENT.pack(time & 0xFFFFFFFF, value, type_, number)


def parse_events(data: bytes) -> Tuple[List[JsEvent], bytes]:
    """The whole events in ``data`` and the bytes left over (the start of an event not yet read)."""
    whole = len(data) - len(data) % EVENT_SIZE
    events = [JsEvent(*_EVENT.unpack_from(data, i)) for i in range(0, whole, EVENT_SIZE)]
    return events, bytes(data[whole:])


def scale_axis(value: int, deadzone: float) -> float:
    """An axis value in -1..1 with the joy package's sign (negated) and continuous dead zone."""
    unscaled = AXIS_MAX * deadzone
    if value > unscaled:
        shifted = value - unscaled
    elif value < -unscaled:
        shifted = value + unscaled
    else:
        return 0.0
    scaled = -shifted / (AXIS_MAX - unscaled)
    return max(-1.0, min(1.0, scaled))


class Settings(NamedTuple):
    deadzone: float
    autorepeat_rate: float  # [Hz], 0: off
    coalesce_interval: float  # [s]


def check_settings(deadzone: float, autorepeat_rate: float, coalesce_interval: float) -> Tuple[Settings, List[str]]:
    """The parameters as the joy package corrects them, and a warning for each correction."""
    warnings = []
    if deadzone >= 1:
        warnings.append(
            f"deadzone {deadzone} is given in raw units; it is a fraction of the axis range (-1..1): "
            f"using {deadzone / AXIS_MAX:.4f}"
        )
        deadzone /= AXIS_MAX
    if deadzone > MAX_DEADZONE:
        warnings.append(f"deadzone {deadzone} greater than {MAX_DEADZONE}: using {MAX_DEADZONE}")
        deadzone = MAX_DEADZONE
    if deadzone < 0:
        warnings.append(f"deadzone {deadzone} less than 0: using 0")
        deadzone = 0.0
    if autorepeat_rate < 0:
        warnings.append(f"autorepeat_rate {autorepeat_rate} less than 0: using 0 (off)")
        autorepeat_rate = 0.0
    if coalesce_interval < 0:
        warnings.append(f"coalesce_interval {coalesce_interval} less than 0: using 0")
        coalesce_interval = 0.0
    if autorepeat_rate > 0 and coalesce_interval > 0 and autorepeat_rate > 1.0 / coalesce_interval:
        warnings.append(
            f"autorepeat_rate ({autorepeat_rate} Hz) > 1/coalesce_interval ({1.0 / coalesce_interval} Hz) "
            "does not make sense: repeats come no faster than the coalesce interval"
        )
    return Settings(float(deadzone), float(autorepeat_rate), float(coalesce_interval)), warnings


class JoystickState:
    """The axes (-1..1) and buttons (0/1) of a joystick, updated event by event."""

    def __init__(self, deadzone: float = 0.05, default_trig_val: bool = False):
        self.deadzone = deadzone
        self.default_trig_val = default_trig_val
        self.axes: List[float] = []
        self.buttons: List[int] = []

    def reset(self) -> None:
        """Forgets everything (a device that opens again reports its state anew)."""
        self.axes = []
        self.buttons = []

    def apply(self, event: JsEvent) -> bool:
        """Applies one event; False for an event of an unknown type, which changes nothing."""
        if event.is_button:
            _grow(self.buttons, event.number, 0)
            self.buttons[event.number] = 1 if event.value else 0
            return True
        if event.is_axis:
            _grow(self.axes, event.number, 0.0)
            if not event.is_init or self.default_trig_val:
                self.axes[event.number] = scale_axis(event.value, self.deadzone)
            return True
        return False

    def neutral(self) -> Tuple[List[float], List[int]]:
        """Axes and buttons of the same sizes, all 0: what is published when the device goes away."""
        return [0.0] * len(self.axes), [0] * len(self.buttons)


def _grow(values: list, number: int, fill) -> None:
    if number >= len(values):
        values.extend([fill] * (number + 1 - len(values)))


class PublishSchedule:
    """When to publish the state, as joy_node does; times are seconds on any monotonic clock.

    A button change (not an initial-state one) is published at once, with any axis change waiting.
    Axis changes and initial-state events start a coalesce timer (not restarted by further events):
    everything that arrives before it runs out goes into one message. While nothing is waiting, the
    last message is repeated every ``1 / autorepeat_rate`` seconds once one has been published.
    """

    def __init__(self, coalesce_interval: float, autorepeat_rate: float):
        self.coalesce_interval = coalesce_interval
        self.repeat_interval = 1.0 / autorepeat_rate if autorepeat_rate > 0 else None
        self.reset()

    def reset(self) -> None:
        self.deadline: Optional[float] = None  # of the waiting publication
        self.last_published: Optional[float] = None

    def on_event(self, event: JsEvent, now: float) -> bool:
        """True when the state after ``event`` must be published now."""
        if event.is_button and not event.is_init:
            return True
        if (event.is_axis or event.is_button) and self.deadline is None:
            self.deadline = now + self.coalesce_interval
        return False

    def next_time(self) -> Optional[float]:
        """When the next publication is due (a waiting one, or a repeat); None: not before an event."""
        if self.deadline is not None:
            return self.deadline
        if self.repeat_interval is not None and self.last_published is not None:
            return self.last_published + self.repeat_interval
        return None

    def due(self, now: float) -> bool:
        due = self.next_time()
        return due is not None and now >= due

    def published(self, now: float) -> None:
        self.deadline = None
        self.last_published = now


# read errors that mean the device went away (ENODEV: unplugged joystick)
_GONE = {errno.ENODEV, errno.ENXIO, errno.EIO, errno.EBADF, errno.ENOENT}
_READ_SIZE = 64 * EVENT_SIZE
_MAX_READS = 16  # per call, so a flood of events cannot stall the caller


class JoystickReader:
    """Reads the events of one joystick device, non-blocking.

    :meth:`open` raises :class:`DeviceUnavailable` when the device cannot be opened, or reads end of
    file at once (a FIFO without a writer); :meth:`read_events` returns the events available (maybe
    none) and raises :class:`DeviceUnavailable` when the device went away (end of file, ``ENODEV``),
    after the events read before it have been returned. Either closes the device before raising.
    """

    def __init__(self, path: str):
        self.path = path
        self.fd: Optional[int] = None
        self._rest = b""
        self._events: List[JsEvent] = []
        self._gone: Optional[str] = None

    @property
    def is_open(self) -> bool:
        return self.fd is not None

    @property
    def pending(self) -> bool:
        """Events already read, or a loss already seen: read_events() answers without waiting."""
        return bool(self._events) or self._gone is not None

    def fileno(self) -> int:
        if self.fd is None:
            raise ValueError(f"{self.path} is not open")
        return self.fd

    def open(self) -> None:
        self.close()
        try:
            self.fd = os.open(self.path, os.O_RDONLY | os.O_NONBLOCK)
        except OSError as e:
            raise DeviceUnavailable(self.path, _reason(e)) from None
        # a FIFO without a writer opens, then reads end of file: no device yet
        self._events = self._read()
        if self._gone is not None:
            reason, self._events = self._gone, []
            self.close()
            raise DeviceUnavailable(self.path, reason)

    def read_events(self) -> List[JsEvent]:
        if self.fd is None:
            raise DeviceUnavailable(self.path, "not open")
        events, self._events = self._events + self._read(), []
        if events:
            return events
        if self._gone is not None:
            reason = self._gone
            self.close()
            raise DeviceUnavailable(self.path, reason)
        return []

    def close(self) -> None:
        if self.fd is not None:
            try:
                os.close(self.fd)
            except OSError:
                pass
        self.fd = None
        self._rest = b""
        self._events = []
        self._gone = None

    def _read(self) -> List[JsEvent]:
        """The events readable now; a loss is noted in _gone (the events before it are kept)."""
        if self._gone is not None or self.fd is None:
            return []
        data = self._rest
        for _ in range(_MAX_READS):
            try:
                chunk = os.read(self.fd, _READ_SIZE)
            except InterruptedError:
                continue
            except BlockingIOError:
                break
            except OSError as e:
                self._gone = _reason(e) if e.errno in _GONE else f"read failed: {_reason(e)}"
                break
            if not chunk:
                self._gone = "end of file (unplugged, or no writer)"
                break
            data += chunk
            if len(chunk) < _READ_SIZE:
                break
        events, self._rest = parse_events(data)
        return events

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def _reason(e: OSError) -> str:
    name = errno.errorcode.get(e.errno, str(e.errno)) if e.errno is not None else "error"
    return f"{e.strerror or e} ({name})"
