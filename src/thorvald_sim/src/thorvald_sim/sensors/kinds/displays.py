"""RViz displays a sensor kind may ask for (plain dicts of an RViz configuration's ``Displays``)."""

from typing import Any, Dict


def laser_display(topic: str, name: str, colour: str) -> Dict[str, Any]:
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


def cloud_display(topic: str, name: str, colour: str, rgb: bool = False) -> Dict[str, Any]:
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


def image_display(topic: str, name: str) -> Dict[str, Any]:
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
