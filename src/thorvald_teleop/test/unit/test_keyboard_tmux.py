"""teleop_keyboard end to end: the real node in a terminal (a detached tmux session), driven with tmux send-keys,
its Twist messages read by a listener process, on a ROS master of this module's own (a free port).

Each node runs as ``stty -g > before; rosrun ...; echo $? > rc; stty -g > after`` in its pane, so the exit
status and the terminal's settings before and after are files to compare. Every wait polls with a deadline;
the only fixed intervals are the windows in which the node must stay silent and the period of a simulated key
repeat.
"""

import json
import os
import pty
import queue
import shlex
import shutil
import signal
import subprocess
import sys
import termios
import threading
import time

import pytest

from thorvald_teleop.keyboard_node import RawTerminal
from thorvald_testing import START, children, poll, stop_group

pytestmark = pytest.mark.long(11)  # [s] in all: the parallel run starts it early


@pytest.fixture(autouse=True)
def _tmux_and_ros():
    """A missing tool fails the test (tools/setup installs them): a skipped test would pass unseen."""
    missing = [tool for tool in ("tmux", "roscore", "rosrun") if not shutil.which(tool)]
    if missing:
        pytest.fail(f"needs {', '.join(missing)} (tools/setup installs them)", pytrace=False)


SPEED = 0.5
KEY_TIMEOUT = 0.6
RATE = 20.0
WAIT = 5.0  # deadline for an expected message [s]
SILENCE = 0.8  # after a stop the node must stay silent this long (longer than the mux's 0.5 s timeout)
FORWARD = [SPEED, 0, 0, 0, 0, 0]
ZERO = [0.0] * 6

# The listener: prints every Twist on argv[1] as a JSON line with its arrival time (CLOCK_MONOTONIC, the same
# clock as the test's), and the number of its publishers' connections whenever it changes.
LISTENER = """
import json, os, signal, sys, time
import rospy
from geometry_msgs.msg import Twist

# ended by SIGINT at the test's end: at once (rospy's shutdown at exit took the suite 10 s a test in CI,
# until stop_group's grace ran out)
signal.signal(signal.SIGINT, lambda *_: os._exit(0))

def on_twist(m):
    v = [m.linear.x, m.linear.y, m.linear.z, m.angular.x, m.angular.y, m.angular.z]
    print(json.dumps({"t": time.monotonic(), "v": v}), flush=True)

rospy.init_node("keyboard_test_listener", anonymous=True, disable_signals=True)
sub = rospy.Subscriber(sys.argv[1], Twist, on_twist, queue_size=1000)
print(json.dumps({"ready": True}), flush=True)
n = 0
while True:
    if sub.get_num_connections() != n:
        n = sub.get_num_connections()
        print(json.dumps({"connections": n}), flush=True)
    time.sleep(0.02)
"""


class Listener:
    """The Twist messages on one topic, read by a listener process."""

    def __init__(self, env, topic, log):
        self.lines = queue.Queue()
        self.messages = []  # [(arrival time, [linear xyz, angular xyz])]
        self.connections = 0
        with open(log, "w") as err:
            self.proc = subprocess.Popen(
                [sys.executable, "-c", LISTENER, topic],
                env=env,
                stdin=subprocess.DEVNULL,
                stdout=subprocess.PIPE,
                stderr=err,
                text=True,
                start_new_session=True,
            )
        self.reader = threading.Thread(target=self._read, daemon=True)
        self.reader.start()

    def _read(self):
        for line in self.proc.stdout:
            self.lines.put(json.loads(line))

    def update(self):
        while True:
            try:
                item = self.lines.get_nowait()
            except queue.Empty:
                return
            if "v" in item:
                self.messages.append((item["t"], item["v"]))
            elif "connections" in item:
                self.connections = item["connections"]

    def wait_for_message(self, after, timeout=WAIT, what="a message"):
        """The index of the first message after index ``after`` (waiting for it)."""

        def arrived():
            self.update()
            return len(self.messages) > after

        poll(arrived, timeout, what)
        return after

    def wait_for_zero(self, start, timeout=WAIT):
        """The index of the first zero message from index ``start``."""

        def zero():
            self.update()
            found = [i for i in range(start, len(self.messages)) if self.messages[i][1] == ZERO]
            return found[:1]

        return poll(zero, timeout, "a zero Twist")[0]

    def assert_silent(self, count, duration):
        """No message beyond the first ``count`` within ``duration`` seconds from now."""
        end = time.monotonic() + duration
        while time.monotonic() < end:
            self.update()
            assert len(self.messages) == count, f"a message after the stop: {self.messages[count:]}"
            time.sleep(0.02)

    def stop(self):
        stop_group(self.proc)
        self.reader.join(timeout=5)
        self.proc.stdout.close()


