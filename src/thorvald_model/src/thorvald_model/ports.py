"""A TCP port for a ROS master of our own (tests, benchmarks, rviz_capture, odometry_report).

Asking the kernel for port 0 and closing the socket hands out a port from the ephemeral range,
the same range every ROS node's XML-RPC and TCPROS servers are given, so on a busy machine a node
started in the meantime can take it before roslaunch binds it ("port ... is already in use").
The port here is picked at random below the ephemeral range, where the kernel never hands out
ports by itself, and checked free on every address (a master listens on all of them).
Standard library only.
"""

import random
import socket
from typing import Tuple

EPHEMERAL_RANGE_FILE = "/proc/sys/net/ipv4/ip_local_port_range"
_RANDOM = random.SystemRandom()
LOWEST = 10000  # below: ports of well-known services (and ROS's default master, 11311, is above)


def ephemeral_range(path: str = EPHEMERAL_RANGE_FILE) -> Tuple[int, int]:
    """The kernel's (first, last) ephemeral port; Linux's default if unreadable."""
    try:
        with open(path) as f:
            low, high = (int(v) for v in f.read().split()[:2])
        return low, high
    except (OSError, ValueError):
        return 32768, 60999


def is_free(port: int) -> bool:
    with socket.socket() as s:
        try:
            s.bind(("", port))
        except OSError:
            return False
    return True


def free_port(rng: random.Random = _RANDOM) -> int:
    """A port nobody listens on, outside the ephemeral range (see the module's notes)."""
    low, high = ephemeral_range()
    if low - LOWEST >= 1000:
        choices = (LOWEST, low - 1)
    else:  # an unusual range: use what is above it
        choices = (high + 1, 65535)
    for _ in range(200):
        port = rng.randint(*choices)
        if port != 11311 and is_free(port):
            return port
    with socket.socket() as s:  # everything tried was taken: the kernel's choice, as before
        s.bind(("", 0))
        return s.getsockname()[1]
