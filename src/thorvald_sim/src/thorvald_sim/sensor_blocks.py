"""The sensors a robot description asks for, read from its Gazebo blocks, without pybullet or ROS.

Users' sensor xacros (``model_extras``) carry Gazebo blocks: ``<gazebo reference="LINK"><sensor
type=... name=...>`` with a gazebo_ros plugin inside, and ``<gazebo><plugin>`` model plugins. This
module reads them with the plugins' own parameter names and defaults (gazebo_ros_pkgs for ROS 1,
hector_gazebo_plugins, velodyne_gazebo_plugins), so a block written for Gazebo means the same here:

=======================================  ==========================================================
sensor type / plugin                     kind (what the simulator measures and publishes)
=======================================  ==========================================================
``ray``/``gpu_ray`` + gazebo_ros_laser,  ``laser``: sensor_msgs/LaserScan (one vertical sample)
gazebo_ros_gpu_laser
``ray``/``gpu_ray`` + velodyne_laser,    ``multilayer``: sensor_msgs/PointCloud2 (x, y, z,
gazebo_ros_block_laser                   intensity, ring)
``imu`` + gazebo_ros_imu_sensor          ``imu``: sensor_msgs/Imu
model plugin gazebo_ros_imu              ``imu``: the same, of the link ``bodyName``
``gps`` + gazebo_ros_gps_sensor          ``gps``: sensor_msgs/NavSatFix
model plugin hector_gazebo_ros_gps       ``gps``: NavSatFix and geometry_msgs/Vector3Stamped velocity
``camera`` + gazebo_ros_camera           ``camera``: sensor_msgs/Image + CameraInfo
``depth`` + gazebo_ros_openni_kinect     ``depth``: the camera's topics, a depth image (32FC1, m)
                                         and an organised PointCloud2 (x, y, z, rgb)
model plugin gazebo_ros_p3d              ``p3d``: nav_msgs/Odometry of a link (ground truth)
=======================================  ==========================================================

Anything else is listed in :attr:`SensorBlocks.unsupported` (its name and link, for the simulator
to log once); a block that breaks a rule (a missing ``<samples>``, a negative rate, a camera
without an image size) is listed in :attr:`SensorBlocks.refused` with the link, the element path
and the rule, and the other sensors are kept.

What one reading may cost is bounded here, before anything is allocated, so that no block can
take the simulator down (a reading runs in the simulation's loop: while it lasts, the clock and
every robot wait, and a failed allocation inside pybullet aborts the process):

==========================  ==========  ===================================================================
bound                       limit       why
==========================  ==========  ===================================================================
camera width, height [px]   8192        wider than any camera a robot carries (8K UHD is 7680 wide)
camera pixels (w x h)       2^24        a 4096 x 4096 frame; 4K (3840 x 2160, 4096 x 2160) and a Kinect v2
                                        (1920 x 1080) pass. A reading costs about 40 bytes a pixel (110
                                        with depth and point cloud) and 0.25-0.5 us of rendering a pixel:
                                        at the limit about 1.8 GB and 8 s a depth frame
lidar rays (samples x       2^19        4096 x 128: the densest mode of a 128-channel lidar (4096 columns);
vertical samples)                       a reading costs about 1-2 us and 170 bytes a ray: at the limit
                                        about 1.1 s and 90 MB
==========================  ==========  ===================================================================

pybullet's TinyRenderer keeps an RGB, a depth, a shadow and a segmentation buffer per pixel (15
bytes), its client copies RGBA, depth and segmentation (12 bytes) and pybullet hands them over as
numpy arrays (12 bytes more); it counts those bytes in C ``int``, which overflows past 2^29 pixels
(a 100000 x 100000 camera is 10^10). A lidar's rays go to pybullet 16383 at a time, so a reading's
time grows with its rays alone. Nothing else a block sets scales a reading's cost: a rate above the
physics rate is read once a step (:class:`thorvald_base.rate_grid.RateGrid`; the simulator's
/diagnostics warns of it), and a ray's length costs nothing more (2000 rays over a height field
cost the same from 30 m to 10^9 m).

Topic and frame names stay as the block writes them; :func:`resolve_topic` and
:func:`resolve_frame` apply the robot's namespace and tf_prefix as the plugins do (each sensor's
``frame_rule`` says which way).
"""

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, replace
from typing import Dict, List, Optional, Tuple, Union

