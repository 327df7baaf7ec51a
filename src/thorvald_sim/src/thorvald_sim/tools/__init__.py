"""Command-line tools that are not nodes: driving a robot without ROS (``run_robot`` over ``runner``),
checking world files (``check_world``) and as-built files (``check_as_built``)."""
