"""Errors of the thorvald_base package.

One hierarchy, in the style of python-can: nodes catch :class:`ThorvaldBaseError` at the top of
``main()``; command-line tools print its message as one line and exit 2.
"""


class ThorvaldBaseError(Exception):
    """Base class of every error this package raises."""


class KinematicsError(ThorvaldBaseError):
    """A calculator cannot serve the drives it was given, or was used before initialize()."""


class PluginError(ThorvaldBaseError):
    """A calculator plugin cannot be found or loaded."""


class PluginNotFoundError(PluginError):
    """No package exports a calculator of that name; the message lists the known names."""

    def __init__(self, name, known):
        self.name = name
        self.known = tuple(sorted(known))
        listed = ", ".join(self.known) if self.known else "none (no package exports thorvald_base plugins)"
        super().__init__(
            f"unknown base_calculator '{name}': known calculators are {listed} (or give a 'python.module:Class')"
        )


class PluginImportError(PluginError):
    """The module of a calculator cannot be imported or lacks the class."""


class PluginTypeError(PluginError):
    """The loaded class is not a BaseCalculator."""


class PluginDescriptionError(PluginError):
    """A package's plugin description file is missing or malformed."""


class ParameterError(ThorvaldBaseError):
    """A node's ROS parameter is missing or invalid; the message names the parameter, value and rule."""


class CalibrationError(ThorvaldBaseError):
    """A recorded drive cannot calibrate odometry (too little of it, no ground truth, or it excites
    no parameter); the message says which and why."""
