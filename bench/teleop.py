#!/usr/bin/env python3
"""Joystick event to teleop_joy/cmd_vel latency: joy_node + teleop_node, as teleop_xbox.launch runs them.

    python bench/teleop.py [--port PORT] [--samples 300]

Starts its own roscore (thorvald_testing's, as the tests use) and teleop_xbox.launch (xbox.yaml)
with a FIFO standing in for /dev/input/js0, holds the deadman, then writes stick events (js_event,
each a new position) 20 to 40 ms apart; latency = receipt of the teleop_joy/cmd_vel that carries
the new speed - the write. Two TCPROS hops (joy, then cmd_vel) and two nodes' Python. Target:
under 5 ms median.
"""

import argparse
import os
import random
import signal
import statistics
import struct
import sys
import tempfile
import threading
import time

import rospy
from base_driver import percentile, ros_session  # the base_driver benchmark's tools
from geometry_msgs.msg import Twist

from thorvald_testing import poll

TARGET_MS = 5.0
BUTTON, AXIS, INIT = 0x01, 0x02, 0x80


def event(value, kind, number):
    return struct.pack("<IhBB", int(time.monotonic() * 1000) & 0xFFFFFFFF, value, kind, number)


def measure(samples, procs, fifo):
    """Latencies [s] of samples stick moves, teleop_xbox.launch started with fifo as its joystick."""
    arrivals = []
    lock = threading.Lock()

    def on_cmd(msg):
        with lock:
            arrivals.append((time.perf_counter(), msg.linear.x))

    sub = rospy.Subscriber("/teleop_joy/cmd_vel", Twist, on_cmd, queue_size=1000, tcp_nodelay=True)
    procs.start(["roslaunch", "thorvald_teleop", "teleop_xbox.launch", f"joy_dev:={fifo}"])
    writer = os.open(fifo, os.O_WRONLY)  # blocks until joy_node opens the device
    try:
        os.write(writer, b"".join(event(0, BUTTON | INIT, k) for k in range(11)))
        os.write(writer, b"".join(event(0, AXIS | INIT, k) for k in range(8)))
        os.write(writer, event(1, BUTTON, 4))  # the deadman, held from here on
        poll(lambda: arrivals, 30, "a teleop_joy/cmd_vel with the deadman held")
        latencies = []
        last_vx = 0.0  # the stick is centred
        for i in range(samples):
            value = -(2000 + 90 * i)  # stick further up each time: a new speed each time
            with lock:
                seen = len(arrivals)
            t0 = time.perf_counter()
            os.write(writer, event(value, AXIS, 1))
            deadline = t0 + 1.0
            got = None
            # a tight loop of its own, not poll(): a move that never comes out is counted, not fatal
            while got is None and time.perf_counter() < deadline:
                with lock:
                    fresh = arrivals[seen:]
                for t, vx in fresh:
                    if vx > 0 and vx != last_vx:  # the new position, not an autorepeat of the last
                        got = (t, vx)
                        break
                if got is None:
                    time.sleep(0.0002)
            if got is not None:
                latencies.append(got[0] - t0)
                last_vx = got[1]
            time.sleep(random.uniform(0.02, 0.04))
        return latencies
    finally:
        os.close(writer)
        sub.unregister()


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--port", type=int, default=None, help="the roscore's port (default: a free one)")
    parser.add_argument("--samples", type=int, default=300)
    args = parser.parse_args()
    signal.signal(signal.SIGTERM, lambda *_: sys.exit(1))  # through ros_session's exit: stop every process
    folder = tempfile.mkdtemp(prefix="thorvald_teleop_bench_")
    fifo = os.path.join(folder, "js0")
    os.mkfifo(fifo)
    try:
        with ros_session("bench_teleop", port=args.port) as (_, procs):
            latencies = measure(args.samples, procs, fifo)
    finally:
        os.unlink(fifo)
        os.rmdir(folder)
    med = 1e3 * statistics.median(latencies)
    print(f"\n{len(latencies)} of {args.samples} stick moves came out on teleop_joy/cmd_vel")
    print(f"latency median {med:.2f} ms, 99th percentile {1e3 * percentile(latencies, 0.99):.2f} ms, "
          f"max {1e3 * max(latencies):.2f} ms (target: median under {TARGET_MS:g} ms)")  # fmt: skip
    return 0 if med < TARGET_MS and len(latencies) == args.samples else 1


if __name__ == "__main__":
    sys.exit(main())
