"""The ROS side of a robot's simulated sensors: their topics, messages, and what they cost.

As gazebo_ros's plugins, a sensor is measured only while one of its topics has a subscriber, so a
1920x1080 camera nobody reads costs nothing; it is measured at its rate on simulated time and its
messages are stamped with the simulated instant of the measurement. Topic and frame names are
resolved as the plugins resolve them (:func:`thorvald_sim.sensors.blocks.resolve_topic`,
:func:`~thorvald_sim.sensors.blocks.resolve_frame`).

A sensor whose reading fails (pybullet raises, memory runs out, numpy refuses, its message cannot be
made: whatever its reading or its messages raise) is disabled, alone: the error is logged once with
the robot, the sensor and its topics, and it stays on /diagnostics as an error from then on
(:attr:`SensorIO.failure`, :meth:`RobotSensors.disabled`); the simulation, its clock and every
other sensor and robot go on. Its topics stay advertised, silent, until the robot is deleted.

A robot is measured where its physics is (:mod:`thorvald_sim.physics.engine`: the node's own client or a
physics worker's): the node asks which sensors have readers (:meth:`RobotSensors.requests`), the
Engine pauses the others' schedules and reads the due ones after its step by the one schedule
(:func:`thorvald_sim.sensors.mounted.read_due`), and the node makes and publishes the messages of what it
read (:meth:`RobotSensors.publish_readings`), or disables a sensor whose reading failed with the
error's text. A sensor on a worker sees only its own worker's world (its robots, not the others').
"""

import importlib
import math
import struct
import time
import traceback
from io import BytesIO
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np
import rospy
from sensor_msgs.msg import Image, LaserScan, PointCloud2, PointField

from thorvald_base.publishing import NonBlockingPublisher

from ..sensors.blocks import resolve_frame, resolve_topic
from ..sensors.kinds import kind_named
from ..sensors.kinds.camera import CAMERA_DTYPE, packed_rgb
from ..sensors.kinds.camera import CAMERA_FIELDS as CAMERA_FIELD_SPECS
from ..sensors.kinds.lidar import LIDAR_DTYPE
from ..sensors.kinds.lidar import LIDAR_FIELDS as LIDAR_FIELD_SPECS
from ..sensors.mounted import DisabledSensor, Sensor, SensorUse, read_due


def point_fields(specs) -> List[PointField]:
    """sensor_msgs/PointField of a kind's (name, offset, datatype name) triples."""
    return [PointField(name, offset, getattr(PointField, datatype), 1) for name, offset, datatype in specs]


# PointCloud2 layouts (the kinds' own, as PointFields)
LIDAR_FIELDS = point_fields(LIDAR_FIELD_SPECS)
CAMERA_FIELDS = point_fields(CAMERA_FIELD_SPECS)

_LENGTH = struct.Struct("<I")  # a ROS array's length


class _ArrayFields:
    """A message whose last array fields (``ARRAYS``: name and element type, in order, followed by
    ``TAIL`` bytes of other fields) may be numpy arrays, serialised with their bytes as they are.
    genpy packs a float array float by float from a list that must be made first, and a uint8[]
    through ``struct`` after the caller made its bytes: for 720 beams at 40 Hz half of what
    publishing a scan cost beyond its rays; for a 320 x 240 depth camera's cloud 2.4 MB copied twice
    a frame. Every other field is genpy's own: it writes the message with those arrays empty, and
    each array's length and bytes go where its zero length was. Readers see the plain message
    (``test_sensor_io`` compares the bytes)."""

    __slots__ = ()
    ARRAYS: Tuple[Tuple[str, str], ...] = ()
    TAIL = 0  # bytes genpy writes after the arrays

    def serialize(self, buff):
        arrays = [getattr(self, name) for name, _ in self.ARRAYS]
        if not all(isinstance(a, np.ndarray) for a in arrays):
            return super().serialize(buff)
        try:
            for name, _ in self.ARRAYS:
                setattr(self, name, b"")
            rest = BytesIO()
            super().serialize(rest)
        finally:
            for (name, _), a in zip(self.ARRAYS, arrays):
                setattr(self, name, a)
        rest = rest.getbuffer()
        end = len(rest) - self.TAIL
        buff.write(rest[: end - _LENGTH.size * len(arrays)])
        for (_, kind), a in zip(self.ARRAYS, arrays):
            a = np.ascontiguousarray(a).reshape(-1)
            a = a.view(np.uint8) if kind == "<u1" else a.astype(kind, copy=False)  # uint8[]: the array's bytes
            buff.write(_LENGTH.pack(a.size))
            buff.write(a)
        buff.write(rest[end:])


