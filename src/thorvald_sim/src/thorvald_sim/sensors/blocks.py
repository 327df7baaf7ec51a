"""The sensors a robot description asks for, read from its Gazebo blocks, without ROS.

Users' sensor xacros (``model_extras``) carry Gazebo blocks: ``<gazebo reference="LINK"><sensor
type=... name=...>`` with a gazebo_ros plugin inside, and ``<gazebo><plugin>`` model plugins. Each
block goes to the reader of the sensor kind that claims it (:mod:`thorvald_sim.sensors.kinds`: laser,
multilayer, imu, gps, camera, depth, p3d, bumper; the table in docs/sensors.md), which reads it with the
plugin's own parameter names and defaults (gazebo_ros_pkgs for ROS 1, hector_gazebo_plugins,
velodyne_gazebo_plugins), so a block written for Gazebo means the same here.

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

import xml.etree.ElementTree as ET
from dataclasses import dataclass, replace
from typing import List, Tuple, Union

from thorvald_model.urdf_check import normalize_frame

from ..errors import BlockError, NotSimulated
from .kinds import kind_of_model_plugin, kind_of_sensor
from .kinds.block import (
    FRAME_AS_IS,
    FRAME_NAMESPACE_FIRST,
    FRAME_TF_RESOLVE,
    Element,
    Found,
    Pose,
    SensorSpec,
    read_rate,
)
from .kinds.camera import IMAGE_FORMATS, MAX_IMAGE_PIXELS, MAX_IMAGE_SIDE, CameraConfig
from .kinds.gnss import HECTOR_REFERENCE, Datum, ErrorModel, GpsConfig, gps_reference
from .kinds.imu import ImuConfig
from .kinds.lidar import MAX_RAYS, RayConfig
from .kinds.p3d import P3dConfig


@dataclass(frozen=True)
class Unsupported:
    what: str  # e.g. "sensor contact 'touch' (libContactPlugin.so)"
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


def _sensor(element: ET.Element, link: str, root: ET.Element) -> SensorSpec:
    sensor_type = element.get("type", "")
    name = element.get("name", "")
    sensor = Element(element, f"sensor[@name='{name}']")
    plugins = element.findall("plugin")
    rate = read_rate(sensor, "update_rate", 0.0)
    for plugin in plugins:
        filename = plugin.get("filename", "")
        kind = kind_of_sensor(sensor_type, filename)
        if kind is not None:
            plugin_element = Element(plugin, f"{sensor.path}/plugin[@filename='{filename}']")
            return kind.read_sensor(Found(sensor, plugin_element, link, name, filename, rate, root))
    what = ", ".join(p.get("filename", "?") for p in plugins) or "no plugin"
    raise NotSimulated(f"sensor {sensor_type} {name!r} ({what})")


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
                    sensors.append(_sensor(element, link, root))
                except NotSimulated as e:
                    unsupported.append(Unsupported(str(e), link))
                except BlockError as e:
                    refused.append(Refused(link, e.path, e.rule))
            continue
        for element in gazebo.findall("plugin"):
            filename = element.get("filename", "")
            name = element.get("name", "")
            if filename in KNOWN_MODEL_PLUGINS:
                continue
            kind = kind_of_model_plugin(filename)
            if kind is None:
                unsupported.append(Unsupported(f"model plugin {name!r} ({filename})", ""))
                continue
            path = f"plugin[@name='{name}']"
            try:
                spec = kind.read_model_plugin(Element(element, path), root_link, filename, name)
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


__all__ = [
    "FRAME_AS_IS",
    "FRAME_NAMESPACE_FIRST",
    "FRAME_TF_RESOLVE",
    "HECTOR_REFERENCE",
    "IMAGE_FORMATS",
    "MAX_IMAGE_PIXELS",
    "MAX_IMAGE_SIDE",
    "MAX_RAYS",
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
