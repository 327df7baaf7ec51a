"""base_driver and twist_mux nodes: kinematics calculator plugins, odometry, the drive layer, and the
simulated and CAN robot base."""
