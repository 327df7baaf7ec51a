"""pybullet simulator of any Thorvald robot generated from its configuration file."""
