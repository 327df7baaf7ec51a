"""python-can's SLCAN interface, reading what the serial port holds at once, writing without blocking.

python-can 4.1 (Debian 12's) reads an SLCAN adapter one byte per system call, a few thousand
calls per cycle on a 9-drive robot; later python-can releases read everything waiting at once,
which this subclass does on 4.1. ``send_batch`` writes several frames in one write (base_driver's
frames of a cycle).

Writes go to the port's file descriptor directly, not through pyserial's ``write``: with a write
timeout, pyserial raises ``SerialTimeoutException`` whenever the call outlasted the timeout, even
after every byte was written (its thread held up on a busy machine: calls of 86, 88 and 131 ms
against a 50 ms timeout raised after the write, with room in the buffer), and after writing part
of the data without saying how much; python-can reports both as "Could not write to serial
device", as it does an unplugged adapter. Here a write says how many frames went: a full buffer is
a number, not an error, and a line the port took part of is finished first at the next write, so
the adapter never sees half a frame followed by another. ``flush`` (tcdrain), which waits without
a bound for a real adapter to send what the kernel holds, is not called: the kernel sends it
anyway. Frames, commands and errors are python-can's own.
"""

import errno
import os
import select
import time
from typing import Optional, Sequence

import can
from can.exceptions import error_check
from can.interfaces.slcan import slcanBus

COMMAND_TIMEOUT = 1.0  # [s] for an SLCAN command ("O", "C", "S8" ...) to fit in the port's buffer


class BufferedSlcanBus(slcanBus):
    _unsent = b""  # the rest of a line the port took only part of: it goes before anything else

    def send_batch(self, messages: Sequence[can.Message], timeout: Optional[float] = None) -> int:
        """Writes the messages in order as one write; returns how many went, the rest did not.

        timeout [s]: how long to wait for room while the port's buffer is full (None: until there is
        room, 0: not at all). A message whose line the port took part of counts as sent: its rest
        goes first at the next write. CanOperationError when the port is broken (closed, gone).
        """
        lines = [self._line(msg) for msg in messages]
        before = self._unsent
        written = self._write_some(before + b"".join(lines), timeout)
        if written < len(before):
            self._unsent = before[written:]
            return 0
        written -= len(before)
        self._unsent = b""
        sent = 0
        for line in lines:
            if written <= 0:
                break
            if written < len(line):
                self._unsent = line[written:]
            written -= len(line)
            sent += 1
        return sent

    def send(self, msg: can.Message, timeout: Optional[float] = None) -> None:
        """python-can's send; a full buffer for timeout [s] is CanOperationError with errno EAGAIN."""
        if not self.send_batch([msg], timeout):
            raise can.CanOperationError("Could not write to serial device: its buffer is full", errno.EAGAIN)

    def _line(self, msg: can.Message) -> bytes:
        kind = "rR"[msg.is_extended_id] if msg.is_remote_frame else "tT"[msg.is_extended_id]
        head = ("%s%08X%d" if msg.is_extended_id else "%s%03X%d") % (kind, msg.arbitration_id, msg.dlc)
        return (head + ("" if msg.is_remote_frame else bytes(msg.data).hex().upper())).encode() + self.LINE_TERMINATOR

    def _write(self, string: str) -> None:
        """An SLCAN command (python-can's open, close, bitrate), after the rest of a frame's line."""
        data = self._unsent + string.encode() + self.LINE_TERMINATOR
        self._unsent = b""
        written = self._write_some(data, COMMAND_TIMEOUT)
        if written < len(data):
            self._unsent = data[written:]
            raise can.CanOperationError(
                f"Could not write to serial device: its buffer stayed full for {COMMAND_TIMEOUT:g} s", errno.EAGAIN
            )

    def _write_some(self, data: bytes, timeout: Optional[float]) -> int:
        """Bytes of data written, waiting up to timeout [s] for room; CanOperationError if the port is broken."""
        port = self.serialPortOrig
        fd = getattr(port, "fd", None)
        if fd is None:  # not a POSIX serial port (a pyserial URL handler): pyserial's own write
            with error_check("Could not write to serial device"):
                port.write_timeout = timeout
                port.write(data)
            return len(data)
        deadline = None if timeout is None else time.monotonic() + timeout
        done = 0
        while done < len(data):
            try:
                done += os.write(fd, data[done:])  # pyserial opens the port non-blocking
                continue
            except (BlockingIOError, InterruptedError):
                pass
            except OSError as e:  # EIO: the far end closed; EBADF: the port closed; ENXIO: unplugged
                raise can.CanOperationError(f"Could not write to serial device: {e.strerror}", e.errno) from e
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                break
            select.select([], [fd], [], left)
        return done

    def _read(self, timeout: Optional[float]) -> Optional[str]:
        port = self.serialPortOrig
        with error_check("Could not read from serial device"):
            waiting = port.in_waiting
            if waiting:
                self._buffer += port.read(waiting)
            deadline = None if timeout is None else time.monotonic() + timeout
            while self._end() < 0:
                remaining = None if deadline is None else deadline - time.monotonic()
                if remaining is not None and remaining <= 0:
                    return None
                port.timeout = remaining
                byte = port.read(1)  # waits up to the time left for the next byte
                if byte:
                    self._buffer += byte
                    waiting = port.in_waiting
                    if waiting:
                        self._buffer += port.read(waiting)
        end = self._end()
        line = self._buffer[: end + 1].decode()
        del self._buffer[: end + 1]
        return line

    def _end(self) -> int:
        """Index of the first line terminator (OK or ERROR) in the buffer, -1 if none."""
        ends = [i for i in (self._buffer.find(self._OK), self._buffer.find(self._ERROR)) if i >= 0]
        return min(ends) if ends else -1
