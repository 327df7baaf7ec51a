"""The ROS side of a robot's simulated sensors: their topics, messages, and what they cost.

As gazebo_ros's plugins, a sensor is measured only while one of its topics has a subscriber, so a
1920x1080 camera nobody reads costs nothing; it is measured at its rate on simulated time and its
messages are stamped with the simulated instant of the measurement. Topic and frame names are
resolved as the plugins resolve them (:func:`thorvald_sim.sensor_blocks.resolve_topic`,
:func:`~thorvald_sim.sensor_blocks.resolve_frame`).

A sensor whose reading fails (pybullet raises, memory runs out, numpy refuses, its message cannot be
made: whatever its reading or its messages raise) is disabled, alone: the error is logged once with
the robot, the sensor and its topics, and it stays on /diagnostics as an error from then on
(:attr:`SensorIO.failure`, :meth:`RobotSensors.disabled`); the simulation, its clock and every
other sensor and robot go on. Its topics stay advertised, silent, until the robot is deleted.
"""

import math
import struct
import time
import traceback
from io import BytesIO
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np
import rospy
from geometry_msgs.msg import Vector3Stamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import CameraInfo, Image, Imu, LaserScan, NavSatFix, NavSatStatus, PointCloud2, PointField

from thorvald_base.publishing import NonBlockingPublisher

from .sensor_blocks import resolve_frame, resolve_topic
from .sensors import DisabledSensor, Sensor, SensorUse, depth_to_points

MESSAGE_TYPES = {
    "scan": LaserScan,
    "points": PointCloud2,
    "imu": Imu,
    "fix": NavSatFix,
    "velocity": Vector3Stamped,
    "image": Image,
    "camera_info": CameraInfo,
    "depth": Image,
    "depth_info": CameraInfo,
    "odometry": Odometry,
}

# PointCloud2 layouts
LIDAR_FIELDS = [
    PointField("x", 0, PointField.FLOAT32, 1),
    PointField("y", 4, PointField.FLOAT32, 1),
    PointField("z", 8, PointField.FLOAT32, 1),
    PointField("intensity", 12, PointField.FLOAT32, 1),
    PointField("ring", 16, PointField.UINT16, 1),
    PointField("time", 18, PointField.FLOAT32, 1),
]
# velodyne_gazebo_plugins' layout: 22 bytes a point, the time of every point 0 (an instantaneous sweep)
LIDAR_DTYPE = np.dtype(
    {
        "names": ["x", "y", "z", "intensity", "ring", "time"],
        "formats": ["<f4", "<f4", "<f4", "<f4", "<u2", "<f4"],
        "offsets": [0, 4, 8, 12, 16, 18],
        "itemsize": 22,
    }
)
CAMERA_FIELDS = [
    PointField("x", 0, PointField.FLOAT32, 1),
    PointField("y", 4, PointField.FLOAT32, 1),
    PointField("z", 8, PointField.FLOAT32, 1),
    PointField("rgb", 16, PointField.FLOAT32, 1),
]
CAMERA_DTYPE = np.dtype(
    {"names": ["x", "y", "z", "rgb"], "formats": ["<f4", "<f4", "<f4", "<u4"], "offsets": [0, 4, 8, 16], "itemsize": 32}
)


_LENGTH = struct.Struct("<I")  # a ROS array's length


def packed_rgb(rgba: np.ndarray, out: Optional[np.ndarray] = None) -> np.ndarray:
    """The packed colours of RGBA pixels (... x 4, uint8) as a cloud's ``rgb`` field holds them,
    r << 16 | g << 8 | b (uint32; gazebo_ros's and PCL's layout), into out if given: each pixel's
    little-endian word (a b g r) byte-swapped and shifted right by 8."""
    words = np.ascontiguousarray(rgba, dtype=np.uint8).view("<u4")[..., 0]
    return np.right_shift(words.byteswap(), 8, out=out)


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


