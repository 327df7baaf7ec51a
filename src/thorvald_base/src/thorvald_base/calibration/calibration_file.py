"""The calibration file base_driver loads at start (``~calibration``), in the robot file's own shape::

    motor_drives:
      drive0: {r_wheel: 0.20131, steering_offset: 0.0042}
      drive2: {r_wheel: 0.19874}
    odometry:
      yaw_rate_multiplier: 1.0061
      yaw_per_metre: 0.00021
      yaw_per_metre_sideways: -0.0012
      wheel_weights: {drive0: 0.0, drive1: 3.0, drive2: 0.0, drive3: 1.8, drive4: 0.0, drive5: 1.2}

Any drive key set_drive_params may change (thorvald_model's RUNTIME_DRIVE_KEYS) may be given; base_driver
applies the file through set_drive_params, so each value is checked as the robot file's is.
``odometry`` is the calculator's :class:`OdometryCorrection` of the yaw rate odometry reads:
``yaw_rate_multiplier`` (``calibrate_odometry --fit turns``: turns of the working radius read as ground
truth turns them), ``yaw_per_metre`` [rad/m] (``--fit straight``: straight legs read straight),
``yaw_per_metre_sideways`` [rad/m] (crab legs read straight) and ``wheel_weights`` (each drive's weight in
the yaw rate's least-squares fit: the wheels that carry the frame; every drive of the robot, each >= 0,
relative: scaled to the mean 1 on reading, so wheel loads in newtons do), all four from ``--fit heading``.
Reading it (:func:`load_calibration`) checks it first against the robot it is for, with the robot file's
loader helpers, and reports every problem with this file's name, the key path, the value and the rule.

Pure: no rospy, no messages.
"""

from dataclasses import dataclass, replace
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

import yaml

from thorvald_model import with_drive_param
from thorvald_model.config import RUNTIME_DRIVE_KEYS
from thorvald_model.errors import MISSING, ConfigError, Problem
from thorvald_model.keys import DRIVE_KEYS
from thorvald_model.schema import Key, check_top_level, parse_entry, read_yaml_file
from thorvald_model.values import RobotConfig

from ..kinematics.calculator import (
    MAX_WEIGHTED_GAIN,
    MAX_YAW_PER_METRE,
    YAW_RATE_MULTIPLIER_RANGE,
    OdometryCorrection,
    weighted_gain_ratio,
)
from ..kinematics.geometry import Layout
from .estimate import Calibration

WHAT = "calibration file"
TOP_KEYS = ("motor_drives", "odometry")
# the drive keys a calibration may set, each given or not (None: not given)
KEYS = tuple(replace(k, default=None) for k in DRIVE_KEYS if k.runtime)
Change = Tuple[int, str, float]  # (drive index, key, value), as set_drive_params takes it
_LOW, _HIGH = YAW_RATE_MULTIPLIER_RANGE
ODOMETRY_KEYS = (
    Key(
        "yaw_rate_multiplier",
        float,
        None,
        lambda v: _LOW <= v <= _HIGH,
        f"must be in [{_LOW:g}, {_HIGH:g}] (a turn read a few per mille short is tyre slip; 10 % is a wrong robot "
        "file)",
    ),
    Key(
        "yaw_per_metre",
        float,
        None,
        lambda v: abs(v) <= MAX_YAW_PER_METRE,
        f"must be within +-{MAX_YAW_PER_METRE:g} rad/m (0.3 degrees a metre is a bent frame, not a calibration)",
    ),
    Key(
        "yaw_per_metre_sideways",
        float,
        None,
        lambda v: abs(v) <= MAX_YAW_PER_METRE,
        f"must be within +-{MAX_YAW_PER_METRE:g} rad/m (0.3 degrees a metre crabbing is a broken module, not a "
        "calibration)",
    ),
)
WEIGHTS = "wheel_weights"


@dataclass(frozen=True)
class CalibrationValues:
    """What a calibration file sets: drive changes, and odometry's correction (each None: not given)."""

    changes: Tuple[Change, ...] = ()
    yaw_rate_multiplier: Optional[float] = None
    yaw_per_metre: Optional[float] = None
    yaw_per_metre_sideways: Optional[float] = None
    wheel_weights: Optional[Tuple[float, ...]] = None  # in drive order, the mean 1

    @property
    def odometry(self) -> Optional[OdometryCorrection]:
        """The correction the file sets (what it does not give at its default), None if it sets none."""
        given = (self.yaw_rate_multiplier, self.yaw_per_metre, self.yaw_per_metre_sideways, self.wheel_weights)
        if all(value is None for value in given):
            return None
        m = 1.0 if self.yaw_rate_multiplier is None else self.yaw_rate_multiplier
        return OdometryCorrection(
            m,
            0.0 if self.yaw_per_metre is None else self.yaw_per_metre,
            0.0 if self.yaw_per_metre_sideways is None else self.yaw_per_metre_sideways,
            self.wheel_weights or (),
        )


