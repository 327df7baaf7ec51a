"""Cameras: ``camera`` (sensor_msgs/Image and CameraInfo) and ``depth`` (also a 32FC1 depth image and
an organised PointCloud2), from Gazebo ``camera``/``depth`` sensors with gazebo_ros_camera,
gazebo_ros_openni_kinect or gazebo_ros_depth_camera; topics under the plugin's ``cameraName``."""

import math
from dataclasses import dataclass
from typing import Optional

import numpy as np

from ...errors import BlockError
from .block import (
    FRAME_TF_RESOLVE,
    NON_NEGATIVE,
    POSITIVE,
    Element,
    Found,
    SensorSpec,
    read_namespace,
    read_pose,
    read_rate,
    unpack,
)
from .displays import cloud_display, image_display
from .kind import SensorKind
from .model import Sensor, p, rotate

CAMERA_PLUGINS = ("libgazebo_ros_camera.so",)
DEPTH_PLUGINS = ("libgazebo_ros_openni_kinect.so", "libgazebo_ros_depth_camera.so")
# Image formats of Gazebo's <image><format> and the sensor_msgs encodings they are published in
IMAGE_FORMATS = {"R8G8B8": ("rgb8", 3), "B8G8R8": ("bgr8", 3), "L8": ("mono8", 1), "RGB_INT8": ("rgb8", 3)}

# What one reading may cost (thorvald_sim.sensors.blocks says why these figures)
MAX_IMAGE_SIDE = 8192  # [px] a camera's width or height
MAX_IMAGE_PIXELS = 2**24  # [px] width x height: 4096 x 4096


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


# ---------------------------------------------------------------------------------------------
# The blocks
# ---------------------------------------------------------------------------------------------
def _check_pixels(image: Element, width: int, height: int) -> None:
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


def _camera(found: Found, depth: bool) -> SensorSpec:
    sensor, plugin, link, name, filename, rate = unpack(found)
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
    plugin_rate = read_rate(plugin, "updateRate", 0.0)
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
        "depth" if depth else "camera", name, link, read_pose(sensor), plugin_rate or rate, filename, topics,
        plugin.text("frameName", "/world"), FRAME_TF_RESOLVE, read_namespace(plugin), config,
    )  # fmt: skip


# ---------------------------------------------------------------------------------------------
# The model
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
    """Renders with pybullet's software renderer (no display): the camera looks along its frame's +x
    with +z up, as Gazebo's; a depth camera also gives metric depth."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        c: CameraConfig = self.spec.config
        vfov = 2.0 * math.atan(math.tan(c.horizontal_fov / 2.0) * c.height / c.width)
        self.projection = p.computeProjectionMatrixFOV(math.degrees(vfov), c.width / c.height, c.near, c.far)

    def read(self, now: float) -> Frame:
        c: CameraConfig = self.spec.config
        eye, quat = self.pose()
        forward = rotate(quat, (1.0, 0.0, 0.0))
        up = rotate(quat, (0.0, 0.0, 1.0))
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
# The messages and displays
# ---------------------------------------------------------------------------------------------
# a depth camera's cloud: gazebo_ros's layout, 32 bytes a point, rgb packed in a word at 16
CAMERA_DTYPE = np.dtype(
    {"names": ["x", "y", "z", "rgb"], "formats": ["<f4", "<f4", "<f4", "<u4"], "offsets": [0, 4, 8, 16], "itemsize": 32}
)
CAMERA_FIELDS = (("x", 0, "FLOAT32"), ("y", 4, "FLOAT32"), ("z", 8, "FLOAT32"), ("rgb", 16, "FLOAT32"))


def packed_rgb(rgba: np.ndarray, out: Optional[np.ndarray] = None) -> np.ndarray:
    """The packed colours of RGBA pixels (... x 4, uint8) as a cloud's ``rgb`` field holds them,
    r << 16 | g << 8 | b (uint32; gazebo_ros's and PCL's layout), into out if given: each pixel's
    little-endian word (a b g r) byte-swapped and shifted right by 8."""
    words = np.ascontiguousarray(rgba, dtype=np.uint8).view("<u4")[..., 0]
    return np.right_shift(words.byteswap(), 8, out=out)


def camera_info(out):
    """gazebo_ros_camera_utils's intrinsics: focal length from horizontal_fov, centre ((w+1)/2, (h+1)/2)."""
    c: CameraConfig = out.spec.config
    f = c.focal_length
    cx, cy = (c.width + 1) / 2.0, (c.height + 1) / 2.0
    info = out.message("camera_info")
    info.height, info.width = c.height, c.width
    info.distortion_model = "plumb_bob"
    info.D = [0.0] * 5
    info.K = [f, 0.0, cx, 0.0, f, cy, 0.0, 0.0, 1.0]
    info.R = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0]
    info.P = [f, 0.0, cx, 0.0, 0.0, f, cy, 0.0, 0.0, 0.0, 1.0, 0.0]
    return info


