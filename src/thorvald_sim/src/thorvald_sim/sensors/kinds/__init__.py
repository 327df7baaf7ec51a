"""The registry of sensor kinds: one :class:`~thorvald_sim.sensors.kinds.kind.SensorKind` a kind.

Every part of the simulator that does something per kind of sensor looks the kind up here: the
block reader (:func:`thorvald_sim.sensors.blocks.read_sensor_blocks`: which reader a ``<sensor>`` or
model ``<plugin>`` goes to), the models (:func:`thorvald_sim.sensors.mounted.build_sensors`), the publishers
(:class:`thorvald_sim.node.sensor_io.SensorIO`: each topic's message type and the messages of a
reading), the RViz configuration (:func:`thorvald_sim.sensors.rviz.sensor_displays`) and the docs'
table of kinds (:func:`kinds_markdown`, ``python -m thorvald_sim.sensors.kinds --update
docs/sensors.md``).

A new kind is a module of its own (its blocks' reader, its model, its messages, its displays and an
example block, in one :class:`SensorKind`) and one line in ``BUILT_IN``; a kind of a test or of a
user's program is added for a while with :func:`registered`. A kind that is not whole is refused
when it is made; two kinds claiming one block, when they are registered.
"""

from contextlib import contextmanager
from typing import Iterator, List, Optional, Sequence, Tuple

from ...errors import SensorKindError
from . import bumper, camera, gnss, imu, lidar, p3d
from .kind import SensorKind

BUILT_IN: Tuple[SensorKind, ...] = (
    lidar.LASER,
    lidar.MULTILAYER,
    imu.IMU,
    gnss.GPS,
    camera.CAMERA,
    camera.DEPTH,
    p3d.P3D,
    bumper.BUMPER,
)

_kinds: List[SensorKind] = list(BUILT_IN)  # BUILT_IN, then the kinds registered() added


def _check(kinds: Sequence[SensorKind]) -> None:
    """SensorKindError if two kinds share a name or claim the same block."""
    names, sensor_blocks, model_plugins = {}, {}, {}
    for kind in kinds:
        if kind.name in names:
            raise SensorKindError(f"sensor kind {kind.name!r} is registered twice")
        names[kind.name] = kind
        for sensor_type, plugins in kind.sensors:
            for plugin in plugins:
                other = sensor_blocks.setdefault((sensor_type, plugin), kind.name)
                if other != kind.name:
                    raise SensorKindError(
                        f"sensor kinds {other!r} and {kind.name!r} both read {sensor_type} + {plugin}"
                    )
        for plugin in kind.model_plugins:
            other = model_plugins.setdefault(plugin, kind.name)
            if other != kind.name:
                raise SensorKindError(f"sensor kinds {other!r} and {kind.name!r} both read model plugin {plugin}")


_check(BUILT_IN)


def sensor_kinds() -> Tuple[SensorKind, ...]:
    """The kinds registered now, built-in first."""
    return tuple(_kinds)


def kind_named(name: str) -> SensorKind:
    """The kind of that name (KeyError naming the registered ones if none)."""
    for kind in _kinds:
        if kind.name == name:
            return kind
    raise KeyError(f"no sensor kind {name!r} (registered: {', '.join(k.name for k in _kinds)})")


def kind_of_sensor(sensor_type: str, filename: str) -> Optional[SensorKind]:
    """The kind reading a ``<sensor type=sensor_type>`` with that plugin, or None."""
    return next((kind for kind in _kinds if kind.reads_sensor(sensor_type, filename)), None)


def kind_of_model_plugin(filename: str) -> Optional[SensorKind]:
    """The kind reading a model ``<plugin filename=...>``, or None."""
    return next((kind for kind in _kinds if filename in kind.model_plugins), None)


@contextmanager
def registered(*kinds: SensorKind) -> Iterator[None]:
    """The kinds added to the registry for the duration of a ``with`` block."""
    _check([*_kinds, *kinds])
    before = len(_kinds)
    _kinds.extend(kinds)
    try:
        yield
    finally:
        del _kinds[before:]


KINDS_TABLE = "sensor-kinds"  # the name of its marker lines in docs/sensors.md


def kinds_markdown() -> str:
    """The docs' table of kinds: the blocks each reads and what it publishes."""
    lines = ["| kind | block | published (in the robot's namespace unless the name is absolute) |", "|---|---|---|"]
    for kind in _kinds:
        lines.append(f"| `{kind.name}` | {kind.blocks} | {kind.published} |")
    return "\n".join(lines) + "\n"


__all__ = [
    "BUILT_IN",
    "KINDS_TABLE",
    "SensorKind",
    "SensorKindError",
    "kind_named",
    "kind_of_model_plugin",
    "kind_of_sensor",
    "kinds_markdown",
    "registered",
    "sensor_kinds",
]