class Terminal:
    """The node in a detached tmux session of a private tmux server; the pane stays after the command ends."""

    def __init__(self, env, workdir, namespace, args):
        # the server's socket (-L) in the test's directory, not in /tmp/tmux-UID
        self.env = dict(env, TMUX_TMPDIR=str(workdir))
        self.dir = workdir
        self.socket = f"kbtest-{os.getpid()}-{namespace.strip('/')}"
        self.name = "teleop"
        conf = workdir / "tmux.conf"
        conf.write_text("set -g remain-on-exit on\nset -g default-shell /bin/sh\n")
        files = {k: shlex.quote(str(workdir / k)) for k in ("before", "after", "rc")}
        command = (
            f"stty -g > {files['before']}; "
            f"ROS_NAMESPACE={namespace} rosrun thorvald_teleop teleop_keyboard {args}; "
            f"echo $? > {files['rc']}; stty -g > {files['after']}"
        )
        self.tmux("-f", str(conf), "new-session", "-d", "-s", self.name, "-x", "120", "-y", "40", command)

    def tmux(self, *args):
        out = subprocess.run(["tmux", "-L", self.socket, *args], env=self.env, capture_output=True, text=True)
        assert out.returncode == 0, out.stderr
        return out.stdout

    def keys(self, *keys):
        self.tmux("send-keys", "-t", self.name, *keys)

    def screen(self):
        return self.tmux("capture-pane", "-p", "-J", "-t", self.name, "-S", "-")

    def wait_for_screen(self, text, timeout=START):
        return poll(lambda: text in self.screen() and self.screen(), timeout, f"{text!r} on the terminal")

    def node_pid(self):
        pane = int(self.tmux("display-message", "-p", "-t", self.name, "#{pane_pid}"))
        for pid in children(pane):
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                if b"teleop_keyboard" in f.read():
                    return int(pid)
        return None

    def wait_for_exit(self, timeout=WAIT):
        """The node's exit status, once the pane's command has written it and the terminal's settings after."""
        after = self.dir / "after"
        poll(lambda: after.exists() and after.read_text().strip(), timeout, "the node to exit")
        return int((self.dir / "rc").read_text())

    def settings(self, which):
        return (self.dir / which).read_text().strip()

    def close(self):
        subprocess.run(["tmux", "-L", self.socket, "kill-server"], env=self.env, capture_output=True)


@pytest.fixture
def start_teleop(ros_env, tmp_path):
    """start_teleop(namespace, args) starts the node in ``namespace`` (rosrun's arguments ``args``) and a listener
    on its topic; returns (terminal, listener) once the node shows its help screen and the listener is connected
    to it. Both are ended after the test, failed or not."""
    started = []

    def start(namespace, args="", speed=SPEED):
        listener = Listener(ros_env, namespace + "/teleop_joy/cmd_vel", tmp_path / "listener.err")
        started.append(listener)
        terminal = Terminal(ros_env, tmp_path, namespace, args)
        started.append(terminal)
        terminal.wait_for_screen("Keyboard teleoperation")
        terminal.wait_for_screen(f"speed {speed:g} m/s")
        poll(lambda: listener.update() or listener.connections > 0, START, "the listener to connect")
        return terminal, listener

    try:
        yield start
    finally:
        for item in reversed(started):
            if isinstance(item, Terminal):
                try:
                    print(item.screen())  # shown on failure
                except AssertionError:
                    pass
                item.close()
            else:
                item.stop()


def assert_close(v, expected):
    assert v == pytest.approx(expected, abs=1e-9), v


