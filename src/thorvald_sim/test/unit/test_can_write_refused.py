"""A CAN link that refuses writes for a while (a full buffer, a write timeout) is not a lost device.

base_driver's CAN base against the emulated devices on python-can's in-process virtual bus, stepped
on one simulated clock (issue 45, item 2). The link is a test double of the serial port or socket
between them: python-can's virtual bus whose writes fail, while told to, with the exception
python-can raises for a full buffer (the slcan interface's pyserial write timeout, SocketCAN's
ENOBUFS). The base keeps the bus, keeps reading, and sends the newest commands when the link takes
them again; only a device's own silence (LOST_AFTER) loses it; a broken port is shut and reopened,
which over SLCAN costs the 2 s python-can waits after opening a port (the devices unheard meanwhile:
what every refused write cost before, issue 45's "every drive lost for about a second").
"""

import errno
import itertools
import os

import can
import pytest
import serial
from can.exceptions import error_check
from can.interfaces.slcan import slcanBus

from thorvald_base.bases.can_base import CanBase
from thorvald_base.bases.handle import Frame
from thorvald_base.can.devices import LOST_AFTER
from thorvald_base.can.outbox import MAX_WAIT
from thorvald_base.kinematics import DriveCommand
from thorvald_model import load_robot_config
from thorvald_sim.can.emulator import CanEmulator

SLCAN_OPEN = slcanBus._SLEEP_AFTER_SERIAL_OPEN  # [s] python-can's slcan waits after opening a port

HERE = os.path.dirname(os.path.abspath(__file__))
STD = os.path.join(
    HERE, "..", "..", "..", "thorvald_model", "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml"
)
CYCLE = 0.02  # [s] base_driver at 50 Hz
# A refused link is tried three times in this test's cycle (at the polls of sending and reading, and
# after the cycle's frames are queued): LOST_AFTER's worth of refused writes at 50 Hz is
# 3 * 2 s / 0.02 s = 300. (base_driver's cycle reads once more before it sends: four.)
WRITES_PER_CYCLE = 3
TIMEOUTS_WORTH = round(WRITES_PER_CYCLE * LOST_AFTER / CYCLE)
_channels = itertools.count()


def python_can_error(cause: BaseException) -> can.CanError:
    """The exception python-can's slcan interface raises from a failed pyserial write (error_check)."""
    try:
        with error_check("Could not write to serial device"):
            raise cause
    except can.CanError as e:
        return e
    raise AssertionError("unreachable")


FULL_BUFFER = {
    "slcan": lambda: python_can_error(serial.SerialTimeoutException("Write timeout")),
    "socketcan": lambda: can.CanOperationError("Failed to transmit: No buffer space available", errno.ENOBUFS),
}
BROKEN = lambda: python_can_error(serial.SerialException("write failed: [Errno 5] Input/output error"))  # noqa: E731


class Link(can.BusABC):
    """The base's end of the wire: a virtual bus whose next ``refuse`` writes fail with ``error()``."""

    def __init__(self, channel: str, error=FULL_BUFFER["slcan"]):
        self.inner = can.Bus(interface="virtual", channel=channel, receive_own_messages=False)
        self.name = channel
        self.error = error
        self.refuse = 0
        self.refused = 0
        self.closed = False
        super().__init__(channel=channel)

    def send(self, msg, timeout=None):
        if self.refuse > 0:
            self.refuse -= 1
            self.refused += 1
            raise self.error()
        self.inner.send(msg, timeout)

    def _recv_internal(self, timeout):
        return self.inner.recv(timeout), False

    def shutdown(self):
        self.closed = True
        self.inner.shutdown()
        super().shutdown()


class Clock:
    """The simulated time base_driver's cycle and the devices share [s]."""

    t = 0.0


@pytest.fixture
def robot():
    """(a CAN base on a Link, the emulator of the same robot) on a fresh virtual channel."""
    channel = f"thorvald-refused-{os.getpid()}-{next(_channels)}"
    config = load_robot_config(STD)
    links = [Link(channel)]
    clock = Clock()
    emulator = CanEmulator(config, can.Bus(interface="virtual", channel=channel, receive_own_messages=False))

    def reopen():
        """An SLCAN port reopened: base_driver's loop waits 2 s while the devices go on, unheard."""
        end = clock.t + SLCAN_OPEN
        while clock.t < end:
            emulator.step(clock.t)
            clock.t += CYCLE / 4
        links.append(Link(channel))
        return links[-1]

    handle = CanBase(config, links[0], reopen=reopen)
    handle.links, handle.clock = links, clock  # the link the base holds now is links[-1]
    yield handle, emulator
    handle.close()
    emulator.drop_bus()


