"""The paper's odometry verification manoeuvre (section 3.3.2), as a plan of twists and a report.

The paper's six-wheeled robot drove for 77 s, translating in x and y and rotating about z, and
stopped roughly where it started: 80.2 m by ground truth, 81.0 m by odometry, 2.2 m apart at the
end. Our plan does the same on any example robot: about 80 m in 80 s at 1 m/s, ending at the start.

A robot whose wheels cannot all steer (a fixed axle: differential drive, one-wheel drive, 4WD2WS)
cannot translate sideways; it drives a stadium (straights and half circles about points of its
axle line) twice instead. Pure Python: the node publishes the twists and collects odometry.
"""

import math
from dataclasses import dataclass
from typing import List, Optional, Sequence, Tuple

from thorvald_model.config import RobotConfig
from thorvald_model.layout import common_axle

from .calibration.toe_balance import toe_legs
from .kinematics import Pose, Twist, integrate_se2

SPEED = 1.0  # [m/s] of base_link
PAUSE = 0.5  # [s] standing still between segments, as a driver would


@dataclass(frozen=True)
class Segment:
    twist: Twist
    duration: float  # [s]
    label: str


def plan_for(config: RobotConfig) -> Tuple[str, List[Segment]]:
    """(description, segments) of the manoeuvre this robot can drive."""
    axle, _ = common_axle(config.drives, config.passive_wheels)
    if axle is None:
        return "translation in x and y, and rotation about z", _omnidirectional()
    return "a stadium twice: straights and half circles about its axle line", _stadium(axle)


MANOEUVRES = ("verification", "calibration", "field", "balance", "straight", "turns", "heading", "paper")
ROWS, ROW_LENGTH, ROW_SPACING = 5, 15.0, 1.5  # the field route: every second row of 0.75 m rows
TURN_SIGNS = (1.0, 1.0, -1.0, -1.0, 1.0, 1.0, -1.0, -1.0)  # the turns manoeuvre's U turns: two loops each way
SIDE = 4.0  # [m] of the calibration drive's square (UMBmark's 4 m)
CORNER = 1.0  # [m] a fixed-axle robot's corner radius on the calibration drive (about a point of its axle line)
TURN_SHARE = 0.9  # of a wheel's speed limit: a fixed-axle robot's turns are slowed to keep within it
# the balancing drive (balance_wheels): straight legs back and forth, slowly (no wheel slides while the
# radii are still off), each measured after it settled, with a pause after it to change the radii in
BALANCE_SPEED = 0.2  # [m/s]
BALANCE_LEGS = 8
BALANCE_SETTLE = 3.0  # [s] from a leg's start: the robot at speed and the fight steady
BALANCE_PAUSE = 3.0  # [s]
BALANCE_LEG = "balance leg"  # the label every leg of the radii starts with
# legs of the radii again after the toe search: the first at the first legs' fit, the second a probe (the
# stiffness known from the first legs, which the scrub softened: about half the one without it), then at
# the fit of these legs, twice
BALANCE_AGAIN = 4
# the toe search's legs (thorvald_base.calibration.toe_balance), on a steered robot between the radii's
# legs: shorter, each measured after BALANCE_SETTLE, with a pause after it to change the offsets in
TOE_LEG = "toe leg"
TOE_LEG_TIME = 6.0  # [s]
# the straight drive (calibrate_odometry --fit scale): legs along the rolling direction at SPEED, as rows
# are driven, with standstills between them long enough to average ground truth's position over
STRAIGHT_PAUSE = 2.0  # [s]


