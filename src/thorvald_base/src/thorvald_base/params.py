"""base_driver's own parameters, read once into one frozen value (the node's private namespace).

:meth:`DriverParams.from_dict` takes the private namespace as rospy gives it (the robot
configuration's keys beside them are left to the loader) and checks each value; a bad one raises
:class:`~thorvald_base.errors.ParameterError` naming the parameter, the value and the rule. The node
reads the namespace once and hands this value to every part that needs a parameter: the base handle
factory and its handles never see the raw dictionary.
"""

import math
import re
from dataclasses import dataclass, fields
from typing import Any, Mapping

from thorvald_model.frames import normalize_tf_prefix

from .core import DEFAULT_TWIST_COVARIANCE
from .errors import ParameterError

DEFAULT_BITRATE = 1000000  # [bit/s]: the robot's CAN bus


@dataclass(frozen=True)
class DriverParams:
    """base_driver's private parameters besides the robot configuration (units in brackets)."""

    robot_model: str = ""  # the robot's YAML: read when the namespace holds no configuration
    calibration: str = ""  # a calibration file (calibrate_odometry's) applied at start through set_drive_params
    simple_sim: bool = False  # simulate the drives (true) or drive the real base
    base_handle: str = ""  # thorvald_base.bases name; empty: simple_sim, or can without simple_sim
    tf_prefix: str = ""  # normalised: "" or "robot_1/" (from "robot_1/" or the older "robot_1")
    enable_odom_tf: bool = True
    odom_frame_id: str = "odom"
    passthrough_gazebo_odometry: bool = False
    rate: float = 50.0  # control loop [Hz]
    command_timeout: float = 0.5  # [s]
    twist_covariance: Any = DEFAULT_TWIST_COVARIANCE  # 36 values, row-major 6 x 6 (PoseCovariance checks)
    estimator: str = "lsq"
    projection: str = "axle"
    measured_timeout: float = 0.5  # simulated_joints: drive states older than this stop the wheels [s]
    lockstep: bool = False  # simulated_joints: a cycle per arrival of drive states, each answered (the simulator's)
    can_interface_type: str = ""  # python-can interface (socketcan, slcan, virtual, pcan, ...)
    can_interface_name: str = ""  # its channel
    can_bitrate: int = DEFAULT_BITRATE  # [bit/s], for interfaces that set it
    allow_relay_to_base_devices: bool = False
    joint_states_remap_to: str = ""  # base_bringup.launch's argument, kept beside the others

    @property
    def handle(self) -> str:
        """The base handle asked for: ``~base_handle``, else ``simple_sim`` or ``can``."""
        return self.base_handle or ("simple_sim" if self.simple_sim else "can")

    @property
    def base_frame(self) -> str:
        return self.tf_prefix + "base_link"

    @classmethod
    def from_dict(cls, params: Mapping[str, Any]) -> "DriverParams":
        """The parameters of a private namespace; ParameterError for the first bad one."""
        values = {name: params[name] for name in PARAMETER_NAMES if name in params}
        out = cls(
            **{
                **values,
                "tf_prefix": normalize_tf_prefix(values.get("tf_prefix", "")),
                "robot_model": str(values.get("robot_model", "") or ""),
                "calibration": str(values.get("calibration", "") or ""),
                "base_handle": str(values.get("base_handle", "") or ""),
                "odom_frame_id": str(values.get("odom_frame_id", "odom")),
                "can_interface_type": str(values.get("can_interface_type", "") or ""),
                "can_interface_name": str(values.get("can_interface_name", "") or ""),
                "joint_states_remap_to": str(values.get("joint_states_remap_to", "") or ""),
                "simple_sim": _flag(values, "simple_sim", False),
                "enable_odom_tf": _flag(values, "enable_odom_tf", True),
                "passthrough_gazebo_odometry": _flag(values, "passthrough_gazebo_odometry", False),
                "allow_relay_to_base_devices": _flag(values, "allow_relay_to_base_devices", False),
                "lockstep": _flag(values, "lockstep", False),
                "rate": _positive(values, "rate", 50.0, "Hz"),
                "command_timeout": _number(values, "command_timeout", 0.5),  # BaseDriverCore checks > 0
                "measured_timeout": _positive(values, "measured_timeout", 0.5, "s"),
                "can_bitrate": int(_positive(values, "can_bitrate", DEFAULT_BITRATE, "bit/s")),
                # as given: PoseCovariance checks it, the calculator checks estimator and projection
                "twist_covariance": values.get("twist_covariance", DEFAULT_TWIST_COVARIANCE),
                "estimator": str(values.get("estimator", "lsq")),
                "projection": str(values.get("projection", "axle")),
            }
        )
        return out


PARAMETER_NAMES = tuple(f.name for f in fields(DriverParams))
"""The names of base_driver's own parameters: every other key of its namespace is the robot's."""


def _flag(values: Mapping, name: str, default: bool) -> bool:
    value = values.get(name, default)
    if isinstance(value, bool):
        return value
    if isinstance(value, str) and value.strip().lower() in ("true", "false", "1", "0"):
        return value.strip().lower() in ("true", "1")
    if isinstance(value, int) and value in (0, 1):
        return bool(value)
    raise ParameterError(f"~{name}: {value!r}: must be true or false")


def _number(values: Mapping, name: str, default: float) -> float:
    value = values.get(name, default)
    try:
        if isinstance(value, bool):
            raise ValueError
        return float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"~{name}: {value!r}: must be a number") from None


def _positive(values: Mapping, name: str, default: float, unit: str) -> float:
    number = _number(values, name, default)
    if not math.isfinite(number) or not number > 0:
        raise ParameterError(f"~{name}: {values.get(name, default)!r}: must be > 0 [{unit}]")
    return number


__all__ = ["DEFAULT_BITRATE", "PARAMETER_NAMES", "DriverParams"]


def robot_namespaces(value) -> list:
    """~robots as absolute namespaces ending in "/": ["/robot_1/", ...]; ParameterError if empty or
    not names."""
    if isinstance(value, str):
        items = [v for v in re.split(r"[\s,]+", value) if v]
    elif isinstance(value, (list, tuple)):
        items = [str(v) for v in value]
    else:
        raise ParameterError(f"~robots: {value!r}: give the robots' namespaces, a list or a string")
    if not items:
        raise ParameterError("~robots: <missing>: give the robots' namespaces (robot_1 robot_2 ...)")
    out = []
    for item in items:
        name = item.strip("/")
        if not re.fullmatch(r"[A-Za-z][\w/]*", name):
            raise ParameterError(f"~robots: {item!r}: not a ROS namespace")
        ns = "/" + name + "/"
        if ns in out:
            raise ParameterError(f"~robots: {item!r} given twice")
        out.append(ns)
    return out
