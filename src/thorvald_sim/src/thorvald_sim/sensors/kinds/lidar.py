"""Lidars: ``laser`` (a planar scan, sensor_msgs/LaserScan) and ``multilayer`` (a 3D lidar,
sensor_msgs/PointCloud2 in velodyne's layout), from Gazebo ``ray``/``gpu_ray`` sensor blocks.

Each ray is cast with pybullet's ``rayTestBatch`` from ``range_min`` to ``range_max`` along its beam
(as Gazebo's ray sensor, whose rays start at the minimum range), so a lidar sees the world, the
other robots and its robot's own body beyond range_min; no hit is ``inf``. Gaussian noise on every
beam (one without a return stays ``inf``).
"""

import operator
from dataclasses import dataclass, replace
from typing import Optional, Tuple

import numpy as np

from ...errors import BlockError
from .block import (
    FRAME_NAMESPACE_FIRST,
    FRAME_TF_RESOLVE,
    NON_NEGATIVE,
    Element,
    Found,
    SensorSpec,
    read_namespace,
    read_noise,
    read_pose,
    unpack,
)
from .displays import cloud_display, laser_display
from .kind import SensorKind
from .model import Sensor, Transform, p

LASER_PLUGINS = ("libgazebo_ros_laser.so", "libgazebo_ros_gpu_laser.so")
MULTILAYER_PLUGINS = (
    "libgazebo_ros_velodyne_laser.so",
    "libgazebo_ros_velodyne_gpu_laser.so",
    "libgazebo_ros_block_laser.so",
)
MAX_RAYS = 2**19  # a lidar's samples x vertical samples: 4096 x 128 (thorvald_sim.sensors.blocks says why)

try:  # the arithmetic around a lidar's rays in C (csrc/scan.c, built by catkin_make); numpy otherwise
    from ... import _scan
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


@dataclass(frozen=True)
class RayConfig:
    """A lidar: horizontal and vertical fans of rays from range_min to range_max [m]."""

    samples: int
    min_angle: float  # [rad]
    max_angle: float
    vertical_samples: int
    vertical_min_angle: float
    vertical_max_angle: float
    range_min: float  # [m]
    range_max: float
    range_resolution: float
    noise_mean: float = 0.0  # [m]
    noise_stddev: float = 0.0

    @property
    def angle_increment(self) -> float:
        return (self.max_angle - self.min_angle) / (self.samples - 1) if self.samples > 1 else 0.0

    @property
    def vertical_increment(self) -> float:
        if self.vertical_samples <= 1:
            return 0.0
        return (self.vertical_max_angle - self.vertical_min_angle) / (self.vertical_samples - 1)


# ---------------------------------------------------------------------------------------------
# The blocks
# ---------------------------------------------------------------------------------------------
def _check_rays(scan: Element, samples: int, vertical: int) -> None:
    """BlockError unless a reading's rays (samples x vertical samples) are within MAX_RAYS."""
    why = f"<= {MAX_RAYS} rays a reading (4096 columns x 128 channels; a ray costs about 1-2 us)"
    for tag, n in (("horizontal/samples", samples), ("vertical/samples", vertical)):
        if n > MAX_RAYS:
            raise BlockError(f"{scan.path}/{tag}", f"{n} must be {why}")
    if samples * vertical > MAX_RAYS:
        rays = f"{samples} x {vertical} = {samples * vertical}"
        raise BlockError(scan.path, f"samples x vertical samples = {rays} must be {why}")