from thorvald_model.datum import Datum
from thorvald_model.joint_tree import Origin as Pose  # a transform: SDF's <pose> is URDF's <origin>
from thorvald_model.urdf_check import normalize_frame

from .errors import BlockError

Vec3 = Tuple[float, float, float]

# What the plugins do with frameName (see resolve_frame)
FRAME_TF_RESOLVE = "tf_resolve"  # gazebo_ros laser, gpu_laser, block_laser, camera, openni, p3d, gps sensor
FRAME_AS_IS = "as_is"  # imu_sensor, imu, hector gps: the name as written
FRAME_NAMESPACE_FIRST = "namespace_first"  # velodyne: tf::resolve with the namespace, else tf_prefix

LASER_PLUGINS = ("libgazebo_ros_laser.so", "libgazebo_ros_gpu_laser.so")
MULTILAYER_PLUGINS = (
    "libgazebo_ros_velodyne_laser.so",
    "libgazebo_ros_velodyne_gpu_laser.so",
    "libgazebo_ros_block_laser.so",
)
IMU_SENSOR_PLUGINS = ("libgazebo_ros_imu_sensor.so",)
GPS_SENSOR_PLUGINS = ("libgazebo_ros_gps_sensor.so",)
CAMERA_PLUGINS = ("libgazebo_ros_camera.so",)
DEPTH_PLUGINS = ("libgazebo_ros_openni_kinect.so", "libgazebo_ros_depth_camera.so")
MODEL_IMU_PLUGINS = ("libgazebo_ros_imu.so",)
MODEL_GPS_PLUGINS = ("libhector_gazebo_ros_gps.so",)
MODEL_P3D_PLUGINS = ("libgazebo_ros_p3d.so",)

# hector_gazebo_ros_gps's defaults (its source): a reference in Germany, x pointing north
HECTOR_REFERENCE = (49.9, 8.9, 0.0, 0.0)  # latitude [deg], longitude [deg], heading [deg], altitude [m]
HECTOR_RATE = 4.0  # [Hz]
HECTOR_DRIFT_FREQUENCY = 1.0 / 3600.0  # [1/s]: SensorModel's default time constant of an hour

# Image formats of Gazebo's <image><format> and the sensor_msgs encodings they are published in
IMAGE_FORMATS = {"R8G8B8": ("rgb8", 3), "B8G8R8": ("bgr8", 3), "L8": ("mono8", 1), "RGB_INT8": ("rgb8", 3)}

# What one reading may cost (the module's docstring says why these figures)
MAX_IMAGE_SIDE = 8192  # [px] a camera's width or height
MAX_IMAGE_PIXELS = 2**24  # [px] width x height: 4096 x 4096
MAX_RAYS = 2**19  # a lidar's samples x vertical samples: 4096 x 128


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


@dataclass(frozen=True)
class ImuConfig:
    noise: float = 0.0  # gaussianNoise: the stddev added to every component (as gazebo_ros's plugins)
    rpy_offset: Vec3 = (0.0, 0.0, 0.0)  # [rad] applied to the orientation


@dataclass(frozen=True)
class ErrorModel:
    """hector_gazebo_plugins' SensorModel per axis: offset, a drift (a first-order Gauss-Markov process
    of standard deviation ``drift`` and frequency ``drift_frequency``) and white gaussian noise."""

    offset: Vec3 = (0.0, 0.0, 0.0)
    drift: Vec3 = (0.0, 0.0, 0.0)
    drift_frequency: Vec3 = (HECTOR_DRIFT_FREQUENCY,) * 3
    gaussian_noise: Vec3 = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class GpsConfig:
    reference: Optional[Tuple[float, float, float, float]]  # (lat, lon, heading [deg], alt [m]); None: the datum's
    position: ErrorModel = ErrorModel()
    velocity: ErrorModel = ErrorModel()
    status: int = 0  # sensor_msgs/NavSatStatus STATUS_FIX
    service: int = 0  # hector's default (the gps sensor: SERVICE_GPS)
    hector: bool = True  # hector's axes and velocity topic; False: gazebo_ros_gps_sensor (no velocity)


