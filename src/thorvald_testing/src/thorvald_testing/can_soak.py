"""The CAN base over SLCAN to the device emulator in another process, in real time, beside busy loops.

Issue 45 (item 2): beside a busy machine, writes to the emulator's pseudo-terminal failed and every
drive was declared lost. The soak runs base_driver's CAN base as base_driver opens it (``open_bus``:
python-can's slcan interface through ``BufferedSlcanBus``) at 50 Hz on the wall clock against
``rosrun thorvald_sim can_emulator`` (its SLCAN hub of pseudo-terminals, without a ROS master), with
busy processes (``python3 -c 'while 1: pass'``) beside it, Python threads in its own process that
hold the interpreter lock half the time (as base_driver's rospy threads do, publishing and
subscribing), and a sniffer on the hub's second port that checks every command the base wrote. It
measures what the issue is about: cycles with a wheel stopped for a lost device, bus reopenings,
refused writes and how long frames waited, write calls longer than the 50 ms write timeout the base
used to give pyserial (each of those was a "bus error" then), and what the hub carried and dropped.

The busy loops alone rarely hold the writer up: it sleeps between cycles and the scheduler favours
it when it wakes (the longest write call in 30 s: 4 to 8 ms, even niced 10 below them). What stalled
base_driver's writes (calls of 86 to 131 ms, one of 0.96 s) was most likely the interpreter lock: a
thread of its own holding it while the busy loops had the cores. Four threads working 2.5 ms of every 5 ms
(THREADS, THREAD_DUTY) are harsher than base_driver's own, so that what took minutes there shows in
half a minute: with them, the CAN base as it was before issue 45 reopened its bus 3 and 7 times and
lost every drive in 2 and 9 cycles in two 30 s runs.

``python -m thorvald_testing.can_soak --seconds 300`` prints the figures (bench/can_soak.py runs it
for five minutes); thorvald_sim's test_can_soak runs it shorter with ``--json``. Needs the workspace
sourced (rosrun). ``--nice N`` lowers the soak's own priority below the busy loops'.
"""

import argparse
import json
import os
import re
import sys
import tempfile
import threading
import time
from dataclasses import asdict, dataclass
from typing import Dict, List, Optional

from thorvald_model.ports import free_port

from . import START, Processes, poll

