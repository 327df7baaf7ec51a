"""The RViz configuration of a robot's sensors (thorvald_sim.sensors.rviz): a display per sensor topic,
at the topic the simulator publishes, on top of thorvald_model's model.rviz."""

import math
import os

import yaml

from thorvald_model.description import generate_urdf, package_file
from thorvald_sim.sensors.blocks import read_sensor_blocks
from thorvald_sim.sensors.rviz import root_link, rviz_config, sensor_displays

HERE = os.path.dirname(os.path.abspath(__file__))
STD = os.path.join(
    HERE, "..", "..", "..", "thorvald_model", "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml"
)
PROBE = os.path.join(HERE, "..", "data", "sensors_probe.xacro")


def test_every_visible_sensor_gets_a_display_on_its_topic():
    urdf = generate_urdf(STD, tf_prefix="thorvald_001/", model_extras=PROBE, robot_name="thorvald_001")
    specs = read_sensor_blocks(urdf).sensors
    shown = {(d["Class"], d.get("Topic") or d.get("Image Topic")) for d in sensor_displays(specs, "/thorvald_001/")}
    assert shown == {
        ("rviz/LaserScan", "/thorvald_001/scan"),
        ("rviz/PointCloud2", "/thorvald_001/velodyne_points"),
        ("rviz/Image", "/thorvald_001/rgbd/rgb/image_raw"),
        ("rviz/PointCloud2", "/thorvald_001/rgbd/depth/points"),
    }


def test_the_configuration_is_model_rviz_with_the_displays_and_the_fixed_frame():
    with open(package_file("rviz", "model.rviz")) as f:
        template = yaml.safe_load(f)
    urdf = generate_urdf(STD, model_extras=PROBE)
    config = rviz_config(template, read_sensor_blocks(urdf).sensors, "/", "odom")
    manager = config["Visualization Manager"]
    classes = [d["Class"] for d in manager["Displays"]]
    assert classes[: len(template["Visualization Manager"]["Displays"])] == [
        d["Class"] for d in template["Visualization Manager"]["Displays"]
    ]
    assert "rviz/LaserScan" in classes and manager["Global Options"]["Fixed Frame"] == "odom"
    # it survives a YAML round trip, as RViz reads it
    assert yaml.safe_load(yaml.safe_dump(config)) == config


def test_the_view_looks_over_the_robot_from_behind_and_above_and_images_are_titled_by_their_topic():
    with open(package_file("rviz", "model.rviz")) as f:
        template = yaml.safe_load(f)
    urdf = generate_urdf(STD, tf_prefix="thorvald_001/", model_extras=PROBE, robot_name="thorvald_001")
    assert root_link(urdf) == "thorvald_001/base_link"
    specs = read_sensor_blocks(urdf).sensors
    config = rviz_config(template, specs, "/thorvald_001/", "thorvald_001/odom", view_frame=root_link(urdf))
    view = config["Visualization Manager"]["Views"]["Current"]
    # following base_link, the eye behind it (yaw within 45 degrees of straight back) and above,
    # the focal point ahead of base_link, where the scan and the clouds are
    assert view["Class"] == "rviz/Orbit" and view["Target Frame"] == "thorvald_001/base_link"
    assert math.cos(view["Yaw"]) < -0.7 and 0.2 < view["Pitch"] < 1.2 and view["Focal Point"]["X"] > 0.5
    # without view_frame, model.rviz's own view
    assert (
        rviz_config(template, specs, "/", "odom")["Visualization Manager"]["Views"]
        == template["Visualization Manager"]["Views"]
    )
    # the depth camera's image panel says which image it shows (not "rgbd (depth) image")
    images = [d for d in config["Visualization Manager"]["Displays"] if d["Class"] == "rviz/Image"]
    assert [(d["Name"], d["Image Topic"]) for d in images] == [
        ("rgbd/rgb/image_raw", "/thorvald_001/rgbd/rgb/image_raw")
    ]
