"""headland: leave a row, turn in the headland and enter the next (or the n-th) row, with each turn the
robot can make: how much headland it needs, and how many plants it runs over.

The field: rows of plants along +x ending at x = 0 (``row_spacing`` apart, plants ``plant_width``
wide every ``plant_spacing``, ``plant_height`` tall); the robot drives along row 0 (base_link over
it, as a Thorvald straddles a row) towards the row ends and must come back along row ``next``. The
plants are counted from the geometry (:func:`thorvald_sim.world.kinds.rows.plant_positions`), not put in
the physics: a leaf bends, it does not stop a robot. Each turn is driven by the robot's own
base_driver core:

- ``U``: out of the row until its rear wheels are clear of the last plants, a half circle of radius
  next x row_spacing / 2 about a point in the headland, and back in; only where the robot turns that
  tight (its tightest turn, :func:`thorvald_design.scenarios.turning.turn_centre`);
- ``omega``: the same with a bulb (:func:`thorvald_design.route.turn`) where it does not;
- ``crab``: out until clear, sideways (its wheels all steered along y) to the next row, and back in
  driving backwards; only a robot whose wheels all steer;
- ``spin``: out until its whole outline is clear of the rows, a quarter turn on the spot, across to
  the next row, another quarter turn, and back in; only a robot that spins.

Metrics, from ground truth: a turn works when the robot ends in the target row (within a quarter of
the row spacing of it, heading back along it); its headland is the furthest any point of the robot
(its outline: every link's bounding box in plan) went beyond the row ends; its plants touched are
the plants whose circle any wheel's footprint (its radius long, its width wide) overlapped at any
instant (:func:`thorvald_design.metrics.plants_touched`) and, for plants taller than the frame's
clearance, the frame's too. ``min_headland_m`` is the narrowest headland of the turns that work
touching the fewest plants, ``turn`` which turn gave it and ``plants_touched`` its count; every turn's
figures are under ``turns``.
"""

import math
from dataclasses import dataclass
from typing import Any, Dict, List, Mapping, Optional, Tuple

import numpy as np

from thorvald_model.errors import Problem
from thorvald_model.schema import Key, one_of
from thorvald_sim.world import parse_world
from thorvald_sim.world.kinds.rows import plant_positions

from ..metrics import plants_touched
from ..route import PurePursuit, line, path_of, turn
from .driving import SURFACE_RULE, SURFACES, TIPPED, feasible_twist, flat_world, track_of
from .gradeability import SETTLE
from .kind import SMALLER, WORDS, Metric, ScenarioKind, not_applicable
from .turning import turn_centre

TURNS = ("U", "omega", "crab", "spin")
CLEAR = 0.1  # [m] beyond the last plant before a turn starts
IN_ROW = 2.0  # [m] driven into the target row before the turn counts as done
MARGIN = 0.05  # [m] a turn's radius beyond the robot's tightest

KEYS = (
    Key("row_spacing", float, 0.75, check=lambda v: 0.2 <= v <= 10.0, rule="must be in [0.2, 10] [m]"),
    Key("next", int, 1, check=lambda v: 1 <= v <= 20, rule="must be in [1, 20] (1: the next row)"),
    Key("plant_spacing", float, 0.3, check=lambda v: 0.05 <= v <= 10.0, rule="must be in [0.05, 10] [m]"),
    Key("plant_width", float, 0.2, check=lambda v: 0.01 <= v <= 5.0, rule="must be in [0.01, 5] [m]"),
    Key("plant_height", float, 0.4, check=lambda v: 0.01 <= v <= 5.0, rule="must be in [0.01, 5] [m]"),
    Key("speed", float, 0.5, check=lambda v: 0.05 <= v <= 3.0, rule="must be in [0.05, 3] [m/s]"),
    Key("turns", str, ", ".join(TURNS)),
    Key("surface", str, "grass", check=one_of(*SURFACES), rule=SURFACE_RULE),
)
METRICS = (
    Metric("min_headland_m", "m", SMALLER, "the narrowest headland of the turns that work, touching the fewest plants"),
    Metric("turn", "", WORDS, "the turn that gave it: U, omega, crab or spin"),
    Metric("plants_touched", "plants", SMALLER, "the plants that turn's wheels (and frame, over tall plants) touched"),
)
RESULTS = tuple(m.name for m in METRICS)


def turn_names(text: str) -> Tuple[str, ...]:
    return tuple(t.strip() for t in text.split(",") if t.strip())


def check(values: Mapping[str, Any], path: str, problems: List[Problem]) -> None:
    names = turn_names(values["turns"])
    wrong = [t for t in names if t not in TURNS]
    if wrong or not names:
        rule = "must list turns of " + ", ".join(TURNS) + " separated by commas"
        problems.append(Problem(f"{path}.turns", values["turns"], rule))
    if values["plant_width"] >= values["row_spacing"]:
        rule = f"must be < row_spacing ({values['row_spacing']:g}): the rows would touch"
        problems.append(Problem(f"{path}.plant_width", values["plant_width"], rule))


