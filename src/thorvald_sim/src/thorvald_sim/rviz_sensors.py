"""An RViz configuration showing a robot and whatever sensors its description carries.

``rosrun thorvald_sim rviz_sensors`` (``sim.launch with_rviz:=true``) reads the robot's
``robot_description``, finds its sensor blocks (:mod:`thorvald_sim.sensor_blocks`), and starts RViz
with thorvald_model's ``model.rviz`` plus one display per sensor topic: LaserScan for planar lidars,
PointCloud2 for 3D lidars and depth cameras' clouds, Image for cameras. (IMU and GNSS have no display
in a plain RViz.) The configuration is made here, without ROS: :func:`sensor_displays`.
"""

from typing import Any, Dict, Iterable, List

from .sensor_blocks import SensorSpec, resolve_topic

# the colours of the displays, one per sensor in turn
COLOURS = ("255; 80; 80", "80; 200; 80", "80; 160; 255", "255; 200; 0", "200; 80; 255")


def _laser(topic: str, name: str, colour: str) -> Dict[str, Any]:
    return {
        "Class": "rviz/LaserScan",
        "Name": name,
        "Topic": topic,
        "Enabled": True,
        "Value": True,
        "Size (m)": 0.05,
        "Style": "Flat Squares",
        "Color Transformer": "FlatColor",
        "Color": colour,
        "Queue Size": 10,
        "Decay Time": 0,
    }


def _cloud(topic: str, name: str, colour: str, rgb: bool = False) -> Dict[str, Any]:
    return {
        "Class": "rviz/PointCloud2",
        "Name": name,
        "Topic": topic,
        "Enabled": True,
        "Value": True,
        "Size (m)": 0.03,
        "Style": "Flat Squares",
        "Color Transformer": "RGB8" if rgb else "AxisColor",
        "Axis": "Z",
        "Color": colour,
        "Queue Size": 10,
        "Decay Time": 0,
    }


def _image(topic: str, name: str) -> Dict[str, Any]:
    return {
        "Class": "rviz/Image",
        "Name": name,
        "Image Topic": topic,
        "Enabled": True,
        "Value": True,
        "Transport Hint": "raw",
        "Normalize Range": True,
        "Queue Size": 2,
    }


def sensor_displays(specs: Iterable[SensorSpec], namespace: str) -> List[Dict[str, Any]]:
    """One RViz display per visible sensor topic, subscribed at the topic the simulator publishes."""
    displays = []
    for k, spec in enumerate(specs):
        colour = COLOURS[k % len(COLOURS)]
        name = f"{spec.name} ({spec.kind})"
        if spec.kind == "laser":
            displays.append(_laser(resolve_topic(spec, "scan", namespace), name, colour))
        elif spec.kind == "multilayer":
            displays.append(_cloud(resolve_topic(spec, "points", namespace), name, colour))
        elif spec.kind in ("camera", "depth"):
            displays.append(_image(resolve_topic(spec, "image", namespace), name + " image"))
            if spec.kind == "depth":
                displays.append(_cloud(resolve_topic(spec, "points", namespace), name + " cloud", colour, rgb=True))
    return displays


def rviz_config(
    template: Dict[str, Any], specs: Iterable[SensorSpec], namespace: str, fixed_frame: str
) -> Dict[str, Any]:
    """model.rviz (parsed) with the sensors' displays added and the fixed frame set."""
    config = dict(template)
    manager = dict(config["Visualization Manager"])
    manager["Displays"] = list(manager["Displays"]) + sensor_displays(specs, namespace)
    options = dict(manager["Global Options"])
    options["Fixed Frame"] = fixed_frame
    manager["Global Options"] = options
    config["Visualization Manager"] = manager
    return config
