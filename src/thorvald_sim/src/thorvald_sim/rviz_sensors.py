"""An RViz configuration showing a robot and whatever sensors its description carries.

``rosrun thorvald_sim rviz_sensors`` (``sim.launch with_rviz:=true``) reads the robot's
``robot_description``, finds its sensor blocks (:mod:`thorvald_sim.sensor_blocks`), and starts RViz
with thorvald_model's ``model.rviz`` plus the displays each sensor's kind asks for
(:mod:`thorvald_sim.sensor_kinds`): LaserScan for planar lidars, PointCloud2 for 3D lidars and depth
cameras' clouds, Image for cameras. (IMU and GNSS have no display in a plain RViz.) The
configuration is made here, without ROS: :func:`sensor_displays`.
"""

from typing import Any, Dict, Iterable, List

from .sensor_blocks import SensorSpec, resolve_topic
from .sensor_kinds import kind_named

# the colours of the displays, one per sensor in turn
COLOURS = ("255; 80; 80", "80; 200; 80", "80; 160; 255", "255; 200; 0", "200; 80; 255")


def sensor_displays(specs: Iterable[SensorSpec], namespace: str) -> List[Dict[str, Any]]:
    """The displays each sensor's kind asks for, subscribed at the topics the simulator publishes."""
    displays = []
    for k, spec in enumerate(specs):

        def topic(role: str, spec=spec) -> str:
            return resolve_topic(spec, role, namespace)

        displays += kind_named(spec.kind).displays(spec, topic, f"{spec.name} ({spec.kind})", COLOURS[k % len(COLOURS)])
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
