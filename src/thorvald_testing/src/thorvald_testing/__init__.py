"""What the workspace's tests share (pytest suites, rostest nodes and benchmarks alike).

* :func:`free_port`: a TCP port nobody listens on, for a ROS master of a test's own (outside the
  ephemeral range, so no node takes it meanwhile: thorvald_model.ports);
* :func:`poll`: wait for a condition with a deadline, failing with what was awaited;
* :func:`ros_env`, :class:`Master`, :func:`ros_master`: a private ROS master (its own port and
  ROS_HOME; roscore, or a bare rosmaster without rosout);
* :class:`Launch`: roslaunch in a session of its own (on a master of its own, or on a running one),
  stopped with everything it started;
* :class:`Processes`: processes started each in a session of its own, all stopped at the end;
* :func:`stop_group`, :func:`group_members`, :func:`processes_naming`, :func:`kill_processes_naming`:
  ending processes;
* :func:`children`, :func:`cmdline`, :func:`cpu_seconds`: what a process started and what it cost.

The benchmarks (bench/) use the same pieces, so a benchmark and a test start, wait for and stop
ROS processes one way.

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


class Master:
    """A ROS master of its own, up when the constructor returns: roscore (or, core_only, a bare
    ``rosmaster --core``: no rosout, nothing but the master to measure) on port (default: a free
    one), ROS_HOME in home, in a session of its own, its output in home/roscore.out. ``env`` is the
    environment to run processes on it with; :meth:`stop` ends it and what it started."""

    def __init__(self, home, core_only: bool = False, port: Optional[int] = None, base=None):
        self.home = str(home)
        self.port = free_port() if port is None else port
        self.env = ros_env(home, self.port, base)
        self.uri = self.env["ROS_MASTER_URI"]
        self.output = os.path.join(self.home, "roscore.out")
        command = ["rosmaster", "--core"] if core_only else ["roscore"]
        with open(self.output, "w") as out:
            self.proc = subprocess.Popen(
                [*command, "-p", str(self.port)],
                env=self.env,
                stdin=subprocess.DEVNULL,
                stdout=out,
                stderr=subprocess.STDOUT,
                start_new_session=True,
            )

        def up():
            if self.proc.poll() is not None:
                with open(self.output) as f:
                    raise AssertionError(f"{command[0]} exited:\n" + f.read()[-3000:])
            return master_is_up(self.uri)

        try:
            poll(up, START, "the ROS master")
        except BaseException:
            self.stop()
            raise

    def stop(self) -> None:
        stop_group(self.proc)

    def __enter__(self) -> "Master":
        return self

    def __exit__(self, *exc) -> None:
        self.stop()


def ros_master(home) -> Iterator[Dict[str, str]]:
    """Generator (for a pytest fixture): roscore on a free port with ROS_HOME in home; yields the
    environment to run processes with, and stops roscore when resumed."""
    master = Master(home)
    try:
        yield master.env
    finally:
        master.stop()


def children(pid: int) -> List[int]:
    out = subprocess.run(["pgrep", "-P", str(pid)], capture_output=True, text=True)
    return [int(p) for p in out.stdout.split()]


def cmdline(pid: int) -> str:
    """A process's command line, its arguments joined by spaces; "" if it has gone."""
    try:
        with open(f"/proc/{pid}/cmdline", "rb") as f:
            return f.read().replace(b"\0", b" ").decode(errors="replace")
    except OSError:
        return ""


CLK_TCK = os.sysconf("SC_CLK_TCK")  # [ticks/s] of /proc/<pid>/stat's times


def cpu_seconds(pid: int, missing: Optional[float] = None) -> float:
    """CPU time [s] a process has used, user and system (/proc/<pid>/stat fields 14 and 15); missing
    if it has gone (None: OSError)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            fields = f.read().rsplit(")", 1)[1].split()  # after the command name, which may hold spaces
    except OSError:
        if missing is None:
            raise
        return missing
    return (int(fields[11]) + int(fields[12])) / CLK_TCK


def group_members(pgid: int) -> List[int]:
    """The live processes of a process group (zombies, already dead, left out)."""
    out = subprocess.run(["pgrep", "-g", str(pgid)], capture_output=True, text=True)
    live = []
    for pid in (int(p) for p in out.stdout.split()):
        try:
            with open(f"/proc/{pid}/stat") as f:
                state = f.read().rsplit(")", 1)[1].split()[0]
        except (OSError, IndexError):
            continue
        if state != "Z":
            live.append(pid)
    return live


def stop_group(proc: subprocess.Popen, grace: float = 10.0) -> None:
    """Ends a process started in a session of its own, and its children: SIGINT to its group (roscore
    and roslaunch stop what they started), SIGKILL to whatever is left after grace [s], the leader's
    children and the members of its group that outlived it (a shell's background job ignores SIGINT)."""
    kids = children(proc.pid)
    deadline = time.monotonic() + grace
    if proc.poll() is None:
        try:
            os.killpg(proc.pid, signal.SIGINT)
            proc.wait(timeout=grace)
        except subprocess.TimeoutExpired:
            pass
        except ProcessLookupError:
            proc.wait(timeout=grace)
        if proc.poll() is not None:  # the leader has gone: the rest of its group has what is left of grace
            while group_members(proc.pid) and time.monotonic() < deadline:
                time.sleep(0.02)
            if not group_members(proc.pid):
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


class Processes:
    """Processes started each in a session of its own (so each stops with everything it started),
    with env (default: this process's environment); :meth:`stop_all` ends them, the last first."""

    def __init__(self, env: Optional[Dict[str, str]] = None):
        self.env = env
        self.procs: List[subprocess.Popen] = []

    def start(self, args: Sequence[str], out=subprocess.DEVNULL) -> subprocess.Popen:
        """args started with its output (and errors) to out (a file, or DEVNULL)."""
        proc = subprocess.Popen(
            list(args), env=self.env, stdin=subprocess.DEVNULL, stdout=out, stderr=subprocess.STDOUT,
            start_new_session=True,
        )  # fmt: skip
        self.procs.append(proc)
        return proc

    def stop(self, proc: subprocess.Popen, grace: float = 10.0) -> None:
        """proc and its group ended (stop_group); it is forgotten."""
        try:
            stop_group(proc, grace)
        finally:
            if proc in self.procs:
                self.procs.remove(proc)

    def stop_all(self) -> None:
        for proc in reversed(list(self.procs)):
            self.stop(proc)

    def __enter__(self) -> "Processes":
        return self

    def __exit__(self, *exc) -> None:
        self.stop_all()


class Launch:
    """``roslaunch -p PORT FILE ARGS`` in a session of its own, its output in home/roslaunch.out:
    on a master of its own (started by roslaunch on a free port), or, given port, on the master
    running there (roslaunch uses it and leaves it running). :meth:`stop` ends it and everything it
    started: every process naming home (ROS_HOME and the logs are there), so give each launch a
    home of its own that no other's path contains."""

    def __init__(
        self,
        home,
        launch_file: str,
        args: Sequence[str] = (),
        env: Optional[Dict[str, str]] = None,
        port: Optional[int] = None,
    ):
        self.home = str(home)
        self.port = free_port() if port is None else port
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
    "CLK_TCK",
    "START",
    "Launch",
    "Master",
    "Processes",
    "children",
    "cmdline",
    "cpu_seconds",
    "free_port",
    "group_members",
    "kill_processes_naming",
    "master_is_up",
    "poll",
    "processes_naming",
    "ros_env",
    "ros_master",
    "stop_group",
]
