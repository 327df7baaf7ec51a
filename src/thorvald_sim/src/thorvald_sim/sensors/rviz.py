"""An RViz configuration showing a robot and whatever sensors its description carries.

``rosrun thorvald_sim rviz_sensors`` (``sim.launch with_rviz:=true``) reads the robot's
``robot_description``, finds its sensor blocks (:mod:`thorvald_sim.sensors.blocks`), and starts RViz
with thorvald_model's ``model.rviz`` plus the displays each sensor's kind asks for
(:mod:`thorvald_sim.sensors.kinds`): LaserScan for planar lidars, PointCloud2 for 3D lidars and depth
cameras' clouds, Image for cameras (each image panel titled with the topic it shows). (IMU and GNSS
have no display in a plain RViz.) The view looks over the robot from behind and above, following
its base_link, so the scan and the clouds ahead of it are in sight as it sets off. The configuration
is made here, without ROS: :func:`rviz_config`.
"""

import xml.etree.ElementTree as ET
from typing import Any, Dict, Iterable, List, Optional

from .blocks import SensorSpec, resolve_topic
from .kinds import kind_named

# the colours of the displays, one per sensor in turn
COLOURS = ("255; 80; 80", "80; 200; 80", "80; 160; 255", "255; 200; 0", "200; 80; 255")

# RViz's orbit view from behind and above the robot, looking ahead of it: the eye at Distance [m]
# from the focal point, Yaw [rad] about z from the x axis (pi: straight behind; a little more: behind
# and to the right), Pitch [rad] above the ground plane. The orbit view follows its target frame's
# position, not its heading: the axes are the fixed frame's (odom), along which the robot starts.
BEHIND_VIEW = {"Distance": 5.5, "Focal Point": {"X": 1.2, "Y": 0.0, "Z": 0.6}, "Pitch": 0.45, "Yaw": 3.6}


def sensor_displays(specs: Iterable[SensorSpec], namespace: str) -> List[Dict[str, Any]]:
    """The displays each sensor's kind asks for, subscribed at the topics the simulator publishes."""
    displays = []
    for k, spec in enumerate(specs):

        def topic(role: str, spec=spec) -> str:
            return resolve_topic(spec, role, namespace)

        shown = kind_named(spec.kind).displays(spec, topic, f"{spec.name} ({spec.kind})", COLOURS[k % len(COLOURS)])
        displays += [_image_titled(d, spec, namespace) for d in shown]
    return displays


def _image_titled(display: Dict[str, Any], spec: SensorSpec, namespace: str) -> Dict[str, Any]:
    """An Image display named by the topic it shows: RViz titles its panel with the display's name,
    and a depth camera's "camera_front (depth) image" read as the depth image where it shows
    rgb/image_raw. The topic relative to the robot's namespace, after the sensor's name unless it
    begins with it ("camera_front/rgb/image_raw"; a sensor "front" publishing under cameraName "cam":
    "front: cam/image_raw")."""
    if display.get("Class") != "rviz/Image":
        return display
    topic = display["Image Topic"]
    prefix = "/" + namespace.strip("/") + "/" if namespace.strip("/") else "/"
    relative = topic[len(prefix) :] if topic.startswith(prefix) else topic
    name = relative if relative.startswith(spec.name + "/") else f"{spec.name}: {relative}"
    return {**display, "Name": name}


def root_link(urdf: str) -> Optional[str]:
    """The description's root link (no joint's child: base_link, with its tf_prefix), or None."""
    try:
        robot = ET.fromstring(urdf)
    except ET.ParseError:
        return None
    children = {c.get("link") for c in robot.iter("child")}
    roots = [link.get("name") for link in robot.findall("link") if link.get("name") not in children]
    return roots[0] if len(roots) == 1 else None


def rviz_config(
    template: Dict[str, Any],
    specs: Iterable[SensorSpec],
    namespace: str,
    fixed_frame: str,
    view_frame: Optional[str] = None,
) -> Dict[str, Any]:
    """model.rviz (parsed) with the sensors' displays added and the fixed frame set; with view_frame
    (the robot's base_link), the view from behind and above it (:data:`BEHIND_VIEW`), following it."""
    config = dict(template)
    manager = dict(config["Visualization Manager"])
    manager["Displays"] = list(manager["Displays"]) + sensor_displays(specs, namespace)
    options = dict(manager["Global Options"])
    options["Fixed Frame"] = fixed_frame
    manager["Global Options"] = options
    if view_frame:
        views = dict(manager["Views"])
        views["Current"] = {**views["Current"], **BEHIND_VIEW, "Target Frame": view_frame}
        manager["Views"] = views
    config["Visualization Manager"] = manager
    return config
