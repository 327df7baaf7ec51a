"""Keyboard teleoperation, the pure part: the key map and the state machine of ``teleop_keyboard``.

No ROS here: :class:`KeyboardTeleop` takes keys and times (any monotonic clock, in seconds) and says what to
publish and when, so tests can drive it with fake times. The node (:mod:`thorvald_teleop.keyboard_node`) reads
the terminal, feeds the keys in and publishes what :meth:`KeyboardTeleop.due` returns.

The rules:

* a motion key sets the motion (the direction times the current speeds); a different motion key replaces it;
* while a motion is active it is published at ``rate``; a new motion, or a new speed, is published at once;
* a motion key not repeated within ``key_timeout`` stops the motion (the terminal's key repeat keeps it alive
  while the key is held);
* a stop (the stop key, the key timeout or quitting) gives ONE zero velocity and then nothing, so that the
  robot's twist_mux falls back to its next input (navigation) after its timeout; the stop key gives its zero
  even when idle;
* the speed keys multiply the linear and the angular speed by 1.1 or 0.9, each kept within its limits.
"""

import math
from typing import Dict, List, NamedTuple, Optional, Tuple

from .errors import TeleopConfigError


class Velocity(NamedTuple):
    """A planar velocity command: linear x, y [m/s] and angular z [rad/s]."""

    linear_x: float = 0.0
    linear_y: float = 0.0
    angular_z: float = 0.0


ZERO = Velocity()

# Directions: (linear x, linear y, angular z), each scaled by the linear or the angular speed.
FORWARD = (1, 0, 0)
BACKWARD = (-1, 0, 0)
LEFT = (0, 1, 0)
RIGHT = (0, -1, 0)
ROTATE_LEFT = (0, 0, 1)
ROTATE_RIGHT = (0, 0, -1)

# The terminal's byte sequences of the arrow keys (normal and application cursor mode).
ARROW_UP = ("\x1b[A", "\x1bOA")
ARROW_DOWN = ("\x1b[B", "\x1bOB")
ARROW_RIGHT = ("\x1b[C", "\x1bOC")
ARROW_LEFT = ("\x1b[D", "\x1bOD")

MOTION_KEYS: Dict[str, Tuple[int, int, int]] = {
    "w": FORWARD,
    "i": FORWARD,
    "s": BACKWARD,
    ",": BACKWARD,
    "a": LEFT,
    "j": LEFT,
    "d": RIGHT,
    "l": RIGHT,
    "q": ROTATE_LEFT,
    "u": ROTATE_LEFT,
    "e": ROTATE_RIGHT,
    "o": ROTATE_RIGHT,
}
MOTION_KEYS.update({k: FORWARD for k in ARROW_UP})
MOTION_KEYS.update({k: BACKWARD for k in ARROW_DOWN})
MOTION_KEYS.update({k: ROTATE_LEFT for k in ARROW_LEFT})
MOTION_KEYS.update({k: ROTATE_RIGHT for k in ARROW_RIGHT})
FASTER_KEYS = ("+", "=")  # "=" is "+" without shift on most layouts
SLOWER_KEYS = ("-",)
STOP_KEYS = (" ", "k")
ESC = "\x1b"
CTRL_C = "\x03"
QUIT_KEYS = (CTRL_C, ESC)

FASTER = 1.1
SLOWER = 0.9
# The speed keys never go below these (nor below the starting speeds, when those are lower).
MIN_SPEED = 0.05  # m/s
MIN_TURN = 0.05  # rad/s

# What on_key did.
MOTION = "motion"
SPEED = "speed"
STOP = "stop"
QUIT = "quit"
IGNORED = "ignored"

HELP = """\
Keyboard teleoperation: publishes geometry_msgs/Twist on {topic}

   forward           w  or  i  or  Up
   backward          s  or  ,  or  Down
   sideways left     a  or  j        (holonomic robots)
   sideways right    d  or  l        (holonomic robots)
   rotate left       q  or  u  or  Left
   rotate right      e  or  o  or  Right
   faster / slower   +  (or =)  /  -      (x1.1 / x0.9, linear and angular)
   stop              space  or  k
   quit              Esc  or  Ctrl-C

Hold a motion key to keep moving: the robot stops when the key is not repeated within {key_timeout:g} s."""


def split_keys(text: str) -> List[str]:
    """The keys in a chunk read from the terminal: one character each, an escape sequence (an arrow key:
    ESC [ X or ESC O X) as one key, a lone ESC as the Esc key."""
    keys = []
    i = 0
    while i < len(text):
        if text[i] == ESC and i + 1 < len(text) and text[i + 1] in "[O":
            # CSI / SS3: parameters, then one final byte in @..~
            j = i + 2
            while j < len(text) and not ("@" <= text[j] <= "~"):
                j += 1
            keys.append(text[i : j + 1])
            i = j + 1
        else:
            keys.append(text[i])
            i += 1
    return keys


