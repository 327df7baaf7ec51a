"""thorvald_base's SLCAN bus writing to a pseudo-terminal nobody reads for a while: a full buffer is
a count of frames sent, never half a line; a closed far end is an error (python-can's own)."""

import contextlib
import os
import select
import tty

import can
import pytest

from thorvald_base.can.outbox import write_refused
from thorvald_base.can.slcan import BufferedSlcanBus


@pytest.fixture
def port():
    """(the bus on a terminal's slave end, its master end: the adapter's side, read by the test)."""
    master, slave = os.openpty()
    tty.setraw(slave)
    os.set_blocking(master, False)
    bus = BufferedSlcanBus(channel=os.ttyname(slave), sleep_after_open=0)
    assert read_all(master).endswith(b"O\r")  # python-can opens the channel
    yield bus, master
    with contextlib.suppress(can.CanError, OSError):
        bus.shutdown()
    for fd in (master, slave):
        with contextlib.suppress(OSError):
            os.close(fd)


def read_all(master) -> bytes:
    out = b""
    while select.select([master], [], [], 0.0)[0]:
        try:
            chunk = os.read(master, 65536)
        except BlockingIOError:
            break
        if not chunk:
            break
        out += chunk
    return out


def frames(first, n):
    return [
        can.Message(arbitration_id=0x200 + k % 0x80, data=(first + k).to_bytes(8, "little"), is_extended_id=False)
        for k in range(n)
    ]


def test_a_full_buffer_sends_whole_frames_and_the_rest_first_next_time(port):
    bus, master = port
    sent, given, partial = [], 0, False
    for _ in range(10000):  # until the terminal (about 20 KB on Linux) takes part of a batch only
        batch = frames(given, 50)
        n = bus.send_batch(batch, timeout=0)
        sent += batch[:n]
        given += 50
        partial = partial or bool(bus._unsent)  # the port took part of a frame: its buffer ended mid-line
        if n < len(batch):
            break
    # the kernel moves bytes to the reader's side in the background: the buffer is full for good a
    # little later, and then python-can's send says so with an error the base takes for a refusal
    for _ in range(100000):
        msg = frames(given, 1)[0]
        given += 1
        try:
            bus.send(msg, timeout=0)
        except can.CanOperationError as e:
            assert write_refused(e)
            break
        sent.append(msg)
        partial = partial or bool(bus._unsent)
    else:
        raise AssertionError("the terminal's buffer never filled")
    assert partial
    data = read_all(master)
    more = frames(10**6, 3)
    assert bus.send_batch(more, timeout=1.0) == 3
    expected = [b"t%03X8%s\r" % (m.arbitration_id, bytes(m.data).hex().upper().encode()) for m in sent + more]
    while len(data) < sum(map(len, expected)) and select.select([master], [], [], 5.0)[0]:
        data += read_all(master)
    assert data.split(b"\r") == [line[:-1] for line in expected] + [b""]  # whole lines, in order, none twice


def test_a_closed_far_end_is_a_broken_port(port):
    bus, master = port
    os.close(master)  # the hub unplugged the adapter
    with pytest.raises(can.CanOperationError) as broken:
        bus.send_batch(frames(0, 2), timeout=0)
    assert not write_refused(broken.value)  # the base shuts it and reopens
