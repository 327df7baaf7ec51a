"""Joystick to velocity commands, the joystick priority lock and steering homing, without ROS.

teleop_twist_joy's parameters and rules: nothing is commanded unless the deadman
(``enable_button``, or ``enable_turbo_button`` for the turbo scales) is held; releasing it sends
one zero twist, then nothing, so twist_mux falls back to navigation after its timeout. Ours on
top: a button toggles the joystick priority (twist_mux's lock on navigation), a button homes the
steering, and joystick messages that stop while the deadman is held (a lost joystick) give one
zero twist after ``joy_timeout``. A button index or axis index of -1 is unused.
"""

import math
from dataclasses import dataclass, field
from typing import Dict, Optional, Sequence, Tuple

from .errors import TeleopConfigError

__all__ = ["ZERO", "Actions", "TeleopConfig", "TeleopConfigError", "TeleopCore", "parameter_number"]

Twist3 = Tuple[float, float, float]  # vx [m/s], vy [m/s], wz [rad/s]
ZERO: Twist3 = (0.0, 0.0, 0.0)


def _axes(value, name: str, keys: Sequence[str], default: Dict[str, float]) -> Dict[str, float]:
    """teleop_twist_joy's forms: a number (the first key's), or a map {x: .., y: ..} / {yaw: ..}."""
    if value is None:
        return dict(default)
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return {keys[0]: value}
    if isinstance(value, dict):
        unknown = sorted(set(value) - set(keys))
        if unknown:
            raise TeleopConfigError(f"~{name}: {value!r}: unknown key(s) {unknown}; use {list(keys)}")
        out = {}
        for k, v in value.items():
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                raise TeleopConfigError(f"~{name}.{k}: {v!r}: must be a number")
            out[k] = v
        return out
    raise TeleopConfigError(f"~{name}: {value!r}: must be a number or a map of {list(keys)}")


def parameter_number(name: str, value) -> float:
    """A node's numeric parameter ``~name`` as a float; TeleopConfigError naming it if it is no number."""
    if isinstance(value, bool):
        raise TeleopConfigError(f"~{name}: {value!r}: must be a number")
    try:
        return float(value)
    except (TypeError, ValueError):
        raise TeleopConfigError(f"~{name}: {value!r}: must be a number") from None


def _index(params: dict, name: str, default: int) -> int:
    value = params.get(name, default)
    if isinstance(value, bool) or not isinstance(value, int) or value < -1:
        raise TeleopConfigError(f"~{name}: {value!r}: must be a button or axis index (>= 0), or -1 for none")
    return value


