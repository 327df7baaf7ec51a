"""Errors of the thorvald_bringup package.

One hierarchy, as thorvald_model.errors and thorvald_base.errors have: every error this package
raises derives from :class:`ThorvaldBringupError`. The command-line tool (odometry_report) catches
it at the top of ``main()``, prints it as one line and exits 2, as it does for a robot file's
ConfigError.
"""


class ThorvaldBringupError(Exception):
    """Base class of every error this package raises."""


class ReportError(ThorvaldBringupError, ValueError):
    """The recording cannot make a report (missing topics, no manoeuvre in it, another robot's bag).
    Also a ValueError, as it was before this hierarchy, for code that catches that."""


class UnknownRobot(ThorvaldBringupError, LookupError):
    """A robot named on the command line is not one of the example robots; the message lists them."""


class DriveError(ThorvaldBringupError, RuntimeError):
    """The simulated drive did not finish (too slow, or the launch stopped without a bag); the
    message names the launch's log, and ``log_tail`` holds its last lines."""

    def __init__(self, message: str, log_tail: str = ""):
        super().__init__(message)
        self.log_tail = log_tail
