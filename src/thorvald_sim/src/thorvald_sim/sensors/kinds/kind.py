"""One kind of sensor, as one value: :class:`SensorKind`.

A kind holds everything the simulator does with it: the Gazebo blocks it reads (sensor types with
plugin file names, or model plugins) and its readers, its model in pybullet, the messages it
publishes (a message type per topic role, and the function turning a reading into them) and its
RViz displays. :mod:`thorvald_sim.sensors.kinds` registers the kinds; the block reader
(:mod:`thorvald_sim.sensors.blocks`), the models (:mod:`thorvald_sim.sensors.mounted`), the publishers
(:mod:`thorvald_sim.node.sensor_io`) and the RViz configuration (:mod:`thorvald_sim.sensors.rviz`) all
look a kind up there and nowhere else.

A kind's functions see neither rospy nor message classes: ``messages(out, reading, wanted)`` asks
``out`` (a :class:`thorvald_sim.node.sensor_io.SensorIO`) for what it publishes:

* ``out.message(role)``: a new message of the role's type, its header stamped with the reading's
  instant and the sensor's frame;
* ``out.cloud(role, points, fields, dense)``: a ``sensor_msgs/PointCloud2`` of a structured array;
* ``out.publishes(role)``: whether the sensor has that topic (a block may leave one out);
* ``out.keep``: a dict kept from reading to reading (a message or a buffer made once);
* ``out.spec``: the sensor's :class:`~thorvald_sim.sensors.kinds.block.SensorSpec`.

It yields ``(role, message)`` for each topic read (``wanted[role]``: it has a subscriber).
``displays(spec, topic, name, colour)`` returns RViz display dicts, ``topic(role)`` being the full
topic the simulator publishes the role on.
"""

import re
from dataclasses import dataclass, field
from typing import Callable, Mapping, Optional, Tuple

from ...errors import SensorKindError

MESSAGE_TYPE = re.compile(r"^[A-Za-z][A-Za-z0-9_]*/[A-Za-z][A-Za-z0-9_]*$")
NAME = re.compile(r"^[a-z][a-z0-9_]*$")


@dataclass(frozen=True)
class SensorKind:
    """One kind of sensor (see the module's docstring)."""

    name: str  # SensorSpec.kind of the sensors it reads
    blocks: str  # the docs: the Gazebo blocks it reads (markdown, one table cell)
    published: str  # the docs: what it publishes (markdown, one table cell)
    model: type  # a thorvald_sim.sensors.kinds.model.Sensor: model(spec, robot, mount, noise, dt, context)
    roles: Mapping[str, str]  # topic role -> message type, e.g. {"scan": "sensor_msgs/LaserScan"}
    messages: Callable  # (out, reading, wanted) -> iterable of (role, message)
    displays: Callable  # (spec, topic: role -> full topic, name, colour) -> list of RViz display dicts
    sensors: Tuple[Tuple[str, Tuple[str, ...]], ...] = ()  # (<sensor type>, plugin file names) it reads
    read_sensor: Optional[Callable] = None  # (thorvald_sim.sensors.kinds.block.Found) -> SensorSpec
    model_plugins: Tuple[str, ...] = ()  # <gazebo><plugin> file names it reads
    read_model_plugin: Optional[Callable] = None  # (plugin Element, root link, file name, name) -> SensorSpec
    example: str = field(default="", repr=False)  # a block of the kind on a link "sensor_link" (its test reads it)

    def __post_init__(self) -> None:
        problems = []
        if not NAME.match(self.name):
            problems.append(f"name {self.name!r} must be a lower-case identifier")
        if not self.sensors and not self.model_plugins:
            problems.append("it reads no block: give sensors or model_plugins")
        if self.sensors and self.read_sensor is None:
            problems.append("it names sensor blocks but has no read_sensor")
        if self.model_plugins and self.read_model_plugin is None:
            problems.append("it names model plugins but has no read_model_plugin")
        for sensor_type, plugins in self.sensors:
            if not sensor_type or not plugins or isinstance(plugins, str):
                problems.append(f"sensors entry ({sensor_type!r}, {plugins!r}) must be (type, (plugin, ...))")
        if not self.roles:
            problems.append("it publishes nothing: give roles")
        for role, message_type in self.roles.items():
            if not MESSAGE_TYPE.match(message_type):
                problems.append(f"role {role!r}: {message_type!r} must be a message type, package/Type")
        if not isinstance(self.model, type) or not callable(getattr(self.model, "read", None)):
            problems.append(f"model {self.model!r} must be a Sensor class with read()")
        for what in ("messages", "displays"):
            if not callable(getattr(self, what)):
                problems.append(f"{what} must be a function")
        if not self.example:
            problems.append("it needs an example block (its test reads, builds and publishes it)")
        if problems:
            raise SensorKindError(f"sensor kind {self.name!r}: " + "; ".join(problems))

    def reads_sensor(self, sensor_type: str, filename: str) -> bool:
        return any(sensor_type == t and filename in plugins for t, plugins in self.sensors)


def no_display(spec, topic, name, colour):
    """A kind plain RViz has no display for (an IMU, a GNSS fix)."""
    return []
