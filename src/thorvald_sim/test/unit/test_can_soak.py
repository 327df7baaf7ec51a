"""The CAN base over SLCAN to the emulator on its pseudo-terminals, in real time beside busy loops
(issue 45, item 2): no device lost, the bus never reopened, every command through, nothing dropped.

Slow on purpose: what it guards against happens on the wall clock (a writer held up while other
processes have the cores), so it runs in real time, 15 s plus the emulator's start and python-can's
2 s wait after opening a port (18 s of wall time, 36 core-seconds: the busy loops take both cores).
Under the load of thorvald_testing.can_soak (two busy processes, four threads of its own holding the
interpreter lock half the time) the CAN base as it was before issue 45 reopened its bus 3 and 7 times
and lost every drive in both 30 s runs tried, and in three 15 s runs reopened it 7, 2 and 1 times
(lost every drive in 2, 1 and 0 cycles): each would fail here. The five minutes the issue asks for
are bench/can_soak.py (figures in docs/benchmarks.md): the same soak, longer.
"""

import json
import subprocess
import sys

import pytest

SECONDS = 15.0


@pytest.mark.slow
@pytest.mark.long(35)
def test_fifteen_seconds_beside_two_busy_loops_lose_no_device():
    # a process of its own: the soak lowers nothing and starts processes this one must not inherit
    out = subprocess.run(
        [sys.executable, "-m", "thorvald_testing.can_soak", "--seconds", str(SECONDS), "--json"],
        capture_output=True,
        text=True,
        timeout=SECONDS + 120,
    )
    assert out.stdout.strip(), out.stderr[-3000:]
    figures = json.loads(out.stdout.strip().splitlines()[-1])
    report = "\n".join(f"{k}: {v}" for k, v in figures.items())
    assert figures["lost_cycles"] == 0, report
    assert (figures["reopened"], figures["send_errors"]) == (0, 0), report
    assert (figures["frames_dropped"], figures["malformed"], figures["hub_lost"]) == (0, 0, 0), report
    assert figures["stale_commands"] == 0, report
    # every cycle's command got through to the other end of the hub (a cycle may stall, not vanish)
    assert figures["commands_seen"] >= 0.9 * 4 * figures["cycles"], report
    assert out.returncode == 0, report
