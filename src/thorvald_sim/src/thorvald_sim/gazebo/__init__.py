"""Gazebo's ROS API on the simulator (``/gazebo``): the entities as Gazebo names them
(:mod:`.entities`), the frame arithmetic of gazebo_ros (:mod:`.frames`), the services and topics
(:mod:`.api`, the ROS side) and what they do in a world's bodies (:mod:`.bodies`, pybullet).
docs/coming-from-gazebo.md says what each interface does here and what differs.
"""
