"""Errors of the thorvald_model package: one base class, :class:`ThorvaldModelError`, for everything
the package refuses with a message that says why; a file's every problem as a :class:`ConfigError`.

Each class keeps the built-in class it was before it joined this module (a ``ValueError``, a YAML
error), for code that catches that. One class is not an error of the package's: RobotConfigAbort, a
``BaseException`` that carries a ConfigError out of xacro and never reaches a user.
"""

from dataclasses import dataclass
from typing import Any, Sequence

import yaml

from .value_text import value_text


class ThorvaldModelError(Exception):
    """Base class of every error this package raises."""


MISSING = object()
"""Stands for the value of a key that is not in the file."""


@dataclass(frozen=True)
class Problem:
    """One broken rule of the robot configuration.

    path: dotted key path, e.g. ``motor_drives.drive1.str_lim``
    value: the offending value (``MISSING`` for an absent key)
    rule: what the value must satisfy, in words
    """

    path: str
    value: Any
    rule: str

    def format(self, source: str) -> str:
        # the value's repr, cut: it may be anything a file or a parameter tree holds, however large
        value = "<missing>" if self.value is MISSING else value_text(self.value)
        return "{}: {}: {}: {}".format(source, self.path or "<top level>", value, self.rule)


class ConfigError(ThorvaldModelError):
    """A robot configuration breaks one or more rules; every problem found is listed.

    A file that cannot be read at all is one problem of the whole file (path "", no value), and
    formats as one line: ``FILE: reason``.
    """

    def __init__(self, source: str, problems: Sequence[Problem], what: str = "robot configuration"):
        self.source = source
        self.problems = tuple(problems)
        self.what = what
        if len(self.problems) == 1 and self.problems[0].path == "" and self.problems[0].value is MISSING:
            super().__init__(f"{source}: {self.problems[0].rule}")
            return
        lines = [p.format(source) for p in self.problems]
        header = "{}: invalid {} ({} problem{}):".format(source, what, len(lines), "" if len(lines) == 1 else "s")
        super().__init__("\n".join([header] + ["  " + line for line in lines]))


class UrdfCheckError(ConfigError):
    """A robot description that breaks urdfdom's rules (:mod:`thorvald_model.urdf_check`); every
    problem is listed."""

    def __init__(self, source: str, problems: Sequence[Problem]):
        super().__init__(source, problems, what="robot description")


class UnknownRobotError(ThorvaldModelError, LookupError):
    """A robot named by a name that is none of the example robots' (:mod:`thorvald_model.examples`).

    ``rule`` is the broken rule in words, without the name, for a :class:`Problem` of the key that
    names it (a study's ``robot:``); the message is the rule with the name, one line.
    """

    def __init__(self, name: str, rule: str):
        super().__init__(f"{name!r}: {rule}")
        self.name = name
        self.rule = rule


class PluginError(ThorvaldModelError):
    """A plugin the robot file names (``base_calculator``) cannot be found or loaded
    (:mod:`thorvald_model.plugins`).

    ``rule`` is the broken rule in words, without the plugin's name, for a :class:`Problem` of the
    key that names it; the message is the rule with the plugin's name.
    """

    def __init__(self, message: str, rule: str = ""):
        super().__init__(message)
        self.rule = rule or message


class PluginNotFoundError(PluginError):
    """No package exports a plugin of that name; the message lists the known names."""

    def __init__(self, message: str, rule: str, name: str, known: Sequence[str]):
        super().__init__(message, rule)
        self.name = name
        self.known = tuple(sorted(known))


class PluginImportError(PluginError):
    """The module of a plugin cannot be imported or lacks the class."""


class PluginTypeError(PluginError):
    """The loaded class is not a subclass of the plugins' base class, or cannot be constructed."""


class PluginDescriptionError(PluginError):
    """A package's plugin description file is missing or malformed."""


class XacroError(ThorvaldModelError):
    """xacro failed on something other than the robot configuration (e.g. a broken extras file)."""


class RobotConfigAbort(BaseException):
    """Carries a ConfigError out of xacro (:mod:`thorvald_model.description`); not an error of its own.

    xacro catches every ``Exception`` while it evaluates an expression and again in its ``main()``,
    where it prints its own message and the file stack. A BaseException passes through both, so
    the caller can report the loader's message alone.
    """

    def __init__(self, error: ConfigError):
        super().__init__(str(error))
        self.error = error


class YamlBoundError(ThorvaldModelError, yaml.MarkedYAMLError):
    """A document past one of the bounds of :class:`thorvald_model.schema.BoundedLoader`; a YAML
    error as well (PyYAML's ``MarkedYAMLError``: its place in the document), as PyYAML's own are."""


class UrdfError(ThorvaldModelError, ValueError):
    """A robot description whose joints or masses cannot be read (:mod:`thorvald_model.joint_tree`,
    :mod:`thorvald_model.mass_properties`); the message says which and why. Also a ValueError, as it
    was before it joined this hierarchy."""


class StatePublisherError(ThorvaldModelError):
    """The state_publisher shim cannot start robot_state_publisher; the message says why."""
