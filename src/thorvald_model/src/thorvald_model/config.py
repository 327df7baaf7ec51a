"""The robot configuration file: schema, loader and validation.

One file describes one robot (the paper's section 2.3). The format is the original's: top-level
``base_calculator``, ``motor_drives: {drive0: {...}, ...}``, ``batteries``, ``pipes``, ``corners``,
``beams`` and ``io``, with the original's keys. Keys of ours describe the modules the paper names
that the original files lack: ``suspensions``, ``passive_wheels`` (casters and fixed support
wheels) and ``frame_parts`` (custom frame members).

Everything here is pure Python (no rospy, no messages): base_driver, the model generator and the
simulator all load the same file through :func:`load_robot_config` so they agree on geometry.

Loading never stops at the first mistake: every problem is collected, each with its dotted key
path, the value and the rule, and raised together in one :class:`ConfigError`.
"""

import logging
import math
import re
from dataclasses import dataclass, field, replace
from typing import Any, Dict, Iterable, List, Mapping, Optional, Tuple

from .constants import (
    DIFF_CALCULATOR,
    DRIVE_DIFF,
    DRIVE_STEERED,
    IO_MAIN_BOARD,
    ONE_WHEEL_CALCULATOR,
    STD_CALCULATOR,
)
from .errors import MISSING, ConfigError, Problem
from .layout import layout_problems
from .schema import (
    NON_NEGATIVE,
    POSITIVE,
    Kept,
    Key,
    check_top_level,
    in_range,
    non_negative,
    one_of,
    parse_section,
    read_yaml_file,
)

# Top-level keys that robot files of users carry for their own xacro extras (LCAS sensor frames).
# They are kept verbatim in RobotConfig.extras and not validated.
PASSTHROUGH_KEYS = (
    "extras",
    "lidar_front",
    "lidar_back",
    "gnss_antenna_main",
    "gnss_antenna_aux",
    "imu",
    "cameras",
)

FRAME_PART_COLORS = ("grey", "dark_grey", "black", "white", "silver", "orange", "red", "green", "blue", "yellow")


# ---------------------------------------------------------------------------------------------
# Value types (SI units: m, rad, s, kg; motor speeds stay in rpm, as the motor controllers use)
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Suspension:
    """A suspension module between a drive's steering module and the frame (paper 2.1.4)."""

    name: str
    index: int
    drive: str  # name of the drive it carries, e.g. "drive0"
    travel: float  # vertical travel [m]
    stiffness: float  # spring rate [N/m]
    damping: float  # [N s/m]


@dataclass(frozen=True)
class Drive:
    """One drive module, ``motor_drives/driveN``."""

    name: str
    index: int
    node: int  # CANopen node id of its motor controller
    x: float  # steering axis position in base_link [m]
    y: float  # [m]
    type: int  # DRIVE_STEERED (0) or DRIVE_DIFF (1)
    leg_mesh: int
    r_wheel: float  # wheel radius [m]
    w_wheel: float  # wheel width [m]
    prp_gr_rt: float  # propulsion gear ratio (motor turns per wheel turn)
    prp_enc_ppr: int  # propulsion encoder pulses per motor revolution
    prp_max_rpm: float  # motor speed at full command [rpm]
    prp_sim_a: float  # simulated propulsion acceleration [m/s^2]
    str_gr_rt: float  # steering gear ratio
    str_enc_ppr: int  # steering encoder pulses per motor revolution
    str_lim: float  # steering angle limit, either side of straight ahead [rad]
    str_sim_v: float  # simulated steering speed [rad/s]
    prp_motor_torque: float  # propulsion motor torque limit [N m] (the wheel gets it times prp_gr_rt)
    str_motor_torque: float  # steering motor torque limit [N m] (the steering gets it times str_gr_rt)
    steering_name: str  # joint name without tf_prefix, default "steeringN"
    wheel_name: str  # joint name without tf_prefix, default "wheelN"
    tower: bool  # a tower module stands above the drive (model only)
    suspension: Optional[Suspension] = None
    channel: int = 1  # propulsion channel on its motor controller: 2 for the second type-1 drive of a node

    @property
    def steerable(self) -> bool:
        return self.type == DRIVE_STEERED

    @property
    def max_wheel_torque(self) -> float:
        """Torque limit at the wheel [N m]: the propulsion motor's through its gear."""
        return self.prp_motor_torque * self.prp_gr_rt

    @property
    def max_steering_torque(self) -> float:
        """Torque limit about the steering axis [N m]: the steering motor's through its gear."""
        return self.str_motor_torque * self.str_gr_rt

    @property
    def max_steering_speed(self) -> float:
        """The steering speed the drive is allowed [rad/s]: ``str_sim_v``, 0 for a type-1 drive.

        The simulated drive slews at it; on a real base it is the controller's steering speed limit.
        """
        return self.str_sim_v if self.steerable else 0.0

    @property
    def max_wheel_speed(self) -> float:
        """Highest wheel rim speed the motor allows [m/s]."""
        return self.prp_max_rpm * 2.0 * math.pi / 60.0 / self.prp_gr_rt * self.r_wheel