_KEY_ORDER = {k.name: n for n, k in enumerate(DRIVE_KEYS)}  # the robot file's order of a drive's keys


def calibration_dict(calibration: Calibration, extra: Sequence[Change] = ()) -> Dict[str, Any]:
    """What was estimated, in the robot file's shape (parameters not excited are left out), with
    extra (drive index, key, value) besides, e.g. what an earlier calibration set and this one kept."""
    return changes_dict([(p.index, p.key, p.value) for p in calibration.estimated], extra)


def changes_dict(
    changes: Sequence[Change], extra: Sequence[Change] = (), odometry: Optional[OdometryCorrection] = None
) -> Dict[str, Any]:
    """(drive index, key, value) changes in the robot file's shape, with extra besides (a key the
    changes set wins over the same key in extra), and odometry's correction if given (its sideways yaw
    per metre and wheel weights only where set, so a file without them reads as before)."""
    # 9 significant digits: far below any uncertainty, and 0.2016 stays 0.2016 in the file
    values = {(index, key): float(f"{value:.9g}") for index, key, value in changes}
    for index, key, value in extra:
        values.setdefault((index, key), float(value))
    drives: Dict[str, Dict[str, float]] = {}
    for (index, key), value in sorted(values.items(), key=lambda item: (item[0][0], _KEY_ORDER.get(item[0][1], 0))):
        drives.setdefault(f"drive{index}", {})[key] = value
    out: Dict[str, Any] = {"motor_drives": drives}
    if odometry is not None:
        out["odometry"] = {
            "yaw_rate_multiplier": float(f"{odometry.yaw_rate_multiplier:.9g}"),
            "yaw_per_metre": float(f"{odometry.yaw_per_metre:.9g}"),
        }
        if odometry.yaw_per_metre_sideways:
            out["odometry"]["yaw_per_metre_sideways"] = float(f"{odometry.yaw_per_metre_sideways:.9g}")
        if odometry.wheel_weights:
            out["odometry"][WEIGHTS] = {f"drive{k}": float(f"{w:.9g}") for k, w in enumerate(odometry.wheel_weights)}
    return out


def calibration_yaml(
    calibration: Calibration,
    header: str = "",
    extra: Sequence[Change] = (),
    odometry: Optional[OdometryCorrection] = None,
) -> str:
    """The file's text: an optional comment header (each line prefixed with '# '), then the values."""
    changes = [(p.index, p.key, p.value) for p in calibration.estimated]
    return changes_yaml(changes, header, extra, odometry)


def changes_yaml(
    changes: Sequence[Change],
    header: str = "",
    extra: Sequence[Change] = (),
    odometry: Optional[OdometryCorrection] = None,
) -> str:
    """The file's text for (drive index, key, value) changes: as calibration_yaml."""
    comment = "".join(f"# {line}\n" for line in header.splitlines())
    data = changes_dict(changes, extra, odometry)
    return comment + yaml.safe_dump(data, sort_keys=False, default_flow_style=False)


def load_calibration(path: str, config: RobotConfig) -> List[Change]:
    """The changes a calibration file makes to the robot of config's drives, checked; ConfigError naming
    every problem (file, key path, value, rule)."""
    return list(read_calibration(path, config).changes)


def read_calibration(path: str, config: RobotConfig) -> CalibrationValues:
    """Everything a calibration file sets, checked as :func:`load_calibration`."""
    return parse_calibration_values(read_yaml_file(path, WHAT), config, path)


def parse_calibration(data: Any, config: RobotConfig, source: str = "<calibration>") -> List[Change]:
    return list(parse_calibration_values(data, config, source).changes)


