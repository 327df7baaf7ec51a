#!/usr/bin/env python3
"""The CAN base against simple_sim, side by side in one run: CPU, frames per cycle, loop rate, relay.

    python bench/can_bus.py [--port PORT] [--window 10] [--rounds 2] [--relay-rate 1000]

Starts its own roscore and the CAN device emulator of the 9-drive robot (rosrun thorvald_sim
can_emulator, an SLCAN hub of pseudo-terminals), and stops everything it started. Needs the
workspace sourced. The bench itself joins the bus on the hub's second port as an implement.

1. CPU share of base_driver at 50 Hz, 9 drives, driving, a subscriber on every topic it publishes:
   over SLCAN to the emulator and with simple_sim, alternated (rounds), medians. Target: CAN at
   most 1.5 times simple_sim.
2. Frames per cycle on the bus (counted by the implement): base_driver's, and the devices'.
3. The highest loop rate held over CAN (~rate 100, 200, 400 Hz; held = 95 %).
4. Relay throughput at 50 Hz: the implement sends --relay-rate frames/s for 5 s (each numbered)
   and counts those base_driver puts on can_frames_device_r; a publisher sends as many on
   can_frames_device_t and the implement counts them on the bus; base_driver's loop rate
   meanwhile. Target: 1000 frames/s each way, none lost, the loop holding 50 Hz.

(Named can_bus.py, not can.py: a can.py in bench/ would shadow python-can for every script here.)
"""

import argparse
import os
import shutil
import signal
import statistics
import sys
import tempfile
import threading
import time

import can
import rospy
from base_driver import HELD, NINE, Bench, ros_session  # the base_driver benchmark's tools
from nav_msgs.msg import Odometry

from thorvald_base.can.slcan import BufferedSlcanBus
from thorvald_msgs.msg import CANFrame
from thorvald_testing import poll

RATES = (100, 200, 400)  # [Hz]
TARGET_CPU_RATIO = 1.5
RELAY_SECONDS = 5.0
RELAY_IN, RELAY_OUT = 0x123, 0x124  # ids the implement sends and receives (no base device owns them)
BASE_FUNCTIONS = (0x200, 0x300, 0x400, 0x500)  # frames from base_driver to the controllers (RxPDO1..4 + node)


class Implement:
    """The bench on the bus (port1): counts every frame by direction, sends numbered frames."""

    def __init__(self, path):
        self.bus = BufferedSlcanBus(channel=path, sleep_after_open=0)  # base_driver's reader
        self.lock = threading.Lock()
        self.counts = {"base": 0, "devices": 0}
        self.received_out = set()
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self):
        while not self.stop.is_set():
            try:
                msg = self.bus.recv(0.05)
            except can.CanError:
                continue
            if msg is None:
                continue
            with self.lock:
                if msg.arbitration_id == RELAY_OUT:
                    self.received_out.add(int.from_bytes(bytes(msg.data[:4]), "little"))
                elif msg.arbitration_id & 0x780 in BASE_FUNCTIONS:
                    self.counts["base"] += 1
                else:
                    self.counts["devices"] += 1

    def snapshot(self):
        with self.lock:
            return dict(self.counts)

    def send_numbered(self, rate, seconds):
        n = int(rate * seconds)
        start = time.perf_counter()
        for k in range(n):
            target = start + k / rate
            delay = target - time.perf_counter()
            if delay > 0:
                time.sleep(delay)
            self.bus.send(
                can.Message(arbitration_id=RELAY_IN, data=k.to_bytes(4, "little") + bytes(4), is_extended_id=False)
            )
        return n

    def close(self):
        self.stop.set()
        self.thread.join(2)
        try:
            self.bus.shutdown()
        except can.CanError:
            pass