@dataclass(frozen=True)
class Battery:
    """A battery enclosure, ``batteries/batN``; type 0 is an empty enclosure, 1 a KC battery."""

    name: str
    index: int
    id: int  # battery CAN id (the original's deprecated node = id + 344); -1 for none
    type: int
    x: float
    y: float
    z: float
    yaw: float
    bat_mesh: int
    with_battery: bool


@dataclass(frozen=True)
class Pipe:
    """Two parallel frame tubes from (x1, y1) to (x2, y2), ``pipes/pipeN`` (model only)."""

    name: str
    index: int
    x1: float
    y1: float
    x2: float
    y2: float
    height: float  # height of the middle between the two tubes [m]
    space: float  # vertical distance between the tubes [m]

    @property
    def length(self) -> float:
        return math.hypot(self.x2 - self.x1, self.y2 - self.y1)


@dataclass(frozen=True)
class Corner:
    """A frame corner clamp, ``corners/cornerN`` (model only)."""

    name: str
    index: int
    type: int  # orientation 0..3
    corner_mesh: int
    x: float
    y: float
    z: float
    space: float
    susp_ang: float  # [rad]


@dataclass(frozen=True)
class Beam:
    """A frame beam between two drive modules, ``beams/beamN`` (model only)."""

    name: str
    index: int
    start: str  # drive name
    end: str  # drive name
    height: float  # [m]


@dataclass(frozen=True)
class IOBoard:
    """An IO board on the CAN bus, ``io/ioN``."""

    name: str
    index: int
    id: int
    type: int  # 0 main enclosure PCB, 1 sister enclosure PCB, 2 UV lamp board
    rl0_init_state: bool
    rl1_init_state: bool

    @property
    def is_main(self) -> bool:
        """The main enclosure PCB: its relays are the original's ``setRl1`` and ``setRl2``."""
        return self.type == IO_MAIN_BOARD


DEFAULT_MAIN_IO_BOARD = IOBoard("io0", 0, id=0, type=IO_MAIN_BOARD, rl0_init_state=False, rl1_init_state=False)


@dataclass(frozen=True)
class PassiveWheel:
    """An unpowered wheel, ``passive_wheels/passiveN`` (paper 2.1.5).

    A ``caster`` swivels freely and constrains nothing; a ``fixed`` wheel rolls only along its
    ``yaw`` and so cannot slide sideways, which confines the centre of rotation to its axle line.
    """

    name: str
    index: int
    type: str  # "caster" or "fixed"
    x: float  # wheel contact (caster: swivel axis) in base_link [m]
    y: float
    r_wheel: float  # [m]
    w_wheel: float  # [m]
    yaw: float  # rolling direction of a fixed wheel in base_link [rad]
    caster_offset: float  # horizontal trail from swivel axis to wheel centre [m]

    @property
    def fixed(self) -> bool:
        return self.type == "fixed"


@dataclass(frozen=True)
class FramePart:
    """A custom frame member, ``frame_parts/partN``: a box, cylinder or sphere (model only)."""

    name: str
    index: int
    shape: str  # "box", "cylinder" or "sphere"
    x: float  # centre in base_link [m]
    y: float
    z: float
    roll: float  # [rad]
    pitch: float
    yaw: float
    size_x: float  # box [m]
    size_y: float
    size_z: float
    radius: float  # cylinder and sphere [m]
    length: float  # cylinder, along its local z [m]
    mass: float  # [kg]
    color: str


