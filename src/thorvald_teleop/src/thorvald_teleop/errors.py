"""Errors of the thorvald_teleop package.

One hierarchy, as thorvald_model.errors and thorvald_base.errors have: every error this package
raises derives from :class:`ThorvaldTeleopError`, so the nodes (joy_node, teleop_node,
teleop_keyboard) catch it at the top of ``main()``, log it fatally and exit non-zero.
"""


class ThorvaldTeleopError(Exception):
    """Base class of every error this package raises."""


class TeleopConfigError(ThorvaldTeleopError, ValueError):
    """A controller file or parameter that cannot be used; the message names the parameter, the value
    and the rule. Also a ValueError, as it was before this hierarchy, for code that catches that."""


class DeviceUnavailable(ThorvaldTeleopError):
    """The joystick device is missing or went away; ``reason`` says why (for logs and diagnostics).
    joy_node waits for the device to come back rather than stopping on it."""

    def __init__(self, path: str, reason: str):
        super().__init__(f"{path}: {reason}")
        self.path = path
        self.reason = reason