def normalize_key(key: str) -> str:
    """Letters in either case (Caps Lock on)."""
    return key.lower() if len(key) == 1 else key


class KeyboardTeleop:
    """The state machine of the keyboard teleoperation (see the module's docstring)."""

    def __init__(
        self,
        *,
        speed: float = 0.5,
        turn: float = 0.5,
        rate: float = 20.0,
        key_timeout: float = 0.6,
        max_speed: float = 2.0,
        max_turn: float = 2.0,
    ):
        for name, value in (("speed", speed), ("turn", turn), ("rate", rate), ("key_timeout", key_timeout)):
            if not (value > 0 and math.isfinite(value)):
                raise TeleopConfigError(f"{name} must be a positive number, not {value!r}")
        if not speed <= max_speed:
            raise TeleopConfigError(f"speed {speed!r} m/s is above max_speed {max_speed!r} m/s")
        if not turn <= max_turn:
            raise TeleopConfigError(f"turn {turn!r} rad/s is above max_turn {max_turn!r} rad/s")
        self.speed = float(speed)
        self.turn = float(turn)
        self.period = 1.0 / float(rate)
        self.key_timeout = float(key_timeout)
        self.speed_limits = (min(MIN_SPEED, self.speed), float(max_speed))
        self.turn_limits = (min(MIN_TURN, self.turn), float(max_turn))
        self.direction: Optional[Tuple[int, int, int]] = None  # the active motion; None when idle
        self.last_motion_key = 0.0  # when the active motion's key was last seen
        self.next_publish: Optional[float] = None  # None: publish the motion at once
        self.zero_pending = False  # a stop happened: publish one zero

    @property
    def moving(self) -> bool:
        return self.direction is not None

    def command(self) -> Velocity:
        """The current motion's velocity (zero when idle)."""
        if self.direction is None:
            return ZERO
        x, y, z = self.direction
        return Velocity(x * self.speed, y * self.speed, z * self.turn)

    def on_key(self, key: str, now: float) -> str:
        """Takes one key (as :func:`split_keys` gives it) pressed at ``now``; returns what it did: MOTION,
        SPEED, STOP, QUIT or IGNORED. After QUIT, call :meth:`quit`."""
        key = normalize_key(key)
        if key in MOTION_KEYS:
            direction = MOTION_KEYS[key]
            if direction != self.direction:
                self.direction = direction
                self.next_publish = None
            self.last_motion_key = now
            self.zero_pending = False
            return MOTION
        if key in FASTER_KEYS or key in SLOWER_KEYS:
            factor = FASTER if key in FASTER_KEYS else SLOWER
            self.speed = _clamp(self.speed * factor, self.speed_limits)
            self.turn = _clamp(self.turn * factor, self.turn_limits)
            if self.moving:
                self.next_publish = None  # the new speed at once
            return SPEED
        if key in STOP_KEYS:
            self._stop()
            self.zero_pending = True  # even when idle: the user asked for a stop
            return STOP
        if key in QUIT_KEYS:
            return QUIT
        return IGNORED

    def due(self, now: float) -> Optional[Velocity]:
        """What to publish at ``now``, or None for nothing. Call it after every key and whenever
        :meth:`next_deadline` passes."""
        if self.moving and now - self.last_motion_key >= self.key_timeout:
            self._stop()
        if self.zero_pending:
            self.zero_pending = False
            return ZERO
        if not self.moving:
            return None
        if self.next_publish is None or now >= self.next_publish:
            # on schedule; after a stall (a late call), restart the schedule from now
            if self.next_publish is None or now >= self.next_publish + self.period:
                self.next_publish = now + self.period
            else:
                self.next_publish += self.period
            return self.command()
        return None

    def next_deadline(self, now: float) -> Optional[float]:
        """When :meth:`due` will next have something to publish without a key (the next publication or the key
        timeout); None when idle (nothing happens until a key)."""
        if self.zero_pending or (self.moving and self.next_publish is None):
            return now
        if not self.moving:
            return None
        return min(self.next_publish, self.last_motion_key + self.key_timeout)

    def quit(self) -> Optional[Velocity]:
        """Ends: ZERO when a motion was active or its zero not yet published (publish it), else None."""
        stop = self.moving or self.zero_pending
        self.direction = None
        self.next_publish = None
        self.zero_pending = False
        return ZERO if stop else None

    def _stop(self) -> None:
        if self.moving:
            self.zero_pending = True
        self.direction = None
        self.next_publish = None


def _clamp(value: float, limits: Tuple[float, float]) -> float:
    low, high = limits
    return min(max(value, low), high)
