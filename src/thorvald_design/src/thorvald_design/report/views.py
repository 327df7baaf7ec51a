"""What the report's figures show, worked out before anything is drawn: a measured limit beside its
quasi-static prediction and what the page says when they disagree, a turn's ISO 789-3 circles, the
side view of a series of tries, the headland's turns.

Pure: results.json's values and the tracks files' contents in, numbers and sentences out (stdlib,
numpy, :mod:`thorvald_design.metrics` and the world's parser; no matplotlib, no pybullet), so that what
a plot carries is unit-tested without drawing it.

Which metrics have a prediction, in what unit, with what step and what else parts them, is each
scenario's declaration (:class:`thorvald_design.scenarios.kind.Prediction`), read from the registry
when the report is made: a scenario registered later is compared as the built-in ones are.

A series measures a limit in steps (ramps every ``step_deg``, pulls every ``step_n``): the value it
reports is the last try held, so a limit the prediction has right lies between it and the first try
that failed, at most a step above it. The page says a measured limit and its prediction disagree
where they are more than the study's step apart, and why: what the results carry of the simulated
robot (``as_simulated``: its centre of mass, measured in the simulator, should a fault of its loading
move it from the description's, and the predictions with it, standing and rolling) and what the
scenario's meaning says of the rest.
"""

import math
from dataclasses import dataclass
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

import numpy as np

from ..geometry import Point, convex_hull, in_world
from ..metrics import Track, body_point_path
from ..scenarios import SCENARIOS
from .table import columns


def _number(value: Any) -> Optional[float]:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    return float(value) if math.isfinite(value) else None


def _g(value: float, digits: int = 4) -> str:
    """A number as a reader wants it: no trailing zeros, at most ``digits`` significant ones."""
    return f"{value:.{digits}g}"


# ---- measured against predicted ----------------------------------------------------------------------
@dataclass(frozen=True)
class Pairing:
    """A measured metric and the quasi-static figure it is to agree with: its scenario's declaration
    (:class:`~thorvald_design.scenarios.kind.Metric` and its
    :class:`~thorvald_design.scenarios.kind.Prediction`) as the report reads it."""

    scenario: str
    measured: str  # the metric ("max_climb_deg")
    predicted: str  # its prediction's ("predicted_climb_deg")
    step: str  # the scenario's parameter that is the series' step ("step_deg")
    unit: str  # "deg", "N": the measured metric's
    tries: str = ""  # the key of the scenario's tries ("climbs": [value, outcome, ...] each)
    held: str = "held"  # what the measured value is, in a sentence: "climbed", "pulled"
    # what else parts them, from the metric's meaning (the scenario's docstring)
    rest: str = ""


def pairings() -> Tuple[Pairing, ...]:
    """Every measured metric with a prediction, of the scenarios registered now, in their order."""
    out = []
    for kind in SCENARIOS.values():
        for m in kind.metrics:
            p = m.prediction
            if p is not None:
                out.append(Pairing(kind.name, m.name, p.metric, p.step, m.unit, p.tries, p.held, p.rest))
    return tuple(out)


@dataclass(frozen=True)
class Comparison:
    """One measured column and its prediction's, for every candidate."""

    pairing: Pairing
    column: str  # "drawbar.max_pull_n.mud"
    predicted_column: str
    step: Optional[float]  # the study's step for the scenario (None: unknown)
    rows: Tuple["Compared", ...]

    @property
    def suffix(self) -> str:
        """ ".mud" of a surface's column, "" of the headline's."""
        return self.column[len(f"{self.pairing.scenario}.{self.pairing.measured}") :]


@dataclass(frozen=True)
class Compared:
    """One candidate's measured value (the last try held), its prediction and what explains a gap."""

    candidate: str
    measured: Any  # as results.json holds it: a number, or "n/a: why", "failed: why", None
    predicted: Any
    failed_at: Optional[float]  # the first try that failed (None: none did, or unknown)
    failed_how: str  # its outcome ("tipping")
    predicted_limited_by: str
    com_height: Optional[float]  # [m] the description's centre of mass above the ground
    simulated_com_height: Optional[float]  # [m] the simulated robot's
    with_com: Optional[float]  # the prediction with the simulated robot's centre of mass, standing
    with_com_and_rolling: Optional[float]  # ... rolling
    rolling_offset: Optional[float]  # [m] each wheel's load ahead of its contact, rolling

    @property
    def numbers(self) -> bool:
        return _number(self.measured) is not None and _number(self.predicted) is not None

    def gap(self) -> Optional[float]:
        """The prediction less the measured value (positive: the prediction is higher)."""
        return float(self.predicted) - float(self.measured) if self.numbers else None


