"""thorvald_bringup: launch files for real and simulated robots, and the paper's odometry report."""
