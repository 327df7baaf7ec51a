"""turning: the tightest turn the robot's calculator allows, both ways, at 2 km/h: ISO 789-3's
turning diameter and clearance diameter.

The tightest turn: every wheel rolls about the robot's centre of rotation (its instantaneous centre),
so the turn is tightest when that centre is as close to the robot as the wheels allow.

- A robot whose wheels all steer (or swivel) may turn about any point: it spins on the spot, about
  base_link's origin.
- Wheels that cannot steer (type-1 drives, fixed passive wheels) confine the centre to their
  common axle line (:func:`thorvald_model.layout.axle_lines`): the centre is the point of that line
  nearest base_link's origin.
- Either way every steered wheel must stand at the angle the centre asks (across the line from the
  centre to its contact) within its steering limit ``str_lim`` (or the opposite angle, rolling
  backwards); where one cannot, the centre moves out along the line (or out along base_link's y
  axis, for a robot without an axle line) until every wheel can, in 5 mm steps.

The robot is commanded the twist of that turn, its outermost wheel contact at ``speed`` [m/s]
(2 km/h by default), for one full turn after its wheels have steered (``settle`` [s]), one way then
the other. From ground truth, every wheel contact and every outermost point of the robot (the
corners in plan of its links' bounding boxes) describes a circle about the turn's centre:

- ``turning_diameter_m`` (ISO 789-3): the diameter of the circle the outermost wheel's contact
  describes;
- ``clearance_diameter_m``: the diameter of the circle the robot's outermost point describes, the
  room it needs to turn without touching anything;

each the larger of the two ways. ``turn`` says which turn it was (``spin`` on the spot, or about
a point on the axle line).
"""

import math
from typing import Any, Dict, List, Mapping, Sequence, Tuple

from thorvald_model.layout import axle_lines
from thorvald_model.schema import Key, one_of

from ..errors import ScenarioError
from ..geometry import convex_hull
from ..metrics import turning_diameters
from .driving import SURFACE_RULE, SURFACES, flat_world, track_of
from .kind import SMALLER, WORDS, Metric, ScenarioKind

CENTRE_STEP = 0.005  # [m] the centre moves out in these steps until every steered wheel can stand
MAX_CENTRE = 50.0  # [m]: a robot that cannot turn tighter than this cannot turn

KEYS = (
    Key("speed", float, 2.0 / 3.6, check=lambda v: 0.05 <= v <= 3.0, rule="must be in [0.05, 3] [m/s]"),
    Key("surface", str, "tarmac", check=one_of(*SURFACES), rule=SURFACE_RULE),
    Key("settle", float, 3.0, check=lambda v: 0.0 <= v <= 30.0, rule="must be in [0, 30] [s]"),
)
METRICS = (
    Metric("turning_diameter_m", "m", SMALLER, "ISO 789-3: the outermost wheel contact's circle, the larger way"),
    Metric("clearance_diameter_m", "m", SMALLER, "the circle of the robot's outermost point, the larger way"),
    Metric("turn", "", WORDS, "the turn: spin on the spot, or about a point of the axle line"),
)


def turn_centre(drives: Sequence, passive_wheels: Sequence = ()) -> Tuple[Tuple[float, float], str]:
    """The tightest turn's centre in base_link [m] and what turn it is ("spin" or "about the axle line")."""
    lines = axle_lines(drives, passive_wheels)
    if lines:
        line = lines[0]
        # the foot of the perpendicular from the origin to the line through (x, y) along (dx, dy)
        s = -(line.x * line.dx + line.y * line.dy)
        base = (line.x + s * line.dx, line.y + s * line.dy)
        direction, turn = (line.dx, line.dy), "about the axle line"
    else:
        base, direction, turn = (0.0, 0.0), (0.0, 1.0), "spin"
    steps = int(MAX_CENTRE / CENTRE_STEP)
    for k in range(steps + 1):
        for sign in (1.0, -1.0) if k else (1.0,):
            c = (base[0] + sign * k * CENTRE_STEP * direction[0], base[1] + sign * k * CENTRE_STEP * direction[1])
            if _steerable(drives, c):
                return c, turn if k == 0 else turn + f", {k * CENTRE_STEP:.3f} m out (steering limits)"
    raise ScenarioError(f"no centre of rotation within {MAX_CENTRE} m suits every drive's steering limit")