class SensorIO:
    """One sensor's publishers, and its readings turned into messages. publisher: the publisher class,
    called as ``publisher(topic, message type)`` (a test's may record what is published)."""

    def __init__(self, sensor: Sensor, namespace: str, tf_prefix: str, publisher=NonBlockingPublisher):
        self.sensor = sensor
        spec = sensor.spec
        self.frame = resolve_frame(spec, tf_prefix, namespace)
        self.topics = {role: resolve_topic(spec, role, namespace) for role in spec.topics}
        self.pubs = {role: publisher(topic, MESSAGE_TYPES[role]) for role, topic in self.topics.items()}
        self.cpu = 0.0  # [s] spent measuring and publishing since the last report
        self.readings = 0
        self.active = False
        self.failure: Optional[DisabledSensor] = None  # set when a reading failed: never read again
        self._scan_msg = None  # a planar lidar's LaserScan, reused
        self._points = None  # a depth camera's cloud, reused

    def subscribed(self) -> Dict[str, bool]:
        return {role: pub.get_num_connections() > 0 for role, pub in self.pubs.items()}

    def step(self, now: float, wanted: Dict[str, bool]) -> None:
        """After a physics step at simulated time now: measure and publish if it is due and read. A
        reading that fails disables this sensor (see the module's docstring); nothing is raised."""
        if self.failure is not None:
            return
        try:
            self._step(now, wanted)
        except Exception as e:  # whatever one sensor raises must not stop the simulation
            self.disable(now, e)

    def disable(self, now: float, error: BaseException) -> None:
        """This sensor is not read again: the error logged once, kept for /diagnostics."""
        spec = self.sensor.spec
        what = f"{spec.describe()}: its reading failed: {type(error).__name__}: {error}"
        self.failure = DisabledSensor(spec.name, what, tuple(self.topics.values()), now)
        self.active = False
        self._scan_msg = self._points = None  # a large frame's buffers go with it
        robot = self.sensor.robot.name
        rospy.logerr(
            "simulator: %s: sensor %s (%s) disabled at %.3f s, the simulation goes on without it: %s",
            robot, spec.name, ", ".join(self.topics.values()), now, what,
        )  # fmt: skip
        trace = "".join(traceback.format_exception(type(error), error, error.__traceback__))
        rospy.logdebug("simulator: %s: sensor %s: %s", robot, spec.name, trace)

    def _step(self, now: float, wanted: Dict[str, bool]) -> None:
        if not any(wanted.values()):
            if self.active:
                self.sensor.schedule.pause()
                self.active = False
            return
        self.active = True
        if not self.sensor.due(now):
            return
        start = time.thread_time()
        reading = self.sensor.read(now)
        stamp = rospy.Time.from_sec(now)
        for role, msg in self.messages(reading, stamp, wanted):
            self.pubs[role].publish(msg)
        self.cpu += time.thread_time() - start
        self.readings += 1

    def messages(self, reading, stamp, wanted):
        kind = self.sensor.spec.kind
        return getattr(self, "_" + kind)(reading, stamp, wanted)

    def header(self, msg, stamp, frame: Optional[str] = None):
        msg.header.stamp = stamp
        msg.header.frame_id = self.frame if frame is None else frame
        return msg

    # ---- kinds ------------------------------------------------------------------------------
    def _laser(self, scan, stamp, wanted):
        msg = self._scan_msg
        if msg is None:  # made once: a scan's fields but its stamp and ranges stay (publish serialises at once)
            c = self.sensor.spec.config
            msg = self._scan_msg = self.header(FastLaserScan(), stamp)
            msg.angle_min, msg.angle_max, msg.angle_increment = c.min_angle, c.max_angle, c.angle_increment
            msg.time_increment = 0.0  # an instantaneous scan, as gazebo_ros's
            msg.scan_time = 0.0
            msg.range_min, msg.range_max = c.range_min, c.range_max
            msg.intensities = np.zeros(scan.ranges.shape[1], dtype=np.float32)  # gazebo_ros's: one per beam
        msg.header.stamp = stamp
        ranges = scan.ranges[0] if scan.ranges.shape[0] == 1 else scan.ranges[scan.ranges.shape[0] // 2]
        msg.ranges = ranges.astype(np.float32)
        yield "scan", msg

    def _multilayer(self, scan, stamp, wanted):
        hit = np.isfinite(scan.ranges)
        points = scan.directions[hit] * scan.ranges[hit][:, None]
        rings = np.broadcast_to(np.arange(scan.ranges.shape[0])[:, None], scan.ranges.shape)[hit]
        data = np.zeros(len(points), dtype=LIDAR_DTYPE)
        data["x"], data["y"], data["z"] = points[:, 0], points[:, 1], points[:, 2]
        data["ring"] = rings
        yield "points", self.cloud(stamp, data[None, :], LIDAR_FIELDS, dense=True)

    def cloud(self, stamp, data: np.ndarray, fields, dense: bool) -> PointCloud2:
        """A PointCloud2 of a structured array of points (height x width), little-endian."""
        msg = self.header(FastPointCloud2(), stamp)
        msg.height, msg.width = data.shape
        msg.fields = fields
        msg.is_bigendian = False
        msg.point_step = data.dtype.itemsize
        msg.row_step = msg.point_step * msg.width
        msg.is_dense = dense
        msg.data = data  # its bytes written as they are when published
        return msg

    def _imu(self, r, stamp, wanted):
        msg = self.header(Imu(), stamp)
        msg.orientation.x, msg.orientation.y, msg.orientation.z, msg.orientation.w = r.orientation
        msg.angular_velocity.x, msg.angular_velocity.y, msg.angular_velocity.z = r.angular_velocity
        msg.linear_acceleration.x, msg.linear_acceleration.y, msg.linear_acceleration.z = r.linear_acceleration
        n2 = r.noise * r.noise
        diagonal = [n2, 0.0, 0.0, 0.0, n2, 0.0, 0.0, 0.0, n2]
        msg.orientation_covariance = diagonal
        msg.angular_velocity_covariance = diagonal
        msg.linear_acceleration_covariance = diagonal
        yield "imu", msg

    def _gps(self, r, stamp, wanted):
        c = self.sensor.spec.config
        fix = self.header(NavSatFix(), stamp)
        fix.status = NavSatStatus(status=c.status, service=c.service)
        fix.latitude, fix.longitude, fix.altitude = r.latitude, r.longitude, r.altitude
        fix.position_covariance = [r.covariance[0], 0.0, 0.0, 0.0, r.covariance[1], 0.0, 0.0, 0.0, r.covariance[2]]
        fix.position_covariance_type = NavSatFix.COVARIANCE_TYPE_DIAGONAL_KNOWN
        yield "fix", fix
        if "velocity" in self.pubs:
            velocity = self.header(Vector3Stamped(), stamp)
            velocity.vector.x, velocity.vector.y, velocity.vector.z = r.velocity
            yield "velocity", velocity

    def _camera(self, frame, stamp, wanted):
        c = self.sensor.spec.config
        if wanted.get("image"):
            image = self.header(FastImage(), stamp)
            image.height, image.width = c.height, c.width
            image.encoding = c.encoding
            image.is_bigendian = 0
            image.step = c.width * c.channels
            image.data = frame.image
            yield "image", image
        info = self.camera_info(stamp)
        if wanted.get("camera_info"):
            yield "camera_info", info
        if frame.depth is None:
            return
        if wanted.get("depth"):
            depth = self.header(FastImage(), stamp)
            depth.height, depth.width = c.height, c.width
            depth.encoding = "32FC1"
            depth.is_bigendian = 0
            depth.step = c.width * 4
            depth.data = np.asarray(frame.depth, dtype="<f4")
            yield "depth", depth
        if wanted.get("depth_info"):
            yield "depth_info", info
        if wanted.get("points"):
            data = self._points
            if data is None:  # made once, its padding zero: publish serialises at once, so reuse is safe
                data = self._points = np.zeros((c.height, c.width), dtype=CAMERA_DTYPE)
            depth_to_points(frame.depth, c, out=(data["x"], data["y"], data["z"]))
            if c.channels == 1:  # grey in each of r, g, b
                data["rgb"] = frame.image[..., 0].astype(np.uint32) * 0x010101
            else:  # from the renderer's RGBA, whatever the image's channel order
                packed_rgb(frame.rgba, out=data["rgb"])
            yield "points", self.cloud(stamp, data, CAMERA_FIELDS, dense=False)

    _depth = _camera

    def camera_info(self, stamp) -> CameraInfo:
        """gazebo_ros_camera_utils's intrinsics: focal length from horizontal_fov, centre ((w+1)/2, (h+1)/2)."""
        c = self.sensor.spec.config
        f = c.focal_length
        cx, cy = (c.width + 1) / 2.0, (c.height + 1) / 2.0
        info = self.header(CameraInfo(), stamp)
        info.height, info.width = c.height, c.width
        info.distortion_model = "plumb_bob"
        info.D = [0.0] * 5
        info.K = [f, 0.0, cx, 0.0, f, cy, 0.0, 0.0, 1.0]
        info.R = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
        info.P = [f, 0.0, cx, 0.0, 0.0, f, cy, 0.0, 0.0, 0.0, 1.0, 0.0]
        return info

    def _p3d(self, t, stamp, wanted):
        msg = self.header(Odometry(), stamp)
        msg.child_frame_id = self.sensor.spec.child_frame
        pose, twist = msg.pose.pose, msg.twist.twist
        pose.position.x, pose.position.y, pose.position.z = t.position
        pose.orientation.x, pose.orientation.y, pose.orientation.z, pose.orientation.w = t.orientation
        twist.linear.x, twist.linear.y, twist.linear.z = t.linear
        twist.angular.x, twist.angular.y, twist.angular.z = t.angular
        n2 = t.noise * t.noise
        covariance = [0.0] * 36
        for k in range(6):
            covariance[7 * k] = n2
        msg.pose.covariance = covariance
        msg.twist.covariance = list(covariance)
        yield "odometry", msg

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

    def step(self, now: float) -> None:
        if not self.ios:
            return
        if now - self._checked >= self.CHECK_PERIOD:
            self._checked = now
            self._wanted = [io.subscribed() for io in self.ios]
        for io, wanted in zip(self.ios, self._wanted):
            io.step(now, wanted)

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