@dataclass(frozen=True)
class CameraConfig:
    width: int
    height: int
    encoding: str  # sensor_msgs/image_encodings name
    channels: int
    horizontal_fov: float  # [rad]
    near: float  # [m] clip
    far: float
    depth: bool = False
    point_cloud_cutoff: float = 0.4  # [m] openni_kinect: nearer depth is NaN
    point_cloud_cutoff_max: float = 5.0  # [m] farther is NaN

    @property
    def focal_length(self) -> float:
        """[px], as gazebo_ros_camera_utils computes it."""
        return self.width / (2.0 * math.tan(self.horizontal_fov / 2.0))


@dataclass(frozen=True)
class P3dConfig:
    reference_frame: str  # "world" or a link of the robot
    xyz_offsets: Vec3 = (0.0, 0.0, 0.0)
    rpy_offsets: Vec3 = (0.0, 0.0, 0.0)
    noise: float = 0.0


@dataclass(frozen=True)
class SensorSpec:
    """One sensor the description asks for."""

    kind: str  # laser, multilayer, imu, gps, camera, depth, p3d
    name: str  # the sensor's name (or the model plugin's)
    link: str  # the URDF link it is on
    pose: Pose  # of the sensor frame in the link's frame
    rate: float  # [Hz] of simulated time; 0: every physics step
    plugin: str  # the plugin's file name
    topics: Dict[str, str]  # role -> topic as written (roles per kind: scan, points, imu, fix, ...)
    frame: str  # frame_id as written (before resolve_frame)
    frame_rule: str  # FRAME_TF_RESOLVE or FRAME_AS_IS
    namespace: Optional[str]  # the plugin's <robotNamespace>; None: the robot's
    config: object  # RayConfig, ImuConfig, GpsConfig, CameraConfig or P3dConfig
    child_frame: str = ""  # p3d: the child frame (its bodyName)

    def describe(self) -> str:
        return f"{self.kind} {self.name!r} on link {self.link} ({self.plugin})"


@dataclass(frozen=True)
class Unsupported:
    what: str  # e.g. "sensor contact 'bumper' (libgazebo_ros_bumper.so)"
    link: str  # "" for a model plugin


@dataclass(frozen=True)
class Refused:
    link: str
    path: str  # the element path, e.g. sensor[@name='front_lidar']/ray/scan/horizontal/samples
    rule: str

    def __str__(self) -> str:
        return f"link {self.link or '(model)'}: {self.path}: {self.rule}"


@dataclass(frozen=True)
class SensorBlocks:
    sensors: Tuple[SensorSpec, ...] = ()
    unsupported: Tuple[Unsupported, ...] = ()
    refused: Tuple[Refused, ...] = ()


# ---------------------------------------------------------------------------------------------
# Reading elements
# ---------------------------------------------------------------------------------------------
class _Element:
    """An element and its path, with typed reads that raise BlockError naming the path and the rule."""

    def __init__(self, element: ET.Element, path: str):
        self.e = element
        self.path = path

    def child(self, tag: str) -> Optional["_Element"]:
        found = self.e.find(tag)
        return None if found is None else _Element(found, f"{self.path}/{tag}")

    def required(self, tag: str, rule: str) -> "_Element":
        """The child element, or BlockError naming its path: ``missing: <rule>``."""
        found = self.child(tag)
        if found is None:
            raise BlockError(f"{self.path}/{tag}", f"missing: {rule}")
        return found

    def has(self, tag: str) -> bool:
        return self.e.find(tag) is not None

    def text(self, tag: str, default: Optional[str] = None) -> Optional[str]:
        found = self.e.find(tag)
        if found is None or found.text is None:
            return default
        return found.text.strip()

    def number(self, tag: str, default: Optional[float] = None, *, rule: str = "", check=None) -> float:
        text = self.text(tag)
        path = f"{self.path}/{tag}"
        if text is None or text == "":
            if default is None:
                raise BlockError(path, "missing: the sensor needs it")
            return default
        try:
            value = float(text)
        except ValueError:
            raise BlockError(path, f"{text!r} is not a number") from None
        if not math.isfinite(value):
            raise BlockError(path, f"{text!r} must be finite")
        if check is not None and not check(value):
            raise BlockError(path, f"{text!r} {rule}")
        return value

    def count(self, tag: str, default: Optional[int] = None) -> int:
        value = self.number(
            tag,
            None if default is None else float(default),
            rule="must be a whole number >= 1",
            check=lambda v: v >= 1 and v == int(v),
        )
        return int(value)

    def vector(self, tag: str, default: Vec3 = (0.0, 0.0, 0.0)) -> Vec3:
        text = self.text(tag)
        if text is None or text == "":
            return default
        parts = text.split()
        try:
            values = tuple(float(v) for v in parts)
        except ValueError:
            values = ()
        if len(values) == 1:
            values = values * 3  # hector's SensorModel accepts one value for every axis
        if len(values) != 3 or not all(math.isfinite(v) for v in values):
            raise BlockError(f"{self.path}/{tag}", f"{text!r} must be 3 finite numbers")
        return values  # type: ignore[return-value]