def _tries_failed(entry: Mapping[str, Any], pairing: Pairing) -> Tuple[Optional[float], str]:
    """The first failed try of the scenario's series and how it failed, from its ``tries`` list."""
    tries = entry.get(pairing.tries) if pairing.tries else None
    if not isinstance(tries, list):
        return None, ""
    for one in tries:
        if not isinstance(one, list) or not one or _number(one[0]) is None:
            continue
        outcomes = [o[0] if isinstance(o, list) and o else o for o in one[1:]]
        failed = [str(o) for o in outcomes if isinstance(o, str) and o != "ok"]
        if failed:
            return float(one[0]), failed[0]
    return None, ""


def comparisons(results: Mapping[str, Any], study) -> List[Comparison]:
    """Every measured column of the study that has a quasi-static figure, with every candidate's values,
    in the table's order (a drawbar surface's columns too)."""
    known = columns(study)
    params = dict(study.scenarios)
    paired = {(p.scenario, p.measured): p for p in pairings()}
    out = []
    for column in known:
        scenario, metric = column.split(".", 1)
        name, dot, suffix = metric.partition(".")
        pairing = paired.get((scenario, name))
        predicted_column = f"{scenario}.{pairing.predicted}{dot}{suffix}" if pairing else ""
        if pairing is None or predicted_column not in known:
            continue
        if not dot and any(c.startswith(f"{scenario}.{name}.") for c in known):
            continue  # the headline is the first surface's, which has its own column
        step = _number(params.get(scenario, {}).get(pairing.step))
        rows = []
        for candidate, entry in results["candidates"].items():
            scenarios = entry.get("scenarios") or {}
            found = scenarios.get(scenario)
            values = found if isinstance(found, Mapping) else {}
            missing = found if isinstance(found, str) else None
            measured = values.get(f"{pairing.measured}{dot}{suffix}", missing)
            predicted = values.get(f"{pairing.predicted}{dot}{suffix}", missing)
            failed_at, how = _tries_failed(values, pairing)
            if failed_at is None and pairing.tries == "" and _number(measured) is not None and step:
                limited = str(values.get(f"limited_by{dot}{suffix}", ""))
                if limited and not limited.startswith("none"):  # a pull series stops at the first it lost
                    failed_at, how = float(measured) + step, limited
            simulated = values.get("as_simulated") if isinstance(values.get("as_simulated"), Mapping) else {}
            standing = simulated.get("with_com") if isinstance(simulated.get("with_com"), Mapping) else {}
            rolling = simulated.get("with_com_and_rolling")
            rolling = rolling if isinstance(rolling, Mapping) else {}
            key = f"{pairing.predicted}{dot}{suffix}"
            rows.append(
                Compared(
                    candidate,
                    measured,
                    predicted,
                    failed_at,
                    how,
                    str(values.get(f"predicted_limited_by{dot}{suffix}", "")),
                    _number(simulated.get("com_height_m")),
                    _number(simulated.get("simulated_com_height_m")),
                    _number(standing.get(key)),
                    _number(rolling.get(key)),
                    _number(rolling.get(f"rolling_offset_m{dot}{suffix}")),
                )
            )
        out.append(Comparison(pairing, column, predicted_column, step, tuple(rows)))
    return out


def disagrees(comparison: Comparison, row: Compared) -> bool:
    """Whether the measured value and its prediction are more than the study's step apart."""
    gap = row.gap()
    return gap is not None and comparison.step is not None and abs(gap) > comparison.step + 1e-9


def _value(value: float, unit: str) -> str:
    return f"{_g(value)} {unit}"