@dataclass(frozen=True)
class RobotConfig:
    """A validated robot configuration."""

    source: str
    base_calculator: str
    drives: Tuple[Drive, ...]
    batteries: Tuple[Battery, ...] = ()
    pipes: Tuple[Pipe, ...] = ()
    corners: Tuple[Corner, ...] = ()
    beams: Tuple[Beam, ...] = ()
    io: Tuple[IOBoard, ...] = ()
    passive_wheels: Tuple[PassiveWheel, ...] = ()
    suspensions: Tuple[Suspension, ...] = ()
    frame_parts: Tuple[FramePart, ...] = ()
    # Top-level keys for the user's own files (the sensor keys, and unknown ones kept), and unknown
    # keys kept inside entries: (section, entry, key, value). to_dict() gives them back.
    extras: Tuple[Tuple[str, Any], ...] = field(default=(), compare=False)
    entry_extras: Tuple[Tuple[str, str, str, Any], ...] = field(default=(), compare=False)
    warnings: Tuple[Problem, ...] = field(default=(), compare=False)  # each unknown key kept

    @property
    def io_boards_on_bus(self) -> Tuple[IOBoard, ...]:
        """The IO boards on the robot's CAN bus: the ``io`` section's, or, without one, the main
        enclosure PCB every Thorvald has (the original's default board, id 0, relays off at start)."""
        return self.io or (DEFAULT_MAIN_IO_BOARD,)

    def drive(self, name: str) -> Drive:
        for d in self.drives:
            if d.name == name:
                return d
        raise KeyError(name)

    @property
    def steered_drives(self) -> Tuple[Drive, ...]:
        return tuple(d for d in self.drives if d.steerable)

    @property
    def track(self) -> float:
        """Widest lateral distance between two wheel contacts [m]."""
        ys = [w[1] for w in self.wheel_contacts()]
        return max(ys) - min(ys)

    @property
    def wheelbase(self) -> float:
        """Longest longitudinal distance between two wheel contacts [m]."""
        xs = [w[0] for w in self.wheel_contacts()]
        return max(xs) - min(xs)

    def wheel_contacts(self) -> List[Tuple[float, float]]:
        return [(d.x, d.y) for d in self.drives] + [(w.x, w.y) for w in self.passive_wheels]

    def to_dict(self) -> Dict[str, Any]:
        """The configuration in the file's format, with every default filled in."""
        out = {"base_calculator": self.base_calculator}
        for section in SECTIONS:
            items = getattr(self, section.attr)
            if items:
                out[section.key] = {item.name: _item_to_dict(section, item) for item in items}
        out.update(dict(self.extras))
        for section_key, entry, key, value in self.entry_extras:
            out[section_key][entry][key] = value
        return out

    def with_drive_param(self, index: int, key: str, value: Any) -> "RobotConfig":
        """A copy with ``motor_drives/drive<index>/<key>`` set to value, validated like a file."""
        data = self.to_dict()
        drives = data.get("motor_drives", {})
        name = f"drive{index}"
        if name not in drives:
            raise ConfigError(self.source, [Problem("motor_drives." + name, MISSING, "no such drive")])
        drives[name][key] = value
        return parse_robot_config(data, self.source)


# ---------------------------------------------------------------------------------------------
# Schema
# ---------------------------------------------------------------------------------------------
# The standard Thorvald II drive module: the values of every published robot file.
DRIVE_KEYS = (
    Key("node", int, check=in_range(1, 127), rule="must be a CANopen node id in 1..127"),
    Key("x", float),
    Key("y", float),
    Key("type", int, 0, one_of(0, 1), "must be 0 (propulsion/steering) or 1 (propulsion/propulsion)"),
    Key("leg_mesh", int, 0, in_range(0, 6), "must be in 0..6"),
    Key("r_wheel", float, 0.2, **POSITIVE),
    Key("w_wheel", float, 0.16, **POSITIVE),
    Key("prp_gr_rt", float, 42.0, **POSITIVE),
    Key("prp_enc_ppr", int, 1024, **POSITIVE),
    Key("prp_max_rpm", float, 3000.0, **POSITIVE),
    Key("prp_sim_a", float, 1.5, aliases=("prp_slm_e",), **POSITIVE),
    Key("str_gr_rt", float, 42.8571429, **POSITIVE),
    Key("str_enc_ppr", int, 1024, **POSITIVE),
    Key("str_lim", float, 3.078027759, lambda v: 0 < v <= math.pi, "must be in (0, pi] [rad]"),
    Key("str_sim_v", float, 4.0, aliases=("str_slm_v",), **POSITIVE),
    # Ours: the motors' torque limits, for the simulator. About 500 W at 3000 rpm for propulsion
    # (1.6 N m x 42 = 67 N m at the wheel, 336 N at a 0.2 m rim); 1 N m x 42.9 = 43 N m for steering,
    # enough to turn a loaded wheel on the spot on tarmac.
    Key("prp_motor_torque", float, 1.6, **POSITIVE),
    Key("str_motor_torque", float, 1.0, **POSITIVE),
    Key("steering_name", str, ""),
    Key("wheel_name", str, ""),
    Key("tower", bool, True),
)