def field(params: Mapping[str, Any], length: float) -> Dict:
    """The rows as a world's ``rows`` section: from row -1 (beside the robot's row) to row next + 1,
    ``length`` [m] long, ending at x = 0."""
    spacing = params["row_spacing"]
    return {
        "row0": {
            "x": -length, "y": -spacing, "count": params["next"] + 3, "spacing": spacing, "length": length,
            "plant_spacing": params["plant_spacing"], "plant_radius": params["plant_width"] / 2.0,
            "plant_height": params["plant_height"],
        }
    }  # fmt: skip


@dataclass(frozen=True)
class Headland:
    """What every turn of one candidate shares."""

    params: Mapping[str, Any]
    shown: Mapping  # the world the report draws: the ground and the rows
    plants: np.ndarray  # (x, y) [m] of every plant
    centre: Tuple[float, float]  # the robot's tightest turn's centre in base_link
    target: float  # [m] the target row's y
    length: float  # [m] of the rows

    @property
    def radius(self) -> float:
        """[m] of base_link's circle in the robot's tightest turn, with a margin."""
        return math.hypot(*self.centre) + MARGIN


def procedure(lab, design, params: Mapping[str, Any]) -> Dict[str, Any]:
    config = design.config
    length = design.length + 4.0
    shown = {**flat_world(params["surface"]), "rows": field(params, length)}
    rows = parse_world(shown, source="<headland>").rows[0]
    plants = np.array([p for row in plant_positions(rows) for p in row])
    centre, _ = turn_centre(config.drives, config.passive_wheels)
    h = Headland(params, shown, plants, centre, params["next"] * params["row_spacing"], length)
    results: Dict[str, Any] = {}
    for name in turn_names(params["turns"]):
        why = _cannot(name, design, h)
        if why:
            results[name] = not_applicable(why)
            continue
        results[name] = _drive(lab, design, h, name)
    working = {n: r for n, r in results.items() if isinstance(r, dict) and r["works"]}
    out: Dict[str, Any] = {"turns": results}
    if not working:
        out.update({k: not_applicable("no turn worked") for k in RESULTS})
        return out
    best = min(working, key=lambda n: (working[n]["plants_touched"], working[n]["headland_m"]))
    out.update(min_headland_m=working[best]["headland_m"], turn=best, plants_touched=working[best]["plants_touched"])
    return out


def _cannot(name: str, design, h: Headland) -> Optional[str]:
    config = design.config
    if name == "U" and h.radius > h.target / 2.0:
        return f"its tightest turn ({h.radius:.2f} m about base_link) is wider than half the rows' distance"
    if name == "omega" and h.radius <= h.target / 2.0:
        return "a U turn fits: an omega turn would only be longer"
    if name == "crab" and (config.passive_wheels or not all(d.steerable for d in config.drives)):
        return "not every wheel steers"
    if name == "spin" and math.hypot(*h.centre) > 1e-9:
        return "it cannot turn on the spot"
    return None


def _drive(lab, design, h: Headland, name: str) -> Dict[str, Any]:
    params, target, speed = h.params, h.target, h.params["speed"]
    out_x = design.rear + CLEAR + params["plant_width"] / 2.0  # base_link here: the rear wheels clear the rows
    start_x = -h.length + design.rear + 0.5
    label = f"{name} turn"
    with lab.session(flat_world(params["surface"]), x=start_x, label=label) as session:
        session.shown = h.shown
        session.run(SETTLE, lambda t: (0.0, 0.0, 0.0))
        first = len(session.track)
        if name in ("U", "omega"):
            radius = max(h.radius, target / 2.0)
            points = line((start_x, 0.0), (out_x, 0.0)) + turn((out_x, 0.0), 0.0, target, radius)[1:]
            points += line((out_x, target), (-IN_ROW - 1.0, target))[1:]
            pursuit = PurePursuit(path_of(points), lookahead=max(0.4, min(1.0, radius)), speed=speed)

            def command(t: float):
                q = session.track[-1]
                vx, wz = pursuit.command(q.x, q.y, q.yaw)
                return feasible_twist(design.config, vx, wz)

            limit = session.time + 2.0 * pursuit.path.length / speed + 20.0
            session.run(limit, command, lambda s: _tipped(s) or (s.track[-1].x < -IN_ROW and pursuit.done()))
        else:
            _phases(session, name, speed, out_x, target)
        result, touched = _measure(session.track[first:], session.outline, design, h, name)
        session.outcome = "ok" if result["works"] else "failed"
        # what the report draws: the turn's figures and the plants it touched, where they stand
        where = [[round(float(v), 4) for v in h.plants[i]] for i in touched]
        session.marks = {"turn": name, **result, "touched": where}
    return result


