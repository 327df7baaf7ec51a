"""The robot configuration file: the loader (paper section 2.3).

One file describes one robot. The format is the original's: top-level ``base_calculator``,
``motor_drives: {drive0: {...}, ...}``, ``batteries``, ``pipes``, ``corners``, ``beams`` and ``io``,
with the original's keys. Keys of ours describe the modules the paper names that the original files
lack: ``suspensions``, ``passive_wheels`` (casters and fixed support wheels) and ``frame_parts``.

The configuration's parts live by job: the value types and what is derived from them in
:mod:`~thorvald_model.values`, the file's schema (read off those types) in
:mod:`~thorvald_model.keys`, the rules across fields in :mod:`~thorvald_model.rules`, the machinery
of a validated YAML file in :mod:`~thorvald_model.schema`; this module loads a file through them.

Everything here is pure Python (no rospy, no messages): base_driver, the model generator and the
simulator all load the same file through :func:`load_robot_config` so they agree on geometry.

Loading never stops at the first mistake: every problem is collected, each with its dotted key
path, the value and the rule, and raised together in one :class:`ConfigError`.
"""

import logging
import re
from dataclasses import replace
from typing import Any, Dict, Iterable, List, Tuple

from .constants import DIFF_CALCULATOR, DRIVE_DIFF, DRIVE_STEERED, ONE_WHEEL_CALCULATOR, STD_CALCULATOR
from .errors import MISSING, ConfigError, Problem
from .keys import PASSTHROUGH_KEYS, RUNTIME_DRIVE_KEYS, SCHEMA_TOP_LEVEL_KEYS, SECTIONS, TOP_LEVEL_KEYS, Section
from .rules import cross_field_problems
from .schema import Kept, check_top_level, parse_section, read_yaml_file
from .values import (
    ALL_DIMENSIONS,
    FRAME_PART_DIMENSIONS,
    RAIL_FLANGE_WIDTH,
    Battery,
    Beam,
    Corner,
    Drive,
    FramePart,
    IOBoard,
    MotorController,
    PassiveWheel,
    Pipe,
    RobotConfig,
    Suspension,
)


def load_robot_config(path: str) -> RobotConfig:
    """Loads and validates a robot configuration file; raises ConfigError naming every problem.

    A file that cannot be read at all (missing, a directory, no permission, not UTF-8 text, not
    YAML) raises a ConfigError with one problem at the top level, which formats as one line.
    """
    return parse_robot_config(read_yaml_file(path), path)


def parse_robot_config(data: Any, source: str = "<robot configuration>", ignore: Iterable[str] = ()) -> RobotConfig:
    """Validates an already parsed configuration (a YAML document or a ROS parameter tree).

    ``ignore`` lists top-level keys that belong to something else (e.g. base_driver's own
    parameters beside the robot configuration in its private namespace).
    """
    problems: List[Problem] = []
    kept: List[Kept] = []
    data = check_top_level(
        data, TOP_LEVEL_KEYS, problems, ignore, kept=kept, mistakable=SCHEMA_TOP_LEVEL_KEYS, source=source
    )

    calculator = data.get("base_calculator", STD_CALCULATOR)
    if not isinstance(calculator, str) or not _CALCULATOR_NAME.match(calculator):
        problems.append(
            Problem(
                "base_calculator",
                calculator,
                f"must name a calculator class, 'namespace::Class' (e.g. '{STD_CALCULATOR}') or 'python.module:Class'",
            )
        )

    parsed = {}
    for section in SECTIONS:
        entries = parse_section(data.get(section.key), section.key, section.prefix, section.keys, problems, kept=kept)
        parsed[section.attr] = [_build(section, name, index, values) for name, index, values in entries]

    extras = tuple((k, data[k]) for k in PASSTHROUGH_KEYS if k in data)
    extras += tuple((k.path[0], k.value) for k in kept if len(k.path) == 1)
    built = {(section.key, item.name) for section in SECTIONS for item in parsed[section.attr]}
    entry_extras = tuple((*k.path, k.value) for k in kept if len(k.path) == 3 and tuple(k.path[:2]) in built)
    drives = _attach_channels(_attach_suspensions(parsed["drives"], parsed["suspensions"]))
    config = RobotConfig(
        source=source,
        base_calculator=calculator if isinstance(calculator, str) else STD_CALCULATOR,
        drives=tuple(drives),
        batteries=tuple(parsed["batteries"]),
        pipes=tuple(parsed["pipes"]),
        corners=tuple(parsed["corners"]),
        beams=tuple(parsed["beams"]),
        io=tuple(parsed["io"]),
        passive_wheels=tuple(parsed["passive_wheels"]),
        suspensions=tuple(parsed["suspensions"]),
        frame_parts=tuple(parsed["frame_parts"]),
        extras=extras,
        entry_extras=entry_extras,
        warnings=tuple(k.problem() for k in kept),
    )
    problems.extend(cross_field_problems(config, data))
    if problems:
        raise ConfigError(source, problems)
    _log_kept_keys(config)
    return config


_log = logging.getLogger(__name__)
_logged = set()  # (source, key path): each kept key is logged once per process, however often loaded


