"""pybullet, imported without the line its C++ prints on standard error as it loads ("pybullet build
time: ..."), which every tool of ours would print first; and :func:`quiet_stdout` for what it prints
on standard output later (every merged link while loading a URDF, warnings while building shapes).

``from .bullet import pybullet as p`` where a module would ``import pybullet as p``.
"""

import contextlib
import ctypes
import os
import sys

_LIBC = ctypes.CDLL(None)


@contextlib.contextmanager
def _quiet(fd: int, stream):
    """Silences file descriptor fd (stream is Python's over it) meanwhile. C's own buffers are flushed
    before the descriptor comes back: to a pipe, C buffers what it prints until the process ends."""
    stream.flush()
    saved = os.dup(fd)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), fd)
        yield
    finally:
        _LIBC.fflush(None)
        os.dup2(saved, fd)
        os.close(saved)


def quiet_stdout():
    """Silences file descriptor 1, where pybullet's C++ prints while it loads and builds, meanwhile."""
    return _quiet(1, sys.stdout)


with _quiet(2, sys.stderr):
    import pybullet  # after the redirection, on purpose

__all__ = ["pybullet", "quiet_stdout"]
