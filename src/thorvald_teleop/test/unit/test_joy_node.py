"""The real joy_node on a ROS master of this test's own, with a FIFO standing in for /dev/input/js0.

The test writes recorded js_event streams into the FIFO (the initial-state burst, presses, stick
moves) and reads what the node publishes through a listener process (rospy stays out of the pytest
process). Closing the writer unplugs the joystick, opening it again plugs it back. Every wait polls
for a message with a deadline; "nothing else was published" is checked by the next message seen.
"""

import json
import os
import queue
import subprocess
import sys
import threading
import time

import pytest

from thorvald_teleop.joystick import JS_EVENT_AXIS, JS_EVENT_BUTTON, JS_EVENT_INIT, pack_event
from thorvald_testing import START, stop_group

TIMEOUT = 10.0  # [s] for a message that should come
OK, ERROR = 0, 2

pytestmark = pytest.mark.long(11)  # [s] in all: the parallel run starts it early

LISTENER = r"""
import json, sys
import rospy
from diagnostic_msgs.msg import DiagnosticArray
from sensor_msgs.msg import Joy

def out(item):
    sys.stdout.write(json.dumps(item) + "\n")
    sys.stdout.flush()

def on_joy(m):
    out({"joy": {"axes": list(m.axes), "buttons": list(m.buttons), "stamp": m.header.stamp.to_sec(),
                 "received": rospy.get_time()}})

def on_diagnostics(m):
    for s in m.status:
        if s.name.startswith("/joy_node:"):
            out({"diag": {"level": int(s.level), "message": s.message, "hardware_id": s.hardware_id}})

rospy.init_node("joy_listener", anonymous=True)
joy = rospy.Subscriber("joy", Joy, on_joy, queue_size=1000)
rospy.Subscriber("/diagnostics", DiagnosticArray, on_diagnostics, queue_size=1000)
rate = rospy.Rate(50)
said = False
while not rospy.is_shutdown():
    if not said and joy.get_num_connections() > 0:
        out({"connected": True})
        said = True
    rate.sleep()
"""


class Listener:
    """The Joy messages and joy_node's diagnostics, as a listener process receives them."""

    def __init__(self, env):
        self.proc = subprocess.Popen(
            [sys.executable, "-c", LISTENER],
            env=env,
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
            start_new_session=True,
        )
        self.lines = queue.Queue()
        self.joys, self.diags = [], []
        self.connected = False
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self):
        for line in self.proc.stdout:
            self.lines.put(json.loads(line))

    def _take(self, deadline):
        try:
            item = self.lines.get(timeout=max(0.0, deadline - time.monotonic()))
        except queue.Empty:
            return False
        if "joy" in item:
            self.joys.append(item["joy"])
        elif "diag" in item:
            self.diags.append(item["diag"])
        else:
            self.connected = True
        return True

    def wait_connected(self, timeout=START):
        deadline = time.monotonic() + timeout
        while not self.connected:
            assert self._take(deadline), "the listener never connected to joy_node's joy topic"

    def next_joy(self, timeout=TIMEOUT):
        """The next Joy message after the ones already returned."""
        deadline = time.monotonic() + timeout
        start = self.joy_cursor = getattr(self, "joy_cursor", 0)
        while len(self.joys) <= start:
            assert self._take(deadline), f"no Joy message within {timeout} s (got {len(self.joys)} in all)"
        self.joy_cursor += 1
        return self.joys[start]

    def pending_joys(self):
        """The Joy messages received and not yet returned (reads what has arrived, without waiting)."""
        while self._take(time.monotonic()):
            pass
        return self.joys[getattr(self, "joy_cursor", 0) :]

    def wait_diag(self, level, message_start="", timeout=TIMEOUT):
        """The next diagnostics of joy_node at ``level`` with a message starting so; skips the others."""
        deadline = time.monotonic() + timeout
        start = getattr(self, "diag_cursor", 0)
        while True:
            for i in range(start, len(self.diags)):
                d = self.diags[i]
                if d["level"] == level and d["message"].startswith(message_start):
                    self.diag_cursor = i + 1
                    return d
            start = len(self.diags)
            assert self._take(deadline), (
                f"no diagnostics {level} {message_start!r} within {timeout} s; last: {self.diags[-3:]}"
            )

    def close(self):
        stop_group(self.proc)