def _ray(sensor: Element) -> RayConfig:
    ray = sensor.required("ray", "a ray sensor needs <ray>")
    scan = ray.required("scan", "a ray sensor needs <scan>")
    horizontal = scan.required("horizontal", "a ray sensor needs <horizontal>")
    samples = horizontal.count("samples")
    min_angle = horizontal.number("min_angle", 0.0)
    max_angle = horizontal.number("max_angle", 0.0)
    if max_angle < min_angle:
        raise BlockError(f"{horizontal.path}/max_angle", f"{max_angle!r} must be >= min_angle ({min_angle!r})")
    vertical = scan.child("vertical")
    if vertical is not None:
        v_samples = vertical.count("samples", 1)
        v_min, v_max = vertical.number("min_angle", 0.0), vertical.number("max_angle", 0.0)
        if v_max < v_min:
            raise BlockError(f"{vertical.path}/max_angle", f"{v_max!r} must be >= min_angle ({v_min!r})")
    else:
        v_samples, v_min, v_max = 1, 0.0, 0.0
    _check_rays(scan, samples, v_samples)
    rng = ray.required("range", "a ray sensor needs <range> (min, max)")
    range_min = rng.number("min", rule=NON_NEGATIVE[0], check=NON_NEGATIVE[1])
    range_max = rng.number("max", rule=f"must be > min ({range_min!r})", check=lambda v: v > range_min)
    resolution = rng.number("resolution", 0.0, rule=NON_NEGATIVE[0], check=NON_NEGATIVE[1])
    mean, stddev = read_noise(ray)
    return RayConfig(
        samples, min_angle, max_angle, v_samples, v_min, v_max, range_min, range_max, resolution, mean, stddev
    )


def _laser(found: Found) -> SensorSpec:
    sensor, plugin, link, name, filename, rate = unpack(found)
    config = _ray(sensor)
    return SensorSpec(
        "laser", name, link, read_pose(sensor), rate, filename,
        {"scan": plugin.text("topicName", "/world")},
        plugin.text("frameName", "/world"), FRAME_TF_RESOLVE, read_namespace(plugin), config,
    )  # fmt: skip


def _multilayer(found: Found) -> SensorSpec:
    sensor, plugin, link, name, filename, rate = unpack(found)
    config = _ray(sensor)
    if "velodyne" in filename:
        # velodyne_gazebo_plugins: min_range/max_range clip the ray's range, gaussianNoise adds noise
        rmin = plugin.number("min_range", config.range_min, rule=NON_NEGATIVE[0], check=NON_NEGATIVE[1])
        rmax = plugin.number(
            "max_range", config.range_max, rule=f"must be > min_range ({rmin!r})", check=lambda v: v > rmin
        )
        noise = plugin.number("gaussianNoise", config.noise_stddev, rule=NON_NEGATIVE[0], check=NON_NEGATIVE[1])
        config = replace(config, range_min=max(rmin, config.range_min), range_max=min(rmax, config.range_max),
                         noise_stddev=noise)  # fmt: skip
        topic, frame = plugin.text("topicName", "/points"), plugin.text("frameName", "/world")
        rule = FRAME_NAMESPACE_FIRST
    else:  # gazebo_ros_block_laser
        noise = plugin.number("gaussianNoise", config.noise_stddev, rule=NON_NEGATIVE[0], check=NON_NEGATIVE[1])
        config = replace(config, noise_stddev=noise)
        topic, frame, rule = plugin.text("topicName", "/world"), plugin.text("frameName", "/world"), FRAME_TF_RESOLVE
    return SensorSpec(
        "multilayer",
        name,
        link,
        read_pose(sensor),
        rate,
        filename,
        {"points": topic},
        frame,
        rule,
        read_namespace(plugin),
        config,
    )


# ---------------------------------------------------------------------------------------------
# The model
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
# The messages and displays
# ---------------------------------------------------------------------------------------------
# velodyne_gazebo_plugins' layout: 22 bytes a point, the time of every point 0 (an instantaneous sweep)
LIDAR_DTYPE = np.dtype(
    {
        "names": ["x", "y", "z", "intensity", "ring", "time"],
        "formats": ["<f4", "<f4", "<f4", "<f4", "<u2", "<f4"],
        "offsets": [0, 4, 8, 12, 16, 18],
        "itemsize": 22,
    }
)
# its PointCloud2 fields: (name, offset, sensor_msgs/PointField datatype)
LIDAR_FIELDS = (
    ("x", 0, "FLOAT32"),
    ("y", 4, "FLOAT32"),
    ("z", 8, "FLOAT32"),
    ("intensity", 12, "FLOAT32"),
    ("ring", 16, "UINT16"),
    ("time", 18, "FLOAT32"),
)


