"""Robot configuration schema and loader shared by every package, the example robots, and the
robot description (URDF) generated from one configuration file."""

from .config import (
    RobotConfig,
    config_to_dict,
    description_dict,
    load_robot_config,
    parse_robot_config,
    with_drive_param,
    with_drive_params,
)
from .errors import ConfigError, ThorvaldModelError

__all__ = [
    "ConfigError",
    "RobotConfig",
    "ThorvaldModelError",
    "config_to_dict",
    "description_dict",
    "load_robot_config",
    "parse_robot_config",
    "with_drive_param",
    "with_drive_params",
]