BATTERY_KEYS = (
    Key("id", int, None),
    Key("node", int, None),  # deprecated: id = node - 344
    Key("type", int, 1, one_of(0, 1), "must be 0 (empty enclosure) or 1 (KC battery)"),
    Key("x", float, 0.0),
    Key("y", float, 0.0),
    Key("z", float, 0.72),
    Key("yaw", float, 0.0),
    Key("bat_mesh", int, 0, **NON_NEGATIVE),
    Key("with_battery", bool, True),
)

PIPE_KEYS = (
    Key("x1", float),
    Key("y1", float),
    Key("x2", float),
    Key("y2", float),
    Key("height", float, 0.65, **POSITIVE),
    Key("space", float, 0.15, **NON_NEGATIVE),
)

CORNER_KEYS = (
    Key("type", int, 0, in_range(0, 3), "must be in 0..3"),
    Key("corner_mesh", int, 0, **NON_NEGATIVE),
    Key("x", float),
    Key("y", float),
    Key("z", float, 0.65),
    Key("space", float, 0.15, **NON_NEGATIVE),
    Key("susp_ang", float, 0.0),
)

BEAM_KEYS = (
    Key("start", str),
    Key("end", str),
    Key("height", float, 0.65, **POSITIVE),
)

IO_KEYS = (
    Key("id", int, check=non_negative, rule="must be >= 0"),
    Key("type", int, 0, in_range(0, 2), "must be 0 (main PCB), 1 (sister PCB) or 2 (UV lamp board)"),
    Key("rl0_init_state", bool, False),
    Key("rl1_init_state", bool, False),
)

PASSIVE_WHEEL_KEYS = (
    Key("type", str, check=one_of("caster", "fixed"), rule="must be 'caster' or 'fixed'"),
    Key("x", float),
    Key("y", float),
    Key("r_wheel", float, 0.1, **POSITIVE),
    Key("w_wheel", float, 0.05, **POSITIVE),
    Key("yaw", float, 0.0),
    Key("caster_offset", float, 0.05, **NON_NEGATIVE),
)

SUSPENSION_KEYS = (
    Key("drive", str),
    Key("travel", float, 0.1, **POSITIVE),
    Key("stiffness", float, 30000.0, **POSITIVE),
    Key("damping", float, 3000.0, **NON_NEGATIVE),
)

FRAME_PART_KEYS = (
    Key("shape", str, check=one_of("box", "cylinder", "sphere"), rule="must be 'box', 'cylinder' or 'sphere'"),
    Key("x", float, 0.0),
    Key("y", float, 0.0),
    Key("z", float, 0.0),
    Key("roll", float, 0.0),
    Key("pitch", float, 0.0),
    Key("yaw", float, 0.0),
    Key("size_x", float, 0.0, **POSITIVE),
    Key("size_y", float, 0.0, **POSITIVE),
    Key("size_z", float, 0.0, **POSITIVE),
    Key("radius", float, 0.0, **POSITIVE),
    Key("length", float, 0.0, **POSITIVE),
    Key("mass", float, **POSITIVE),
    Key("color", str, "grey", one_of(*FRAME_PART_COLORS), "must be one of " + ", ".join(FRAME_PART_COLORS)),
)
FRAME_PART_DIMENSIONS = {
    "box": ("size_x", "size_y", "size_z"),
    "cylinder": ("radius", "length"),
    "sphere": ("radius",),
}
_ALL_DIMENSIONS = ("size_x", "size_y", "size_z", "radius", "length")


@dataclass(frozen=True)
class Section:
    key: str  # top-level key, e.g. "motor_drives"
    prefix: str  # entry prefix, e.g. "drive"
    keys: Tuple[Key, ...]
    cls: type
    attr: str  # RobotConfig field