@dataclass(frozen=True)
class TeleopConfig:
    enable_button: int = 4
    enable_turbo_button: int = -1
    axis_linear: Dict[str, int] = field(default_factory=lambda: {"x": 1})
    scale_linear: Dict[str, float] = field(default_factory=lambda: {"x": 0.5})
    scale_linear_turbo: Dict[str, float] = field(default_factory=lambda: {"x": 1.0})
    axis_angular: Dict[str, int] = field(default_factory=lambda: {"yaw": 3})
    scale_angular: Dict[str, float] = field(default_factory=lambda: {"yaw": 0.5})
    scale_angular_turbo: Dict[str, float] = field(default_factory=lambda: {"yaw": 1.0})
    priority_button: int = -1
    home_steering_button: int = -1
    joy_timeout: float = 0.5  # [s]

    @classmethod
    def from_params(cls, params: dict) -> "TeleopConfig":
        d = cls()
        axis_linear = _axes(params.get("axis_linear"), "axis_linear", ("x", "y"), d.axis_linear)
        axis_angular = _axes(params.get("axis_angular"), "axis_angular", ("yaw",), d.axis_angular)
        for name, axes in (("axis_linear", axis_linear), ("axis_angular", axis_angular)):
            for k, v in axes.items():
                if v != int(v) or v < -1:
                    raise TeleopConfigError(f"~{name}.{k}: {v!r}: must be an axis index (>= 0), or -1 for none")
        scale_linear = _axes(params.get("scale_linear"), "scale_linear", ("x", "y"), d.scale_linear)
        scale_angular = _axes(params.get("scale_angular"), "scale_angular", ("yaw",), d.scale_angular)
        timeout = params.get("joy_timeout", d.joy_timeout)
        if isinstance(timeout, bool) or not isinstance(timeout, (int, float)) or not timeout > 0:
            raise TeleopConfigError(f"~joy_timeout: {timeout!r}: must be > 0 [s]")
        return cls(
            enable_button=_index(params, "enable_button", d.enable_button),
            enable_turbo_button=_index(params, "enable_turbo_button", d.enable_turbo_button),
            axis_linear={k: int(v) for k, v in axis_linear.items()},
            scale_linear=scale_linear,
            scale_linear_turbo=_axes(params.get("scale_linear_turbo"), "scale_linear_turbo", ("x", "y"), scale_linear),
            axis_angular={k: int(v) for k, v in axis_angular.items()},
            scale_angular=scale_angular,
            scale_angular_turbo=_axes(
                params.get("scale_angular_turbo"), "scale_angular_turbo", ("yaw",), scale_angular
            ),
            priority_button=_index(params, "priority_button", d.priority_button),
            home_steering_button=_index(params, "home_steering_button", d.home_steering_button),
            joy_timeout=float(timeout),
        )


@dataclass
class Actions:
    """What one joystick message (or a timeout) asks of the node."""

    twist: Optional[Twist3] = None  # publish this on cmd_vel
    priority: Optional[bool] = None  # publish this on joy_priority
    home_steering: bool = False  # call home_steering


class TeleopCore:
    def __init__(self, config: TeleopConfig):
        self.config = config
        self.priority = False
        self.sending = False  # the last twist sent was a motion (a zero is owed on release)
        self.last_joy: Optional[float] = None
        self._previous: Tuple[int, ...] = ()

    @staticmethod
    def _button(buttons: Sequence[int], index: int) -> bool:
        return 0 <= index < len(buttons) and bool(buttons[index])

    @staticmethod
    def _axis(axes: Sequence[float], index: int) -> float:
        value = axes[index] if 0 <= index < len(axes) else 0.0
        return value if math.isfinite(value) else 0.0

    def _pressed(self, buttons: Sequence[int], index: int) -> bool:
        """A rising edge of the button since the last message."""
        return self._button(buttons, index) and not self._button(self._previous, index)

    def on_joy(self, axes: Sequence[float], buttons: Sequence[int], now: float) -> Actions:
        c = self.config
        actions = Actions()
        self.last_joy = now
        if self._pressed(buttons, c.priority_button):
            self.priority = not self.priority
            actions.priority = self.priority
        if self._pressed(buttons, c.home_steering_button):
            actions.home_steering = True
        self._previous = tuple(int(b) for b in buttons)
        turbo = self._button(buttons, c.enable_turbo_button)
        if turbo or self._button(buttons, c.enable_button):
            linear = c.scale_linear_turbo if turbo else c.scale_linear
            angular = c.scale_angular_turbo if turbo else c.scale_angular
            actions.twist = (
                self._axis(axes, c.axis_linear.get("x", -1)) * linear.get("x", 0.0),
                self._axis(axes, c.axis_linear.get("y", -1)) * linear.get("y", 0.0),
                self._axis(axes, c.axis_angular.get("yaw", -1)) * angular.get("yaw", 0.0),
            )
            self.sending = True
        elif self.sending:
            actions.twist = ZERO  # released: one zero, then silence
            self.sending = False
        return actions

    def on_timer(self, now: float) -> Actions:
        """Joystick messages stopped while the deadman was held: one zero twist."""
        if self.sending and self.last_joy is not None and now - self.last_joy > self.config.joy_timeout:
            self.sending = False
            return Actions(twist=ZERO)
        return Actions()