def cycle(handle, emulator, command, clock, emulator_reads=True):
    """One base_driver cycle (commands out, states in) with the devices stepped meanwhile."""
    handle.send_drive_commands([command] * 4, clock.t)
    if emulator_reads:
        for k in range(4):  # the devices run faster than the base's cycle
            emulator.step(clock.t + k * CYCLE / 4)
    clock.t += CYCLE
    handle.read_drive_states(clock.t)


def sequences(emulator):
    return [c.last_sequence for c in emulator.controllers.values()]


@pytest.mark.parametrize("kind", sorted(FULL_BUFFER))
@pytest.mark.parametrize("k", [1, 2, 10, 100, TIMEOUTS_WORTH - 10])
def test_k_refused_writes_lose_no_drive_and_the_newest_commands_arrive(robot, k, kind):
    handle, emulator = robot
    link = handle.links[0]
    link.error = FULL_BUFFER[kind]
    clock = handle.clock
    for _ in range(50):
        cycle(handle, emulator, DriveCommand(0.2, 0.5), clock)
    assert handle.stopped_for_lost == []
    link.refuse = k
    seen = sequences(emulator)
    speeds = itertools.count(1)
    refused_cycles = 0
    for _ in range(k):  # a cycle refuses one write at least
        command = DriveCommand(0.2, 0.5 + 0.002 * next(speeds))  # a new command every cycle
        cycle(handle, emulator, command, clock)
        refused_cycles += 1
        assert handle.stopped_for_lost == [], f"a drive lost after {link.refused} refused writes"
        now = sequences(emulator)
        assert all(b >= a for a, b in zip(seen, now)), "a stale command arrived after a newer one"
        seen = now
        if link.refuse == 0:
            break
    assert link.refused == k and refused_cycles <= k // WRITES_PER_CYCLE + 1
    assert handle.bus is link, "the bus was shut for a full buffer"
    # the link takes writes again: the newest command is there within the cycle, nothing piled up
    cycle(handle, emulator, command, clock)
    for c in emulator.controllers.values():
        assert c.channels[0].target == pytest.approx(command.speed, rel=0.01)
        assert c.last_sequence == handle.controller(c.node).sequence
    diagnostics = handle.diagnostics(clock.t)
    assert diagnostics["writes refused"] == str(k)
    assert (diagnostics["bus reopened"], diagnostics["send errors"], diagnostics["frames dropped"]) == ("0", "0", "0")
    assert diagnostics["frames waiting"] == "0" and int(diagnostics["frames queued"]) > 0
    # the newest command replaced the one waiting for each controller: one waiting frame per id at most
    assert int(diagnostics["commands superseded"]) <= 8 * refused_cycles
    assert (
        "Write timeout" in diagnostics["last write refused"] or "No buffer space" in diagnostics["last write refused"]
    )
    assert "last error" not in diagnostics  # nothing for base_driver to warn about as a bus error
    # a frame waited at most one cycle; the whole refusal, for those given first
    assert float(diagnostics["worst write latency"].split()[0]) <= refused_cycles * CYCLE + 1e-9


def test_a_link_refusing_for_longer_than_the_timeout_still_loses_no_talking_device(robot):
    """The devices still report: they are not silent, so not lost. Frames nothing replaces (a relay
    setting) wait at most MAX_WAIT and are then dropped and counted, never sent late."""
    handle, emulator = robot
    link = handle.links[0]
    clock = handle.clock
    for _ in range(50):
        cycle(handle, emulator, DriveCommand(0.0, 0.3), clock)
    link.refuse = 10**9
    handle.set_relay(0, 0, True)  # an IO board's relay (the main enclosure's board, id 0)
    for _ in range(round(3 * LOST_AFTER / CYCLE)):
        cycle(handle, emulator, DriveCommand(0.0, 0.3), clock)
        assert handle.stopped_for_lost == []
    diagnostics = handle.diagnostics(clock.t)
    assert diagnostics["frames dropped"] == "1" and diagnostics["frames waiting"] == "8"  # the commands
    link.refuse = 0
    cycle(handle, emulator, DriveCommand(0.0, 0.4), clock)
    assert [c.channels[0].target for c in emulator.controllers.values()] == [pytest.approx(0.4, rel=0.01)] * 4
    assert emulator.ios[0].relays[0] is False  # the relay frame was MAX_WAIT late: dropped, not sent
    assert MAX_WAIT < 3 * LOST_AFTER