class FastLaserScan(_ArrayFields, LaserScan):
    """A LaserScan whose ``ranges`` and ``intensities`` may be numpy arrays (float32)."""

    __slots__ = ()
    ARRAYS = (("ranges", "<f4"), ("intensities", "<f4"))


class FastImage(_ArrayFields, Image):
    """An Image whose ``data`` may be a numpy array (its bytes, row after row)."""

    __slots__ = ()
    ARRAYS = (("data", "<u1"),)


class FastPointCloud2(_ArrayFields, PointCloud2):
    """A PointCloud2 whose ``data`` may be a numpy array of its points (its bytes, point after point)."""

    __slots__ = ()
    ARRAYS = (("data", "<u1"),)
    TAIL = 1  # is_dense


def search_tf_prefix(namespace: str) -> str:
    """tf::getPrefixParam: the ``tf_prefix`` parameter searched up from the namespace ("" if none)."""
    parts = [p for p in namespace.strip("/").split("/") if p]
    for k in range(len(parts), -1, -1):
        name = "/" + "/".join([*parts[:k], "tf_prefix"])
        try:
            if rospy.has_param(name):
                return str(rospy.get_param(name) or "")
        except (OSError, rospy.ROSException):
            return ""
    return ""


# the message classes whose arrays may be numpy arrays (what a kind's messages hand over as they are)
FAST = {
    "sensor_msgs/LaserScan": FastLaserScan,
    "sensor_msgs/Image": FastImage,
    "sensor_msgs/PointCloud2": FastPointCloud2,
}


def message_class(message_type: str):
    """The class of a message type ("sensor_msgs/LaserScan"), its fast variant where there is one."""
    if message_type in FAST:
        return FAST[message_type]
    package, name = message_type.split("/")
    return getattr(importlib.import_module(f"{package}.msg"), name)