def test_drive_step_speed_stop_and_quit_with_esc(start_teleop):
    terminal, listener = start_teleop("/kb_drive")  # the default parameters
    screen = terminal.screen()
    assert "/kb_drive/teleop_joy/cmd_vel" in screen  # the relative name, in the node's namespace
    listener.update()
    assert listener.messages == []  # idle: silent

    # one press, not repeated: forward at ~speed for ~key_timeout, then one zero, then silence
    terminal.keys("-l", "w")
    first = listener.wait_for_message(0)
    zero = listener.wait_for_zero(first)
    moving = listener.messages[first:zero]
    for _, v in moving:
        assert_close(v, FORWARD)
    span = listener.messages[zero][0] - listener.messages[first][0]
    assert KEY_TIMEOUT - 0.15 < span < KEY_TIMEOUT + 0.4, span
    assert len(moving) >= 0.5 * KEY_TIMEOUT * RATE, len(moving)
    listener.assert_silent(zero + 1, SILENCE)

    # a speed step: shown, published nothing while idle; the motion then goes at speed x 1.1
    terminal.keys("-l", "+")
    terminal.wait_for_screen("speed 0.55 m/s, turn 0.55 rad/s", WAIT)
    listener.assert_silent(zero + 1, 0.1)

    # a held key (the terminal's key repeat: every 50 ms for 1 s): published at the rate, never a zero
    start = len(listener.messages)
    t0 = time.monotonic()
    while time.monotonic() - t0 < 1.0:
        terminal.keys("-l", "w")
        time.sleep(0.05)  # the key repeat's period, not a wait for a result
    held = listener.wait_for_message(start)
    # the stop key: one zero at once (before the key timeout), then silence
    terminal.keys("Space")
    pressed = time.monotonic()
    zero = listener.wait_for_zero(held)
    assert listener.messages[zero][0] - pressed < KEY_TIMEOUT, "the stop key did not stop at once"
    moving = listener.messages[held:zero]
    for _, v in moving:
        assert_close(v, [0.55, 0, 0, 0, 0, 0])
    times = [t for t, _ in moving]
    rate = (len(times) - 1) / (times[-1] - times[0])
    assert 0.6 * RATE < rate < 1.4 * RATE, rate
    listener.assert_silent(zero + 1, SILENCE)

    # sideways, then stop with k; rotate, then slower
    terminal.keys("-l", "a")
    i = listener.wait_for_message(zero + 1)
    assert_close(listener.messages[i][1], [0, 0.55, 0, 0, 0, 0])
    terminal.keys("-l", "k")
    zero = listener.wait_for_zero(i)
    terminal.keys("-l", "q")
    i = listener.wait_for_message(zero + 1)
    assert_close(listener.messages[i][1], [0, 0, 0, 0, 0, 0.55])
    terminal.keys("-l", "-")
    poll(
        lambda: listener.update() or any(v[5] == pytest.approx(0.495) for _, v in listener.messages[i:]),
        WAIT,
        "the slower rotation",
    )

    # quit with Esc while rotating: one zero, exit 0, the terminal's settings restored
    listener.update()
    i = len(listener.messages)
    terminal.keys("Escape")
    assert terminal.wait_for_exit() == 0
    zero = listener.wait_for_zero(i)
    listener.assert_silent(zero + 1, 0.3)
    assert terminal.settings("after") == terminal.settings("before")
    assert "Traceback" not in terminal.screen()


@pytest.mark.parametrize("how", ["ctrl_c", "sigterm"])
def test_quit_while_moving_stops_the_robot_and_restores_the_terminal(start_teleop, how):
    terminal, listener = start_teleop("/kb_" + how, "_speed:=0.8 _turn:=0.3", speed=0.8)
    terminal.keys("-l", "d")
    first = listener.wait_for_message(0)
    assert_close(listener.messages[first][1], [0, -0.8, 0, 0, 0, 0])  # ~speed
    assert "speed 0.8 m/s, turn 0.3 rad/s" in terminal.screen()
    quitting = time.monotonic()
    if how == "ctrl_c":
        terminal.keys("C-c")
    else:
        pid = poll(terminal.node_pid, WAIT, "the node's process")
        os.kill(pid, signal.SIGTERM)
    assert terminal.wait_for_exit() == 0
    zero = listener.wait_for_zero(first)
    assert listener.messages[zero][0] - quitting < KEY_TIMEOUT, "stopped by the key timeout, not by quitting"
    listener.assert_silent(zero + 1, 0.3)
    assert terminal.settings("after") == terminal.settings("before")
    assert "Traceback" not in terminal.screen()


@pytest.mark.slow  # a process per case: the command as a user types it
def test_refuses_to_start_without_a_terminal(tmp_path):
    env = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:9", ROS_HOME=str(tmp_path))  # no master needed
    out = subprocess.run(
        ["rosrun", "thorvald_teleop", "teleop_keyboard"],
        stdin=subprocess.DEVNULL,
        capture_output=True,
        text=True,
        env=env,
        timeout=START,
    )
    assert out.returncode == 2, out
    lines = out.stderr.strip().splitlines()
    assert len(lines) == 1 and "not a terminal" in lines[0], out.stderr
    assert "Traceback" not in out.stderr + out.stdout


def test_the_terminal_settings_are_restored_on_an_exception():
    master, slave = pty.openpty()
    try:
        before = termios.tcgetattr(slave)
        with pytest.raises(RuntimeError), RawTerminal(slave):
            raw = termios.tcgetattr(slave)
            assert not raw[3] & (termios.ICANON | termios.ECHO | termios.ISIG)
            assert raw[1] & termios.OPOST  # output still processed: newlines print as such
            raise RuntimeError("boom")
        assert termios.tcgetattr(slave) == before
        # keys typed in raw mode arrive one by one, escape sequences whole
        with RawTerminal(slave) as term:
            os.write(master, b"w\x1b[A\x03")
            assert poll(lambda: term.read_keys(0.1), WAIT, "the keys") == ["w", "\x1b[A", "\x03"]
            assert term.read_keys(0.0) == []
        assert termios.tcgetattr(slave) == before
    finally:
        os.close(master)
        os.close(slave)