SECTIONS = (
    Section("motor_drives", "drive", DRIVE_KEYS, Drive, "drives"),
    Section("batteries", "bat", BATTERY_KEYS, Battery, "batteries"),
    Section("pipes", "pipe", PIPE_KEYS, Pipe, "pipes"),
    Section("corners", "corner", CORNER_KEYS, Corner, "corners"),
    Section("beams", "beam", BEAM_KEYS, Beam, "beams"),
    Section("io", "io", IO_KEYS, IOBoard, "io"),
    Section("passive_wheels", "passive", PASSIVE_WHEEL_KEYS, PassiveWheel, "passive_wheels"),
    Section("suspensions", "susp", SUSPENSION_KEYS, Suspension, "suspensions"),
    Section("frame_parts", "part", FRAME_PART_KEYS, FramePart, "frame_parts"),
)
SCHEMA_TOP_LEVEL_KEYS = ("base_calculator", *(s.key for s in SECTIONS))
TOP_LEVEL_KEYS = (*SCHEMA_TOP_LEVEL_KEYS, *PASSTHROUGH_KEYS)


# ---------------------------------------------------------------------------------------------
# Loading
# ---------------------------------------------------------------------------------------------
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
    try:
        data = check_top_level(data, TOP_LEVEL_KEYS, problems, ignore, kept=kept, mistakable=SCHEMA_TOP_LEVEL_KEYS)
    except ConfigError as e:
        raise ConfigError(source, e.problems) from None

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
    problems.extend(_cross_field_problems(config, data))
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
            and key.name in _ALL_DIMENSIONS
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


# ---------------------------------------------------------------------------------------------
# Cross-field rules
# ---------------------------------------------------------------------------------------------
SAME_SPOT_DISTANCE = 0.01  # [m]: closer wheel contacts are a typing mistake, not a design