class JoyNode:
    """joy_node as rosrun starts it; its output goes to a file."""

    def __init__(self, env, tmp_path, dev, **params):
        self.log_path = tmp_path / "joy_node.log"
        self.log = open(self.log_path, "w")
        args = [f"_{k}:={v}" for k, v in params.items()]
        self.proc = subprocess.Popen(
            ["rosrun", "thorvald_teleop", "joy_node", f"_dev:={dev}", *args],
            env=env,
            stdout=self.log,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )

    def output(self):
        return self.log_path.read_text()

    def assert_running(self):
        assert self.proc.poll() is None, "joy_node exited:\n" + self.output()[-3000:]

    def stop(self):
        stop_group(self.proc)
        self.log.close()


@pytest.fixture
def run(ros_env, tmp_path):
    """Starts joy_node on a device path, and a listener connected to it; both stop after the test."""
    started = []

    def start(dev, **params):
        node = JoyNode(ros_env, tmp_path, dev, **params)
        listener = Listener(ros_env)
        started.extend([node, listener])
        try:
            listener.wait_connected()
        except AssertionError:
            raise AssertionError("no joy topic from joy_node:\n" + node.output()[-3000:]) from None
        return node, listener

    yield start
    for p in started:
        if isinstance(p, JoyNode):
            p.stop()
        else:
            p.close()


def plug(path, burst, timeout=TIMEOUT):
    """Opens the FIFO for writing, as a joystick plugged in, and writes its opening burst: returns the
    writer once joy_node has it. The reader the open meets may be joy_node's last look at an empty FIFO,
    closing after the end of file it read (the write then breaks the pipe): then plugged again."""
    deadline = time.monotonic() + timeout
    while True:
        writer = _open_writer(path, timeout)
        try:
            os.write(writer, burst)
            return writer
        except BrokenPipeError:
            os.close(writer)
            if time.monotonic() > deadline:
                pytest.fail(f"joy_node closed {path} after each open for {timeout} s")


def _open_writer(path, timeout):
    """Opens the FIFO for writing: returns once a reader (joy_node) has it open too."""
    opened = {}
    opener = threading.Thread(target=lambda: opened.setdefault("fd", os.open(path, os.O_WRONLY)), daemon=True)
    opener.start()
    opener.join(timeout)
    if opener.is_alive():  # release the blocked open with a reader of our own
        fd = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
        opener.join()
        os.close(opened["fd"])
        os.close(fd)
        pytest.fail(f"joy_node did not open {path} within {timeout} s")
    return opened["fd"]


def init_burst(buttons, axes):
    """What a joystick gives when it opens: the state of every button and axis, flagged JS_EVENT_INIT."""
    data = b"".join(pack_event(0, v, JS_EVENT_BUTTON | JS_EVENT_INIT, i) for i, v in enumerate(buttons))
    return data + b"".join(pack_event(0, v, JS_EVENT_AXIS | JS_EVENT_INIT, i) for i, v in enumerate(axes))


def button(number, pressed, t=100):
    return pack_event(t, int(pressed), JS_EVENT_BUTTON, number)


def axis(number, value, t=100):
    return pack_event(t, value, JS_EVENT_AXIS, number)


def scaled(value, deadzone=0.05):
    """The joy package's axis value: negated, the deadzone cut out and the rest rescaled to 1."""
    dz = 32767 * deadzone
    return -(value - dz) / (32767 - dz) if value > dz else -(value + dz) / (32767 - dz) if value < -dz else 0.0