def plan_named(name: str, config: RobotConfig, side: float = SIDE) -> Tuple[str, List[Segment]]:
    """(description, segments) of the manoeuvre ``name`` (MANOEUVRES) for this robot; ValueError for
    another name or a side that is not a positive length."""
    if name == "verification":
        return plan_for(config)
    if name == "field":
        return (
            f"a field route: {ROWS} rows of {ROW_LENGTH:g} m, {ROW_SPACING:g} m apart, joined by headland U turns",
            _field_route(config),
        )
    if name == "paper":
        return _paper(config)
    if name not in ("calibration", "balance", "straight", "turns", "heading"):
        raise ValueError(f"manoeuvre must be one of {', '.join(MANOEUVRES)}, not {name!r}")
    if not (side > 0.0 and math.isfinite(side)):
        raise ValueError(f"side must be a positive length [m], not {side!r}")
    if name == "balance":
        toe = toe_legs(config)
        again = (
            f", {toe} of {BALANCE_SPEED * TOE_LEG_TIME:g} m the steering offsets changed between them, "
            f"then {BALANCE_AGAIN} more of {side:g} m"
        )
        return (
            f"balancing the wheels: {BALANCE_LEGS} straight legs of {side:g} m back and forth at "
            f"{BALANCE_SPEED:g} m/s, the radii changed between them" + (again if toe else ""),
            _balance(config, side),
        )
    if name == "turns":
        return (
            f"turns: {len(TURN_SIGNS)} headland U turns of the field route's radius ({ROW_SPACING / 2:g} m), "
            f"twice left and twice right in turn, joined by {side:g} m rows",
            _turns(config, side),
        )
    if name == "heading":
        calibration, straight, turns = (plan_named(part, config, side) for part in ("calibration", "straight", "turns"))
        return (
            f"heading: every motion the robot makes, one after another: the {calibration[0]}; the {straight[0]}; "
            f"the {turns[0]}",
            calibration[1] + straight[1] + turns[1],
        )
    if name == "straight":
        return (
            f"straight legs: {side:g} m out, {2 * side:g} m back and forth three times, {side:g} m back to the start, "
            f"at {SPEED:g} m/s with {STRAIGHT_PAUSE:g} s stops between them",
            _straight(config, side),
        )
    axle, _ = common_axle(config.drives, config.passive_wheels)
    if axle is None:
        return (
            f"calibration: straight {side:g} m both ways, crab legs both ways, spins both ways, UMBmark "
            f"squares of {side:g} m both ways, circles both ways",
            _calibration_omnidirectional(side),
        )
    return (
        f"calibration: straight {side:g} m both ways, UMBmark squares of {side:g} m both ways with rounded "
        "corners about the axle line, circles both ways",
        _calibration_axle(axle, side, config.drives),
    )


def _calibration_omnidirectional(side: float) -> List[Segment]:
    """What a calibration drive must excite on a robot whose every wheel steers: vx alone both ways (the
    common scale), vy alone both ways (the common offset: crab legs), wz alone both ways (spins: the
    left-right and front-rear differences), and combined (UMBmark's squares both ways, whose errors
    in turning and in distance show apart, and circles both ways: translating while turning). Every
    part ends where it started, so the drive stays within a square of 2 side around the start."""
    t = side / SPEED
    spin = SPEED / 1.0  # [rad/s]: a quarter turn in pi/2 s
    quarter = (math.pi / 2.0) / spin
    circle = math.pi * side / SPEED  # a circle of diameter side
    w = 2.0 * math.pi / circle
    legs = [
        Segment(Twist(SPEED, 0.0, 0.0), t, f"forward {side:g} m"),
        Segment(Twist(-SPEED, 0.0, 0.0), t, f"backward {side:g} m"),
        Segment(Twist(0.0, SPEED, 0.0), t, f"crab left {side:g} m"),
        Segment(Twist(0.0, -SPEED, 0.0), t, f"crab right {side:g} m"),
        Segment(Twist(0.0, 0.0, spin), 4.0 * quarter, "spin left, a full turn"),
        Segment(Twist(0.0, 0.0, -spin), 4.0 * quarter, "spin right, a full turn"),
    ]
    for sign, way in ((1.0, "counter-clockwise"), (-1.0, "clockwise")):
        for corner in range(4):
            legs.append(Segment(Twist(SPEED, 0.0, 0.0), t, f"square {way}: side {corner + 1}"))
            legs.append(Segment(Twist(0.0, 0.0, sign * spin), quarter, f"square {way}: corner {corner + 1}"))
    legs += [
        Segment(Twist(SPEED, 0.0, w), circle, f"circle left, {side:g} m across"),
        Segment(Twist(SPEED, 0.0, -w), circle, f"circle right, {side:g} m across"),
    ]
    return _with_pauses(legs)


