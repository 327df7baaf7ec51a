"""The ``joy_node`` node: a Linux joystick (``/dev/input/jsN``) as ``sensor_msgs/Joy`` on ``joy``.

The ROS ``joy`` package's node and parameters (Debian has no ``joy`` package):

- ``~dev`` (``/dev/input/js0``): the joystick device;
- ``~deadzone`` (0.05): axes within it read 0, the rest is rescaled so the output is continuous;
- ``~autorepeat_rate`` [Hz] (0, off): the last state is republished at this rate while nothing changes;
- ``~coalesce_interval`` [s] (0.001): axis events within it are merged into one message (a button
  change is published at once);
- ``~default_trig_val`` (false): take the axes' initial-state values (otherwise an axis reads 0 until
  it first moves, as in the joy package).

Axes are in -1..1 with the joy package's sign (``-value / 32767``: stick up or left is positive),
buttons 0 or 1; see :mod:`thorvald_teleop.joystick`. A missing or unplugged device is logged once,
one neutral message (all axes and buttons 0, the sizes last published) stops whatever follows the
joystick, and the device is opened again every second until it is back. The device's state is
published on ``/diagnostics`` once a second and when it changes: OK "connected" or ERROR
"no device <path>: <reason>".
"""

import select
import threading
import time

import rospy
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus, KeyValue
from sensor_msgs.msg import Joy

from .errors import DeviceUnavailable, ThorvaldTeleopError
from .joystick import JoystickReader, JoystickState, PublishSchedule, check_settings
from .teleop import parameter_number

RETRY_PERIOD = 1.0  # [s] between attempts to open a missing device
MAX_WAIT = 0.1  # [s] longest wait for events, so shutdown is seen quickly
REMINDER_PERIOD = 60.0  # [s] between warnings while a device stays missing for a new reason


