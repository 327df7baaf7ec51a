"""Helpers of the thorvald_teleop tests that run real nodes: a ROS master of the test module's own,
polling with deadlines, stopping process groups. (A uniquely named module: the conftest.py files of
several packages load in one pytest run.)"""

import os
import signal
import socket
import subprocess
import time
import xmlrpc.client

START = 30.0  # [s] for a process to come up on a busy machine


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def poll(predicate, timeout, what, interval=0.02):
    """predicate()'s first true value; AssertionError naming what after timeout [s]."""
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout} s waiting for {what}")
        time.sleep(interval)


def children(pid):
    out = subprocess.run(["pgrep", "-P", str(pid)], capture_output=True, text=True)
    return [int(p) for p in out.stdout.split()]


def stop_group(proc):
    """Ends a process started in its own session, and its children (roscore's rosmaster and rosout run in
    process groups of their own: roscore ends them on SIGINT; they are killed if it does not)."""
    kids = children(proc.pid)
    if proc.poll() is None:
        try:
            os.killpg(proc.pid, signal.SIGINT)
            proc.wait(timeout=10)
            return
        except subprocess.TimeoutExpired:
            pass
        except ProcessLookupError:
            proc.wait(timeout=10)
            return
    for pid in kids:
        try:
            os.kill(pid, signal.SIGKILL)
        except ProcessLookupError:
            pass
    try:
        os.killpg(proc.pid, signal.SIGKILL)
    except ProcessLookupError:
        pass
    proc.wait(timeout=10)


def ros_master(home):
    """Generator: roscore on a free port with ROS_HOME in home; yields the environment to run processes
    with (ROS_MASTER_URI set, no ROS_NAMESPACE or TMUX inherited), stops roscore when resumed."""
    port = free_port()
    env = dict(os.environ)
    env.pop("TMUX", None)
    env.pop("ROS_NAMESPACE", None)
    env.update(
        ROS_MASTER_URI=f"http://127.0.0.1:{port}",
        ROS_HOME=str(home),
        ROS_LOG_DIR=str(home / "log"),
        PYTHONUNBUFFERED="1",
    )
    with open(home / "roscore.out", "w") as out:
        core = subprocess.Popen(
            ["roscore", "-p", str(port)],
            env=env,
            stdin=subprocess.DEVNULL,
            stdout=out,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
    try:

        def master_up():
            assert core.poll() is None, (home / "roscore.out").read_text()
            try:
                with xmlrpc.client.ServerProxy(env["ROS_MASTER_URI"]) as master:
                    master.getPid("/test")
                return True
            except OSError:
                return False

        poll(master_up, START, "the ROS master")
        yield env
    finally:
        stop_group(core)
