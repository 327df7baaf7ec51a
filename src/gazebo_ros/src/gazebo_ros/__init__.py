"""gazebo_ros's Python package: :mod:`gazebo_ros.gazebo_interface`, the original's helpers around the
/gazebo services, which thorvald_sim's simulator offers."""