class SensorIO:
    """One sensor's publishers, and its readings turned into messages by its kind
    (:attr:`thorvald_sim.sensors.kinds.kind.SensorKind.messages`, which asks this object for them: see
    :mod:`thorvald_sim.sensors.kinds.kind`). publisher: the publisher class, called as
    ``publisher(topic, message class)`` (a test's may record what is published)."""

    def __init__(self, sensor: Sensor, namespace: str, tf_prefix: str, publisher=NonBlockingPublisher):
        self.sensor = sensor
        self.spec = spec = sensor.spec
        self.kind = kind_named(spec.kind)
        self.frame = resolve_frame(spec, tf_prefix, namespace)
        self.topics = {role: resolve_topic(spec, role, namespace) for role in spec.topics}
        self.classes = {role: message_class(self.kind.roles[role]) for role in spec.topics}
        self.pubs = {role: publisher(topic, self.classes[role]) for role, topic in self.topics.items()}
        self.cpu = 0.0  # [s] spent measuring and publishing since the last report
        self.readings = 0
        self.active = False
        self.failure: Optional[DisabledSensor] = None  # set when a reading failed: never read again
        self.keep: Dict[str, object] = {}  # the kind's messages and buffers kept from reading to reading
        self.stamp = rospy.Time()  # the instant of the reading being published
        self._schedule: Dict = {}  # read_due's record of this sensor's readers, when step measures it here

    def subscribed(self) -> Dict[str, bool]:
        return {role: pub.get_num_connections() > 0 for role, pub in self.pubs.items()}

    def step(self, now: float, wanted: Dict[str, bool]) -> None:
        """After a physics step at simulated time now, in the process that holds the sensor (a test, a
        tool): measured by the one schedule (:func:`thorvald_sim.sensors.mounted.read_due`) if it is due and
        read, and published. A reading that fails disables this sensor; nothing is raised."""
        if self.failure is not None:
            return
        self.active = any(wanted.values())
        results = read_due([self.sensor], [0] if self.active else [], now, self._schedule, self.sensor.robot.name)
        for result in results.values():
            if result[0] == "failed":
                self.failed(now, result[1], result[2])
            else:
                self.publish_reading(now, result[1], wanted, result[2])

    def disable(self, now: float, error: BaseException) -> None:
        """This sensor is not read again: the error logged once, kept for /diagnostics."""
        trace = "".join(traceback.format_exception(type(error), error, error.__traceback__))
        self.failed(now, f"{type(error).__name__}: {error}", trace)

    def failed(self, now: float, error: str, trace: str = "") -> None:
        """disable with the error's type and text (a worker's reading fails in its process: its text comes back)."""
        spec = self.sensor.spec
        what = f"{spec.describe()}: its reading failed: {error}"
        self.failure = DisabledSensor(spec.name, what, tuple(self.topics.values()), now)
        self.active = False
        self.keep.clear()  # a large frame's buffers go with it
        robot = self.sensor.robot.name
        rospy.logerr(
            "simulator: %s: sensor %s (%s) disabled at %.3f s, the simulation goes on without it: %s",
            robot, spec.name, ", ".join(self.topics.values()), now, what,
        )  # fmt: skip
        rospy.logdebug("simulator: %s: sensor %s: %s", robot, spec.name, trace)

    def _publish(self, now: float, reading, wanted: Dict[str, bool]) -> None:
        for role, msg in self.messages(reading, rospy.Time.from_sec(now), wanted):
            self.pubs[role].publish(msg)

    def publish_reading(self, now: float, reading, wanted: Dict[str, bool], cpu: float) -> None:
        """A reading at now measured by the one schedule (in an Engine: it cost cpu [s] there), published;
        a message that fails disables the sensor."""
        start = time.thread_time()
        try:
            self._publish(now, reading, wanted)
        except Exception as e:  # whatever one sensor raises must not stop the simulation
            self.disable(now, e)
            return
        self.cpu += cpu + time.thread_time() - start
        self.readings += 1

    def messages(self, reading, stamp, wanted):
        """(role, message) of a reading at stamp, those wanted (its kind's messages)."""
        self.stamp = stamp
        return self.kind.messages(self, reading, wanted)

    # ---- what a kind's messages ask for ---------------------------------------------------------
    def publishes(self, role: str) -> bool:
        return role in self.pubs

    def message(self, role: str):
        """A new message of the role's type, stamped with the reading's instant and the sensor's frame."""
        return self.header(self.classes[role](), self.stamp)

    def header(self, msg, stamp, frame: Optional[str] = None):
        msg.header.stamp = stamp
        msg.header.frame_id = self.frame if frame is None else frame
        return msg

    def cloud(self, role: str, data: np.ndarray, fields, dense: bool) -> PointCloud2:
        """A PointCloud2 of a structured array of points (height x width), little-endian; fields:
        (name, offset, sensor_msgs/PointField datatype name) of each."""
        msg = self.message(role)
        msg.height, msg.width = data.shape
        msg.fields = point_fields(fields)
        msg.is_bigendian = False
        msg.point_step = data.dtype.itemsize
        msg.row_step = msg.point_step * msg.width
        msg.is_dense = dense
        msg.data = data  # its bytes written as they are when published
        return msg

    def close(self) -> None:
        for pub in self.pubs.values():
            pub.unregister()


