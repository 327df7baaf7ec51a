"""What every kind of sensor block is read with: an element's typed reads that name the element's path
and the rule they break, the sensor's pose, rate, namespace and noise, and the value a block becomes
(:class:`SensorSpec`). No pybullet, no ROS: the block readers of :mod:`thorvald_sim.sensors.kinds`
are built on this.
"""

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Dict, Optional, Tuple

from thorvald_model.joint_tree import Origin as Pose  # a transform: SDF's <pose> is URDF's <origin>

from ...errors import BlockError

Vec3 = Tuple[float, float, float]

# What the plugins do with frameName (see thorvald_sim.sensors.blocks.resolve_frame)
FRAME_TF_RESOLVE = "tf_resolve"  # gazebo_ros laser, gpu_laser, block_laser, camera, openni, p3d, gps sensor
FRAME_AS_IS = "as_is"  # imu_sensor, imu, hector gps: the name as written
FRAME_NAMESPACE_FIRST = "namespace_first"  # velodyne: tf::resolve with the namespace, else tf_prefix


@dataclass(frozen=True)
class SensorSpec:
    """One sensor the description asks for."""

    kind: str  # the name of its kind (thorvald_sim.sensors.kinds): laser, multilayer, imu, gps, camera, ...
    name: str  # the sensor's name (or the model plugin's)
    link: str  # the URDF link it is on
    pose: Pose  # of the sensor frame in the link's frame
    rate: float  # [Hz] of simulated time; 0: every physics step
    plugin: str  # the plugin's file name
    topics: Dict[str, str]  # role -> topic as written (roles per kind: scan, points, imu, fix, ...)
    frame: str  # frame_id as written (before resolve_frame)
    frame_rule: str  # FRAME_TF_RESOLVE or FRAME_AS_IS
    namespace: Optional[str]  # the plugin's <robotNamespace>; None: the robot's
    config: object  # the kind's own configuration (RayConfig, ImuConfig, ...)
    child_frame: str = ""  # p3d: the child frame (its bodyName)

    def describe(self) -> str:
        return f"{self.kind} {self.name!r} on link {self.link} ({self.plugin})"


class Element:
    """An element and its path, with typed reads that raise BlockError naming the path and the rule."""

    def __init__(self, element: ET.Element, path: str):
        self.e = element
        self.path = path

    def child(self, tag: str) -> Optional["Element"]:
        found = self.e.find(tag)
        return None if found is None else Element(found, f"{self.path}/{tag}")

    def required(self, tag: str, rule: str) -> "Element":
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


def read_rate(e: Element, tag: str, default: float) -> float:
    return e.number(tag, default, rule=NON_NEGATIVE[0], check=NON_NEGATIVE[1])


def read_pose(e: Element) -> Pose:
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


def read_namespace(plugin: Element) -> Optional[str]:
    return plugin.text("robotNamespace") if plugin.has("robotNamespace") else None


def read_noise(parent: Element) -> Tuple[float, float]:
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
class Found:
    """A <sensor> with the plugin that says what to do with it."""

    sensor: Element
    plugin: Element
    link: str
    name: str
    filename: str
    rate: float  # the sensor's <update_rate> [Hz]
    robot: Optional[ET.Element] = None  # the description's <robot> (a bumper finds its collisions there)


def unpack(found: "Found"):
    """(sensor, plugin, link, name, plugin file name, the sensor's update_rate) of a found block."""
    return found.sensor, found.plugin, found.link, found.name, found.filename, found.rate
