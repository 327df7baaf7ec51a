"""The ``teleop_keyboard`` node: drives the robot from a terminal, for users without a joystick.

    rosrun thorvald_teleop teleop_keyboard [_speed:=0.5] [_turn:=0.5] [_rate:=20] [_key_timeout:=0.6]
    ROS_NAMESPACE=thorvald_001 rosrun thorvald_teleop teleop_keyboard     # a robot in a namespace

Publishes geometry_msgs/Twist on ``teleop_joy/cmd_vel`` (a relative name: it lands in the node's namespace,
where the robot's twist_mux takes it with a 0.5 s timeout). Keys (a help screen is printed at start):

    forward           w  or  i  or  Up
    backward          s  or  ,  or  Down
    sideways left     a  or  j        (holonomic robots)
    sideways right    d  or  l        (holonomic robots)
    rotate left       q  or  u  or  Left
    rotate right      e  or  o  or  Right
    faster / slower   +  (or =)  /  -      (linear and angular speed x1.1 / x0.9, within the limits)
    stop              space  or  k
    quit              Esc  or  Ctrl-C

Letters work in either case. A motion key not repeated within ``~key_timeout`` stops the motion: hold the key
and the terminal's key repeat keeps it alive (if the motion stutters when a key is first held, the terminal's
repeat delay is longer than ``~key_timeout``: raise it).

While a motion is active it is published at ``~rate``; a stop (the stop key, the key timeout, quitting) publishes
ONE zero Twist and then nothing, so that the twist_mux falls back to navigation.

Private parameters: ``~speed`` [m/s] (0.5) and ``~turn`` [rad/s] (0.5), the starting linear and angular speeds;
``~max_speed`` [m/s] (2.0) and ``~max_turn`` [rad/s] (2.0), the limits of the speed keys; ``~rate`` [Hz] (20);
``~key_timeout`` [s] (0.6).

It needs a terminal: with standard input not a terminal (roslaunch without ``launch-prefix="xterm -e"``, a
pipe) it exits at once with status 2. The terminal's settings are restored on exit, also on an exception,
SIGTERM, SIGINT or SIGHUP (each of which also stops the robot with one zero Twist first).

The state machine and the key map are in :mod:`thorvald_teleop.keyboard` (pure); this module reads the
terminal and publishes.
"""

import os
import select
import signal
import sys
import termios
import time
import warnings

import rospy
from geometry_msgs.msg import Twist

from .errors import ThorvaldTeleopError
from .keyboard import HELP, QUIT, SPEED, KeyboardTeleop, Velocity, split_keys
from .teleop import parameter_number

NAME = "teleop_keyboard"
TOPIC = "teleop_joy/cmd_vel"
EXIT_NO_TERMINAL = 2
EXIT_BAD_PARAMETER = 1
# The longest wait for a key when nothing is due, so that a signal or a ROS shutdown is noticed.
MAX_WAIT = 0.1


class RawTerminal:
    """Context manager: the terminal of ``fd`` without line buffering, echo or signal keys (Ctrl-C and Esc
    arrive as keys), output processing kept; the saved settings are restored on exit, exception or not."""

    def __init__(self, fd: int):
        self.fd = fd
        self.saved = None

    def __enter__(self):
        self.saved = termios.tcgetattr(self.fd)
        mode = termios.tcgetattr(self.fd)
        mode[0] &= ~(termios.IXON | termios.IXOFF)  # Ctrl-S / Ctrl-Q are keys, not flow control
        mode[3] &= ~(termios.ICANON | termios.ECHO | termios.ISIG | termios.IEXTEN)
        mode[6][termios.VMIN] = 1
        mode[6][termios.VTIME] = 0
        termios.tcsetattr(self.fd, termios.TCSADRAIN, mode)
        return self

    def __exit__(self, *exc):
        self.restore()
        return False

    def restore(self) -> None:
        if self.saved is None:
            return
        try:
            termios.tcsetattr(self.fd, termios.TCSADRAIN, self.saved)
        except (termios.error, OSError):
            pass  # the terminal is gone (hangup): nothing to restore
        self.saved = None

    def read_keys(self, timeout: float):
        """The keys typed within ``timeout`` seconds (empty when none); None at the end of input (hangup)."""
        ready, _, _ = select.select([self.fd], [], [], max(0.0, timeout))
        if not ready:
            return []
        try:
            data = os.read(self.fd, 1024)
        except OSError:
            return None
        if not data:
            return None
        return split_keys(data.decode("utf-8", "replace"))


