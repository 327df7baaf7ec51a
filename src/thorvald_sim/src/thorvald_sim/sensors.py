"""The robot's sensors in the pybullet world: what each measures, when, with its noise. No ROS here.

A :class:`Sensor` is made from a :class:`thorvald_sim.sensor_blocks.SensorSpec` and the robot it is
on. It is mounted on the link its Gazebo block names: pybullet merges links fixed to each other
(``URDF_MERGE_FIXED_LINKS``), so the mount is the nearest link pybullet kept (the base, or the
child of a moving joint) and the fixed joints' origins between, composed with the block's
``<pose>``.

Measurements are taken at the sensor's rate on simulated time (``due``): the next instant is the
last one plus the period, so 40 Hz gives 40 measurements per simulated second whatever the physics
rate; a sensor nobody reads is not measured at all (the simulator node asks ``due`` only while
the sensor has subscribers) and starts again from the instant it is read again.

* Lidars cast one ray per beam with ``rayTestBatch`` from ``range_min`` to ``range_max`` along the
  beam (as Gazebo's ray sensor, whose rays start at the minimum range), so they see the world, the
  other robots and the robot's own body beyond range_min; no hit is ``inf``. Gaussian noise on
  every beam (one without a return stays ``inf``).
* The IMU reads the mount's orientation in the world (its ``rpyOffset`` applied), its angular
  velocity and its proper acceleration (the mean acceleration since the last reading, minus
  gravity: +9.81 m/s^2 up at rest), in the sensor's axes; gaussianNoise on every component.
* The GNSS reads the mount's position and velocity in the world through hector's error model (an
  offset, a Gauss-Markov drift and white noise per axis) and converts them with hector's
  convention: world x is the reference heading's direction (compass, 0 = north), y 90 degrees
  to its left, latitude and longitude from the WGS84 radii at the reference latitude.
* Cameras render with pybullet's software renderer (no display): the camera looks along its
  frame's +x with +z up, as Gazebo's; depth cameras also give metric depth.
* p3d reports a link's pose and twist in the world (or in another link), with its offsets.

A sensor the robot goes without is a :class:`DisabledSensor`: refused at spawn (its block breaks
a rule, :mod:`thorvald_sim.sensor_blocks`, or its link cannot be mounted) or disabled when a
reading of it failed (``thorvald_sim.sensor_io``); the simulator reports each on /diagnostics
(:func:`disabled_report`) from then on.

Every sensor's noise comes from its own generator, seeded from the simulation's seed, the
robot's and sensor's names and the instant of the reading; readings fall on the multiples of the
sensor's period. A run therefore repeats whenever its subscribers came (see InstantNoise).
"""

import math
import operator
import re
import zlib
from dataclasses import dataclass
from typing import Dict, List, Optional, Tuple, Union

import numpy as np
import pybullet as p

from thorvald_base.rate_grid import RateGrid
from thorvald_model.datum import WGS84_A, WGS84_E2, earth_radii  # noqa: F401  (the constants: for tests)

from .description import ParentJoint, link_tree
from .errors import MountError
from .sensor_blocks import (
    CameraConfig,
    Datum,
    GpsConfig,
    ImuConfig,
    P3dConfig,
    RayConfig,
    SensorBlocks,
    SensorSpec,
    gps_reference,
)

Vec3 = Tuple[float, float, float]
Quat = Tuple[float, float, float, float]
Transform = Tuple[Vec3, Quat]
IDENTITY: Transform = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))

try:  # the arithmetic around a lidar's rays in C (csrc/scan.c, built by catkin_make); numpy otherwise
    from . import _scan
except ImportError:  # pragma: no cover - a build without Python's headers
    _scan = None

_FRACTION = operator.itemgetter(2)  # of a rayTestBatch result: (object, link, fraction, ...)
# pybullet's largest rayTestBatch: it refuses more than MAX_RAY_INTERSECTION_BATCH_SIZE_STREAMING (16384) rays,
# and for exactly that many it returns no results at all without an error (pybullet 3.2.7, checked)
RAY_BATCH = 16383


