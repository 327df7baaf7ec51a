"""Sensors: one module a kind (``kinds``), a description's Gazebo blocks read by their kinds
(``blocks``), the sensors mounted on a robot in the pybullet world (``mounted``), and an RViz
configuration showing them (``rviz``). Their ROS topics are the node's (:mod:`thorvald_sim.node.sensor_io`)."""
