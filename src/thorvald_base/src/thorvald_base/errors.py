"""Errors of the thorvald_base package.

One hierarchy, in the style of python-can: nodes catch :class:`ThorvaldBaseError` at the top of
``main()``; command-line tools print its message as one line and exit 2.

The calculator plugins' errors (PluginError and its kinds) are thorvald_model's, as the plugin
mechanism is (thorvald_model.plugins: the robot file names the calculator); their names stay
importable from here. base_driver meets them as a ConfigError of the robot file (load_calculator).
"""

from thorvald_model.errors import (  # noqa: F401  (the names code written against this module imports)
    PluginDescriptionError,
    PluginError,
    PluginImportError,
    PluginNotFoundError,
    PluginTypeError,
)


class ThorvaldBaseError(Exception):
    """Base class of every error this package raises."""


class KinematicsError(ThorvaldBaseError):
    """A calculator cannot serve the drives it was given, or was used before initialize()."""


class ParameterError(ThorvaldBaseError):
    """A node's ROS parameter is missing or invalid; the message names the parameter, value and rule."""


class CalibrationError(ThorvaldBaseError):
    """A recorded drive cannot calibrate odometry (too little of it, no ground truth, or it excites
    no parameter); the message says which and why."""


class BagError(ThorvaldBaseError):
    """A recorded bag cannot be read, or lacks what calibration needs (calibrate_odometry)."""


class MalformedFrame(ThorvaldBaseError, ValueError):
    """A CAN frame whose length or content does not fit its identifier's layout
    (:mod:`thorvald_base.can.protocol`); the devices count it and go on. Also a ValueError, as it was
    before it joined this hierarchy, for code that catches that."""