def disagreement(comparison: Comparison, row: Compared) -> str:
    """What the page says of a candidate whose measured value and prediction are more than the step
    apart ("" where they are not): both, the gap, and why, from what the results carry."""
    if not disagrees(comparison, row):
        return ""
    p, unit = comparison.pairing, comparison.pairing.unit
    measured, predicted, step = float(row.measured), float(row.predicted), float(comparison.step)
    gap = predicted - measured
    failed = f" (the {_value(row.failed_at, unit)} try: {row.failed_how})" if row.failed_at is not None else ""
    limited = f" ({row.predicted_limited_by})" if row.predicted_limited_by else ""
    text = (
        f"{row.candidate}: {p.held} {_value(measured, unit)}{failed}, predicted {_value(predicted, unit)}{limited}: "
        f"{_g(abs(gap), 3)} {unit} apart, more than the study's step of {_value(step, unit)}"
        + (" (the simulated robot did better than the model allows)." if gap < 0 else ".")
    )
    # a cause is named where it moves the prediction by a fifth of a step or more
    matters = 0.2 * step
    reasons = []
    standing = predicted
    if row.com_height is not None and row.simulated_com_height is not None and row.with_com is not None:
        dz = row.simulated_com_height - row.com_height
        if abs(dz) >= 0.005 and abs(row.with_com - predicted) >= matters:
            reasons.append(
                f"the simulated robot's centre of mass is {row.simulated_com_height:.3f} m above the ground, "
                f"{abs(dz) * 100:.1f} cm {'above' if dz > 0 else 'below'} its description's {row.com_height:.3f} m "
                f"(the simulator holds a link's mass elsewhere than its description does): with it the prediction "
                f"is {_value(row.with_com, unit)}"
            )
        standing = row.with_com
    rolling = row.with_com_and_rolling
    if rolling is not None and row.rolling_offset and abs(rolling - standing) >= matters:
        reasons.append(
            f"{'and ' if reasons else ''}rolling, each wheel's load acts {row.rolling_offset * 1000:.0f} mm ahead "
            f"of its contact (the rolling resistance's moment, which the prediction leaves out): "
            f"{_value(rolling, unit)}"
        )
    explained = rolling if rolling is not None else row.with_com
    top = row.failed_at if row.failed_at is not None else measured + step
    if reasons and explained is not None and measured - 1e-9 <= explained <= top + 1e-9:
        text += " Why: " + "; ".join(reasons) + ", between the last try held and the first that failed."
    elif reasons and explained is not None:
        apart = f"{_g(abs(explained - measured), 3)} {unit}"
        text += " Why: " + "; ".join(reasons) + f", still {apart} from what was measured."
        text += f" The rest is the simulation's: {p.rest}." if p.rest else ""
    elif p.rest:
        text += f" Why: {p.rest}."
        if explained is not None:  # what the results know moves it too little to name
            text += f" (The robot as simulated, its centre of mass and rolling resistance: {_value(explained, unit)}.)"
    return text


# ---- a turn's circles --------------------------------------------------------------------------------
def circle(centre: Point, diameter: float, n: int = 181) -> Tuple[np.ndarray, np.ndarray]:
    """n points of the circle of a diameter [m] about centre, the first repeated at the end."""
    a = np.linspace(0.0, 2.0 * math.pi, n)
    return centre[0] + 0.5 * diameter * np.cos(a), centre[1] + 0.5 * diameter * np.sin(a)


@dataclass(frozen=True)
class TurnView:
    """What a turning plot draws of one turn (ISO 789-3): its centre, the outermost wheel's path and its
    circle (the turning diameter), the circle of the robot's outermost point (the clearance diameter),
    and the robot's outline where the steady turn began."""

    label: str
    centre: Point
    turning_diameter: float  # [m]
    clearance_diameter: float  # [m]
    outer_wheel: str
    wheel_path: Tuple[np.ndarray, np.ndarray]  # (X, Y) [m] of the outermost wheel's contact
    outline: Tuple[Point, ...]  # the robot's convex hull in the world at the steady turn's start
    outer_point: Point  # in the world, at the same pose
    outer_wheel_at: Point  # the outermost wheel's contact in the world, at the same pose


def _track(drive) -> Track:
    n = len(drive.x)
    t = drive.t if len(drive.t) == n else tuple(0.1 * k for k in range(n))
    return Track(np.array(t, float), np.array(drive.x, float), np.array(drive.y, float), np.array(drive.yaw, float))