NON_NEGATIVE = ("must be >= 0", lambda v: v >= 0)
POSITIVE = ("must be > 0", lambda v: v > 0)


def _rate(e: _Element, tag: str, default: float) -> float:
    return e.number(tag, default, rule=NON_NEGATIVE[0], check=NON_NEGATIVE[1])


def _pose(e: _Element) -> Pose:
    text = e.text("pose")
    if not text:
        return Pose()
    try:
        values = [float(v) for v in text.split()]
    except ValueError:
        values = []
    if len(values) != 6 or not all(math.isfinite(v) for v in values):
        raise BlockError(f"{e.path}/pose", f"{text!r} must be 6 finite numbers: x y z roll pitch yaw")
    return Pose(tuple(values[:3]), tuple(values[3:]))  # type: ignore[arg-type]


def _namespace(plugin: _Element) -> Optional[str]:
    return plugin.text("robotNamespace") if plugin.has("robotNamespace") else None


# ---------------------------------------------------------------------------------------------
# Sensors (<gazebo reference="LINK"><sensor>)
# ---------------------------------------------------------------------------------------------
def _check_rays(scan: _Element, samples: int, vertical: int) -> None:
    """BlockError unless a reading's rays (samples x vertical samples) are within MAX_RAYS."""
    why = f"<= {MAX_RAYS} rays a reading (4096 columns x 128 channels; a ray costs about 1-2 us)"
    for tag, n in (("horizontal/samples", samples), ("vertical/samples", vertical)):
        if n > MAX_RAYS:
            raise BlockError(f"{scan.path}/{tag}", f"{n} must be {why}")
    if samples * vertical > MAX_RAYS:
        rays = f"{samples} x {vertical} = {samples * vertical}"
        raise BlockError(scan.path, f"samples x vertical samples = {rays} must be {why}")


def _ray(sensor: _Element) -> RayConfig:
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
    mean, stddev = _noise(ray)
    return RayConfig(
        samples, min_angle, max_angle, v_samples, v_min, v_max, range_min, range_max, resolution, mean, stddev
    )


def _unpack(found: "_Found"):
    return found.sensor, found.plugin, found.link, found.name, found.filename, found.rate


def _noise(parent: _Element) -> Tuple[float, float]:
    noise = parent.child("noise")
    if noise is None:
        return 0.0, 0.0
    kind = (noise.text("type") or "gaussian").lower()
    if kind == "none":
        return 0.0, 0.0
    if kind != "gaussian":
        raise BlockError(f"{noise.path}/type", f"{kind!r}: only gaussian noise is simulated")
    return noise.number("mean", 0.0), noise.number("stddev", 0.0, rule=NON_NEGATIVE[0], check=NON_NEGATIVE[1])


@dataclass(frozen=True)
class _Found:
    """A <sensor> with the plugin that says what to do with it."""

    sensor: _Element
    plugin: _Element
    link: str
    name: str
    filename: str
    rate: float  # the sensor's <update_rate> [Hz]


def _laser(found: _Found) -> SensorSpec:
    sensor, plugin, link, name, filename, rate = _unpack(found)
    config = _ray(sensor)
    return SensorSpec(
        "laser", name, link, _pose(sensor), rate, filename,
        {"scan": plugin.text("topicName", "/world")},
        plugin.text("frameName", "/world"), FRAME_TF_RESOLVE, _namespace(plugin), config,
    )  # fmt: skip


def _multilayer(found: _Found) -> SensorSpec:
    sensor, plugin, link, name, filename, rate = _unpack(found)
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
        _pose(sensor),
        rate,
        filename,
        {"points": topic},
        frame,
        rule,
        _namespace(plugin),
        config,
    )