STANDARD = os.path.join("thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
OLD_WRITE_TIMEOUT = 0.05  # [s] pyserial's write timeout the base gave a cycle's frames before issue 45
THREADS = 4  # threads in the soak's process holding the interpreter lock ...
THREAD_DUTY = 0.5  # ... this share of every THREAD_PERIOD
THREAD_PERIOD = 0.005  # [s] Python's switch interval: a waiting thread asks for the lock after it


@dataclass(frozen=True)
class SoakResult:
    seconds: float  # [s] of wall time driven
    busy: int  # busy processes beside it
    threads: int  # threads in its own process, holding the interpreter lock THREAD_DUTY of the time
    nice: int  # the soak's own niceness
    cycles: int
    worst_cycle: float  # [s] the longest time between two cycles' starts (50 Hz: 0.02)
    lost_cycles: int  # cycles with the wheels stopped for a lost device, once every device was heard
    lost: str  # the devices those cycles named
    reopened: int
    send_errors: int
    writes_refused: int
    frames_queued: int
    frames_dropped: int
    worst_write_latency: float  # [s] of base_driver's clock a frame waited for a write
    slow_writes: int  # write calls longer than OLD_WRITE_TIMEOUT
    worst_write_call: float  # [s] of wall time
    malformed: int  # frames the base could not read
    commands_seen: int  # RxPDO1 frames the sniffer saw
    stale_commands: int  # of them, older than one seen before (the sequence went back)
    worst_command_gap: float  # [s] between two commands to one controller, at the sniffer
    emulator: str  # the emulator's own summary: what each port carried and dropped
    hub_lost: int  # frames the hub's ports could not read (malformed) or dropped for a slow reader

    def missed(self) -> List[str]:
        """The targets missed: a device lost, the bus reopened, a write failed as a broken bus, a frame
        dropped, malformed or stale anywhere, a summary missing."""
        wrong = [
            name
            for name in ("lost_cycles", "reopened", "send_errors", "frames_dropped", "malformed", "stale_commands")
            if getattr(self, name)
        ]
        if self.hub_lost:
            wrong.append("hub_lost")
        if not self.commands_seen:
            wrong.append("commands_seen")
        return wrong

    def report(self) -> str:
        return "\n".join(
            [
                f"{self.seconds:.0f} s at 50 Hz beside {self.busy} busy loop(s), {self.threads} busy thread(s), "
                f"nice {self.nice}: "
                f"{self.cycles} cycles, the longest {self.worst_cycle * 1000:.0f} ms apart",
                f"cycles with a device lost: {self.lost_cycles} ({self.lost or 'none'}); bus reopened "
                f"{self.reopened} times; send errors {self.send_errors}",
                f"writes refused {self.writes_refused}; frames queued {self.frames_queued}, dropped "
                f"{self.frames_dropped}; worst write latency {self.worst_write_latency * 1000:.0f} ms",
                f"write calls over {OLD_WRITE_TIMEOUT * 1000:.0f} ms (a bus error before issue 45): "
                f"{self.slow_writes}; the longest {self.worst_write_call * 1000:.1f} ms",
                f"commands at the sniffer: {self.commands_seen}, stale {self.stale_commands}, the longest "
                f"gap {self.worst_command_gap * 1000:.0f} ms; malformed frames at the base {self.malformed}",
                f"emulator: {self.emulator}",
                "targets: " + (f"missed: {', '.join(self.missed())}" if self.missed() else "all met"),
            ]
        )


class Sniffer:
    """A participant on the hub's second port: every RxPDO1 the base wrote, by controller."""

    def __init__(self, channel: str, nodes):
        from thorvald_base.can.slcan import BufferedSlcanBus  # noqa: PLC0415  (the workspace's, when soaking)

        self.bus = BufferedSlcanBus(channel=channel, sleep_after_open=0)
        self.nodes = set(nodes)
        self.last: Dict[int, tuple] = {}  # node -> (sequence, monotonic time)
        self.seen = self.stale = 0
        self.worst_gap = 0.0
        self.stop = threading.Event()
        self.thread = threading.Thread(target=self._run, daemon=True)
        self.thread.start()

    def _run(self):
        import can  # noqa: PLC0415

        while not self.stop.is_set():
            try:
                msg = self.bus.recv(0.05)
            except (can.CanError, ValueError):
                continue
            if msg is None or msg.arbitration_id - 0x200 not in self.nodes or len(msg.data) != 8:
                continue
            node, now = msg.arbitration_id - 0x200, time.monotonic()
            sequence = int.from_bytes(bytes(msg.data[:4]), "little", signed=True)
            self.seen += 1
            if node in self.last:
                before, then = self.last[node]
                self.stale += sequence <= before
                self.worst_gap = max(self.worst_gap, now - then)
            self.last[node] = (sequence, now)

    def close(self):
        self.stop.set()
        self.thread.join(2)
        try:
            self.bus.shutdown()
        except Exception:  # the hub may have gone first
            pass


def _work(stop: threading.Event) -> None:
    """Holds the interpreter lock THREAD_DUTY of every THREAD_PERIOD (a rospy thread's bursts)."""
    while not stop.is_set():
        end = time.perf_counter() + THREAD_PERIOD * THREAD_DUTY
        while time.perf_counter() < end:
            pass
        time.sleep(THREAD_PERIOD * (1.0 - THREAD_DUTY))


def soak(
    seconds: float,
    busy: int = 2,
    nice: int = 0,
    robot: Optional[str] = None,
    rate: float = 50.0,
    *,
    threads: int = THREADS,
) -> SoakResult:
    import rospkg  # noqa: PLC0415

    from thorvald_base.bases.can_base import CanBase, open_bus  # noqa: PLC0415
    from thorvald_base.kinematics import DriveCommand  # noqa: PLC0415
    from thorvald_model import load_robot_config  # noqa: PLC0415

    if robot is None:
        robot = os.path.join(rospkg.RosPack().get_path("thorvald_model"), "config", STANDARD)
    config = load_robot_config(robot)
    with tempfile.TemporaryDirectory(prefix="can_soak-") as tmp, Processes(_no_master_env()) as procs:
        log = open(os.path.join(tmp, "emulator.out"), "w+")
        emulator = procs.start(["rosrun", "thorvald_sim", "can_emulator", robot, "--link-dir", tmp], out=log)
        for _ in range(busy):
            procs.start([sys.executable, "-c", "while 1: pass"])
        if nice:
            os.nice(nice)
        port0, port1 = os.path.join(tmp, "port0"), os.path.join(tmp, "port1")
        poll(lambda: os.path.exists(port1), START, "the emulator's ports")
        sniffer = Sniffer(port1, [c.node for c in config.motor_controllers])
        handle = CanBase(config, open_bus("slcan", port0), reopen=lambda: open_bus("slcan", port0))
        calls = []
        batch = handle.bus.send_batch

        def timed(*args, **kwargs):
            start = time.perf_counter()
            try:
                return batch(*args, **kwargs)
            finally:
                calls.append(time.perf_counter() - start)

        handle.bus.send_batch = timed  # the bus base_driver opened; a reopened one is counted by `reopened`
        stop = threading.Event()
        workers = [threading.Thread(target=_work, args=(stop,), daemon=True) for _ in range(threads)]
        for w in workers:
            w.start()
        try:
            period = 1.0 / rate
            start = time.monotonic()
            next_cycle, last, worst_cycle = start, None, 0.0
            cycles = lost_cycles = 0
            lost = set()
            all_heard = False
            while time.monotonic() - start < seconds:
                now = time.monotonic()
                if last is not None:
                    worst_cycle = max(worst_cycle, now - last)
                last = now
                t = now - start
                speed = 0.3 + 0.2 * ((t / 10.0) % 1.0)  # a new command every cycle
                handle.send_drive_commands([DriveCommand(0.1, speed)] * len(config.drives), t)
                handle.read_drive_states(t)
                cycles += 1
                if all_heard and handle.stopped_for_lost:
                    lost_cycles += 1
                    lost.update(handle.stopped_for_lost)
                all_heard = all_heard or all(c.online(t) for c in handle.controllers_)
                next_cycle += period
                delay = next_cycle - time.monotonic()
                if delay > 0:
                    time.sleep(delay)
                elif delay < -period:  # late by more than a cycle: start again from now, as rospy.Rate
                    next_cycle = time.monotonic()
            elapsed = time.monotonic() - start
            diagnostics = handle.diagnostics(elapsed)
        finally:
            stop.set()
            for w in workers:
                w.join(1.0)
            handle.close()
            sniffer.close()
        procs.stop(emulator)
        log.seek(0)
        summary = [line.strip() for line in log if line.startswith("can_emulator: port")]
        log.close()

    def number(key):
        value = diagnostics.get(key, "-1")
        return float(value.split()[0])

    return SoakResult(
        seconds=elapsed,
        busy=busy,
        threads=threads,
        nice=nice,
        cycles=cycles,
        worst_cycle=worst_cycle,
        lost_cycles=lost_cycles,
        lost=", ".join(sorted(lost)),
        reopened=int(number("bus reopened")),
        send_errors=int(number("send errors")),
        writes_refused=int(number("writes refused")),
        frames_queued=int(number("frames queued")),
        frames_dropped=int(number("frames dropped")),
        worst_write_latency=number("worst write latency"),
        slow_writes=sum(d > OLD_WRITE_TIMEOUT for d in calls),
        worst_write_call=max(calls, default=0.0),
        malformed=int(number("malformed frames")),
        commands_seen=sniffer.seen,
        stale_commands=sniffer.stale,
        worst_command_gap=sniffer.worst_gap,
        emulator=summary[-1][len("can_emulator: ") :] if summary else "no summary (the emulator did not stop cleanly)",
        hub_lost=sum(int(n) for pair in re.findall(r"(\d+) malformed, (\d+) dropped", "".join(summary)) for n in pair)
        if summary
        else -1,
    )


def _no_master_env() -> Dict[str, str]:
    """This environment, with ROS_MASTER_URI where no master runs: the emulator runs on its own."""
    return dict(os.environ, ROS_MASTER_URI=f"http://127.0.0.1:{free_port()}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(prog="can_soak", description=__doc__.split("\n")[0])
    parser.add_argument("--seconds", type=float, default=300.0, help="[s] of wall time (300)")
    parser.add_argument("--busy", type=int, default=2, help="busy processes beside it (2)")
    parser.add_argument("--threads", type=int, default=THREADS, help=f"busy threads in its own process ({THREADS})")
    parser.add_argument("--nice", type=int, default=0, help="the soak's own niceness (0: the busy loops' own)")
    parser.add_argument("--robot", help="a robot file (the standard robot)")
    parser.add_argument("--json", action="store_true", help="the figures as one JSON object")
    args = parser.parse_args(argv)
    result = soak(args.seconds, args.busy, args.nice, args.robot, threads=args.threads)
    print(json.dumps(asdict(result)) if args.json else result.report(), flush=True)
    return 1 if result.missed() else 0


if __name__ == "__main__":
    sys.exit(main())