def _cross_field_problems(config: RobotConfig, data: Mapping) -> List[Problem]:
    problems: List[Problem] = []
    if not config.drives:
        raw = data.get("motor_drives")
        if not raw or not isinstance(raw, Mapping):  # a broken drive entry has its own problem already
            problems.append(Problem("motor_drives", MISSING, "at least one driven wheel is needed"))
        return problems

    # Motor controllers: one per type-0 drive; one dual-channel controller per pair of type-1 drives.
    nodes: Dict[int, List[Drive]] = {}
    for d in config.drives:
        nodes.setdefault(d.node, []).append(d)
    for node, drives in nodes.items():
        diff = [d for d in drives if d.type == DRIVE_DIFF]
        steered = [d for d in drives if d.type == DRIVE_STEERED]
        names = ", ".join(d.name for d in drives)
        if diff and (len(diff) != 2 or steered):
            for d in diff:
                problems.append(
                    Problem(
                        f"motor_drives.{d.name}.node",
                        node,
                        f"type-1 drives come in pairs on one controller node; node {node} has: {names}",
                    )
                )
        elif len(steered) > 1:
            for d in steered[1:]:
                problems.append(
                    Problem(
                        f"motor_drives.{d.name}.node",
                        node,
                        f"each type-0 drive has a motor controller of its own; node {node} is also {steered[0].name}'s",
                    )
                )

    # Wheels: no two at one spot; steered wheels must not hit each other when they turn.
    wheels = [("motor_drives." + d.name, d.x, d.y, d) for d in config.drives]
    wheels += [("passive_wheels." + w.name, w.x, w.y, w) for w in config.passive_wheels]
    for i, (path_a, xa, ya, a) in enumerate(wheels):
        for path_b, xb, yb, b in wheels[i + 1 :]:
            dist = math.hypot(xb - xa, yb - ya)
            if dist < SAME_SPOT_DISTANCE:
                problems.append(
                    Problem(
                        path_b,
                        {"x": xb, "y": yb},
                        f"no two wheels at one spot: {path_a} is {dist:.3f} m away",
                    )
                )
            elif _turns(a) or _turns(b):
                reach = _reach(a) + _reach(b)
                if dist < reach:
                    problems.append(
                        Problem(
                            path_b,
                            {"x": xb, "y": yb},
                            f"wheels collide when they turn: {path_a} is {dist:.3f} m away, less than the "
                            f"{reach:.3f} m their footprints reach",
                        )
                    )

    drive_names = {d.name for d in config.drives}
    for beam in config.beams:
        for end in ("start", "end"):
            value = getattr(beam, end)
            if value not in drive_names:
                problems.append(Problem(f"beams.{beam.name}.{end}", value, "must name a drive of motor_drives"))
        if beam.start == beam.end:
            problems.append(Problem(f"beams.{beam.name}.end", beam.end, "must differ from start"))

    carried = {}
    for s in config.suspensions:
        path = f"suspensions.{s.name}.drive"
        if s.drive not in drive_names:
            problems.append(Problem(path, s.drive, "must name a drive of motor_drives"))
        elif s.drive in carried:
            problems.append(Problem(path, s.drive, f"{carried[s.drive]} already carries {s.drive}"))
        else:
            carried[s.drive] = s.name

    raw_batteries = data.get("batteries") if isinstance(data.get("batteries"), Mapping) else {}
    battery_ids = {}
    for b in config.batteries:
        raw = raw_batteries.get(b.name, {}) if isinstance(raw_batteries, Mapping) else {}
        node = raw.get("node") if isinstance(raw, Mapping) else None
        path = f"batteries.{b.name}"
        if "id" in raw and node is not None:
            problems.append(Problem(path + ".node", node, "give 'id' or the deprecated 'node', not both"))
        if b.type == 1 and b.with_battery:
            if b.id < 1:
                key = ".node" if node is not None else ".id"
                value = node if node is not None else (raw.get("id", MISSING) if isinstance(raw, Mapping) else MISSING)
                problems.append(Problem(path + key, value, "a KC battery (type 1) needs an id >= 1 (node >= 345)"))
            elif b.id in battery_ids:
                problems.append(Problem(path + ".id", b.id, "battery id also used by " + battery_ids[b.id]))
            else:
                battery_ids[b.id] = b.name

    io_ids = {}
    for board in config.io:
        if board.id in io_ids:
            problems.append(Problem(f"io.{board.name}.id", board.id, "IO board id also used by " + io_ids[board.id]))
        io_ids.setdefault(board.id, board.name)

    for pipe in config.pipes:
        if pipe.length < SAME_SPOT_DISTANCE:
            problems.append(
                Problem(
                    f"pipes.{pipe.name}",
                    {"x1": pipe.x1, "y1": pipe.y1, "x2": pipe.x2, "y2": pipe.y2},
                    "the two ends must differ",
                )
            )

    raw_parts = data.get("frame_parts") if isinstance(data.get("frame_parts"), Mapping) else {}
    for part in config.frame_parts:
        raw = raw_parts.get(part.name, {})
        needed = FRAME_PART_DIMENSIONS[part.shape]
        for dim in needed:
            if dim not in raw:
                problems.append(
                    Problem(
                        f"frame_parts.{part.name}.{dim}",
                        MISSING,
                        "a {} needs {}".format(part.shape, ", ".join(needed)),
                    )
                )
        for dim in _ALL_DIMENSIONS:
            if dim in raw and dim not in needed:
                problems.append(
                    Problem(
                        f"frame_parts.{part.name}.{dim}",
                        raw[dim],
                        "a {} has only {}".format(part.shape, ", ".join(needed)),
                    )
                )

    problems.extend(layout_problems(config.base_calculator, config.drives, config.passive_wheels))
    return problems


def _turns(wheel) -> bool:
    """A steered drive or a caster sweeps a circle about its vertical axis."""
    return wheel.steerable if isinstance(wheel, Drive) else not wheel.fixed


def _reach(wheel) -> float:
    """How far a wheel's footprint reaches from its x, y, seen from above, as it turns [m].

    A wheel of radius r and width w is a 2r x w rectangle from above; turning about its centre it
    sweeps a circle of radius hypot(r, w/2); a caster's wheel centre trails caster_offset behind.
    """
    reach = math.hypot(wheel.r_wheel, wheel.w_wheel / 2.0)
    if isinstance(wheel, PassiveWheel) and not wheel.fixed:
        reach += wheel.caster_offset
    return reach


__all__ = [
    "DIFF_CALCULATOR",
    "DRIVE_DIFF",
    "DRIVE_STEERED",
    "ONE_WHEEL_CALCULATOR",
    "STD_CALCULATOR",
    "Battery",
    "Beam",
    "ConfigError",
    "Corner",
    "Drive",
    "FramePart",
    "IOBoard",
    "PassiveWheel",
    "Pipe",
    "RobotConfig",
    "Suspension",
    "load_robot_config",
    "parse_robot_config",
]