def _imu_sensor(found: _Found) -> SensorSpec:
    sensor, plugin, link, name, filename, rate = _unpack(found)
    plugin.required("frameName", "gazebo_ros_imu_sensor needs it (it refuses to load)")
    # the plugin's own updateRateHZ (default 1 Hz) paces the messages, within the sensor's update_rate
    plugin_rate = _rate(plugin, "updateRateHZ", 1.0)
    effective = min(r for r in (plugin_rate, rate) if r > 0) if (plugin_rate > 0 or rate > 0) else 0.0
    config = ImuConfig(
        plugin.number("gaussianNoise", 0.0, rule=NON_NEGATIVE[0], check=NON_NEGATIVE[1]), plugin.vector("rpyOffset")
    )
    return SensorSpec(
        "imu", name, link, _pose(sensor), effective, filename, {"imu": plugin.text("topicName", "imu_data")},
        plugin.text("frameName"), FRAME_AS_IS, _namespace(plugin), config,
    )  # fmt: skip


def _gps_sensor(found: _Found) -> SensorSpec:
    sensor, plugin, link, name, filename, rate = _unpack(found)
    noise = 0.0
    gps = sensor.child("gps")
    if gps is not None:
        horizontal = gps.child("position_sensing/horizontal")
        if horizontal is not None:
            noise = _noise(horizontal)[1]
    model = ErrorModel(gaussian_noise=(noise, noise, noise))
    config = GpsConfig(None, model, ErrorModel(), status=0, service=1, hector=False)
    return SensorSpec(
        "gps", name, link, _pose(sensor), rate, filename, {"fix": plugin.text("topicName", "gps/fix")},
        plugin.text("frameName", link), FRAME_TF_RESOLVE, _namespace(plugin), config,
    )  # fmt: skip


def _check_pixels(image: _Element, width: int, height: int) -> None:
    """BlockError unless a frame's sides and pixels are within MAX_IMAGE_SIDE and MAX_IMAGE_PIXELS."""
    for tag, n in (("width", width), ("height", height)):
        if n > MAX_IMAGE_SIDE:
            raise BlockError(f"{image.path}/{tag}", f"{n} must be <= {MAX_IMAGE_SIDE} pixels (no camera is wider)")
    if width * height > MAX_IMAGE_PIXELS:
        raise BlockError(
            image.path,
            f"width x height = {width} x {height} = {width * height} pixels must be <= {MAX_IMAGE_PIXELS} (4096 x 4096:"
            " a frame costs about 110 bytes and 0.5 us of rendering a pixel)",
        )


def _camera(found: _Found, depth: bool) -> SensorSpec:
    sensor, plugin, link, name, filename, rate = _unpack(found)
    camera = sensor.required("camera", "a camera sensor needs <camera>")
    image = camera.required("image", "a camera needs <image> (width, height)")
    fmt = image.text("format", "R8G8B8")
    if fmt not in IMAGE_FORMATS:
        raise BlockError(f"{image.path}/format", f"{fmt!r} must be one of {', '.join(IMAGE_FORMATS)}")
    encoding, channels = IMAGE_FORMATS[fmt]
    hfov = camera.number("horizontal_fov", 1.047, rule="must be in (0, pi)", check=lambda v: 0 < v < math.pi)
    clip = camera.child("clip")
    near = clip.number("near", 0.1, rule=POSITIVE[0], check=POSITIVE[1]) if clip else 0.1
    far = clip.number("far", 100.0, rule=f"must be > near ({near!r})", check=lambda v: v > near) if clip else 100.0
    width, height = image.count("width", 320), image.count("height", 240)
    _check_pixels(image, width, height)
    config = CameraConfig(
        width, height, encoding, channels, hfov, near, far, depth,
        plugin.number("pointCloudCutoff", 0.4, rule=NON_NEGATIVE[0], check=NON_NEGATIVE[1]),
        plugin.number("pointCloudCutoffMax", 5.0, rule=POSITIVE[0], check=POSITIVE[1]),
    )  # fmt: skip
    # gazebo_ros_camera_utils: topics in <robotNamespace>/<cameraName>; its updateRate (0: the sensor's)
    plugin_rate = _rate(plugin, "updateRate", 0.0)
    camera_name = plugin.text("cameraName", "") or ""
    prefix = camera_name.strip("/") + "/" if camera_name.strip("/") else ""
    topics = {
        "image": prefix + plugin.text("imageTopicName", "image_raw"),
        "camera_info": prefix + plugin.text("cameraInfoTopicName", "camera_info"),
    }
    if depth:
        topics["depth"] = prefix + plugin.text("depthImageTopicName", "depth/image_raw")
        topics["depth_info"] = prefix + plugin.text("depthImageCameraInfoTopicName", "depth/camera_info")
        topics["points"] = prefix + plugin.text("pointCloudTopicName", "points")
    return SensorSpec(
        "depth" if depth else "camera", name, link, _pose(sensor), plugin_rate or rate, filename, topics,
        plugin.text("frameName", "/world"), FRAME_TF_RESOLVE, _namespace(plugin), config,
    )  # fmt: skip


