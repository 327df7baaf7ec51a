"""The simulator's errors: one base class, :class:`ThorvaldSimError`, for everything this package
refuses with a message that says why (the node catches it at the top, logs it and exits non-zero;
a service answers with its text).

The classes are also importable from the modules that raise them (``thorvald_sim.simulation``'s
SpawnError, ``thorvald_sim.description``'s DescriptionError, ...), where code written before this
module imports them.
"""


class ThorvaldSimError(Exception):
    """Something the simulator refuses; the message says what and why."""


class ParameterError(ThorvaldSimError):
    """A parameter of the simulator node that breaks its rule (the name, the value, the rule)."""


class DescriptionError(ThorvaldSimError):
    """A robot description the simulator cannot use; the message says why."""


class SpawnError(ThorvaldSimError):
    """A robot that cannot be spawned (or deleted); the message says why."""


class MountError(ThorvaldSimError):
    """A sensor's link cannot be found on the loaded robot."""


class BlockError(ThorvaldSimError):
    """A Gazebo sensor or plugin block that breaks a rule: its element path and the rule."""

    def __init__(self, path: str, rule: str):
        super().__init__(f"{path}: {rule}")
        self.path = path
        self.rule = rule


class ModelError(SpawnError):
    """A model (an SDF ``<model>`` or a URDF that is not a Thorvald robot) that cannot be read or built:
    where it came from, the element path of the problem, and the rule it breaks."""

    def __init__(self, source: str, path: str, rule: str):
        super().__init__(f"{source}: {path}: {rule}" if path else f"{source}: {rule}")
        self.source = source
        self.path = path
        self.rule = rule