def _phases(session, name: str, speed: float, out_x: float, target: float) -> None:
    """crab and spin: phases, each until its goal (or its time) is reached, the heading held on the
    straight ones and each spin slowing into its heading (P control on the yaw error)."""

    def hold(heading: float, vx: float, vy: float):
        def command(t: float):
            return (vx, vy, _rate(heading - session.track[-1].yaw, 0.5))

        return command

    def until(command, done, seconds: float) -> None:
        session.run(session.time + seconds, command, lambda s: _tipped(s) or done(s.track[-1]))

    if name == "spin":
        reach = max(math.hypot(x, y) for x, y in session.outline)
        out_x = max(out_x, reach + CLEAR)
    until(hold(0.0, speed, 0.0), lambda q: q.x >= out_x, 3.0 * (out_x + 10.0) / speed)
    if name == "crab":
        until(hold(0.0, 0.0, speed), lambda q: q.y >= target, 3.0 * target / speed + 5.0)
        until(hold(0.0, -speed, 0.0), lambda q: q.x <= -IN_ROW, 3.0 * (out_x + IN_ROW) / speed + 5.0)
        return
    rate = speed / max(0.3, *(math.hypot(x, y) for x, y in session.outline))
    for heading, leg in ((math.pi / 2.0, "across"), (math.pi, "in")):
        spin = lambda t, heading=heading: (0.0, 0.0, _rate(heading - session.track[-1].yaw, rate))  # noqa: E731
        until(spin, lambda q, heading=heading: abs(_wrap(heading - q.yaw)) < HEADING_DONE, 3.0 * math.pi / rate + 5.0)
        if leg == "across":
            until(hold(heading, speed, 0.0), lambda q: q.y >= target, 3.0 * target / speed + 5.0)
    until(hold(math.pi, speed, 0.0), lambda q: q.x <= -IN_ROW, 3.0 * (out_x + IN_ROW) / speed + 5.0)


HEADING_DONE = 0.01  # [rad]: a spin is done this close to its heading
HEADING_GAIN = 2.0  # [1/s] turn rate per radian of heading error


def _wrap(angle: float) -> float:
    return math.atan2(math.sin(angle), math.cos(angle))


def _rate(error: float, limit: float) -> float:
    return max(-limit, min(limit, HEADING_GAIN * _wrap(error)))


def _tipped(session) -> bool:
    q = session.track[-1]
    return max(abs(q.roll), abs(q.pitch)) > TIPPED


def _measure(poses, outline, design, h: Headland, name: str) -> Tuple[Dict[str, Any], Tuple[int, ...]]:
    """The turn's figures, and the indices (into ``h.plants``) of the plants it touched."""
    params, target = h.params, h.target
    track = track_of(poses)
    end = poses[-1]
    backwards = name == "crab"  # it comes back driving backwards, heading as it left
    heading_ok = abs(math.cos(end.yaw)) > 0.9 and (math.cos(end.yaw) > 0) == backwards
    works = abs(end.y - target) < params["row_spacing"] / 4.0 and end.x <= -IN_ROW + 0.2 and heading_ok
    c, s = np.cos(track.yaw), np.sin(track.yaw)
    reach = max(float(np.max(track.x + c * px - s * py)) for px, py in outline)
    footprints = _footprints(design, params, outline)
    touched = plants_touched(track, footprints, h.plants, params["plant_width"] / 2.0)
    figures = {
        "works": bool(works),
        "headland_m": round(max(reach, 0.0), 3),
        "plants_touched": int(touched.count),
        "time_s": round(poses[-1].t - poses[0].t, 2),
    }
    return figures, touched.indices


def _footprints(design, params, outline) -> List[Tuple[float, float, float, float]]:
    """(cx, cy, length, width) in base_link of what touches plants: every wheel; the whole outline's
    box too when the plants stand taller than the frame's clearance (:attr:`Design.clearance`)."""
    config = design.config
    wheels = [(d.x, d.y, 2.0 * d.r_wheel, d.w_wheel) for d in config.drives]
    wheels += [(w.x, w.y, 2.0 * w.r_wheel, w.w_wheel) for w in config.passive_wheels]
    if params["plant_height"] > design.clearance:
        xs, ys = [x for x, _ in outline], [y for _, y in outline]
        wheels.append(((max(xs) + min(xs)) / 2, (max(ys) + min(ys)) / 2, max(xs) - min(xs), max(ys) - min(ys)))
    return wheels


HEADLAND = ScenarioKind(
    name="headland",
    what="out of a row, a turn and into the next: the narrowest headland that works, the plants touched",
    keys=KEYS,
    metrics=METRICS,
    procedure=procedure,
    check=check,
    cost=1.7,  # [s] the standard robot's run (ScenarioKind.cost)
)