SENSOR_READERS = {
    ("ray", LASER_PLUGINS): _laser,
    ("gpu_ray", LASER_PLUGINS): _laser,
    ("ray", MULTILAYER_PLUGINS): _multilayer,
    ("gpu_ray", MULTILAYER_PLUGINS): _multilayer,
    ("imu", IMU_SENSOR_PLUGINS): _imu_sensor,
    ("gps", GPS_SENSOR_PLUGINS): _gps_sensor,
    ("camera", CAMERA_PLUGINS): lambda found: _camera(found, depth=False),
    ("depth", DEPTH_PLUGINS): lambda found: _camera(found, depth=True),
    ("camera", DEPTH_PLUGINS): lambda found: _camera(found, depth=True),
}


def _sensor(element: ET.Element, link: str) -> SensorSpec:
    kind = element.get("type", "")
    name = element.get("name", "")
    sensor = _Element(element, f"sensor[@name='{name}']")
    plugins = element.findall("plugin")
    rate = _rate(sensor, "update_rate", 0.0)
    for plugin in plugins:
        filename = plugin.get("filename", "")
        for (sensor_type, names), reader in SENSOR_READERS.items():
            if kind == sensor_type and filename in names:
                plugin_element = _Element(plugin, f"{sensor.path}/plugin[@filename='{filename}']")
                return reader(_Found(sensor, plugin_element, link, name, filename, rate))
    what = ", ".join(p.get("filename", "?") for p in plugins) or "no plugin"
    raise _NotSimulated(f"sensor {kind} {name!r} ({what})")


class _NotSimulated(Exception):
    pass


# ---------------------------------------------------------------------------------------------
# Model plugins (<gazebo><plugin>)
# ---------------------------------------------------------------------------------------------
def _model_imu(plugin: _Element, root_link: str, filename: str, name: str) -> SensorSpec:
    plugin.required("bodyName", "gazebo_ros_imu needs the link to measure")
    body = plugin.text("bodyName")
    plugin.required("topicName", "gazebo_ros_imu needs it")
    rate = _rate(plugin, "updateRate", 0.0) if plugin.has("updateRate") else _rate(plugin, "update_rate", 0.0)
    config = ImuConfig(
        plugin.number("gaussianNoise", 0.0, rule=NON_NEGATIVE[0], check=NON_NEGATIVE[1]), plugin.vector("rpyOffset")
    )
    return SensorSpec(
        "imu", name, body, Pose(plugin.vector("xyzOffset")), rate, filename, {"imu": plugin.text("topicName")},
        plugin.text("frameName", body), FRAME_AS_IS, _namespace(plugin), config,
    )  # fmt: skip


def _error_model(plugin: _Element, prefix: str) -> ErrorModel:
    def named(key: str) -> str:
        return prefix + key[0].upper() + key[1:] if prefix else key

    for key in ("drift", "driftFrequency", "gaussianNoise"):
        vec = plugin.vector(named(key))
        if any(v < 0 for v in vec):
            raise BlockError(f"{plugin.path}/{named(key)}", f"{vec!r} must be >= 0")
    return ErrorModel(
        plugin.vector(named("offset")),
        plugin.vector(named("drift")),
        plugin.vector(named("driftFrequency"), (HECTOR_DRIFT_FREQUENCY,) * 3),
        plugin.vector(named("gaussianNoise")),
    )


