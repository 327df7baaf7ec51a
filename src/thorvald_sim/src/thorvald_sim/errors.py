"""The simulator's errors: one base class, :class:`ThorvaldSimError`, for everything this package
refuses with a message that says why (the node catches it at the top, logs it and exits non-zero;
a service answers with its text).

Every exception class of the package is here. Those that were a built-in class before they joined
this module (a ValueError, a RuntimeError) still are, for code that catches that. The first ones are
also importable from the modules that raise them (``thorvald_sim.physics.simulation``'s SpawnError,
``thorvald_sim.physics.description``'s DescriptionError, ...), where code written before this module imports
them; :class:`SensorKindError` from the kinds' registry, :mod:`thorvald_sim.sensors.kinds`, where a
kind from outside is registered.
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


class WorkerError(ThorvaldSimError, RuntimeError):
    """A physics worker (:mod:`thorvald_sim.physics.workers`) that could not start, or failed a request other
    than a spawn's refusal (its text)."""


class SpawnInputError(ThorvaldSimError):
    """spawn_robot's or spawn_model's model text cannot be sent (:mod:`thorvald_sim.spawn.args`): the
    message says why (file, parameter, XML), in gazebo_ros's words where it has them."""


class SpawnFailed(ThorvaldSimError):
    """What went wrong in spawn_robot or spawn_model after the arguments were taken: no simulator
    answers, or it refused (exit status 1)."""


class MeshReadError(ThorvaldSimError, ValueError):
    """A mesh file that cannot be read (:mod:`thorvald_sim.models.meshes`); the message says why."""


class MalformedTf(ThorvaldSimError, ValueError):
    """Bytes that are not a serialised tf2_msgs/TFMessage (:mod:`thorvald_sim.node.tf_watch`)."""


class SensorKindError(ThorvaldSimError, ValueError):
    """A sensor kind that is not whole (a programming error, raised when the kind is made or
    registered: :mod:`thorvald_sim.sensors.kinds`)."""


class NotSimulated(ThorvaldSimError):
    """A Gazebo sensor block no sensor kind reads: :func:`thorvald_sim.sensors.blocks.read_sensor_blocks`
    lists it as unsupported; it never leaves that function."""