def turn_view(drive) -> Optional[TurnView]:
    """The turn of a drive whose marks are a turning scenario's (``centre``, ``outer_wheel``, both
    diameters, ``outline``); None for any other drive, or one without headings."""
    marks = drive.marks
    centre = marks.get("centre")
    wheel = marks.get("outer_wheel")
    if not (isinstance(centre, list) and isinstance(wheel, list) and len(wheel) == 3 and drive.yaw and drive.x):
        return None
    turning, clearance = _number(marks.get("turning_diameter_m")), _number(marks.get("clearance_diameter_m"))
    if turning is None or clearance is None:
        return None
    track = _track(drive)
    path = body_point_path(track, float(wheel[1]), float(wheel[2]))
    start = _number(marks.get("steady_from_s"))
    k = int(np.searchsorted(track.t, start)) if start is not None else 0
    k = min(k, len(track) - 1)
    hull = convex_hull([tuple(p) for p in marks.get("outline") or []])
    outer = marks.get("outer_point") or wheel[1:]
    pose = (float(track.x[k]), float(track.y[k]), float(track.yaw[k]))
    return TurnView(
        drive.label,
        (float(centre[0]), float(centre[1])),
        turning,
        clearance,
        str(wheel[0]),
        path,
        in_world(*pose, hull),
        in_world(*pose, [(float(outer[0]), float(outer[1]))])[0],
        in_world(*pose, [(float(wheel[1]), float(wheel[2]))])[0],
    )


# ---- the side view of a series ------------------------------------------------------------------------
@dataclass(frozen=True)
class SideTry:
    """One try of a series seen from the side: the ground of its world along the section and the robot's
    path over it (base_link), how far it got and how it ended."""

    series: str  # "climb", "descent", "up", "left side uphill", ...
    value: float  # the try's angle [deg] or height [m]
    unit: str
    label: str
    outcome: str
    ground: Tuple[np.ndarray, np.ndarray]  # (s, z) [m] of the ground's surface along the section
    path: Tuple[np.ndarray, np.ndarray]  # (s, z) [m] of base_link
    reached: float  # [m] the furthest s base_link reached (along) or the distance it covered (across)
    section: str  # "along" (the drive's direction) or "across" (up the hill's face, the drive along it)

    @property
    def ok(self) -> bool:
        return self.outcome == "ok"


def section_direction(world, drive, section: str) -> Point:
    """The unit vector in plan the side view looks across: across a hill's face (up it) for a drive
    along its contour, else the drive's direction at its start."""
    if section == "across" and world is not None and world.slopes:
        yaw = world.slopes[0].yaw
        return (math.cos(yaw), math.sin(yaw))
    yaw = drive.yaw[0] if drive.yaw else 0.0
    return (math.cos(yaw), math.sin(yaw))


def ground_height(world, px: float, py: float) -> float:
    """[m] of the ground's surface at (px, py): the world's ground (hills, patches, a height field) or
    the top of an upright box standing there (a step, a platform)."""
    z = world.ground_height(px, py)
    for ob in world.objects:
        if ob.shape != "box" or ob.roll or ob.pitch:
            continue
        c, s = math.cos(ob.yaw), math.sin(ob.yaw)
        u, v = c * (px - ob.x) + s * (py - ob.y), -s * (px - ob.x) + c * (py - ob.y)
        if abs(u) <= ob.size_x / 2 and abs(v) <= ob.size_y / 2:
            z = max(z, ob.z + ob.size_z / 2)
    return z


def side_try(drive, world, samples: int = 1201, margin: float = 1.0) -> Optional[SideTry]:
    """The side view of a drive whose marks say which try of a series it was (``series``, ``value``,
    ``section``), over its world (parsed); None for any other drive. The section is the vertical
    plane through the drive's start along :func:`section_direction`; s is the world's position along
    it (0 where it passes the world's origin: a hill's foot, a step's edge, in the scenarios'
    worlds). Without recorded heights (an older tracks file) the path lies on the ground."""
    marks = drive.marks
    value = _number(marks.get("value"))
    if not marks.get("series") or value is None or not drive.x:
        return None
    section = str(marks.get("section") or "along")
    ux, uy = section_direction(world, drive, section)
    xs, ys = np.array(drive.x, float), np.array(drive.y, float)
    s = xs * ux + ys * uy
    across = -xs * uy + ys * ux  # the section's plane passes through the drive's start
    offset = float(across[0])
    lo, hi = float(np.min(s)) - margin, float(np.max(s)) + margin
    if world is not None:
        for slope in world.slopes:  # the whole hill in view; across one, its face from the foot
            middle = slope.x * ux + slope.y * uy
            half = slope.footprint_length / 2.0
            lo = min(lo, middle - half - margin)
            hi = max(hi, middle + half + margin) if section == "along" else hi
    grid = np.linspace(lo, hi, samples)
    if world is not None:
        heights = np.array([ground_height(world, g * ux - offset * uy, g * uy + offset * ux) for g in grid])
    else:
        heights = np.zeros_like(grid)
    if len(drive.z) == len(drive.x):
        z = np.array(drive.z, float)
    else:
        z = np.interp(s, grid, heights)
    if section == "across":  # how far along the contour: the distance covered in plan
        steps = np.hypot(np.diff(xs), np.diff(ys))
        reached = float(np.sum(steps))
    else:
        reached = float(np.max(s))
    return SideTry(
        str(marks["series"]), value, str(marks.get("unit") or ""), drive.label, drive.outcome,
        (grid, heights), (s, z), reached, section,
    )  # fmt: skip