def _steerable(drives: Sequence, centre: Tuple[float, float]) -> bool:
    for d in drives:
        if not d.steerable:
            continue
        rx, ry = d.x - centre[0], d.y - centre[1]
        if math.hypot(rx, ry) < 1e-9:
            continue  # on the centre: it turns on the spot, any angle
        # the wheel rolls across the line from the centre: along (-ry, rx) (or backwards)
        angle = math.atan2(rx, -ry)
        back = angle - math.copysign(math.pi, angle)
        if min(abs(angle), abs(back)) > d.str_lim + 1e-9:
            return False
    return True


def turn_twist(centre: Tuple[float, float], contacts: Sequence[Tuple[float, float]], speed: float, way: float):
    """The twist (vx, vy, wz) turning about centre with the furthest contact at speed [m/s]; way +1 left."""
    reach = max(math.hypot(x - centre[0], y - centre[1]) for x, y in contacts)
    wz = way * speed / reach
    # base_link's origin moves as wz x (origin - centre)
    return (wz * centre[1], -wz * centre[0], wz)


def procedure(lab, design, params: Mapping[str, Any]) -> Dict[str, Any]:
    config = design.config
    centre, turn = turn_centre(config.drives, config.passive_wheels)
    contacts = design.contacts
    result: Dict[str, Any] = {"turn": turn}
    ways: List[Dict[str, Any]] = []
    for way in (1.0, -1.0):
        twist = turn_twist(centre, [(x, y) for _, x, y in contacts], params["speed"], way)
        period = 2.0 * math.pi / abs(twist[2])
        with lab.session(flat_world(params["surface"]), label=f"turn {'left' if way > 0 else 'right'}") as session:
            session.run(params["settle"], lambda t, twist=twist: twist)
            start = len(session.track)
            session.run(params["settle"] + period, lambda t, twist=twist: twist)
            poses = session.track[start:]
            found = turning_diameters(track_of(poses), contacts, session.outline)
            session.outcome = "ok"
            session.marks = _marks(found, contacts, session.outline, poses[0].t)
        ways.append(
            {
                "way": "left" if way > 0 else "right",
                "turning_diameter_m": round(found.turning_diameter, 3),
                "clearance_diameter_m": round(found.clearance_diameter, 3),
            }
        )
    result["turning_diameter_m"] = max(w["turning_diameter_m"] for w in ways)
    result["clearance_diameter_m"] = max(w["clearance_diameter_m"] for w in ways)
    result["ways"] = ways
    return result


def _marks(found, contacts, outline, steady_from: float) -> Dict[str, Any]:
    """What the report draws of one turn: its centre in the world, the outermost wheel (its name and
    contact in base_link), the outermost point, both diameters, the robot's outline (its convex hull
    in base_link) and when the steady turn began [s]."""
    outer = next((x, y) for name, x, y in contacts if name == found.outer_wheel)
    return {
        "centre": [round(v, 4) for v in found.centre],
        "outer_wheel": [found.outer_wheel, *(round(v, 4) for v in outer)],
        "outer_point": [round(v, 4) for v in found.outer_point],
        "turning_diameter_m": round(found.turning_diameter, 3),
        "clearance_diameter_m": round(found.clearance_diameter, 3),
        "outline": [[round(x, 4), round(y, 4)] for x, y in convex_hull(outline)],
        "steady_from_s": round(steady_from, 3),
    }


TURNING = ScenarioKind(
    name="turning",
    what="ISO 789-3 turning and clearance diameters of the tightest turn, both ways, at 2 km/h",
    keys=KEYS,
    metrics=METRICS,
    procedure=procedure,
    cost=1.1,  # [s] the standard robot's run (ScenarioKind.cost)
)