def _turn(cx: float, cy: float, sign: float, drives) -> Twist:
    """The twist turning about (cx, cy) in base_link (sign 1: left), base_link at SPEED, slowed so that
    no wheel goes faster than TURN_SHARE of its limit."""
    radius = math.hypot(cx, cy)
    w = sign * SPEED / radius
    fastest = max((abs(w) * math.hypot(d.x - cx, d.y - cy) / d.max_wheel_speed for d in drives), default=0.0)
    w /= max(1.0, fastest / TURN_SHARE)
    return Twist(w * cy, -w * cx, w)  # v = w z x (origin - centre)


def _calibration_axle(axle, side: float, drives) -> List[Segment]:
    """The same for a robot with a fixed axle, which cannot crab nor always spin: straight both ways
    along its rolling direction, UMBmark's squares both ways with corners turned about a point of
    its axle line CORNER to the side, and circles both ways about such points (a turn slowed where
    its outer wheel would pass TURN_SHARE of its speed limit)."""
    dx, dy = _leftwards(axle)
    nx, ny = dy, -dx
    straight, back = Twist(SPEED * nx, SPEED * ny, 0.0), Twist(-SPEED * nx, -SPEED * ny, 0.0)
    foot = -(axle.x * dx + axle.y * dy)  # from the axle point to the foot of base_link's perpendicular
    t = side / SPEED
    legs = [Segment(straight, t, f"straight {side:g} m"), Segment(back, t, f"back {side:g} m")]
    for sign, way in ((1.0, "counter-clockwise"), (-1.0, "clockwise")):
        turn = _turn(axle.x + (foot + sign * CORNER) * dx, axle.y + (foot + sign * CORNER) * dy, sign, drives)
        for corner in range(4):
            legs.append(Segment(straight, t, f"square {way}: side {corner + 1}"))
            legs.append(Segment(turn, (math.pi / 2.0) / abs(turn.wz), f"square {way}: corner {corner + 1}"))
    for sign, way in ((1.0, "left"), (-1.0, "right")):
        turn = _turn(axle.x + (foot + sign * side / 2.0) * dx, axle.y + (foot + sign * side / 2.0) * dy, sign, drives)
        legs.append(Segment(turn, 2.0 * math.pi / abs(turn.wz), f"circle {way}, {side:g} m across"))
    # no pauses, as on the stadium: a fixed-axle robot changes curvature by its wheels' speeds
    return [*legs, Segment(Twist(), PAUSE, "stop")]


def _rolling_direction(config: RobotConfig) -> Tuple[float, float]:
    """The unit direction in base_link along which every wheel rolls without steering: +x, or across a
    fixed axle (towards +x or, for an axle along x, towards -y)."""
    axle, _ = common_axle(config.drives, config.passive_wheels)
    if axle is None:
        return 1.0, 0.0
    dx, dy = _leftwards(axle)
    return dy, -dx


def _leftwards(axle) -> Tuple[float, float]:
    """The axle's unit direction (dx, dy) pointing to the robot's left (for an axle along x: to +x);
    the rolling direction is then (dy, -dx)."""
    dx, dy = axle.dx, axle.dy
    return (-dx, -dy) if dy < 0 or (dy == 0 and dx < 0) else (dx, dy)


def _balance(config: RobotConfig, side: float) -> List[Segment]:
    """Straight legs of side [m] along the rolling direction, alternately forwards and back, each
    followed by a pause (balance_wheels changes the radii there); on a robot with a toe to search,
    then that many shorter toe legs back and forth (the steering offsets changed in each pause), and
    BALANCE_AGAIN legs of the radii again. Each part is an even number of legs, so the drive stays on
    one line of side."""
    nx, ny = _rolling_direction(config)
    legs = []

    def leg(k: int, length: float, label: str, pause: str) -> None:
        sign = 1.0 if len(legs) % 4 == 0 else -1.0  # forwards first, then back, and so on (a leg and a pause)
        twist = Twist(sign * BALANCE_SPEED * nx, sign * BALANCE_SPEED * ny, 0.0)
        way = "forwards" if sign > 0 else "back"
        legs.append(Segment(twist, length / BALANCE_SPEED, f"{label} {k + 1}, {length:g} m {way}"))
        legs.append(Segment(Twist(), BALANCE_PAUSE, pause))

    for k in range(BALANCE_LEGS):
        leg(k, side, BALANCE_LEG, "pause: the radii for the next leg")
    toe = toe_legs(config)
    if toe:
        for k in range(toe):
            leg(k, BALANCE_SPEED * TOE_LEG_TIME, TOE_LEG, "pause: the steering offsets for the next leg")
        for k in range(BALANCE_AGAIN):
            leg(BALANCE_LEGS + k, side, BALANCE_LEG, "pause: the radii for the next leg")
    return legs