class RobotSensors:
    """All sensors of one robot; each checks its subscribers only when its reading is due, then every
    ``CHECK_PERIOD`` of simulated time at most (a connection count is a lock and a list: cheap, but
    not at 240 Hz per sensor per robot)."""

    CHECK_PERIOD = 0.1  # [s] simulated

    def __init__(
        self,
        sensors: List[Sensor],
        namespace: str,
        refused: Sequence[DisabledSensor] = (),
        publisher=NonBlockingPublisher,
    ):
        tf_prefix = search_tf_prefix(namespace)
        self.ios = [SensorIO(s, namespace, tf_prefix, publisher) for s in sensors]
        self.refused = tuple(refused)  # the sensors the robot spawned without
        self._wanted: List[Dict[str, bool]] = [{} for _ in self.ios]
        self._checked = -math.inf
        self._schedule: Dict = {}  # read_due's record of the sensors' readers, when step measures them here

    def step(self, now: float) -> None:
        """After a physics step at simulated time now, in the process that holds the sensors (a test, a
        tool): what the node does across an Engine, here: requests, the one schedule
        (:func:`thorvald_sim.sensors.mounted.read_due`), publish_readings."""
        if not self.ios:
            return
        wanted = self.requests(now)
        sensors = [io.sensor for io in self.ios]
        self.publish_readings(now, read_due(sensors, wanted, now, self._schedule, sensors[0].robot.name))

    def restart_time(self) -> None:
        """Simulated time went back to zero: who reads which sensor is asked again at the next step."""
        self._checked = -math.inf

    def _check(self, now: float) -> None:
        if now - self._checked >= self.CHECK_PERIOD:
            self._checked = now
            self._wanted = [io.subscribed() for io in self.ios]

    # ---- measured by an Engine (thorvald_sim.physics.engine: the node's or a worker's), published here ------
    def requests(self, now: float) -> Tuple[int, ...]:
        """Before a step to simulated time now: the indices of the sensors to step with readers (the
        Engine pauses the others' schedules and reads these when due)."""
        if not self.ios:
            return ()
        self._check(now)
        wanted = []
        for k, (io, roles) in enumerate(zip(self.ios, self._wanted)):
            io.active = io.failure is None and any(roles.values())
            if io.active:
                wanted.append(k)
        return tuple(wanted)

    def publish_readings(self, now: float, results: Dict[int, tuple]) -> None:
        """After the step: each sensor's reading at now published, or its failure (the error's text
        and trace, from wherever it was read) disabling it."""
        for k, result in results.items():
            io = self.ios[k]
            if io.failure is not None:
                continue
            if result[0] == "failed":
                io.failed(now, result[1], result[2])
            else:
                io.publish_reading(now, result[1], self._wanted[k], result[2])

    def uses(self) -> List[SensorUse]:
        """What each sensor read since the last call cost (sensors nobody reads are left out)."""
        out = []
        for io in self.ios:
            cpu, readings = io.cpu, io.readings
            io.cpu, io.readings = 0.0, 0
            if (readings or io.active) and io.failure is None:
                spec = io.sensor.spec
                topic = next(iter(io.topics.values()), "")
                out.append(SensorUse(f"{spec.kind} {spec.name} ({topic})", spec.rate, cpu, readings))
        return out

    def disabled(self) -> List[DisabledSensor]:
        """The robot's sensors refused at spawn and those disabled since (for /diagnostics)."""
        return [*self.refused, *(io.failure for io in self.ios if io.failure is not None)]

    def close(self) -> None:
        for io in self.ios:
            io.close()


__all__ = [
    "CAMERA_DTYPE",
    "CAMERA_FIELDS",
    "FAST",
    "LIDAR_DTYPE",
    "LIDAR_FIELDS",
    "FastImage",
    "FastLaserScan",
    "FastPointCloud2",
    "RobotSensors",
    "SensorIO",
    "message_class",
    "packed_rgb",
    "point_fields",
    "search_tf_prefix",
]
