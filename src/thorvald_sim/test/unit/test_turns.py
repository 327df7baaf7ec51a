"""The simulator node's lock with turns (thorvald_sim.node.turns): a thread waiting for the lock while
the loop holds it has it before the loop's next turn; nobody waiting costs the loop no wait; reentrant
as the node's RLock was."""

import threading

from thorvald_sim.node.turns import TurnLock

LONG = 60.0  # [s] never reached: a turn handed over in time returns at once


def waiting(lock, count):
    """Until count threads wait for lock (a thread that asked blocks within microseconds)."""
    while lock._waiting < count:
        threading.Event().wait(0.001)


def test_threads_waiting_while_the_loop_holds_the_lock_have_it_before_its_next_turn():
    lock = TurnLock(timeout=LONG)
    had = []

    def request(k):
        with lock:
            had.append(k)

    lock.acquire()  # the loop's turn
    requests = [threading.Thread(target=request, args=(k,)) for k in range(3)]
    for thread in requests:
        thread.start()
    waiting(lock, 3)
    lock.release()
    lock.let_waiters_in()
    with lock:  # the loop's next turn: a loop that took the lock back at once would see fewer than 3
        assert sorted(had) == [0, 1, 2]
    for thread in requests:
        thread.join(LONG)


def test_nobody_waiting_costs_the_loop_no_wait():
    lock = TurnLock(timeout=LONG)
    for _ in range(1000):
        with lock:
            pass
        lock.let_waiters_in()  # would block for LONG if it waited for a thread that is not there


def test_reentrant_as_the_nodes_rlock():
    lock = TurnLock(timeout=LONG)
    got = []

    def try_from_another_thread():
        other = threading.Thread(target=lambda: got.append(lock._lock.acquire(blocking=False)))
        other.start()
        other.join(LONG)

    with lock:
        with lock:
            pass
        try_from_another_thread()
    assert got == [False]  # still held by this thread after the inner release
    try_from_another_thread()
    assert got == [False, True]
