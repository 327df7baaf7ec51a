"""A CAN bus shared across processes: one SLCAN pseudo-terminal per participant, no kernel module.

Each port is a pseudo-terminal whose far end a process opens as an SLCAN adapter (python-can's
``slcan`` interface, ``slcan_attach``, SavvyCAN ...); the hub joins the ports and any in-process
participant (the device emulator) on python-can's ``virtual`` bus, so every participant sees every
other one's frames, as on a wire. SLCAN commands (``O``, ``C``, ``S8``, ``V``, ``N`` ...) are
acknowledged as an adapter does. A port can be dropped (its pseudo-terminal closed, as an adapter
unplugged: its link goes away with it) and comes back at the same link path.

No ROS here; ``can_emulator_node`` runs a hub with the emulator.
"""

import errno
import os
import select
import termios
import threading
import tty
from typing import List, Optional

import can

ACK = b"\r"
NACK = b"\a"
MAX_PENDING = 65536  # [bytes] waiting for a participant that does not read; whole frames beyond are dropped


def encode_slcan(msg: can.Message) -> bytes:
    if msg.is_extended_id:
        head = ("R%08X%d" if msg.is_remote_frame else "T%08X%d") % (msg.arbitration_id, msg.dlc)
    else:
        head = ("r%03X%d" if msg.is_remote_frame else "t%03X%d") % (msg.arbitration_id, msg.dlc)
    body = "" if msg.is_remote_frame else bytes(msg.data).hex().upper()
    return (head + body).encode() + ACK


def decode_slcan(line: bytes) -> Optional[can.Message]:
    """A frame from one SLCAN line (without its terminator); None for anything else. ValueError if malformed."""
    if not line or line[:1] not in b"tTrR":
        return None
    text = line.decode("ascii")
    extended = text[0] in "TR"
    n = 8 if extended else 3
    can_id = int(text[1 : 1 + n], 16)
    dlc = int(text[1 + n])
    if not 0 <= dlc <= 8:
        raise ValueError(f"dlc {dlc}")
    remote = text[0] in "rR"
    data = b"" if remote else bytes.fromhex(text[2 + n : 2 + n + 2 * dlc])
    if not remote and len(data) != dlc:
        raise ValueError("data shorter than its dlc")
    return can.Message(arbitration_id=can_id, is_extended_id=extended, is_remote_frame=remote, dlc=dlc, data=data)