def to_twist(v: Velocity) -> Twist:
    msg = Twist()
    msg.linear.x, msg.linear.y, msg.angular.z = v.linear_x, v.linear_y, v.angular_z
    return msg


class KeyboardNode:
    def __init__(self, teleop: KeyboardTeleop, terminal: RawTerminal):
        self.teleop = teleop
        self.terminal = terminal
        # Synchronous publishing (no queue_size): the last zero Twist must be written out before the node
        # shuts down, which a queued publisher's sending thread cannot promise. 20 small messages a second.
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", SyntaxWarning)
            self.pub = rospy.Publisher(TOPIC, Twist)
        self.stop_reason = None

    def on_signal(self, signum, _frame):
        self.stop_reason = signal.Signals(signum).name

    def publish(self, v: Velocity) -> None:
        self.pub.publish(to_twist(v))

    def say(self, text: str) -> None:
        sys.stdout.write(text + "\n")
        sys.stdout.flush()

    def speeds(self) -> str:
        return f"speed {self.teleop.speed:.3g} m/s, turn {self.teleop.turn:.3g} rad/s"

    def run(self) -> None:
        """Reads keys and publishes until quit, a signal, the end of input or a ROS shutdown; then publishes
        the last zero Twist if one is owed (also on an exception)."""
        try:
            while self.stop_reason is None and not rospy.is_shutdown():
                now = time.monotonic()
                deadline = self.teleop.next_deadline(now)
                wait = MAX_WAIT if deadline is None else min(MAX_WAIT, deadline - now)
                keys = self.terminal.read_keys(wait)
                if keys is None:
                    self.stop_reason = "end of input"
                    break
                for key in keys:
                    action = self.teleop.on_key(key, time.monotonic())
                    if action == QUIT:
                        self.stop_reason = "quit"
                        break
                    if action == SPEED:
                        self.say(self.speeds())
                if self.stop_reason is None:
                    v = self.teleop.due(time.monotonic())
                    if v is not None:
                        self.publish(v)
        finally:
            v = self.teleop.quit()
            if v is not None and not rospy.is_shutdown():
                self.publish(v)


def main(argv=None) -> int:
    argv = sys.argv if argv is None else argv
    if not sys.stdin.isatty():
        sys.stderr.write(
            f"{NAME}: standard input is not a terminal; run it in one "
            '(rosrun, or roslaunch with launch-prefix="xterm -e")\n'
        )
        return EXIT_NO_TERMINAL
    try:
        # our own signal handling: the terminal is restored and the robot stopped before exiting
        rospy.init_node(NAME, argv=argv, disable_signals=True)
        defaults = {"speed": 0.5, "turn": 0.5, "rate": 20.0, "key_timeout": 0.6, "max_speed": 2.0, "max_turn": 2.0}
        teleop = KeyboardTeleop(
            **{name: parameter_number(name, rospy.get_param("~" + name, value)) for name, value in defaults.items()}
        )
        node = KeyboardNode(teleop, RawTerminal(sys.stdin.fileno()))
    except ThorvaldTeleopError as e:  # a parameter that cannot be used; the terminal is not touched yet
        rospy.logfatal("%s: bad parameter: %s", NAME, e)
        rospy.signal_shutdown("bad parameter")
        return EXIT_BAD_PARAMETER
    except KeyboardInterrupt:  # Ctrl-C while waiting for the master, before the terminal was touched
        rospy.signal_shutdown("interrupted")
        return 130
    for sig in (signal.SIGTERM, signal.SIGINT, signal.SIGHUP):
        signal.signal(sig, node.on_signal)
    try:
        with node.terminal:
            node.say(HELP.format(topic=node.pub.resolved_name, key_timeout=teleop.key_timeout))
            node.say(node.speeds())
            node.run()
        rospy.loginfo("%s: stopped (%s)", NAME, node.stop_reason or "ROS shutdown")
    finally:
        rospy.signal_shutdown(f"{NAME}: {node.stop_reason or 'exit'}")
    return 0