def _straight(config: RobotConfig, side: float) -> List[Segment]:
    """Legs along the rolling direction at SPEED, stopping STRAIGHT_PAUSE between them (the first
    one too, before it): side out, then 2 side back and forth three times, then side back, so the
    drive stays within side of the start along one line and ends there (8 side in all)."""
    nx, ny = _rolling_direction(config)
    lengths = [side, -2.0 * side, 2.0 * side, -2.0 * side, side]
    legs = [Segment(Twist(), STRAIGHT_PAUSE, "stop")]
    for k, length in enumerate(lengths):
        sign = 1.0 if length > 0 else -1.0
        twist = Twist(sign * SPEED * nx, sign * SPEED * ny, 0.0)
        way = "forwards" if sign > 0 else "back"
        legs.append(Segment(twist, abs(length) / SPEED, f"straight leg {k + 1}, {abs(length):g} m {way}"))
        legs.append(Segment(Twist(), STRAIGHT_PAUSE, "stop"))
    return legs


@dataclass(frozen=True)
class BalanceWindow:
    """A balancing leg's measured part: begin and end [s from the plan's start], its rim speed [m/s,
    negative backwards], and what the leg is for: "radii" or "toe"."""

    begin: float
    end: float
    speed: float
    kind: str


def balance_legs(plan: Sequence[Segment]) -> List[BalanceWindow]:
    """Each balancing leg's measured part, from BALANCE_SETTLE after its start to its end."""
    out, t = [], 0.0
    for seg in plan:
        kind = "radii" if seg.label.startswith(BALANCE_LEG) else "toe" if seg.label.startswith(TOE_LEG) else ""
        if kind:  # forwards first, then back, and so on
            speed = math.hypot(seg.twist.vx, seg.twist.vy) * (1.0 if len(out) % 2 == 0 else -1.0)
            out.append(BalanceWindow(t + BALANCE_SETTLE, t + seg.duration, speed, kind))
        t += seg.duration
    return out


def _turns(config: RobotConfig, side: float) -> List[Segment]:
    """The field route's headland U turns (the working radius, where a calibrated yaw-rate multiplier
    must hold), TURN_SIGNS in order, each between rows of side [m]: two left turns drive a loop back
    to the start, then two right ones the mirrored loop, so the drive stays within side by two row
    spacings; a last row ends it, side ahead of the start."""
    return _rows_and_turns(config, side, TURN_SIGNS)


def _field_route(config: RobotConfig) -> List[Segment]:
    """A drive unlike the calibration drive, about the paper's length: rows along the robot's rolling
    direction joined by half circles at the headland, alternately left and right, as a robot working
    every second row of a field drives them (a robot whose every wheel steers turns about a point
    half the spacing to the side; a fixed-axle robot about such a point of its axle line, slowed as
    its calibration drive's turns are)."""
    return _rows_and_turns(config, ROW_LENGTH, [1.0 if row % 2 == 0 else -1.0 for row in range(ROWS - 1)])


def _rows_and_turns(config: RobotConfig, length: float, signs: Sequence[float]) -> List[Segment]:
    """Rows of length [m] along the rolling direction, joined by headland U turns (sign 1: left) about
    a point ROW_SPACING / 2 to that side (of the axle line, for a fixed-axle robot), then a stop."""
    axle, _ = common_axle(config.drives, config.passive_wheels)
    if axle is None:
        dx, dy, ax, ay = 0.0, 1.0, 0.0, 0.0  # turn about (0, +-spacing/2), straight along +x
    else:
        (dx, dy), ax, ay = _leftwards(axle), axle.x, axle.y
    nx, ny = dy, -dx
    foot = -(ax * dx + ay * dy)
    straight = Twist(SPEED * nx, SPEED * ny, 0.0)
    legs = []
    for row in range(len(signs) + 1):
        legs.append(Segment(straight, length / SPEED, f"row {row + 1}, {length:g} m"))
        if row < len(signs):
            sign = signs[row]
            offset = foot + sign * ROW_SPACING / 2.0
            turn = _turn(ax + offset * dx, ay + offset * dy, sign, config.drives)
            legs.append(Segment(turn, math.pi / abs(turn.wz), f"headland U turn {'left' if sign > 0 else 'right'}"))
    return [*legs, Segment(Twist(), PAUSE, "stop")]


