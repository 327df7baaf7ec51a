#!/usr/bin/env python3
"""Five minutes of the CAN base over SLCAN beside two busy loops: no device may be lost (issue 45).

    python bench/can_soak.py [--seconds 300] [--busy 2] [--threads 4] [--nice 0] [--json]

base_driver's CAN base, opened as base_driver opens it, drives the standard robot at 50 Hz on the
wall clock against ``rosrun thorvald_sim can_emulator`` (its own process and SLCAN hub of
pseudo-terminals, no ROS master), with two ``python3 -c 'while 1: pass'`` beside them on this
machine's cores, four threads in its own process holding the interpreter lock half the time (what
stalled base_driver's writes was its own threads: thorvald_testing.can_soak says why) and a sniffer
on the hub's second port. Prints the
figures; exits 1 when a target is missed: no cycle with a device lost, the bus never reopened, no
write failed as a broken bus, no frame dropped, malformed or stale at the base, the sniffer or the hub.
"""

import sys

from thorvald_testing.can_soak import main

if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