def camera_messages(out, frame: Frame, wanted):
    """The image and its camera info; for a depth camera also the depth image (32FC1, m), its info
    (the camera's) and the organised cloud, each only when read."""
    c: CameraConfig = out.spec.config
    if wanted.get("image"):
        image = out.message("image")
        image.height, image.width = c.height, c.width
        image.encoding = c.encoding
        image.is_bigendian = 0
        image.step = c.width * c.channels
        image.data = frame.image
        yield "image", image
    info = camera_info(out)
    if wanted.get("camera_info"):
        yield "camera_info", info
    if frame.depth is None:
        return
    if wanted.get("depth"):
        depth = out.message("depth")
        depth.height, depth.width = c.height, c.width
        depth.encoding = "32FC1"
        depth.is_bigendian = 0
        depth.step = c.width * 4
        depth.data = np.asarray(frame.depth, dtype="<f4")
        yield "depth", depth
    if wanted.get("depth_info"):
        yield "depth_info", info
    if wanted.get("points"):
        data = out.keep.get("points")
        if data is None:  # made once, its padding zero: publish serialises at once, so reuse is safe
            data = out.keep["points"] = np.zeros((c.height, c.width), dtype=CAMERA_DTYPE)
        depth_to_points(frame.depth, c, out=(data["x"], data["y"], data["z"]))
        if c.channels == 1:  # grey in each of r, g, b
            data["rgb"] = frame.image[..., 0].astype(np.uint32) * 0x010101
        else:  # from the renderer's RGBA, whatever the image's channel order
            packed_rgb(frame.rgba, out=data["rgb"])
        yield "points", out.cloud("points", data, CAMERA_FIELDS, dense=False)


def camera_displays(spec, topic, name, colour):
    return [image_display(topic("image"), name + " image")]


def depth_displays(spec, topic, name, colour):
    return [
        image_display(topic("image"), name + " image"),
        cloud_display(topic("points"), name + " cloud", colour, rgb=True),
    ]


CAMERA_ROLES = {"image": "sensor_msgs/Image", "camera_info": "sensor_msgs/CameraInfo"}
_CAMERA = """<camera><horizontal_fov>1.047</horizontal_fov><image><width>64</width><height>48</height>
<format>R8G8B8</format></image><clip><near>0.1</near><far>20</far></clip></camera>"""

CAMERA = SensorKind(
    "camera",
    blocks="`camera` + `libgazebo_ros_camera.so`",
    published="`Image` + `CameraInfo` under `cameraName`, pybullet's software renderer, no display",
    model=Camera,
    roles=CAMERA_ROLES,
    messages=camera_messages,
    displays=camera_displays,
    sensors=(("camera", CAMERA_PLUGINS),),
    read_sensor=lambda found: _camera(found, depth=False),
    example=f"""<gazebo reference="sensor_link"><sensor type="camera" name="front_camera"><update_rate>10</update_rate>
{_CAMERA}<plugin name="front_camera" filename="libgazebo_ros_camera.so"><cameraName>front_camera</cameraName>
<frameName>sensor_link</frameName></plugin></sensor></gazebo>""",
)

DEPTH = SensorKind(
    "depth",
    blocks="`depth` (or `camera`) + `libgazebo_ros_openni_kinect.so`, `libgazebo_ros_depth_camera.so`",
    published="the camera's topics, a 32FC1 depth image (m) and an organised `PointCloud2` (x, y, z, rgb)",
    model=Camera,
    roles={
        **CAMERA_ROLES,
        "depth": "sensor_msgs/Image",
        "depth_info": "sensor_msgs/CameraInfo",
        "points": "sensor_msgs/PointCloud2",
    },
    messages=camera_messages,
    displays=depth_displays,
    sensors=(("depth", DEPTH_PLUGINS), ("camera", DEPTH_PLUGINS)),
    read_sensor=lambda found: _camera(found, depth=True),
    example=f"""<gazebo reference="sensor_link"><sensor type="depth" name="rgbd"><update_rate>10</update_rate>
{_CAMERA}<plugin name="rgbd" filename="libgazebo_ros_openni_kinect.so"><cameraName>rgbd</cameraName>
<frameName>sensor_link</frameName><pointCloudCutoff>0.3</pointCloudCutoff></plugin></sensor></gazebo>""",
)