def _log_kept_keys(config: RobotConfig) -> None:
    """One warning per unknown key kept (as the original, which ignored them, but said here).

    Without a logging set-up Python prints a warning's text alone on stderr (the command-line
    tools); a node logs it in its log file, and base_driver says it on rosout too.
    """
    for problem in config.warnings:
        if (config.source, problem.path) not in _logged:
            _logged.add((config.source, problem.path))
            _log.warning(problem.format(config.source))


_CALCULATOR_NAME = re.compile(r"^(\w+::\w+|[A-Za-z_][\w.]*:\w+)$")


def _build(section: Section, name: str, index: int, values: dict):
    if section.cls is Drive:
        values = dict(values)
        values["steering_name"] = values["steering_name"] or f"steering{index}"
        values["wheel_name"] = values["wheel_name"] or f"wheel{index}"
    elif section.cls is Battery:
        values = dict(values)
        node = values.pop("node")
        if values["id"] is None:
            # The original's deprecated 'node' is the battery's CANopen node; its id is node - 344.
            values["id"] = node - 344 if node is not None and node > 0 else -1
    return section.cls(name=name, index=index, **values)


def _item_to_dict(section: Section, item) -> dict:
    out = {}
    for key in section.keys:
        if key.name == "node" and section.cls is Battery:
            continue
        if (
            section.cls is FramePart
            and key.name in ALL_DIMENSIONS
            and key.name not in FRAME_PART_DIMENSIONS[item.shape]
        ):
            continue
        value = getattr(item, key.name)
        if isinstance(value, float) and value.is_integer() and key.kind is int:
            value = int(value)
        out[key.name] = value
    return out


def _attach_suspensions(drives: List[Drive], suspensions: List[Suspension]) -> List[Drive]:
    by_drive = {}
    for s in suspensions:
        by_drive.setdefault(s.drive, s)
    return [replace(d, suspension=by_drive.get(d.name)) for d in drives]


def _attach_channels(drives: List[Drive]) -> List[Drive]:
    """Numbers the drives that share a motor controller node 1, 2 in file order (a type-1 pair)."""
    seen: Dict[int, int] = {}
    out = []
    for d in drives:
        seen[d.node] = seen.get(d.node, 0) + 1
        out.append(replace(d, channel=seen[d.node]) if seen[d.node] != d.channel else d)
    return out


def config_to_dict(config: RobotConfig) -> Dict[str, Any]:
    """The configuration in the file's format, with every default filled in."""
    out = {"base_calculator": config.base_calculator}
    for section in SECTIONS:
        items = getattr(config, section.attr)
        if items:
            out[section.key] = {item.name: _item_to_dict(section, item) for item in items}
    out.update(dict(config.extras))
    for section_key, entry, key, value in config.entry_extras:
        out[section_key][entry][key] = value
    return out


def description_dict(config: RobotConfig) -> Dict[str, Any]:
    """:func:`config_to_dict` with the derived facts the model's xacro draws by, under ``derived`` of
    each drive, battery and passive wheel entry (never fed back to the loader)."""
    out = config_to_dict(config)
    for d in config.drives:
        out["motor_drives"][d.name]["derived"] = {
            "steerable": d.steerable,
            "max_wheel_torque": d.max_wheel_torque,
            "max_wheel_rate": d.max_wheel_rate,
            "max_steering_torque": d.max_steering_torque,
            "rail_wheel": d.has_rail_wheel,
            "rail_flange_radius": d.rail_flange_radius,
            "rail_flange_width": RAIL_FLANGE_WIDTH,
        }
    for b in config.batteries:
        out["batteries"][b.name]["derived"] = {"present": b.present}
    for w in config.passive_wheels:
        out["passive_wheels"][w.name]["derived"] = {"caster": not w.fixed}
    return out


def with_drive_param(config: RobotConfig, index: int, key: str, value: Any) -> RobotConfig:
    """A copy with ``motor_drives/drive<index>/<key>`` set to value, validated like a file."""
    return with_drive_params(config, [(index, key, value)])


def with_drive_params(config: RobotConfig, changes: Iterable[Tuple[int, str, Any]]) -> RobotConfig:
    """A copy with each change (drive index, key, value) set, as a calibration file or set_drive_params
    gives them, validated like a file once (config itself when there is none)."""
    changes = list(changes)
    if not changes:
        return config
    data = config_to_dict(config)
    drives = data.get("motor_drives", {})
    for index, key, value in changes:
        name = f"drive{index}"
        if name not in drives:
            raise ConfigError(config.source, [Problem("motor_drives." + name, MISSING, "no such drive")])
        drives[name][key] = value
    return parse_robot_config(data, config.source)


__all__ = [
    "DIFF_CALCULATOR",
    "DRIVE_DIFF",
    "DRIVE_STEERED",
    "ONE_WHEEL_CALCULATOR",
    "RUNTIME_DRIVE_KEYS",
    "STD_CALCULATOR",
    "Battery",
    "Beam",
    "ConfigError",
    "Corner",
    "Drive",
    "FramePart",
    "IOBoard",
    "MotorController",
    "PassiveWheel",
    "Pipe",
    "RobotConfig",
    "Suspension",
    "config_to_dict",
    "description_dict",
    "load_robot_config",
    "parse_robot_config",
    "with_drive_param",
    "with_drive_params",
]