def beams(pose: Transform, directions: np.ndarray, limits: Tuple[float, float], out, *, compiled: bool = True) -> None:
    """The beams' start and end points in the world, into out = (starts, ends) (N x 3 each): origin +
    R d range_min and origin + R d range_max for each unit direction d (N x 3, the sensor frame), pose
    = (origin, quaternion) the sensor's in the world, limits = (range_min, range_max). compiled: the C
    loop of ``_scan`` where it is built (the same figures to a few ulp)."""
    (origin, quat), (range_min, range_max), (starts, ends) = pose, limits, out
    if compiled and _scan is not None:
        _scan.beams(quat, origin, directions, range_min, range_max, starts, ends)
        return
    d = directions @ np.asarray(p.getMatrixFromQuaternion(quat)).reshape(3, 3).T
    np.add(origin, d * range_min, out=starts)
    np.add(origin, d * range_max, out=ends)


def ranges_from_hits(
    hits,
    out: np.ndarray,
    limits: Tuple[float, float],
    noise: Optional[Tuple[float, np.ndarray]] = None,
    *,
    compiled: bool = True,
) -> None:
    """rayTestBatch's results (one per ray, cast from range_min to range_max: limits) as ranges into
    out: inf for a ray that hit nothing (fraction 1.0; a return at range_max is out of range anyway),
    plus stddev z where noise = (stddev, z: one standard normal per ray) is given (inf stays inf).
    compiled: the C loop of ``_scan`` where it is built (the same figures)."""
    range_min, range_max = limits
    stddev, z = noise if noise is not None else (0.0, None)
    if compiled and _scan is not None:
        _scan.ranges(hits, out, range_min, range_max, z, stddev)
        return
    n = len(hits)
    fractions = np.fromiter(map(_FRACTION, hits), float, n)
    out[:n] = np.where(fractions >= 1.0, np.inf, range_min + fractions * (range_max - range_min))
    if z is not None:
        out[:n] += stddev * z[:n]


def _transform(xyz: Vec3, rpy: Vec3) -> Transform:
    return tuple(xyz), tuple(p.getQuaternionFromEuler(rpy))


def _compose(a: Transform, b: Transform) -> Transform:
    pos, quat = p.multiplyTransforms(a[0], a[1], b[0], b[1])
    return tuple(pos), tuple(quat)


def _rotate(quat: Quat, v) -> np.ndarray:
    m = np.asarray(p.getMatrixFromQuaternion(quat)).reshape(3, 3)
    return m @ np.asarray(v, dtype=float)


def _unrotate(quat: Quat, v) -> np.ndarray:
    m = np.asarray(p.getMatrixFromQuaternion(quat)).reshape(3, 3)
    return m.T @ np.asarray(v, dtype=float)


def find_mount(
    tree: Dict[str, ParentJoint], joint_index: Dict[str, int], link: str, offset: Transform = IDENTITY
) -> Tuple[int, Transform]:
    """(pybullet link index, sensor frame in that link's frame) of a sensor on ``link``: up the fixed
    joints to the nearest link pybullet kept (-1: the base)."""
    chain = offset
    seen = set()
    while link in tree:
        joint = tree[link]
        if joint.type != "fixed" and joint.joint in joint_index:
            return joint_index[joint.joint], chain
        if link in seen:
            raise MountError(f"link {link} is in a loop of joints")
        seen.add(link)
        chain = _compose(_transform(joint.origin.xyz, joint.origin.rpy), chain)
        link = joint.parent
    return -1, chain


