"""The robot base on its CAN bus: the frames (protocol, thorvald.dbc) and the devices, without ROS."""
