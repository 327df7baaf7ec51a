"""The simulation in pybullet, without ROS: a spawned description read (``description``, ``as_built``),
the robot, its sensors' models and the world built in a pybullet client (``robot``, ``scene``), stepped
together (``simulation``), behind the one interface the node drives (``engine``: in the node's own
client, or ``workers``: in worker processes); the physics settings by name (``presets``)."""