def test_events_unplug_and_replug(run, tmp_path):
    fifo = str(tmp_path / "js0")
    os.mkfifo(fifo)
    node, joy = run(fifo)  # the default deadzone 0.05, no autorepeat
    # no writer yet: no device
    d = joy.wait_diag(ERROR, f"no device {fifo}: end of file")
    assert d["hardware_id"] == fifo
    assert joy.pending_joys() == []

    # an Xbox pad: 11 buttons (Y held), 8 axes, the triggers (2 and 5) at rest at -32767
    writer = plug(fifo, init_burst([0, 0, 0, 1] + [0] * 7, [0, 0, -32767, 0, 0, -32767, 0, 0]))
    first = joy.next_joy()
    assert first["buttons"] == [0, 0, 0, 1, 0, 0, 0, 0, 0, 0, 0]
    assert first["axes"] == [0.0] * 8  # initial axis values are not taken (the joy package's default)
    assert abs(first["stamp"] - first["received"]) < 2.0  # stamped now
    joy.wait_diag(OK, "connected")

    # a press: one message, so the initial burst was one message too
    os.write(writer, button(0, True))
    m = joy.next_joy()
    assert m["buttons"][:4] == [1, 0, 0, 1] and m["axes"] == [0.0] * 8

    # three axis events read together: one message; stick up is positive, a small move is in the deadzone
    os.write(writer, axis(1, -32767) + axis(0, 16384) + axis(3, 1000))
    m = joy.next_joy()
    assert m["axes"][:4] == [pytest.approx(scaled(16384)), 1.0, 0.0, 0.0]
    assert m["axes"][0] == pytest.approx(-0.4737, abs=1e-3)
    assert m["buttons"][:4] == [1, 0, 0, 1]

    # a release and a press read together: two messages, the press is not lost
    os.write(writer, button(0, False) + button(1, True) + axis(4, 32767))
    m = joy.next_joy()
    assert m["buttons"][:4] == [0, 0, 0, 1]
    m = joy.next_joy()
    assert m["buttons"][:4] == [0, 1, 0, 1]
    assert m["axes"][1] == 1.0 and m["axes"][4] == 0.0  # axis 4 waits for the coalesce interval
    m = joy.next_joy()
    assert m["axes"][4] == -1.0 and m["buttons"][:4] == [0, 1, 0, 1]

    # unplugged: one neutral message of the same sizes, an error in the diagnostics, the node keeps running
    os.close(writer)
    m = joy.next_joy()
    assert m["axes"] == [0.0] * 8 and m["buttons"] == [0] * 11
    joy.wait_diag(ERROR, f"no device {fifo}: end of file")
    joy.wait_diag(ERROR, f"no device {fifo}")  # once a second, while it retries
    joy.wait_diag(ERROR, f"no device {fifo}")
    node.assert_running()
    assert joy.pending_joys() == []
    warnings = [line for line in node.output().splitlines() if "no joystick" in line]
    assert len(warnings) == 2, warnings  # one at start (no writer), one for the unplug, none per retry
    assert "published a neutral Joy" in warnings[1]

    # plugged again, a smaller pad: its own sizes; the message after the neutral one is the new state
    writer = plug(fifo, init_burst([0, 0, 1, 0], [0, 0]))
    m = joy.next_joy()
    assert m["axes"] == [0.0, 0.0] and m["buttons"] == [0, 0, 1, 0]
    joy.wait_diag(OK, "connected")
    os.write(writer, axis(0, 32767))
    m = joy.next_joy()
    assert m["axes"] == [-1.0, 0.0] and m["buttons"] == [0, 0, 1, 0]
    os.close(writer)
    m = joy.next_joy()
    assert m["axes"] == [0.0, 0.0] and m["buttons"] == [0, 0, 0, 0]
    joy.wait_diag(ERROR, f"no device {fifo}")
    node.assert_running()


def test_a_missing_device_then_autorepeat(run, tmp_path):
    dev = tmp_path / "input" / "js1"
    dev.parent.mkdir()
    node, joy = run(str(dev), autorepeat_rate=20, deadzone=0.1)
    joy.wait_diag(ERROR, f"no device {dev}: No such file or directory (ENOENT)")
    joy.wait_diag(ERROR, f"no device {dev}: No such file or directory (ENOENT)")  # still retrying
    node.assert_running()
    assert joy.pending_joys() == []  # nothing known, nothing to stop: no message

    # the device appears
    os.mkfifo(str(dev))
    writer = plug(str(dev), init_burst([0, 0], [0, 0]))
    m = joy.next_joy()
    assert m["axes"] == [0.0, 0.0] and m["buttons"] == [0, 0]
    joy.wait_diag(OK, "connected")
    os.write(writer, axis(1, -20000) + button(1, True))
    moved = joy.next_joy()
    while moved["buttons"] != [0, 1]:  # repeats of the initial state may come first
        assert moved["axes"] == [0.0, 0.0]
        moved = joy.next_joy()
    assert moved["axes"] == [0.0, pytest.approx(scaled(-20000, 0.1))]
    assert moved["axes"][1] == pytest.approx(0.5672, abs=1e-3)

    # nothing changes: the state is repeated at about 20 Hz
    repeats = [joy.next_joy() for _ in range(6)]
    assert all(r["axes"] == moved["axes"] and r["buttons"] == [0, 1] for r in repeats)
    stamps = [moved["stamp"]] + [r["stamp"] for r in repeats]
    mean = (stamps[-1] - stamps[0]) / (len(stamps) - 1)
    assert 0.04 <= mean <= 0.15, stamps

    # unplugged: repeats stop after one neutral message
    os.close(writer)
    m = joy.next_joy()
    while m["buttons"] == [0, 1]:  # repeats sent before the unplug was read
        m = joy.next_joy()
    assert m["axes"] == [0.0, 0.0] and m["buttons"] == [0, 0]
    joy.wait_diag(ERROR, f"no device {dev}")
    joy.wait_diag(ERROR, f"no device {dev}")
    assert joy.pending_joys() == []
    node.assert_running()
