"""The rules across fields of a robot configuration: one function per rule, checked on every load.

Each rule takes the configuration built from the file (every entry that parsed) and the raw
document (for what the file did or did not write), and returns the problems it finds, each with its
dotted key path, the value and the rule in words. :data:`RULES` lists them in report order. The
wheel layout rules shared by every calculator live in :mod:`thorvald_model.layout`.
"""

import math
from typing import Callable, List, Mapping

from .errors import MISSING, Problem
from .layout import shared_layout_problems
from .values import ALL_DIMENSIONS, FRAME_PART_DIMENSIONS, RAIL_FLANGE_DEPTH, Drive, PassiveWheel, RobotConfig

SAME_SPOT_DISTANCE = 0.01  # [m]: closer wheel contacts are a typing mistake, not a design

Rule = Callable[[RobotConfig, Mapping], List[Problem]]


def motor_controllers(config: RobotConfig, data: Mapping) -> List[Problem]:
    """One controller per type-0 drive; one dual-channel controller per pair of type-1 drives."""
    problems = []
    for controller in config.motor_controllers:
        node, drives = controller.node, controller.drives
        diff = [d for d in drives if not d.steerable]
        steered = [d for d in drives if d.steerable]
        names = ", ".join(d.name for d in sorted(drives, key=lambda d: d.index))
        if diff and (len(diff) != 2 or steered):
            for d in sorted(diff, key=lambda d: d.index):
                problems.append(
                    Problem(
                        f"motor_drives.{d.name}.node",
                        node,
                        f"type-1 drives come in pairs on one controller node; node {node} has: {names}",
                    )
                )
        elif len(steered) > 1:
            steered.sort(key=lambda d: d.index)
            for d in steered[1:]:
                problems.append(
                    Problem(
                        f"motor_drives.{d.name}.node",
                        node,
                        f"each type-0 drive has a motor controller of its own; node {node} is also {steered[0].name}'s",
                    )
                )
    return problems


