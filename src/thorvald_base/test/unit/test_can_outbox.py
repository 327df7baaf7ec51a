"""The outbox of frames a refused write left (thorvald_base.can.outbox) and which write failures are
refusals: python-can's and pyserial's own exceptions, raised the way they raise them."""

import errno
import queue

import can
import pytest
import serial
from can.exceptions import error_check

from thorvald_base.can.outbox import MAX_WAIT, Outbox, Waiting, write_refused


def raised(cause: BaseException, message: str = "Could not write to serial device") -> can.CanError:
    """What python-can's slcan interface raises from its write: the interface's error wrapped by error_check."""
    try:
        with error_check(message):
            raise cause
    except can.CanError as e:
        return e
    raise AssertionError("error_check raised nothing")


@pytest.mark.parametrize(
    "error",
    [
        raised(serial.SerialTimeoutException("Write timeout")),  # slcan: pyserial's write timeout
        can.CanOperationError("Transmit buffer full"),  # socketcan: the socket not writable in time
        can.CanOperationError("Failed to transmit: No buffer space available", errno.ENOBUFS),  # socketcan
        can.CanOperationError("Could not send message to one or more recipients"),  # virtual, rx_queue_size
        can.CanOperationError("Could not write to serial device: its buffer is full", errno.EAGAIN),  # ours
        raised(BlockingIOError(errno.EAGAIN, "Resource temporarily unavailable")),
        raised(queue.Full()),
    ],
    ids=["slcan-timeout", "socketcan-select", "socketcan-enobufs", "virtual-full", "buffered-slcan", "eagain", "queue"],
)
def test_a_full_buffer_is_a_refusal(error):
    assert write_refused(error)


@pytest.mark.parametrize(
    "error",
    [
        raised(serial.SerialException("write failed: [Errno 5] Input/output error")),  # the hub's end closed
        raised(serial.PortNotOpenError()),
        can.CanOperationError("Could not write to serial device: Input/output error", errno.EIO),  # ours
        can.CanOperationError("Failed to transmit: No such device or address", errno.ENXIO),  # socketcan, unplugged
        can.CanOperationError("Cannot operate on a closed bus"),
    ],
    ids=["slcan-eio", "slcan-closed", "buffered-slcan-eio", "socketcan-gone", "closed"],
)
def test_a_broken_port_is_not(error):
    assert not write_refused(error)


def frame(can_id, data=b"\x00", t=0.0):
    return Waiting(can_id, data, since=t)


def test_a_newer_command_replaces_the_waiting_one_in_its_place():
    box = Outbox()
    box.put(frame(0x201, b"a"), key=0x201)
    box.put(frame(0x301, b"setup"))  # a setup: never replaced
    box.put(frame(0x501, b"a"), key=0x501)
    box.sent(0, 0.0)  # the write was refused: all three wait
    box.put(frame(0x201, b"b", 0.02), key=0x201)
    box.put(frame(0x301, b"setup"))
    box.put(frame(0x501, b"b", 0.02), key=0x501)
    assert [(f.can_id, f.data) for f in box.waiting(0.02)] == [
        (0x201, b"b"),
        (0x301, b"setup"),
        (0x501, b"b"),
        (0x301, b"setup"),
    ]
    assert box.counters.superseded == 2 and box.counters.deferred == 3
    box.sent(4, 0.04)
    assert len(box) == 0
    # the replacements waited 0.02 s, the first setup 0.04 s
    assert box.counters.worst_latency == pytest.approx(0.04)


def test_frames_wait_at_most_max_wait_and_the_queue_is_bounded():
    box = Outbox(limit=5)
    box.put(frame(0x201, t=0.0), key=0x201)
    for k in range(6):
        box.put(frame(0x124, bytes([k]), t=0.0))
    # beyond the limit the oldest frame nothing replaces goes; the command stays
    assert [f.data for f in box.waiting(0.0)] == [b"\x00", b"\x02", b"\x03", b"\x04", b"\x05"]
    assert box.counters.dropped == 2
    box.put(frame(0x124, b"new", t=MAX_WAIT), None)  # one more: frame 2 goes
    assert box.counters.dropped == 3
    # MAX_WAIT later the old ones are still in time; a cycle more and they are dropped, not sent late
    assert len(box.waiting(MAX_WAIT)) == 5
    assert [f.data for f in box.waiting(MAX_WAIT + 0.02)] == [b"new"]
    assert box.counters.dropped == 3 + 4


def test_frames_given_before_the_clock_is_known_wait_from_its_first_reading():
    box = Outbox()
    box.put(Waiting(0x691, b"\x00\x03"))  # the IO board's first command, before any cycle
    assert box.waiting(1.7e9)[0].since == 1.7e9  # base_driver's clock is ROS time: not "1.7e9 s late"
    box.sent(1, 1.7e9 + 0.02)
    assert box.counters.worst_latency == pytest.approx(0.02) and box.counters.dropped == 0