def laser_messages(out, scan: Scan, wanted):
    """A LaserScan of the scan's middle layer (its only one for a planar lidar)."""
    msg = out.keep.get("scan")
    if msg is None:  # made once: a scan's fields but its stamp and ranges stay (publish serialises at once)
        c: RayConfig = out.spec.config
        msg = out.keep["scan"] = out.message("scan")
        msg.angle_min, msg.angle_max, msg.angle_increment = c.min_angle, c.max_angle, c.angle_increment
        msg.time_increment = 0.0  # an instantaneous scan, as gazebo_ros's
        msg.scan_time = 0.0
        msg.range_min, msg.range_max = c.range_min, c.range_max
        msg.intensities = np.zeros(scan.ranges.shape[1], dtype=np.float32)  # gazebo_ros's: one per beam
    msg.header.stamp = out.stamp
    ranges = scan.ranges[0] if scan.ranges.shape[0] == 1 else scan.ranges[scan.ranges.shape[0] // 2]
    msg.ranges = ranges.astype(np.float32)
    yield "scan", msg


def multilayer_messages(out, scan: Scan, wanted):
    """A PointCloud2 of the returns (velodyne's layout; the ring is the layer)."""
    hit = np.isfinite(scan.ranges)
    points = scan.directions[hit] * scan.ranges[hit][:, None]
    rings = np.broadcast_to(np.arange(scan.ranges.shape[0])[:, None], scan.ranges.shape)[hit]
    data = np.zeros(len(points), dtype=LIDAR_DTYPE)
    data["x"], data["y"], data["z"] = points[:, 0], points[:, 1], points[:, 2]
    data["ring"] = rings
    yield "points", out.cloud("points", data[None, :], LIDAR_FIELDS, dense=True)


def laser_displays(spec, topic, name, colour):
    return [laser_display(topic("scan"), name, colour)]


def multilayer_displays(spec, topic, name, colour):
    return [cloud_display(topic("points"), name, colour)]


_RAY = """<ray><scan><horizontal><samples>{samples}</samples><min_angle>-1.5708</min_angle>
<max_angle>1.5708</max_angle></horizontal>{vertical}</scan><range><min>0.1</min><max>30</max></range></ray>"""

_VERTICAL = "<vertical><samples>4</samples><min_angle>-0.26</min_angle><max_angle>0.26</max_angle></vertical>"

LASER = SensorKind(
    "laser",
    blocks="`ray`/`gpu_ray` + `libgazebo_ros_laser.so`, `libgazebo_ros_gpu_laser.so`",
    published="`sensor_msgs/LaserScan` on `topicName` (default `/world`), frame `frameName`",
    model=Lidar,
    roles={"scan": "sensor_msgs/LaserScan"},
    messages=laser_messages,
    displays=laser_displays,
    sensors=(("ray", LASER_PLUGINS), ("gpu_ray", LASER_PLUGINS)),
    read_sensor=_laser,
    example=f"""<gazebo reference="sensor_link"><sensor type="ray" name="front_lidar"><update_rate>40</update_rate>
{_RAY.format(samples=181, vertical="")}
<plugin name="front_lidar" filename="libgazebo_ros_laser.so"><topicName>scan</topicName>
<frameName>sensor_link</frameName></plugin></sensor></gazebo>""",
)

MULTILAYER = SensorKind(
    "multilayer",
    blocks="`ray` with `<vertical><samples>` > 1 + `libgazebo_ros_velodyne_laser.so`, `libgazebo_ros_block_laser.so`",
    published="`sensor_msgs/PointCloud2` (x, y, z, intensity, ring, time: velodyne's 22-byte layout)",
    model=Lidar,
    roles={"points": "sensor_msgs/PointCloud2"},
    messages=multilayer_messages,
    displays=multilayer_displays,
    sensors=(("ray", MULTILAYER_PLUGINS), ("gpu_ray", MULTILAYER_PLUGINS)),
    read_sensor=_multilayer,
    example=f"""<gazebo reference="sensor_link"><sensor type="ray" name="velodyne"><update_rate>10</update_rate>
{_RAY.format(samples=90, vertical=_VERTICAL)}
<plugin name="velodyne" filename="libgazebo_ros_velodyne_laser.so"><topicName>velodyne_points</topicName>
<frameName>sensor_link</frameName></plugin></sensor></gazebo>""",
)
