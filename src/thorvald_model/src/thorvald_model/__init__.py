"""Robot configuration schema and loader shared by every package, the example robots, and the
robot description (URDF) generated from one configuration file."""

from .config import RobotConfig, load_robot_config, parse_robot_config
from .errors import ConfigError, ThorvaldModelError

__all__ = ["ConfigError", "RobotConfig", "ThorvaldModelError", "load_robot_config", "parse_robot_config"]
