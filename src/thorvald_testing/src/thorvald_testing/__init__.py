"""What the workspace's tests share (pytest suites, rostest nodes and benchmarks alike).

* :func:`free_port`: a TCP port nobody listens on, for a ROS master of a test's own (outside the
  ephemeral range, so no node takes it meanwhile: thorvald_model.ports);
* :func:`poll`: wait for a condition with a deadline, failing with what was awaited;
* :func:`ros_env`, :func:`ros_master`: a private ROS master (its own port and ROS_HOME);
* :class:`Launch`: roslaunch in a session of its own, stopped with everything it started;
* :func:`stop_group`, :func:`processes_naming`, :func:`kill_processes_naming`: ending processes.

Nothing here sleeps to let something happen: every wait polls until a deadline, because the tests
run on a machine shared with other work. Standard library and thorvald_model.ports (and the ROS
command-line tools the functions start).
"""

import os
import signal
import subprocess
import time
import xmlrpc.client
from typing import Callable, Dict, Iterator, List, Optional, Sequence, Union

from thorvald_model.ports import free_port

START = 30.0  # [s] for a process to come up on a busy machine


def poll(predicate: Callable, timeout: float, what: Union[str, Callable[[], str]], interval: float = 0.02):
    """predicate()'s first true value; AssertionError naming what (a string, or a callable giving one
    for a message that shows the state at the end) after timeout [s] of wall time."""
    deadline = time.monotonic() + timeout
    while True:
        value = predicate()
        if value:
            return value
        if time.monotonic() > deadline:
            raise AssertionError(f"timed out after {timeout:.0f} s waiting for {what() if callable(what) else what}")
        time.sleep(interval)


def ros_env(home, port: int, base: Optional[Dict[str, str]] = None) -> Dict[str, str]:
    """The environment of processes on a private master: ROS_MASTER_URI on port, ROS_HOME and logs in
    home, unbuffered Python, and nothing inherited that would put them elsewhere (a namespace, a
    host name, a terminal multiplexer)."""
    env = dict(os.environ if base is None else base)
    for name in ("TMUX", "ROS_NAMESPACE", "ROS_IP", "ROS_HOSTNAME"):
        env.pop(name, None)
    env.update(
        ROS_MASTER_URI=f"http://127.0.0.1:{port}",
        ROS_HOME=str(home),
        ROS_LOG_DIR=os.path.join(str(home), "log"),
        PYTHONUNBUFFERED="1",
    )
    return env


def master_is_up(uri: str) -> bool:
    try:
        with xmlrpc.client.ServerProxy(uri) as master:
            master.getPid("/thorvald_testing")
        return True
    except OSError:
        return False


def ros_master(home) -> Iterator[Dict[str, str]]:
    """Generator (for a pytest fixture): roscore on a free port with ROS_HOME in home; yields the
    environment to run processes with, and stops roscore when resumed."""
    env = ros_env(home, free_port())
    out_path = os.path.join(str(home), "roscore.out")
    with open(out_path, "w") as out:
        core = subprocess.Popen(
            ["roscore", "-p", env["ROS_MASTER_URI"].rsplit(":", 1)[1]],
            env=env,
            stdin=subprocess.DEVNULL,
            stdout=out,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
    try:

        def up():
            if core.poll() is not None:
                with open(out_path) as f:
                    raise AssertionError("roscore exited:\n" + f.read()[-3000:])
            return master_is_up(env["ROS_MASTER_URI"])

        poll(up, START, "the ROS master")
        yield env
    finally:
        stop_group(core)


def children(pid: int) -> List[int]:
    out = subprocess.run(["pgrep", "-P", str(pid)], capture_output=True, text=True)
    return [int(p) for p in out.stdout.split()]


def stop_group(proc: subprocess.Popen, grace: float = 10.0) -> None:
    """Ends a process started in a session of its own, and its children: SIGINT to its group (roscore
    and roslaunch stop what they started), SIGKILL to whatever is left after grace [s]."""
    kids = children(proc.pid)
    if proc.poll() is None:
        try:
            os.killpg(proc.pid, signal.SIGINT)
            proc.wait(timeout=grace)
            return
        except subprocess.TimeoutExpired:
            pass
        except ProcessLookupError:
            proc.wait(timeout=grace)
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
    proc.wait(timeout=grace)


def processes_naming(marker: str) -> List[int]:
    """Processes whose command line names marker (a test's temporary folder: roslaunch hands every
    node and the master a __log path in ROS_HOME), other than this process."""
    out = subprocess.run(["pgrep", "-f", marker], capture_output=True, text=True).stdout.split()
    return [int(p) for p in out if int(p) != os.getpid()]


def kill_processes_naming(marker: str) -> List[str]:
    """SIGKILL to every process naming marker; their command lines (what had to be killed)."""
    killed = []
    for pid in processes_naming(marker):
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                killed.append(f.read().replace(b"\0", b" ").decode(errors="replace"))
            os.kill(pid, signal.SIGKILL)
        except OSError:
            pass
    return killed


class Launch:
    """``roslaunch -p PORT FILE ARGS`` on a master of its own (started by roslaunch), in a session of
    its own, its output in home/roslaunch.out. :meth:`stop` ends it and everything it started."""

    def __init__(self, home, launch_file: str, args: Sequence[str] = (), env: Optional[Dict[str, str]] = None):
        self.home = str(home)
        self.port = free_port()
        self.env = ros_env(home, self.port, env)
        self.output = os.path.join(self.home, "roslaunch.out")
        self.left: List[str] = []  # what had to be killed when the with-block ended
        with open(self.output, "w") as out:
            self.proc = subprocess.Popen(
                ["roslaunch", "-p", str(self.port), launch_file, *args],
                env=self.env,
                stdin=subprocess.DEVNULL,
                stdout=out,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )

    def running(self) -> bool:
        return self.proc.poll() is None

    def tail(self, chars: int = 3000) -> str:
        with open(self.output, errors="replace") as f:
            return f.read()[-chars:]

    def run(self, command: Sequence[str], timeout: float = 30.0) -> subprocess.CompletedProcess:
        """A command (rostopic, rosservice, a probe script) on this launch's master."""
        return subprocess.run(
            list(command), env=self.env, stdin=subprocess.DEVNULL, capture_output=True, text=True, timeout=timeout
        )

    def stop(self) -> List[str]:
        """SIGINT to roslaunch (it stops its nodes and its master), then SIGKILL to whatever still
        names this launch's ROS_HOME; the command lines of what had to be killed."""
        if self.proc.poll() is None:
            try:
                os.killpg(self.proc.pid, signal.SIGINT)
                self.proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait(timeout=10)
            except ProcessLookupError:
                self.proc.wait(timeout=10)
        return kill_processes_naming(self.home)

    def __enter__(self) -> "Launch":
        return self

    def __exit__(self, *exc) -> None:
        self.left = self.stop()


__all__ = [
    "START",
    "Launch",
    "children",
    "free_port",
    "kill_processes_naming",
    "master_is_up",
    "poll",
    "processes_naming",
    "ros_env",
    "ros_master",
    "stop_group",
]