def _omnidirectional() -> List[Segment]:
    circle = 20.0  # [s]: a full circle of 20 m at 1 m/s
    w = 2.0 * math.pi / circle
    legs = [
        Segment(Twist(SPEED, 0.0, 0.0), 10.0, "forward 10 m"),
        Segment(Twist(0.0, SPEED, 0.0), 10.0, "left 10 m"),
        Segment(Twist(-SPEED, 0.0, 0.0), 10.0, "backward 10 m"),
        Segment(Twist(0.0, -SPEED, 0.0), 10.0, "right 10 m"),
        Segment(Twist(SPEED, 0.0, w), circle, "circle left, 20 m"),
        Segment(Twist(0.0, SPEED, -w), circle, "circle right driving sideways, 20 m"),
    ]
    return _with_pauses(legs)


def _paper(config: RobotConfig) -> Tuple[str, List[Segment]]:
    """A validation drive like the paper's (section 3.3.2: 80 m translating in x and y and rotating about
    z, ending where it started), with spins on the spot both ways between its legs: each leg starts from
    wheels steered for another motion, as a robot working among rows re-steers. A robot whose wheels
    cannot all steer cannot crab: it drives straight out and back with a half turn on the spot about its
    axle line at each end, twice, then the stadium once."""
    spin = SPEED / 1.0  # [rad/s], as the calibration drive's spins
    turn = 2.0 * math.pi / spin
    axle, _ = common_axle(config.drives, config.passive_wheels)
    if axle is None:
        circle = 20.0  # [s]: a circle of 20 m at 1 m/s
        w = 2.0 * math.pi / circle
        legs = [
            Segment(Twist(SPEED, 0.0, 0.0), 10.0, "forward 10 m"),
            Segment(Twist(0.0, 0.0, spin), turn, "spin left, a full turn"),
            Segment(Twist(0.0, SPEED, 0.0), 10.0, "crab left 10 m"),
            Segment(Twist(0.0, 0.0, -spin), turn, "spin right, a full turn"),
            Segment(Twist(-SPEED, 0.0, 0.0), 10.0, "backward 10 m"),
            Segment(Twist(0.0, 0.0, spin), turn / 2.0, "spin left, a half turn"),
            Segment(Twist(0.0, SPEED, 0.0), 10.0, "crab left 10 m"),
            Segment(Twist(0.0, 0.0, -spin), turn / 2.0, "spin right, a half turn"),
            Segment(Twist(SPEED, 0.0, w), circle, "circle left, 20 m"),
            Segment(Twist(0.0, SPEED, -w), circle, "circle right driving sideways, 20 m"),
        ]
        return (
            "paper-like: translation in x and y (crab legs), spins on the spot both ways between them, a circle "
            "and a circle crabbing: 80 m and three turns on the spot, ending at the start",
            _with_pauses(legs),
        )
    dx, dy = _leftwards(axle)
    nx, ny = dy, -dx
    foot = -(axle.x * dx + axle.y * dy)
    cx, cy = axle.x + foot * dx, axle.y + foot * dy  # the axle line's point nearest base_link: spun about
    fastest = max((spin * math.hypot(d.x - cx, d.y - cy) / d.max_wheel_speed for d in config.drives), default=0.0)
    w = spin / max(1.0, fastest / TURN_SHARE)
    legs = [
        Segment(Twist(SPEED * nx, SPEED * ny, 0.0), 10.0, "straight 10 m"),
        Segment(Twist(w * cy, -w * cx, w), math.pi / w, "spin left, a half turn"),
        Segment(Twist(SPEED * nx, SPEED * ny, 0.0), 10.0, "straight 10 m back"),
        Segment(Twist(-w * cy, w * cx, -w), math.pi / w, "spin right, a half turn"),
    ]
    stadium = _stadium(axle)
    return (
        "paper-like for a robot that cannot crab: straight 10 m out and back with a half turn on the spot at "
        "each end, twice, then a stadium once (straights and half circles about its axle line)",
        _with_pauses(legs + legs) + stadium[:4] + stadium[-1:],
    )