def side_series(tries: Sequence[SideTry]) -> List[Tuple[str, List[SideTry]]]:
    """The tries by series, in the order each series first appears, each by its value."""
    out: Dict[str, List[SideTry]] = {}
    for one in tries:
        out.setdefault(one.series, []).append(one)
    return [(name, sorted(found, key=lambda t: t.value)) for name, found in out.items()]


def try_text(one: SideTry) -> str:
    """What a side view writes beside a try: its value, how it ended, how far it got."""
    unit = "°" if one.unit == "deg" else f" {one.unit}"
    value = f"{one.value * 100:g} cm" if one.unit == "m" else f"{one.value:g}{unit}"
    if one.section == "across":
        return f"{value}: {one.outcome}, {one.reached:.1f} m along"
    if one.ok:
        return f"{value}: ok"
    return f"{value}: {one.outcome} at {one.reached:.2f} m"


# ---- headland turns ------------------------------------------------------------------------------------
TURN_ORDER = ("U", "omega", "crab", "spin")  # the headland scenario's turns: a colour each


@dataclass(frozen=True)
class TurnRow:
    """One turn a candidate tried in the headland, as results.json holds it."""

    candidate: str
    turn: str
    works: Optional[bool]
    headland_m: Optional[float]
    plants_touched: Optional[int]
    time_s: Optional[float]
    note: str  # why it was not tried ("n/a: ..."), or the scenario's failure


def headland_rows(results: Mapping[str, Any]) -> List[TurnRow]:
    """Every candidate's headland turns (results' ``headland.turns``), in the candidates' and the turns'
    order; a candidate whose headland scenario failed: one row saying so."""
    rows = []
    for candidate, entry in results["candidates"].items():
        found = (entry.get("scenarios") or {}).get("headland")
        if isinstance(found, str):
            rows.append(TurnRow(candidate, "", None, None, None, None, found))
            continue
        if not isinstance(found, Mapping) or not isinstance(found.get("turns"), Mapping):
            continue
        for turn, figures in found["turns"].items():
            if not isinstance(figures, Mapping):
                rows.append(TurnRow(candidate, turn, None, None, None, None, str(figures)))
                continue
            touched = figures.get("plants_touched")
            rows.append(
                TurnRow(
                    candidate, turn, bool(figures.get("works")), _number(figures.get("headland_m")),
                    int(touched) if _number(touched) is not None else None, _number(figures.get("time_s")), "",
                )
            )  # fmt: skip
    return rows


def turn_colour_index(turn: str) -> int:
    """The headland plots' colour of a turn: its place among the scenario's turns (others after them)."""
    return TURN_ORDER.index(turn) if turn in TURN_ORDER else len(TURN_ORDER) + sum(map(ord, turn)) % 4


def turn_legend(marks: Mapping[str, Any]) -> str:
    """A headland turn's legend entry: the turn, whether it works, its headland, plants and time."""
    works = "works" if marks.get("works") else "fails"
    parts = [f"{marks.get('turn', '?')}: {works}"]
    if _number(marks.get("headland_m")) is not None:
        parts.append(f"headland {float(marks['headland_m']):.2f} m")
    if _number(marks.get("plants_touched")) is not None:
        n = int(marks["plants_touched"])
        parts.append(f"{n} plant{'' if n == 1 else 's'} touched")
    if _number(marks.get("time_s")) is not None:
        parts.append(f"{float(marks['time_s']):.0f} s")
    return ", ".join(parts)


__all__ = [
    "Compared",
    "Comparison",
    "Pairing",
    "SideTry",
    "TurnRow",
    "TurnView",
    "circle",
    "comparisons",
    "disagreement",
    "disagrees",
    "ground_height",
    "headland_rows",
    "pairings",
    "section_direction",
    "side_series",
    "side_try",
    "try_text",
    "turn_colour_index",
    "turn_legend",
    "turn_view",
]