def relay(bench, ns, implement, rate):
    """(frames per cycle each way, then sent and received both ways and the achieved loop rate) at 50 Hz
    with rate frames/s each way."""
    driver = bench.start_driver(ns, NINE, 50, **bench.can_params)
    got_in = set()
    stamps = []
    sub = rospy.Subscriber(f"/{ns}/can_frames_device_r", CANFrame,
                           lambda m: got_in.add(int.from_bytes(bytes(bytearray(m.data))[:4], "little"))
                           if m.id == RELAY_IN else None, queue_size=5000)  # fmt: skip
    odom = rospy.Subscriber(f"/{ns}/odometry/base_raw", Odometry, lambda m: stamps.append(m.header.stamp.to_sec()))
    pub = rospy.Publisher(f"/{ns}/can_frames_device_t", CANFrame, queue_size=5000)
    try:
        bench.wait_subscribed(pub)
        before = implement.snapshot()
        time.sleep(5.0)  # base_driver's cycles and the devices' reports, nothing else on the bus
        after = implement.snapshot()
        per_cycle = {k: (after[k] - before[k]) / 5.0 / 50.0 for k in after}
        with implement.lock:
            implement.received_out.clear()
        n = int(rate * RELAY_SECONDS)

        def publish():
            start = time.perf_counter()
            for k in range(n):
                delay = start + k / rate - time.perf_counter()
                if delay > 0:
                    time.sleep(delay)
                pub.publish(CANFrame(id=RELAY_OUT, length=8, data=list(k.to_bytes(4, "little")) + [0] * 4))

        t = threading.Thread(target=publish, daemon=True)
        stamps.clear()
        t.start()
        sent_in = implement.send_numbered(rate, RELAY_SECONDS)
        t.join()
        time.sleep(1.0)  # the last frames through
        window = [s for s in stamps if s >= stamps[0]] if stamps else []
        achieved = (len(window) - 1) / (window[-1] - window[0]) if len(window) > 1 else 0.0
        with implement.lock:
            got_out = len(implement.received_out)
        return per_cycle, (sent_in, len(got_in), n, got_out, achieved)
    finally:
        sub.unregister()
        odom.unregister()
        pub.unregister()
        bench.procs.stop(driver)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--port", type=int, default=None, help="the roscore's port (default: a free one)")
    parser.add_argument("--window", type=float, default=10.0, help="CPU measurement window [s]")
    parser.add_argument("--rounds", type=int, default=2, help="CAN / simple_sim alternations")
    parser.add_argument("--relay-rate", type=float, default=1000.0, help="relayed frames per second each way")
    args = parser.parse_args()

    signal.signal(signal.SIGTERM, lambda *_: sys.exit(1))  # through ros_session's exit: stop every process
    links = tempfile.mkdtemp(prefix="thorvald_can_bench_")
    rows = []
    implement = None
    ok = True
    with ros_session("bench_can", port=args.port) as (master, procs):
        try:
            bench = Bench(procs)
            procs.start(
                ["rosrun", "thorvald_sim", "can_emulator", bench.robot_file(NINE), "--ports", "2", "--link-dir", links]
            )
            poll(lambda: os.path.exists(os.path.join(links, "port1")), 60, "the CAN emulator's ports")
            bench.can_params = {
                "simple_sim": False,
                "can_interface_type": "slcan",
                "can_interface_name": os.path.join(links, "port0"),
            }
            implement = Implement(os.path.join(links, "port1"))
            print(f"roscore on port {master.port}; {os.cpu_count()} cores; emulator ports in {links}", flush=True)

            cpu = {"can": [], "sim": []}
            for r in range(args.rounds):
                for kind in ("can", "sim"):
                    extra = bench.can_params if kind == "can" else {}
                    share, achieved = bench.cpu_and_rate(f"{kind}{r}", NINE, 50, args.window, **extra)
                    cpu[kind].append(share)
                    print(f"  {kind} round {r}: {share:.1f} % CPU, {achieved:.1f} Hz", flush=True)
            can_cpu, sim_cpu = statistics.median(cpu["can"]), statistics.median(cpu["sim"])
            ratio = can_cpu / sim_cpu
            ok &= ratio <= TARGET_CPU_RATIO
            rows.append(("CPU share at 50 Hz, SLCAN", "9 drives", f"{can_cpu:.1f} % of a core", ""))
            rows.append(("CPU share at 50 Hz, simple_sim", "9 drives", f"{sim_cpu:.1f} % of a core", ""))
            rows.append(("CAN / simple_sim", "9 drives", f"{ratio:.2f}", f"<= {TARGET_CPU_RATIO}"))
            best = None
            for rate in RATES:
                share, achieved = bench.cpu_and_rate(f"canrate{rate}", NINE, rate, 5.0, **bench.can_params)
                held = achieved >= HELD * rate
                best = rate if held else best
                rows.append(
                    (
                        f"~rate {rate} Hz, SLCAN",
                        "9 drives",
                        f"{achieved:.0f} Hz, {share:.0f} % CPU",
                        "held" if held else "not held",
                    )
                )
                print(f"  SLCAN at {rate} Hz: {achieved:.1f} Hz achieved, {share:.1f} % CPU", flush=True)
            rows.append(("highest loop rate held, SLCAN", "9 drives", f"{best or 0} Hz", ""))

            frames, (sent_in, got_in, sent_out, got_out, achieved) = relay(bench, "relay", implement, args.relay_rate)
            rows.append(
                ("frames per cycle, base_driver -> devices", "9 drives", f"{frames['base']:.1f}", "2 per controller")
            )
            rows.append(("frames per cycle, devices -> base", "9 drives", f"{frames['devices']:.1f}", ""))
            lossless = got_in == sent_in and got_out == sent_out and achieved >= HELD * 50
            ok &= lossless
            rows.append(
                ("relay, implement -> can_frames_device_r", f"{args.relay_rate:.0f}/s", f"{got_in} of {sent_in}", "all")
            )
            rows.append(
                (
                    "relay, can_frames_device_t -> implement",
                    f"{args.relay_rate:.0f}/s",
                    f"{got_out} of {sent_out}",
                    "all",
                )
            )
            rows.append(("loop rate during the relay", "9 drives", f"{achieved:.1f} Hz", "50 Hz"))
        finally:
            if implement is not None:
                implement.close()
    shutil.rmtree(links, ignore_errors=True)  # the emulator's links, once it has stopped

    table = [("measure", "robot / load", "figure", "target"), *rows]
    widths = [max(len(r[i]) for r in table) for i in range(4)]
    print()
    for r in table:
        print("  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip())
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
