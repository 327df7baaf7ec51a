"""Errors of the thorvald_design package: one base class, :class:`DesignError`, for everything the
package refuses with a message that says why. ``design_study`` catches it at the top of ``main()``,
prints the message and exits 2, without a traceback.

Every class is also a ``ValueError`` (a refused value, as python-can's and thorvald_teleop's are):
code written when the package raised bare ValueErrors, and ``except ValueError`` around a call,
still catch them. A study file is checked as a robot file is, so :class:`StudyError` is also
thorvald_model's ``ConfigError``: every problem of the file at once, each with its key path, value
and rule, in the robot files' format.

A run of a scenario never raises to the study: whatever it refuses becomes the run's
``"failed: ..."`` result (:func:`thorvald_design.runs.run_one`).
"""

from thorvald_model.errors import ConfigError


class DesignError(ValueError):
    """Base class of every error this package raises."""


class StudyError(ConfigError, DesignError):
    """A design study file that breaks its rules (every problem listed, as ``ConfigError`` lists a
    robot file's), or a combination of a search's space that the robot files' rules refuse.
    ConfigError first: its ``__init__`` (source, problems, what) is the one that runs."""


class ScenarioError(DesignError):
    """A scenario that cannot be run as asked (no turn suits the robot's steering limits), or a
    scenario kind that is not whole (a programming error, raised when the kind is made or
    registered: a metric declared twice, a prediction of no declared metric, a name registered twice)."""


class StaticsError(DesignError):
    """The quasi-static model refuses a robot or a question: a layout that cannot stand, a surface or
    an angle out of range, a description whose wheels do not stand on one plane, loads that do not
    converge."""


class MetricError(DesignError):
    """A track that cannot give the metric asked of it (too few poses, a straight line where a turn
    was asked for, a robot that did not advance)."""


class EnergyError(DesignError):
    """A motor, battery or power trace the energy model cannot use (out of range, a short circuit,
    a pack emptied)."""


class SearchError(DesignError):
    """A search (``--optimise``) given what it cannot search: an empty space, a metric of no scenario
    run, an evaluation without the metric, directions or points a Pareto front cannot rank."""


class ReportError(DesignError):
    """What the report cannot be made from: a Pareto plane of columns the results do not have (or
    without a better direction), a tracks file that is not one."""


__all__ = [
    "DesignError",
    "EnergyError",
    "MetricError",
    "ReportError",
    "ScenarioError",
    "SearchError",
    "StaticsError",
    "StudyError",
]