class InstantNoise:
    """A sensor's random numbers, drawn afresh at each instant: what is drawn at an instant depends
    on the seed, the robot's and sensor's names and the instant alone, not on when the sensor began
    to be read (subscribers come when they come), so a run repeats. A counter-based generator
    (Philox): the instant is the counter's second word (the first counts the draws within it), so
    two instants' draws never overlap; repositioning costs a couple of microseconds."""

    BLOCK = 32768  # standard normals drawn at once by normals()

    def __init__(self, seed: int, robot: str, sensor: str):
        self.key = np.array(
            [int(seed) & 0xFFFFFFFFFFFFFFFF, (zlib.crc32(robot.encode()) << 32) | zlib.crc32(sensor.encode())],
            dtype=np.uint64,
        )
        self.bits = np.random.Philox(key=self.key)
        self.generator = np.random.Generator(self.bits)
        self._block: Tuple[int, int, Optional[np.ndarray]] = (-1, 0, None)  # (block, n, its normals)

    def at(self, instant: int) -> np.random.Generator:
        """The generator positioned at the start of instant's draws (a whole number: the physics step)."""
        return self._position(instant, 0)

    def _position(self, word: int, kind: int) -> np.random.Generator:
        self.bits.state = {
            "bit_generator": "Philox",
            "state": {
                "counter": np.array([0, word & 0xFFFFFFFFFFFFFFFF, kind, 0], dtype=np.uint64),
                "key": self.key,
            },
            "buffer": np.zeros(4, dtype=np.uint64),
            "buffer_pos": 4,
            "has_uint32": 0,
            "uinteger": 0,
        }
        return self.generator

    def normals(self, reading: int, n: int) -> np.ndarray:
        """n standard normals of a reading (its index on the sensor's schedule: Sensor.reading), which
        depend on the seed, the names, n and the reading alone. They are drawn for BLOCK // n
        consecutive readings at once (the counter's third word 1 keeps them apart from at()'s): a
        lidar's 720 draws a scan cost a tenth of drawing them scan by scan. The array is the block's:
        read it, do not keep it."""
        per_block = max(1, self.BLOCK // n)
        block, slot = divmod(reading, per_block)
        cached, cached_n, draws = self._block
        if draws is None or cached != block or cached_n != n:
            draws = self._position(block, 1).standard_normal((per_block, n))
            self._block = (block, n, draws)
        return draws[slot]


class Sensor:
    """One sensor on one robot. ``read(now)`` measures and returns a reading (see the subclasses)."""

    def __init__(self, spec: SensorSpec, robot, mount: Tuple[int, Transform], noise: InstantNoise, dt: float):
        self.spec = spec
        self.robot = robot
        self.link_index, self.offset = mount
        self.noise = noise
        self.rng = noise.at(0)  # repositioned at each reading's instant by due()
        self.reading = 0  # the reading's index on the schedule's grid (the physics step's at rate 0), by due()
        self.dt = dt
        self.schedule = RateGrid(spec.rate, dt)  # a rate above the physics rate: once a step

    @property
    def client(self) -> int:
        return self.robot.client

    def due(self, now: float) -> bool:
        """Whether a reading is due at now; if so, the noise is that instant's."""
        if not self.schedule.due(now):
            return False
        self.rng = self.noise.at(round(now / self.dt))
        self.reading = self.schedule.index  # the multiple of the period served (the step's, at rate 0)
        return True

    def pose(self) -> Transform:
        """The sensor frame in the world."""
        pos, quat, _, _, _ = self.robot.link_state(self.link_index)
        return _compose((pos, quat), self.offset)

    def kinematics(self) -> Tuple[Transform, np.ndarray, np.ndarray]:
        """(sensor frame in the world, its point's velocity, angular velocity), world axes."""
        pos, quat, com, v, w = self.robot.link_state(self.link_index)
        frame = _compose((pos, quat), self.offset)
        rx, ry, rz = frame[0][0] - com[0], frame[0][1] - com[1], frame[0][2] - com[2]
        wx, wy, wz = w
        # v + w x r, in floats: numpy's cross on 3-vectors cost more than the rest of an IMU reading
        point = (v[0] + wy * rz - wz * ry, v[1] + wz * rx - wx * rz, v[2] + wx * ry - wy * rx)
        return frame, np.array(point), np.array(w)

    def read(self, now: float):
        """A measurement at simulated time now [s] (what it costs is the caller's to count)."""
        raise NotImplementedError


# ---------------------------------------------------------------------------------------------
# Lidars
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Scan:
    """ranges [m] (vertical samples x horizontal samples, inf: no return) and the beams' unit
    directions in the sensor frame (same shape + 3)."""

    ranges: np.ndarray
    directions: np.ndarray


class Lidar(Sensor):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        c: RayConfig = self.spec.config
        h = np.linspace(c.min_angle, c.max_angle, c.samples) if c.samples > 1 else np.array([c.min_angle])
        if c.vertical_samples > 1:
            v = np.linspace(c.vertical_min_angle, c.vertical_max_angle, c.vertical_samples)
        else:
            v = np.array([c.vertical_min_angle])
        vv, hh = np.meshgrid(v, h, indexing="ij")
        self.directions = np.stack([np.cos(vv) * np.cos(hh), np.cos(vv) * np.sin(hh), np.sin(vv)], axis=-1)
        self._flat = np.ascontiguousarray(self.directions.reshape(-1, 3))
        # the beams' ends in the world, rewritten at each reading (rayTestBatch copies them)
        self._starts, self._ends = np.empty_like(self._flat), np.empty_like(self._flat)

    def read(self, now: float) -> Scan:
        c: RayConfig = self.spec.config
        starts, ends = self._starts, self._ends
        limits = (c.range_min, c.range_max)
        # pybullet takes the arrays as they are (a list of them costs a fifth of the rays' time)
        beams(self.pose(), self._flat, limits, (starts, ends))
        ranges = np.empty(len(starts))
        # every beam's noise drawn (inf stays inf): the same draws whatever the beams hit
        z = self.noise.normals(self.reading, len(ranges)) if c.noise_stddev > 0 else None
        for k in range(0, len(starts), RAY_BATCH):
            n = min(RAY_BATCH, len(starts) - k)
            hits = p.rayTestBatch(starts[k : k + n], ends[k : k + n], physicsClientId=self.client)
            if len(hits) != n:  # the ranges it left unwritten would be published as they are: garbage
                raise RuntimeError(f"pybullet's rayTestBatch returned {len(hits)} results for {n} rays")
            noise = None if z is None else (c.noise_stddev, z[k : k + len(hits)])
            ranges_from_hits(hits, ranges[k : k + len(hits)], limits, noise)
        if c.noise_mean != 0:
            ranges += c.noise_mean
        return Scan(ranges.reshape(self.directions.shape[:2]), self.directions)


# ---------------------------------------------------------------------------------------------
# IMU
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ImuReading:
    orientation: Quat  # x, y, z, w: the sensor frame in the world
    angular_velocity: Vec3  # [rad/s] sensor axes
    linear_acceleration: Vec3  # [m/s^2] sensor axes, proper acceleration (gravity included)
    noise: float


class Imu(Sensor):
    def __init__(self, *args, gravity: float = 9.81, **kwargs):
        super().__init__(*args, **kwargs)
        self.gravity = gravity
        self.last: Optional[Tuple[float, np.ndarray]] = None  # (time, velocity) of the last reading
        self.offset_rotation = p.getQuaternionFromEuler(self.spec.config.rpy_offset)

    def read(self, now: float) -> ImuReading:
        c: ImuConfig = self.spec.config
        (_, quat), v, w = self.kinematics()
        if self.last is not None and now - self.last[0] > 1e-9 and now - self.last[0] < 1.0:
            a = (v - self.last[1]) / (now - self.last[0])
        else:
            a = np.zeros(3)
        self.last = (now, v)
        proper = a + np.array([0.0, 0.0, self.gravity])
        acc = _unrotate(quat, proper)
        gyro = _unrotate(quat, w)
        _, orientation = p.multiplyTransforms((0, 0, 0), self.offset_rotation, (0, 0, 0), quat)
        if c.noise > 0:
            acc = acc + self.rng.normal(0.0, c.noise, 3)
            gyro = gyro + self.rng.normal(0.0, c.noise, 3)
            q = np.asarray(orientation) + self.rng.normal(0.0, c.noise, 4)
            orientation = tuple(q / np.linalg.norm(q))
        return ImuReading(tuple(orientation), tuple(gyro), tuple(acc), c.noise)


# ---------------------------------------------------------------------------------------------
# GNSS
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class GnssReading:
    latitude: float  # [deg]
    longitude: float  # [deg]
    altitude: float  # [m]
    velocity: Vec3  # [m/s] in hector's axes (x the reference heading, y left of it, z up)
    covariance: Vec3  # diagonal [m^2]: drift^2 + noise^2 per axis (hector's)


class _ErrorProcess:
    """hector's SensorModel on three axes: value + offset + drift (Gauss-Markov) + white noise."""

    def __init__(self, model, rng: np.random.Generator):
        self.model = model
        self.rng = rng
        self.drift = np.zeros(3)

    def __call__(self, value: np.ndarray, dt: float) -> np.ndarray:
        m = self.model
        sigma, freq = np.asarray(m.drift), np.asarray(m.drift_frequency)
        if dt > 0 and np.any(sigma > 0):
            decay = np.exp(-dt * freq)
            self.drift = decay * self.drift + sigma * np.sqrt(1.0 - decay * decay) * self.rng.standard_normal(3)
        noise = np.asarray(m.gaussian_noise)
        white = noise * self.rng.standard_normal(3) if np.any(noise > 0) else 0.0
        return value + np.asarray(m.offset) + self.drift + white


class Gnss(Sensor):
    def __init__(self, *args, datum: Optional[Datum] = None, **kwargs):
        super().__init__(*args, **kwargs)
        c: GpsConfig = self.spec.config
        self.reference = gps_reference(self.spec, datum)
        self.radius_north, self.radius_east = earth_radii(self.reference[0])
        self.position_error = _ErrorProcess(c.position, self.rng)
        self.velocity_error = _ErrorProcess(c.velocity, self.rng)
        self.last_time: Optional[float] = None

    def read(self, now: float) -> GnssReading:
        c: GpsConfig = self.spec.config
        (pos, _), v, _ = self.kinematics()
        dt = 0.0 if self.last_time is None else now - self.last_time
        self.last_time = now
        velocity = self.velocity_error(v, dt)
        # hector: a velocity drift integrates into the position's drift
        self.position_error.drift = self.position_error.drift + dt * self.velocity_error.drift
        position = self.position_error(np.asarray(pos), dt)
        lat0, lon0, heading_deg, alt0 = self.reference
        h = math.radians(heading_deg)
        x, y, z = position
        latitude = lat0 + (math.cos(h) * x + math.sin(h) * y) / self.radius_north * 180.0 / math.pi
        longitude = lon0 - (-math.sin(h) * x + math.cos(h) * y) / self.radius_east * 180.0 / math.pi
        vel = (
            math.cos(h) * velocity[0] + math.sin(h) * velocity[1],
            -math.sin(h) * velocity[0] + math.cos(h) * velocity[1],
            float(velocity[2]),
        )
        covariance = tuple(float(d * d + n * n) for d, n in zip(c.position.drift, c.position.gaussian_noise))
        return GnssReading(latitude, longitude, alt0 + z, vel, covariance)


# ---------------------------------------------------------------------------------------------
# Cameras
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Frame:
    """A camera frame: the image (height x width x channels, uint8), for depth cameras the depth along
    the optical axis [m] (float32, NaN outside the point cloud's cutoffs), and the renderer's RGBA
    (height x width x 4, uint8; a cloud's colours come from it)."""

    image: np.ndarray
    depth: Optional[np.ndarray]
    rgba: np.ndarray


class Camera(Sensor):
    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        c: CameraConfig = self.spec.config
        vfov = 2.0 * math.atan(math.tan(c.horizontal_fov / 2.0) * c.height / c.width)
        self.projection = p.computeProjectionMatrixFOV(math.degrees(vfov), c.width / c.height, c.near, c.far)

    def read(self, now: float) -> Frame:
        c: CameraConfig = self.spec.config
        eye, quat = self.pose()
        forward = _rotate(quat, (1.0, 0.0, 0.0))
        up = _rotate(quat, (0.0, 0.0, 1.0))
        view = p.computeViewMatrix(eye, (np.asarray(eye) + forward).tolist(), up.tolist())
        flags = p.ER_NO_SEGMENTATION_MASK
        _, _, rgba, depth_buffer, _ = p.getCameraImage(
            c.width, c.height, view, self.projection, renderer=p.ER_TINY_RENDERER, flags=flags,
            physicsClientId=self.client,
        )  # fmt: skip
        rgba = np.asarray(rgba, dtype=np.uint8).reshape(c.height, c.width, 4)
        if c.channels == 1:
            image = np.asarray(rgba[:, :, :3].mean(axis=2), dtype=np.uint8)[:, :, None]
        else:  # channel by channel: numpy copies 3 bytes of every 4 at once five times slower
            image = np.empty((c.height, c.width, 3), dtype=np.uint8)
            for k, channel in enumerate((2, 1, 0) if c.encoding == "bgr8" else (0, 1, 2)):
                image[:, :, k] = rgba[:, :, channel]
        depth = None
        if c.depth:
            d = np.asarray(depth_buffer, dtype=np.float32).reshape(c.height, c.width)
            # OpenGL's depth buffer to metric depth along the optical axis, far near / (far - (far - near) d),
            # in float32 as the buffer is (0.02 mm at 10 m), in place: a frame's arrays are large
            depth = np.multiply(d, c.far - c.near)
            np.subtract(c.far, depth, out=depth)
            np.divide(c.far * c.near, depth, out=depth)
            invalid = d >= 1.0
            invalid |= depth < c.point_cloud_cutoff
            invalid |= depth > c.point_cloud_cutoff_max
            np.copyto(depth, np.float32(np.nan), where=invalid)
        return Frame(image, depth, rgba)


def depth_to_points(depth: np.ndarray, config: CameraConfig, out=None) -> Optional[np.ndarray]:
    """An organised cloud (height x width x 3) in the optical frame (z forward, x right, y down) from a
    depth image, with gazebo_ros's intrinsics (focal length from horizontal_fov, centre (w+1)/2, (h+1)/2).
    out: (x, y, z) arrays (height x width, e.g. a structured array's fields) to write into instead
    (then it returns None)."""
    h, w = depth.shape
    f = config.focal_length
    u = (np.arange(w, dtype=np.float32) + 1.0 - (w + 1) / 2.0) / np.float32(f)
    v = (np.arange(h, dtype=np.float32) + 1.0 - (h + 1) / 2.0) / np.float32(f)
    cloud = None
    if out is None:
        cloud = np.empty((h, w, 3), dtype=np.float32)
        out = (cloud[..., 0], cloud[..., 1], cloud[..., 2])
    x, y, z = out
    np.multiply(depth, u[None, :], out=x)
    np.multiply(depth, v[:, None], out=y)
    np.copyto(z, depth)
    return cloud


# ---------------------------------------------------------------------------------------------
# p3d (ground truth of a link)
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class LinkTruth:
    position: Vec3
    orientation: Quat
    linear: Vec3  # [m/s] in the reference frame's axes
    angular: Vec3  # [rad/s]
    noise: float


class P3d(Sensor):
    def __init__(self, *args, reference: Optional["Sensor"] = None, **kwargs):
        super().__init__(*args, **kwargs)
        self.reference = reference  # a Sensor-like mount of the reference link; None: the world
        c: P3dConfig = self.spec.config
        self.offset_rotation = p.getQuaternionFromEuler(c.rpy_offsets)

    def read(self, now: float) -> LinkTruth:
        c: P3dConfig = self.spec.config
        (pos, quat), v, w = self.kinematics()
        if self.reference is not None:
            (rpos, rquat), rv, rw = self.reference.kinematics()
            relative = np.asarray(pos) - np.asarray(rpos)
            v = _unrotate(rquat, v - rv - np.cross(rw, relative))
            w = _unrotate(rquat, w - rw)
            inv = p.invertTransform(rpos, rquat)
            pos, quat = p.multiplyTransforms(*inv, pos, quat)
        position = np.asarray(pos) + np.asarray(c.xyz_offsets)
        _, orientation = p.multiplyTransforms((0, 0, 0), self.offset_rotation, (0, 0, 0), quat)
        if c.noise > 0:
            position = position + self.rng.normal(0.0, c.noise, 3)
            v = v + self.rng.normal(0.0, c.noise, 3)
            w = w + self.rng.normal(0.0, c.noise, 3)
        return LinkTruth(tuple(position), tuple(orientation), tuple(v), tuple(w), c.noise)


# ---------------------------------------------------------------------------------------------
# A robot's sensors
# ---------------------------------------------------------------------------------------------
KINDS = {"laser": Lidar, "multilayer": Lidar, "imu": Imu, "gps": Gnss, "camera": Camera, "depth": Camera, "p3d": P3d}


@dataclass(frozen=True)
class MountProblem:
    """A sensor whose link cannot be mounted on the loaded robot."""

    spec: SensorSpec
    problem: str

    def __str__(self) -> str:
        return f"{self.spec.describe()}: {self.problem}"


def build_sensors(
    specs,
    robot,
    links: Union[str, Dict[str, ParentJoint]],
    *,
    seed: int = 0,
    dt: float,
    gravity: float = 9.81,
    datum: Optional[Datum] = None,
) -> Tuple[List[Sensor], List[MountProblem]]:
    """The robot's sensors from its specs and its link tree (or its description's text, parsed for it);
    (sensors, problems) where a problem names a sensor whose link cannot be mounted (the others are kept)."""
    tree = link_tree(links) if isinstance(links, str) else links
    sensors, problems = [], []
    for spec in specs:
        try:
            mount = find_mount(tree, robot.joint_index, spec.link, _transform(spec.pose.xyz, spec.pose.rpy))
        except MountError as e:
            problems.append(MountProblem(spec, str(e)))
            continue
        noise = InstantNoise(seed, robot.name, spec.name + "@" + spec.link)
        extra = {}
        if spec.kind == "imu":
            extra["gravity"] = gravity
        elif spec.kind == "gps":
            extra["datum"] = datum
        elif spec.kind == "p3d" and spec.config.reference_frame != "world":
            ref = spec.config.reference_frame
            if ref not in tree and ref != _root(tree, spec.link):
                problems.append(MountProblem(spec, f"frameName {ref!r} is neither world nor a link of the robot"))
                continue
            extra["reference"] = Sensor(spec, robot, find_mount(tree, robot.joint_index, ref), noise, dt)
        sensors.append(KINDS[spec.kind](spec, robot, mount, noise, dt, **extra))
    return sensors, problems


def _root(tree: Dict[str, ParentJoint], link: str) -> str:
    while link in tree:
        link = tree[link].parent
    return link


# ---------------------------------------------------------------------------------------------
# What sensors cost (the simulator's /diagnostics)
# ---------------------------------------------------------------------------------------------
OK, WARN, ERROR = 0, 1, 2  # diagnostic_msgs/DiagnosticStatus levels


@dataclass(frozen=True)
class SensorUse:
    """One sensor over a window of the simulation."""

    name: str  # how the report names it, e.g. "laser front_lidar (/thorvald_001/scan)"
    rate: float  # [Hz] asked; 0: every physics step
    cpu: float  # [s] of CPU spent measuring and publishing in the window
    readings: int


def sensor_report(
    uses: List[SensorUse], simulated: float, physics_rate: float, real_time_factor: float
) -> Tuple[int, str, Dict[str, str]]:
    """(level, message, values) of the sensors read in a window of ``simulated`` seconds.

    A sensor cannot hold its rate when it is asked for more than the physics rate (it is measured
    once a step at most), or when its own CPU per simulated second exceeds the wall time a
    simulated second may take at the real-time factor asked (it alone slows the simulation below
    it); either is a warning naming the sensor.
    """
    values: Dict[str, str] = {}
    late = []
    total = 0.0
    for use in uses:
        cpu = use.cpu / simulated if simulated > 0 else 0.0
        rate = use.readings / simulated if simulated > 0 else 0.0
        asked = use.rate if use.rate > 0 else physics_rate
        total += cpu
        values[f"{use.name}: CPU per simulated second [s]"] = f"{cpu:.5f}"
        values[f"{use.name}: rate [Hz]"] = f"{rate:.1f} of {asked:g}"
        if use.rate > physics_rate:
            late.append(f"{use.name} asks {use.rate:g} Hz, above the physics rate {physics_rate:g} Hz")
        elif real_time_factor > 0 and cpu * real_time_factor > 1.0:
            late.append(
                f"{use.name} costs {cpu:.2f} s of CPU per simulated second: not at {real_time_factor:g} x real time"
            )
    n = len(uses)
    message = f"{n} sensor{'' if n == 1 else 's'} read, {total:.4f} s CPU per simulated second"
    if late:
        return WARN, message + "; cannot hold its rate: " + "; ".join(late), values
    return OK, message, values


# ---------------------------------------------------------------------------------------------
# Sensors a robot goes without (the simulator's /diagnostics)
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class DisabledSensor:
    """A sensor the robot goes without: refused at spawn (``since`` None) or disabled when a reading
    of it failed (``since``: the simulated instant of that reading [s])."""

    name: str  # the sensor's (or model plugin's) name
    what: str  # the refusal (link, element path, rule) or the sensor and the error its reading raised
    topics: Tuple[str, ...] = ()  # resolved; none for a block refused before its topics were read
    since: Optional[float] = None


_BLOCK_NAME = re.compile(r"^(?:sensor|plugin)\[@name='([^']*)'\]")


def refused_sensors(blocks: Optional[SensorBlocks], problems) -> Tuple[DisabledSensor, ...]:
    """The sensors a robot spawned without: its refused blocks and its sensors that could not be mounted."""
    out = []
    for refused in blocks.refused if blocks is not None else ():
        match = _BLOCK_NAME.match(refused.path)
        out.append(DisabledSensor(match.group(1) if match else refused.path, str(refused)))
    out += [DisabledSensor(problem.spec.name, str(problem)) for problem in problems]
    return tuple(out)


def disabled_report(robot: str, sensor: DisabledSensor) -> Tuple[int, str, Dict[str, str]]:
    """(level, message, values) of a sensor the robot goes without: an error, as long as the robot is there."""
    topics = ", ".join(sensor.topics) or "none"
    if sensor.since is None:
        message = f"{robot}: sensor {sensor.name} refused at spawn: {sensor.what}"
    else:
        message = f"{robot}: sensor {sensor.name} ({topics}) disabled at {sensor.since:.3f} s: {sensor.what}"
    values = {"robot": robot, "sensor": sensor.name, "topics": topics, "why": sensor.what}
    if sensor.since is not None:
        values["disabled at [s]"] = f"{sensor.since:.3f}"
    return ERROR, message, values