class SlcanPort:
    """One participant's pseudo-terminal, joined to the hub's virtual bus."""

    def __init__(self, channel: str, link: Optional[str] = None):
        self.channel = channel
        self.link = link
        self.master = self.slave = -1
        self.bus: Optional[can.BusABC] = None
        self.buffer = b""
        self.pending = b""  # frames the terminal had no room for yet
        self.channel_open = False  # SLCAN "O" .. "C": frames flow only while the channel is open
        self.malformed = 0
        self.dropped = 0  # frames dropped for a participant that does not read
        self.received = 0  # frames the participant wrote
        self.forwarded = 0  # frames given to the participant (written, or waiting for room)
        self.open()

    @property
    def is_open(self) -> bool:
        return self.master >= 0

    def open(self) -> None:
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)  # no echo, no line discipline: bytes as they are
        os.set_blocking(self.master, False)
        self.path = os.ttyname(self.slave)
        if self.link:
            tmp = self.link + ".new"
            if os.path.lexists(tmp):
                os.unlink(tmp)
            os.symlink(self.path, tmp)
            os.replace(tmp, self.link)
        self.bus = can.Bus(interface="virtual", channel=self.channel, receive_own_messages=False)
        self.buffer = self.pending = b""
        self.channel_open = False

    def close(self) -> None:
        """As an adapter unplugged: the terminal and its link go away, as udev removes an unplugged
        adapter's device and its link, until reopened. A link left dangling pointed at a terminal
        number the system hands to the next process that opens one: a driver reopening it reached
        another emulator's bus (two SLCAN rostests side by side)."""
        if self.link and os.path.islink(self.link) and os.readlink(self.link) == self.path:
            os.unlink(self.link)
        if self.bus is not None:
            self.bus.shutdown()
            self.bus = None
        for fd in (self.master, self.slave):
            if fd >= 0:
                os.close(fd)
        self.master = self.slave = -1

    def from_terminal(self) -> None:
        """Reads what the participant wrote: frames go to the hub, commands are acknowledged."""
        try:
            chunk = os.read(self.master, 65536)
        except OSError as e:
            if e.errno in (errno.EAGAIN, errno.EIO):
                return
            raise
        self.buffer += chunk
        *lines, self.buffer = self.buffer.split(b"\r")
        replies = b""
        for line in lines:
            line = line.strip(b"\n")
            if not line:
                continue
            try:
                msg = decode_slcan(line)
            except ValueError:
                self.malformed += 1
                replies += NACK
                continue
            if msg is not None:
                self.bus.send(msg)
                self.received += 1
                continue
            command = line[:1]
            if command == b"O":  # the channel opens: what an earlier participant left unread is stale
                termios.tcflush(self.slave, termios.TCIFLUSH)
                self.pending = b""
                while self.bus.recv(timeout=0.0) is not None:
                    pass
                self.channel_open = True
            elif command == b"C":
                self.channel_open = False
            if command == b"V":
                replies += b"V1013" + ACK
            elif command == b"N":
                replies += b"NTHV1" + ACK
            elif command in b"OCSsFZMm":
                replies += ACK
            else:
                replies += NACK
        if replies:
            self.pending += replies

    def to_terminal(self) -> None:
        """Writes the other participants' frames to the participant while its channel is open."""
        frames = []
        while True:
            msg = self.bus.recv(timeout=0.0)
            if msg is None:
                break
            if self.channel_open:
                frames.append(encode_slcan(msg))
        for frame in frames:  # whole frames only: a participant never reads half a line
            if len(self.pending) + len(frame) > MAX_PENDING:
                self.dropped += 1
            else:
                self.pending += frame
                self.forwarded += 1
        if self.pending:
            self.pending = self.pending[self._write(self.pending) :]

    def _write(self, data: bytes) -> int:
        """Bytes written (the terminal may take part of them)."""
        try:
            return os.write(self.master, data)
        except OSError as e:
            if e.errno in (errno.EAGAIN, errno.EIO):
                return 0
            raise


class Hub:
    """Pseudo-terminal ports and in-process participants on one virtual channel."""

    def __init__(self, channel: str, ports: int = 2, link_dir: Optional[str] = None):
        self.channel = channel
        if link_dir:
            os.makedirs(link_dir, exist_ok=True)
        self.ports: List[SlcanPort] = [
            SlcanPort(channel, os.path.join(link_dir, f"port{k}") if link_dir else None) for k in range(ports)
        ]
        self.lock = threading.Lock()  # pump, drop and restore may run in different threads

    def drop(self, k: int) -> None:
        """Port k's pseudo-terminal goes away, as an adapter unplugged."""
        with self.lock:
            self.ports[k].close()

    def restore(self, k: int) -> None:
        """Port k comes back (a new pseudo-terminal) at the same link."""
        with self.lock:
            if not self.ports[k].is_open:
                self.ports[k].open()

    def participant(self) -> can.BusABC:
        """An in-process participant's bus (the emulator's)."""
        return can.Bus(interface="virtual", channel=self.channel, receive_own_messages=False)

    def pump(self, timeout: float = 0.002) -> None:
        """Moves frames once: waits up to timeout for a participant to write."""
        with self.lock:
            open_ports = [p for p in self.ports if p.is_open]
            if open_ports:
                ready, _, _ = select.select([p.master for p in open_ports], [], [], timeout)
                for p in open_ports:
                    if p.master in ready:
                        p.from_terminal()
            for p in open_ports:
                p.to_terminal()

    def summary(self) -> str:
        """What each port carried and lost, in one line."""
        return "; ".join(
            f"port{k}: {p.received} frames in, {p.forwarded} out, {p.malformed} malformed, {p.dropped} dropped"
            for k, p in enumerate(self.ports)
        )

    def close(self) -> None:
        with self.lock:
            for p in self.ports:
                p.close()
                if p.link and os.path.lexists(p.link):
                    os.unlink(p.link)