def _stadium(axle) -> List[Segment]:
    # Straight along the wheels' rolling direction n (perpendicular to the axle direction d); turn
    # about a centre of rotation on the axle line, 3 m to the left of the axle point.
    dx, dy = _leftwards(axle)
    nx, ny = dy, -dx
    straight = Twist(SPEED * nx, SPEED * ny, 0.0)
    t = -(axle.x * dx + axle.y * dy)  # foot of the perpendicular from base_link's origin
    cx, cy = axle.x + (t + 3.0) * dx, axle.y + (t + 3.0) * dy  # centre of rotation [m] in base_link
    radius = math.hypot(cx, cy)  # base_link's circle
    w = SPEED / radius
    # v = w z x (origin - centre) = w (cy, -cx)
    turn = Twist(w * cy, -w * cx, w)
    half = math.pi / w
    legs = []
    for _ in range(2):
        legs += [
            Segment(straight, 10.0, "straight 10 m"),
            Segment(turn, half, f"half circle, {math.pi * radius:.1f} m"),
            Segment(straight, 10.0, "straight 10 m"),
            Segment(turn, half, f"half circle, {math.pi * radius:.1f} m"),
        ]
    # No pauses: a robot that cannot steer all its wheels changes curvature only by changing wheel
    # speeds, and each wheel ramps on its own, so starting a turn from standstill would drive the
    # first metre straight. Flowing from straight to arc changes each wheel's speed by a few percent.
    return [*legs, Segment(Twist(), PAUSE, "stop")]


def _with_pauses(legs: Sequence[Segment]) -> List[Segment]:
    out = []
    for leg in legs:
        out += [leg, Segment(Twist(), PAUSE, "pause")]
    return out


def twist_at(plan: Sequence[Segment], t: float) -> Optional[Twist]:
    """The planned twist at time t [s] from the start; None after the end."""
    for seg in plan:
        if t < seg.duration:
            return seg.twist
        t -= seg.duration
    return None


def duration(plan: Sequence[Segment]) -> float:
    return sum(s.duration for s in plan)


def commanded_path(plan: Sequence[Segment], step: float = 0.01) -> Tuple[Pose, float]:
    """End pose and distance [m] of a robot that followed the plan exactly."""
    pose, dist = Pose(), 0.0
    for seg in plan:
        n = max(1, round(seg.duration / step))
        dt = seg.duration / n
        for _ in range(n):
            pose = integrate_se2(pose, seg.twist, dt)
        dist += math.hypot(seg.twist.vx, seg.twist.vy) * seg.duration
    return pose, dist


def path_length(points: Sequence[Tuple[float, float]]) -> float:
    return sum(math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(points, points[1:]))


def report(name: str, config: RobotConfig, description: str, plan, odom_points, *, sim_time: float, wall: float) -> str:
    end_cmd, dist_cmd = commanded_path(plan)
    dist_odom = path_length(odom_points)
    ex, ey = odom_points[-1] if odom_points else (math.nan, math.nan)
    diff = math.hypot(ex - end_cmd.x, ey - end_cmd.y)
    return "\n".join(
        [
            f"Verification drive of {name} ({len(config.drives)} drives, {config.base_calculator})",
            f"  manoeuvre               {description}",
            f"  time                    {sim_time:.1f} s simulated, {wall:.1f} s wall",
            f"  distance by command     {dist_cmd:7.2f} m",
            f"  distance by odometry    {dist_odom:7.2f} m",
            f"  end point by command    ({end_cmd.x:+.3f}, {end_cmd.y:+.3f}) m",
            f"  end point by odometry   ({ex:+.3f}, {ey:+.3f}) m",
            f"  end-point difference    {diff:7.3f} m",
            "  (the paper's six-wheeled robot on tarmac: 80.2 m by ground truth, 81.0 m by odometry, 2.2 m)",
        ]
    )