def parse_calibration_values(data: Any, config: RobotConfig, source: str = "<calibration>") -> CalibrationValues:
    problems: List[Problem] = []
    data = check_top_level(data, TOP_KEYS, problems, source=source, what=WHAT)
    odometry: Dict[str, Any] = {}
    raw_weights = None
    if data.get("odometry") is not None:
        entry = data["odometry"]
        if isinstance(entry, Mapping) and WEIGHTS in entry:
            raw_weights = entry[WEIGHTS]
            entry = {k: v for k, v in entry.items() if k != WEIGHTS}
        odometry = parse_entry(entry, "odometry", ODOMETRY_KEYS, problems) or {}
    raw = data.get("motor_drives")
    changes: List[Change] = []
    names = [d.name for d in config.drives]
    if raw is not None and not isinstance(raw, Mapping):
        problems.append(Problem("motor_drives", raw, "must be a mapping of the robot's drives (drive0, ...)"))
        raw = {}
    for name, entry in (raw or {}).items():
        path = f"motor_drives.{name}"
        if name not in names:
            problems.append(Problem(path, MISSING, f"is not a drive of the robot (it has {', '.join(names)})"))
            continue
        if isinstance(entry, Mapping):
            fixed = [key for key in entry if _drive_key(key) not in (None, *RUNTIME_DRIVE_KEYS)]
            for key in fixed:
                rule = (
                    "cannot be calibrated: base_driver applies the file as set_drive_params, which changes "
                    f"only {', '.join(RUNTIME_DRIVE_KEYS)}"
                )
                problems.append(Problem(f"{path}.{key}", entry[key], rule))
            entry = {k: v for k, v in entry.items() if k not in fixed}
        values = parse_entry(entry, path, KEYS, problems)
        if values is None:
            continue
        index = names.index(name)
        changes += [(index, key, value) for key, value in values.items() if value is not None]
    # each value against the robot, as set_drive_params checks it: the robot file's rules
    candidate = config
    for index, key, value in changes:
        try:
            candidate = with_drive_param(candidate, index, key, value)
        except ConfigError as e:
            problems += [p for p in e.problems if p not in problems]
    weights = None if raw_weights is None else _wheel_weights(raw_weights, candidate, problems)
    if problems:
        raise ConfigError(source, problems, WHAT)
    return CalibrationValues(
        tuple(changes),
        odometry.get("yaw_rate_multiplier"),
        odometry.get("yaw_per_metre"),
        odometry.get("yaw_per_metre_sideways"),
        weights,
    )


def _wheel_weights(raw: Any, config: RobotConfig, problems: List[Problem]) -> Optional[Tuple[float, ...]]:
    """odometry.wheel_weights: a weight for every drive of the robot, each a number >= 0, not all 0,
    scaled to the mean 1; the weighted wheels must determine the robot's motion without reading the
    wheels' disagreement as a turn more than MAX_WEIGHTED_GAIN times as strongly as the plain fit."""
    path = f"odometry.{WEIGHTS}"
    names = [d.name for d in config.drives]
    if not isinstance(raw, Mapping):
        problems.append(
            Problem(path, raw, f"must be a mapping of every drive of the robot ({', '.join(names)}) to its weight")
        )
        return None
    bad = len(problems)
    for name in raw:
        if name not in names:
            problems.append(
                Problem(f"{path}.{name}", MISSING, f"is not a drive of the robot (it has {', '.join(names)})")
            )
    for name in names:
        if name not in raw:
            problems.append(
                Problem(f"{path}.{name}", MISSING, "is missing: weigh every drive (0 for a wheel that carries nothing)")
            )
        elif (
            isinstance(raw[name], bool)
            or not isinstance(raw[name], (int, float))
            or not 0.0 <= raw[name] < float("inf")
        ):
            problems.append(Problem(f"{path}.{name}", raw[name], "must be a number >= 0"))
    if len(problems) > bad:
        return None
    total = float(sum(raw[name] for name in names))
    if not total > 0.0:
        problems.append(Problem(path, dict(raw), "must not all be 0: the frame stands on some wheels"))
        return None
    weights = tuple(len(names) * float(raw[name]) / total for name in names)
    ratio = weighted_gain_ratio(Layout(config.drives, config.passive_wheels), weights)
    if ratio > MAX_WEIGHTED_GAIN:
        said = (
            "do not determine the robot's motion"
            if ratio == float("inf")
            else f"read the wheels' disagreement as a turn {ratio:.1f} times as strongly as the plain fit"
        )
        problems.append(
            Problem(
                path,
                dict(raw),
                f"the weighted wheels {said} (at most {MAX_WEIGHTED_GAIN:g}): weights that lean on too few wheels",
            )
        )
        return None
    return weights


def set_drive_params_command(changes: List[Change], namespace: str = "") -> str:
    """The rosservice call that applies the changes to a running robot's base_driver (thorvald_msgs
    DriveParams: params, each DriveParam index, type, value)."""
    service = "/".join(part for part in (namespace.strip("/"), "base_driver", "set_drive_params") if part)
    params = ", ".join(f"{{index: {i}, type: '{key}', value: {value!r}}}" for i, key, value in changes)
    return f'rosservice call /{service} "params: [{params}]"'


def _drive_key(name: Any) -> Optional[str]:
    """The drive key a name of the file means (an alias's key), or None for no drive key."""
    for k in DRIVE_KEYS:
        if name == k.name or name in k.aliases:
            return k.name
    return None


__all__ = [
    "KEYS",
    "ODOMETRY_KEYS",
    "WEIGHTS",
    "WHAT",
    "CalibrationValues",
    "calibration_dict",
    "calibration_yaml",
    "load_calibration",
    "parse_calibration",
    "parse_calibration_values",
    "read_calibration",
    "set_drive_params_command",
]
