"""python-can's SLCAN interface, reading what the serial port holds at once, writing a cycle's frames at once.

python-can 4.1 (Debian 12's) reads an SLCAN adapter one byte per system call, a few thousand
calls per cycle on a 9-drive robot; later python-can releases read everything waiting at once,
which this subclass does on 4.1. ``send_batch`` writes several frames in one write and one flush
(base_driver's commands of a cycle: two frames per motor controller). Frames, commands and errors
are python-can's own.
"""

import time
from typing import Optional, Sequence

import can
from can.exceptions import error_check
from can.interfaces.slcan import slcanBus


class BufferedSlcanBus(slcanBus):
    def send_batch(self, messages: Sequence[can.Message], timeout: Optional[float] = None) -> None:
        """Sends the messages in order, as one write to the adapter."""
        lines = []
        for msg in messages:
            kind = "rR"[msg.is_extended_id] if msg.is_remote_frame else "tT"[msg.is_extended_id]
            head = ("%s%08X%d" if msg.is_extended_id else "%s%03X%d") % (kind, msg.arbitration_id, msg.dlc)
            lines.append(head + ("" if msg.is_remote_frame else bytes(msg.data).hex().upper()))
        if not lines:
            return
        port = self.serialPortOrig
        if timeout != port.write_timeout:
            port.write_timeout = timeout
        with error_check("Could not write to serial device"):
            port.write(self.LINE_TERMINATOR.join(line.encode() for line in lines) + self.LINE_TERMINATOR)
            port.flush()

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