def wheel_spots(config: RobotConfig, data: Mapping) -> List[Problem]:
    """No two wheels at one spot; steered wheels (and casters) must not hit each other as they turn."""
    problems = []
    wheels = [("motor_drives." + d.name, d.x, d.y, d) for d in config.drives]
    wheels += [("passive_wheels." + w.name, w.x, w.y, w) for w in config.passive_wheels]
    for i, (path_a, xa, ya, a) in enumerate(wheels):
        for path_b, xb, yb, b in wheels[i + 1 :]:
            dist = math.hypot(xb - xa, yb - ya)
            if dist < SAME_SPOT_DISTANCE:
                problems.append(
                    Problem(path_b, {"x": xb, "y": yb}, f"no two wheels at one spot: {path_a} is {dist:.3f} m away")
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
    return problems


def beams_join_drives(config: RobotConfig, data: Mapping) -> List[Problem]:
    problems = []
    drive_names = {d.name for d in config.drives}
    for beam in config.beams:
        for end in ("start", "end"):
            value = getattr(beam, end)
            if value not in drive_names:
                problems.append(Problem(f"beams.{beam.name}.{end}", value, "must name a drive of motor_drives"))
        if beam.start == beam.end:
            problems.append(Problem(f"beams.{beam.name}.end", beam.end, "must differ from start"))
    return problems


def suspensions_carry_drives(config: RobotConfig, data: Mapping) -> List[Problem]:
    problems = []
    drive_names = {d.name for d in config.drives}
    carried = {}
    for s in config.suspensions:
        path = f"suspensions.{s.name}.drive"
        if s.drive not in drive_names:
            problems.append(Problem(path, s.drive, "must name a drive of motor_drives"))
        elif s.drive in carried:
            problems.append(Problem(path, s.drive, f"{carried[s.drive]} already carries {s.drive}"))
        else:
            carried[s.drive] = s.name
    return problems


def battery_ids(config: RobotConfig, data: Mapping) -> List[Problem]:
    """'id' or the deprecated 'node'; a fitted KC battery has an id >= 1 of its own."""
    problems = []
    raw_batteries = data.get("batteries") if isinstance(data.get("batteries"), Mapping) else {}
    seen = {}
    for b in config.batteries:
        raw = raw_batteries.get(b.name, {}) if isinstance(raw_batteries, Mapping) else {}
        node = raw.get("node") if isinstance(raw, Mapping) else None
        path = f"batteries.{b.name}"
        if "id" in raw and node is not None:
            problems.append(Problem(path + ".node", node, "give 'id' or the deprecated 'node', not both"))
        if b.present:
            if b.id < 1:
                key = ".node" if node is not None else ".id"
                value = node if node is not None else (raw.get("id", MISSING) if isinstance(raw, Mapping) else MISSING)
                problems.append(Problem(path + key, value, "a KC battery (type 1) needs an id >= 1 (node >= 345)"))
            elif b.id in seen:
                problems.append(Problem(path + ".id", b.id, "battery id also used by " + seen[b.id]))
            else:
                seen[b.id] = b.name
    return problems


def io_board_ids(config: RobotConfig, data: Mapping) -> List[Problem]:
    problems = []
    seen = {}
    for board in config.io:
        if board.id in seen:
            problems.append(Problem(f"io.{board.name}.id", board.id, "IO board id also used by " + seen[board.id]))
        seen.setdefault(board.id, board.name)
    return problems


def pipe_ends_differ(config: RobotConfig, data: Mapping) -> List[Problem]:
    return [
        Problem(
            f"pipes.{pipe.name}",
            {"x1": pipe.x1, "y1": pipe.y1, "x2": pipe.x2, "y2": pipe.y2},
            "the two ends must differ",
        )
        for pipe in config.pipes
        if pipe.length < SAME_SPOT_DISTANCE
    ]


def frame_part_dimensions(config: RobotConfig, data: Mapping) -> List[Problem]:
    """A frame part gives the dimensions of its shape, and only those."""
    problems = []
    raw_parts = data.get("frame_parts") if isinstance(data.get("frame_parts"), Mapping) else {}
    for part in config.frame_parts:
        raw = raw_parts.get(part.name, {})
        needed = FRAME_PART_DIMENSIONS[part.shape]
        for dim in needed:
            if dim not in raw:
                problems.append(
                    Problem(
                        f"frame_parts.{part.name}.{dim}", MISSING, "a {} needs {}".format(part.shape, ", ".join(needed))
                    )
                )
        for dim in ALL_DIMENSIONS:
            if dim in raw and dim not in needed:
                problems.append(
                    Problem(
                        f"frame_parts.{part.name}.{dim}",
                        raw[dim],
                        "a {} has only {}".format(part.shape, ", ".join(needed)),
                    )
                )
    return problems


def steering_offsets(config: RobotConfig, data: Mapping) -> List[Problem]:
    """A drive that does not steer (type 1) has no steering to be homed off: its offset is 0."""
    return [
        Problem(f"motor_drives.{d.name}.steering_offset", d.steering_offset, "must be 0: this drive does not steer")
        for d in config.drives
        if not d.steerable and d.steering_offset != 0
    ]


def rail_wheels(config: RobotConfig, data: Mapping) -> List[Problem]:
    """A rail wheel is the smaller wheel of its drive's double wheel, its flanges clear of the floor
    while the tyre rolls on it, and it sits beside the tyre, not in it; a drive without one has no
    rail_offset.

    r_wheel is the radius base_driver calculates with: the tyre's in the file, the rail wheel's
    while the robot rides its rails (set_drive_params sets it to rail_r_wheel then, and every change
    is validated as a file is), so a drive whose r_wheel equals its rail_r_wheel is in that state,
    not a drive whose tyre is too small.
    """
    problems = []
    for d in config.drives:
        path = f"motor_drives.{d.name}."
        if not d.has_rail_wheel:
            if d.rail_offset != 0:
                problems.append(
                    Problem(
                        path + "rail_offset", d.rail_offset, "must be 0: this drive has no rail wheel (rail_r_wheel 0)"
                    )
                )
            continue
        if d.r_wheel != d.rail_r_wheel and d.rail_flange_radius >= d.r_wheel:
            problems.append(
                Problem(
                    path + "rail_r_wheel",
                    d.rail_r_wheel,
                    f"must be < r_wheel - {RAIL_FLANGE_DEPTH:g} = {d.r_wheel - RAIL_FLANGE_DEPTH:g} m: the tyre is "
                    f"the larger wheel, and the rail wheel's flanges ({RAIL_FLANGE_DEPTH:g} m deeper) clear the floor "
                    "while it rolls on it (equal to r_wheel only while riding the rails, set at run time)",
                )
            )
        if abs(d.rail_offset) < d.rail_clearance_offset:
            problems.append(
                Problem(
                    path + "rail_offset",
                    d.rail_offset,
                    f"must be at least {d.rail_clearance_offset:g} m either way: the rail wheel and its flanges "
                    f"beside the tyre (half its width, {d.w_wheel / 2.0:g} m, and the rail wheel's half span over "
                    f"its flanges, {d.rail_half_span:g} m), not in it",
                )
            )
    return problems


def wheel_layout(config: RobotConfig, data: Mapping) -> List[Problem]:
    """The layout rules every calculator shares (:mod:`thorvald_model.layout`); the calculator's own
    are its to declare and check (thorvald_base's BaseCalculator.layout_rules)."""
    return shared_layout_problems(config.drives, config.passive_wheels)


RULES: List[Rule] = [
    motor_controllers,
    wheel_spots,
    beams_join_drives,
    suspensions_carry_drives,
    battery_ids,
    io_board_ids,
    pipe_ends_differ,
    frame_part_dimensions,
    steering_offsets,
    rail_wheels,
    wheel_layout,
]


def cross_field_problems(config: RobotConfig, data: Mapping) -> List[Problem]:
    """Every rule's problems, in :data:`RULES` order; only "at least one driven wheel" without drives."""
    if not config.drives:
        raw = data.get("motor_drives")
        if not raw or not isinstance(raw, Mapping):  # a broken drive entry has its own problem already
            return [Problem("motor_drives", MISSING, "at least one driven wheel is needed")]
        return []
    problems: List[Problem] = []
    for rule in RULES:
        problems.extend(rule(config, data))
    return problems


def _turns(wheel) -> bool:
    """A steered drive or a caster sweeps a circle about its vertical axis."""
    return wheel.steerable if isinstance(wheel, Drive) else not wheel.fixed


def _reach(wheel) -> float:
    """How far a wheel's footprint reaches from its x, y, seen from above, as it turns [m].

    A wheel of radius r and width w is a 2r x w rectangle from above; turning about its centre it
    sweeps a circle of radius hypot(r, w/2); a caster's wheel centre trails caster_offset behind. A
    rail wheel beside the tyre is a 2 r_f x (its span) rectangle reaching |rail_offset| + its half
    span along the axle (r_f its flanges' radius): it sweeps hypot(r_f, that), if that is further.
    """
    reach = math.hypot(wheel.r_wheel, wheel.w_wheel / 2.0)
    if isinstance(wheel, Drive) and wheel.has_rail_wheel:
        reach = max(reach, math.hypot(wheel.rail_flange_radius, abs(wheel.rail_offset) + wheel.rail_half_span))
    if isinstance(wheel, PassiveWheel) and not wheel.fixed:
        reach += wheel.caster_offset
    return reach