def _hector_gps(plugin: _Element, root_link: str, filename: str, name: str) -> SensorSpec:
    given = [
        plugin.has(k) for k in ("referenceLatitude", "referenceLongitude", "referenceHeading", "referenceAltitude")
    ]
    reference = None
    if any(given):
        reference = (
            plugin.number("referenceLatitude", HECTOR_REFERENCE[0], rule="must be in [-90, 90]",
                          check=lambda v: -90 <= v <= 90),
            plugin.number("referenceLongitude", HECTOR_REFERENCE[1]),
            plugin.number("referenceHeading", HECTOR_REFERENCE[2]),
            plugin.number("referenceAltitude", HECTOR_REFERENCE[3]),
        )  # fmt: skip
    config = GpsConfig(
        reference,
        _error_model(plugin, ""),
        _error_model(plugin, "velocity"),
        status=int(plugin.number("status", 0.0)),
        service=int(plugin.number("service", 0.0)),
        hector=True,
    )
    body = plugin.text("bodyName", root_link) or root_link
    topics = {"fix": plugin.text("topicName", "fix"), "velocity": plugin.text("velocityTopicName", "fix_velocity")}
    return SensorSpec(
        "gps", name, body, Pose(), _rate(plugin, "updateRate", HECTOR_RATE), filename, topics,
        plugin.text("frameId", "/world"), FRAME_AS_IS, _namespace(plugin), config,
    )  # fmt: skip


def _p3d(plugin: _Element, root_link: str, filename: str, name: str) -> SensorSpec:
    plugin.required("bodyName", "gazebo_ros_p3d needs the link to report")
    plugin.required("topicName", "gazebo_ros_p3d needs it")
    body = plugin.text("bodyName")
    frame = plugin.text("frameName", "world")
    reference = "world" if frame.strip("/") in ("world", "map", "") else frame.strip("/")
    config = P3dConfig(
        reference,
        plugin.vector("xyzOffsets"),
        plugin.vector("rpyOffsets"),
        plugin.number("gaussianNoise", 0.0, rule=NON_NEGATIVE[0], check=NON_NEGATIVE[1]),
    )
    return SensorSpec(
        "p3d", name, body, Pose(), _rate(plugin, "updateRate", 0.0), filename, {"odometry": plugin.text("topicName")},
        frame, FRAME_TF_RESOLVE, _namespace(plugin), config, child_frame=body,
    )  # fmt: skip


MODEL_READERS = {}
for _names, _reader in ((MODEL_IMU_PLUGINS, _model_imu), (MODEL_GPS_PLUGINS, _hector_gps), (MODEL_P3D_PLUGINS, _p3d)):
    for _name in _names:
        MODEL_READERS[_name] = _reader

# Model plugins the simulator implements itself (thorvald's) or that mean nothing to it
KNOWN_MODEL_PLUGINS = ("libthorvald_gazebo_plugins_synch.so", "libthorvald_gazebo_plugins.so")


# ---------------------------------------------------------------------------------------------
# The description
# ---------------------------------------------------------------------------------------------
def read_sensor_blocks(xml: Union[str, ET.Element]) -> SensorBlocks:
    """Every sensor of a robot description (a URDF string, or its parsed ``<robot>``); never raises
    for a sensor's fault."""
    root = ET.fromstring(xml) if isinstance(xml, str) else xml
    links = [link.get("name", "") for link in root.findall("link")]
    children = {j.find("child").get("link") for j in root.findall("joint") if j.find("child") is not None}
    root_link = next((link for link in links if link not in children), links[0] if links else "")
    sensors: List[SensorSpec] = []
    unsupported: List[Unsupported] = []
    refused: List[Refused] = []
    for gazebo in root.findall("gazebo"):
        link = gazebo.get("reference")
        if link is not None:
            for element in gazebo.findall("sensor"):
                if link not in links:
                    refused.append(Refused(link, f"sensor[@name='{element.get('name', '')}']",
                                           "the link is not in the description"))  # fmt: skip
                    continue
                try:
                    sensors.append(_sensor(element, link))
                except _NotSimulated as e:
                    unsupported.append(Unsupported(str(e), link))
                except BlockError as e:
                    refused.append(Refused(link, e.path, e.rule))
            continue
        for element in gazebo.findall("plugin"):
            filename = element.get("filename", "")
            name = element.get("name", "")
            if filename in KNOWN_MODEL_PLUGINS:
                continue
            reader = MODEL_READERS.get(filename)
            if reader is None:
                unsupported.append(Unsupported(f"model plugin {name!r} ({filename})", ""))
                continue
            path = f"plugin[@name='{name}']"
            try:
                spec = reader(_Element(element, path), root_link, filename, name)
            except BlockError as e:
                refused.append(Refused("", e.path, e.rule))
                continue
            # bodyName is a link as tf2 reads it (/base_link is base_link), as the spawned description's are
            spec = replace(spec, link=normalize_frame(spec.link), child_frame=normalize_frame(spec.child_frame))
            if spec.link not in links:
                refused.append(Refused("", f"{path}/bodyName", f"{spec.link!r}: no such link in the description"))
                continue
            sensors.append(spec)
    return SensorBlocks(tuple(sensors), tuple(unsupported), tuple(refused))