class JoyNode:
    def __init__(self):
        self.dev = str(rospy.get_param("~dev", "/dev/input/js0"))
        settings, warnings = check_settings(
            parameter_number("deadzone", rospy.get_param("~deadzone", 0.05)),
            parameter_number("autorepeat_rate", rospy.get_param("~autorepeat_rate", 0.0)),
            parameter_number("coalesce_interval", rospy.get_param("~coalesce_interval", 0.001)),
        )
        for w in warnings:
            rospy.logwarn("joy_node: %s", w)
        self.settings = settings
        self.state = JoystickState(settings.deadzone, bool(rospy.get_param("~default_trig_val", False)))
        self.schedule = PublishSchedule(settings.coalesce_interval, settings.autorepeat_rate)
        self.reader = JoystickReader(self.dev)
        # queue of 10: a press and release read together are both delivered
        self.pub = rospy.Publisher("joy", Joy, queue_size=10)
        self.diag_pub = rospy.Publisher("/diagnostics", DiagnosticArray, queue_size=1)
        self.lock = threading.Lock()
        self.problem = "not opened yet"  # None while connected
        self.last_sizes = ([], [])  # axes and buttons of the last message published
        self.active = False  # a message was published since the last neutral one
        self.last_warning = None  # (time, reason)
        self.event_count = 0
        self.pub_count = 0
        self.last_diag = time.monotonic()
        self.stopping = threading.Event()
        rospy.on_shutdown(self.stopping.set)
        self.timer = rospy.Timer(rospy.Duration(1.0), self.publish_diagnostics, reset=True)
        rospy.loginfo(
            "joy_node: %s on %s, deadzone %.3f, autorepeat %.1f Hz, coalesce %.3f s",
            self.dev,
            self.pub.resolved_name,
            settings.deadzone,
            settings.autorepeat_rate,
            settings.coalesce_interval,
        )

    # the loop: open, read and publish, until shutdown

    def run(self):
        while not self.stopping.is_set():
            if not self.reader.is_open:
                try:
                    self.reader.open()
                except DeviceUnavailable as e:
                    self.device_lost(e.reason)
                    self.stopping.wait(RETRY_PERIOD)
                    continue
                self.connected()
            try:
                self.step()
            except DeviceUnavailable as e:
                self.device_lost(e.reason)
        self.reader.close()

    def step(self):
        """Waits for events or the next due publication (at most MAX_WAIT), then handles them."""
        now = time.monotonic()
        due = self.schedule.next_time()
        wait = MAX_WAIT if due is None else min(MAX_WAIT, max(0.0, due - now))
        if self.reader.pending:
            wait = 0.0
        readable, _, _ = select.select([self.reader], [], [], wait)
        if readable or self.reader.pending:
            for event in self.reader.read_events():
                with self.lock:
                    self.event_count += 1
                if not self.state.apply(event):
                    rospy.logwarn_throttle(
                        10.0,
                        "joy_node: unknown event type %#x (number %d, value %d)",
                        event.type,
                        event.number,
                        event.value,
                    )
                    continue
                if self.schedule.on_event(event, time.monotonic()):
                    self.publish(self.state.axes, self.state.buttons)
        if self.schedule.due(time.monotonic()):
            self.publish(self.state.axes, self.state.buttons)

    def connected(self):
        self.state.reset()
        self.schedule.reset()
        with self.lock:
            self.problem = None
        self.last_warning = None
        rospy.loginfo("joy_node: opened joystick %s", self.dev)
        self.publish_diagnostics()

    def device_lost(self, reason):
        """The device is missing or went away: warn once, stop what follows the joystick, report it."""
        self.reader.close()
        with self.lock:
            was_connected = self.problem is None
            self.problem = reason
        now = time.monotonic()
        stopped = self.active
        if stopped:
            axes, buttons = self.last_sizes
            self.publish([0.0] * len(axes), [0] * len(buttons), neutral=True)
        if was_connected or self.last_warning is None:
            rospy.logwarn(
                "joy_node: no joystick %s: %s; %sretrying every %.0f s",
                self.dev,
                reason,
                "published a neutral Joy (axes and buttons 0), " if stopped else "",
                RETRY_PERIOD,
            )
            self.last_warning = (now, reason)
        elif reason != self.last_warning[1] and now - self.last_warning[0] >= REMINDER_PERIOD:
            rospy.logwarn("joy_node: still no joystick %s: %s", self.dev, reason)
            self.last_warning = (now, reason)
        if was_connected:
            self.publish_diagnostics()

    # messages

    def publish(self, axes, buttons, neutral=False):
        msg = Joy(axes=list(axes), buttons=list(buttons))
        msg.header.stamp = rospy.Time.now()
        self.pub.publish(msg)
        self.schedule.published(time.monotonic())
        self.last_sizes = (msg.axes, msg.buttons)
        self.active = not neutral
        with self.lock:
            self.pub_count += 1

    def publish_diagnostics(self, _event=None):
        with self.lock:
            problem = self.problem
            now = time.monotonic()
            interval = max(now - self.last_diag, 1e-3)
            event_rate, pub_rate = self.event_count / interval, self.pub_count / interval
            if _event is not None:  # the rates are per timer period
                self.event_count = self.pub_count = 0
                self.last_diag = now
        status = DiagnosticStatus(name=rospy.get_name() + ": Joystick Driver Status", hardware_id=self.dev)
        if problem is None:
            status.level, status.message = DiagnosticStatus.OK, "connected"
        else:
            status.level, status.message = DiagnosticStatus.ERROR, f"no device {self.dev}: {problem}"
        status.values = [
            KeyValue("device", self.dev),
            KeyValue("topic", self.pub.resolved_name),
            KeyValue("dead zone", f"{self.settings.deadzone:g}"),
            KeyValue("autorepeat rate (Hz)", f"{self.settings.autorepeat_rate:g}"),
            KeyValue("coalesce interval (s)", f"{self.settings.coalesce_interval:g}"),
            KeyValue("recent joystick event rate (Hz)", f"{event_rate:.1f}"),
            KeyValue("recent publication rate (Hz)", f"{pub_rate:.1f}"),
        ]
        array = DiagnosticArray(status=[status])
        array.header.stamp = rospy.Time.now()
        try:
            self.diag_pub.publish(array)
        except rospy.ROSException:  # shutting down
            pass


def main():
    rospy.init_node("joy_node")
    try:
        node = JoyNode()
    except ThorvaldTeleopError as e:  # a parameter that cannot be used (a missing device is waited for)
        rospy.logfatal("joy_node: refusing to start: %s", e)
        return 1
    try:
        node.run()
    finally:
        node.timer.shutdown()
    return 0