def test_muting_forgets_the_relayed_frames_a_refused_write_left(robot):
    handle, emulator = robot
    link = handle.links[0]
    clock = handle.clock
    implement = can.Bus(interface="virtual", channel=link.name, receive_own_messages=False)
    try:
        cycle(handle, emulator, DriveCommand(0.0, 0.0), clock)
        link.refuse = 10**9
        for k in range(3):
            assert handle.relay(Frame(0x123, bytes([k]))) is None
        cycle(handle, emulator, DriveCommand(0.0, 0.0), clock)
        assert handle.diagnostics(clock.t)["frames waiting"] == "11"  # 8 commands, 3 relayed
        handle.mute(True)
        assert handle.diagnostics(clock.t)["frames waiting"] == "8"
        link.refuse = 0
        cycle(handle, emulator, DriveCommand(0.0, 0.0), clock)
        seen = []
        while True:
            msg = implement.recv(0.0)
            if msg is None:
                break
            seen.append(msg.arbitration_id)
        assert 0x123 not in seen and 0x201 in seen
    finally:
        implement.shutdown()


@pytest.mark.slow  # a CAN base and the emulator over thousands of cycles
def test_a_reader_that_stops_reading_fills_the_virtual_queue_and_loses_no_drive():
    """The emulator stops reading for 1 s: python-can's own virtual bus refuses the base's writes
    (its receiver's queue of 16 frames is full); the base keeps its bus and the newest commands
    arrive when the emulator reads again."""
    channel = f"thorvald-refused-{os.getpid()}-{next(_channels)}"
    config = load_robot_config(STD)
    handle = CanBase(config, can.Bus(interface="virtual", channel=channel, receive_own_messages=False))
    emulator = CanEmulator(
        config, can.Bus(interface="virtual", channel=channel, receive_own_messages=False, rx_queue_size=16)
    )
    try:
        clock = Clock()
        for _ in range(50):
            cycle(handle, emulator, DriveCommand(0.0, 0.3), clock)
        for k in range(round(1.0 / CYCLE)):  # the reader stalls: it neither reads nor reports
            cycle(handle, emulator, DriveCommand(0.0, 0.3 + 0.01 * k), clock, emulator_reads=False)
        assert int(handle.diagnostics(clock.t)["writes refused"]) > 0
        for _ in range(3):
            cycle(handle, emulator, DriveCommand(0.0, 0.8), clock)
            assert handle.stopped_for_lost == []
        assert [c.channels[0].target for c in emulator.controllers.values()] == [pytest.approx(0.8, rel=0.01)] * 4
        assert handle.counters.reopened == 0 and handle.bus is not None
    finally:
        handle.close()
        emulator.drop_bus()


def test_a_broken_port_is_shut_and_reopened(robot):
    handle, emulator = robot
    link = handle.links[0]
    clock = handle.clock
    for _ in range(50):
        cycle(handle, emulator, DriveCommand(0.0, 0.3), clock)
    link.error, link.refuse = BROKEN, 1
    cycle(handle, emulator, DriveCommand(0.0, 0.4), clock)
    assert len(handle.links) == 2 and handle.bus is handle.links[1] and link.closed
    # what reopening costs: the devices went unheard for python-can's 2 s, every wheel stops a cycle
    cycle(handle, emulator, DriveCommand(0.0, 0.5), clock)
    assert handle.stopped_for_lost == ["drive0", "drive1", "drive2", "drive3"]
    for _ in range(3):
        cycle(handle, emulator, DriveCommand(0.0, 0.5), clock)
    assert [c.channels[0].target for c in emulator.controllers.values()] == [pytest.approx(0.5, rel=0.01)] * 4
    diagnostics = handle.diagnostics(clock.t)
    assert (diagnostics["send errors"], diagnostics["bus reopened"], diagnostics["writes refused"]) == ("1", "1", "0")
    assert "Input/output error" in diagnostics["last error"]
    assert handle.stopped_for_lost == []