# ---------------------------------------------------------------------------------------------
# Names, as the plugins resolve them
# ---------------------------------------------------------------------------------------------
def tf_resolve(prefix: str, frame: str) -> str:
    """tf::resolve of ROS 1 (what gazebo_ros's plugins apply to frameName): an absolute frame loses its
    leading slash and is kept; otherwise prefix/frame (the prefix's leading slash dropped)."""
    if frame.startswith("/"):
        return frame.lstrip("/")
    prefix = prefix.lstrip("/")
    return f"{prefix}/{frame}" if prefix else frame


def resolve_frame(spec: SensorSpec, tf_prefix: str, namespace: str) -> str:
    """The frame_id a sensor's messages carry.

    FRAME_TF_RESOLVE (gazebo_ros laser, camera, p3d ...): the ``tf_prefix`` parameter found from the
    robot's namespace, or else the namespace without its trailing slash, as prefix (tf::resolve).
    So a frameName of ``hokuyo`` in robot ``thorvald_001`` is ``thorvald_001/hokuyo``; write
    ``/thorvald_001/hokuyo`` for a name to be kept as it is. FRAME_NAMESPACE_FIRST (velodyne): the
    same with the namespace before tf_prefix. FRAME_AS_IS (imu_sensor, imu, hector gps): as written.
    In every case as tf2 reads it (:func:`~thorvald_model.urdf_check.normalize_frame`): no leading
    slash (``/imu_link`` is ``imu_link``), no doubled one (a tf_prefix ``thorvald_001/`` joined with a
    slash), so the frame is the link robot_state_publisher publishes.
    """
    if spec.frame_rule == FRAME_AS_IS:
        return normalize_frame(spec.frame)
    if spec.frame_rule == FRAME_NAMESPACE_FIRST:  # velodyne_gazebo_plugins: the namespace wins over tf_prefix
        prefix = namespace.strip("/") or tf_prefix
    else:
        prefix = tf_prefix if tf_prefix else namespace.strip("/")
    return normalize_frame(tf_resolve(prefix, spec.frame))


def resolve_topic(spec: SensorSpec, role: str, namespace: str) -> str:
    """The full topic name: absolute names are kept; relative ones go into the plugin's
    ``<robotNamespace>`` or, without one, the robot's namespace (gazebo_ros spawn_model writes the
    robot's namespace into every plugin)."""
    topic = spec.topics[role]
    if topic.startswith("/"):
        return topic
    ns = namespace if spec.namespace is None else spec.namespace
    ns = "/" + ns.strip("/") if ns.strip("/") else ""
    return f"{ns}/{topic}"


def gps_reference(spec: SensorSpec, datum: Optional[Datum]) -> Tuple[float, float, float, float]:
    """(lat, lon, heading [deg], alt) of a GNSS: its own, else the datum's, else hector's default."""
    config = spec.config
    if config.reference is not None:
        return config.reference
    return datum.reference if datum is not None else HECTOR_REFERENCE


__all__ = [
    "CameraConfig",
    "Datum",
    "ErrorModel",
    "GpsConfig",
    "ImuConfig",
    "P3dConfig",
    "Pose",
    "RayConfig",
    "Refused",
    "SensorBlocks",
    "SensorSpec",
    "Unsupported",
    "gps_reference",
    "read_sensor_blocks",
    "resolve_frame",
    "resolve_topic",
    "tf_resolve",
]
