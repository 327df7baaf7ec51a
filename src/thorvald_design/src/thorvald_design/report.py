"""A design study's report: ``DIR/report.html``, one page that opens offline and prints, and the plots
it shows in ``DIR/plots/``.

What is on the page: the study's description; the results table (a column a candidate, a row a
metric, as the terminal's table, with each candidate's status, the best value of a row in bold); a
picture of each candidate (``DIR/pictures/<safe name>.png``, when the runs made one); a bar chart of
each numeric metric across the candidates (a candidate without a value: a gap with its reason); for a
sweep, each numeric metric against the swept value; the Pareto front of two metrics when asked for;
each candidate's drives over a plan of the world they drove in (``DIR/tracks/<safe name>/<scenario>.json``,
when the runs wrote them); and the study file as written.

Why one page with everything in it (the plots as base64 data URIs, the CSS inline, no script but a
counter of loaded images): a study's results are passed around as a file and opened on a laptop on a
farm, so nothing it needs may be elsewhere; the same inputs give the same bytes (no dates, no
random ids), so a report is compared and kept like any other result.

Pure: what is plotted (:func:`metrics`, :func:`sweeps`, :func:`pareto_plane`: its front is
:func:`thorvald_design.optimise.pareto_front`, the package's one), the plan of a world
(:func:`world_map`) and the page (:func:`page_html`).
Writing: the plots (matplotlib's Agg canvas, no pyplot) and the page (:func:`write_report`).
"""

import base64
import html
import json
import math
import os
import re
import textwrap
from dataclasses import dataclass
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

import matplotlib
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Circle, Polygon

from thorvald_model.errors import ThorvaldModelError
from thorvald_sim.world import element_kinds, parse_world, plant_positions

from .optimise import pareto_front
from .report_table import _text, columns, rows
from .runs import safe_name
from .scenarios import SCENARIOS
from .study import Candidate, Study

REPORT = "report.html"
PLOTS = "plots"
PICTURES = "pictures"
TRACKS = "tracks"

# Whether more of a metric is better (+1) or less (-1): the table's bold, the Pareto front's directions
DIRECTIONS: Dict[str, int] = {
    "max_climb_deg": +1,
    "max_crest_deg": +1,
    "max_descent_deg": +1,
    "max_traverse_deg": +1,
    "static_overturning_deg": +1,
    "max_pull_n": +1,
    "max_step_m": +1,
    "max_step_down_m": +1,
    "range_km": +1,
    "end_soc": +1,  # the battery's state of charge left after the route
    "predicted_climb_deg": +1,
    "predicted_descent_deg": +1,
    "predicted_pull_n": +1,
    "turning_diameter_m": -1,
    "clearance_diameter_m": -1,
    "drift_per_m": -1,
    "min_headland_m": -1,
    "plants_touched": -1,
    "wh_per_km": -1,
    "wh_per_ha": -1,
    "peak_current_a": -1,
    "rms_current_a": -1,
    "odometry_error_pct": -1,
    "odometry_error_pct_without_switch": -1,
}
# The metrics that are words, not numbers: shown in the table, not plotted
TEXT_METRICS = ("surface", "limited_by", "predicted_limited_by", "turn")

DPI = 100
RC = {  # the plots' look, the same on every machine: matplotlib's own font, a fixed hash salt
    "font.family": "DejaVu Sans",
    "font.size": 9.0,
    "svg.hashsalt": "thorvald_design",
    "axes.grid": True,
    "grid.alpha": 0.3,
}
PNG_METADATA = {"Software": None}  # no matplotlib version in the files (nor a date: PNG carries none)
BAR = "#4878a8"
GAP = "#a03020"
FRONT = "#d55e00"
OK_TRACK = "#0072b2"
OTHER_TRACKS = ("#d55e00", "#e69f00", "#cc79a7", "#009e73", "#56b4e9", "#7f7f7f", "#000000")
SERIES = ("#0072b2", "#d55e00", "#009e73", "#cc79a7", "#e69f00", "#56b4e9", "#7f7f7f", "#000000")
SLOPE = "#b08850"
MIN_VIEW = 4.0  # [m] the least a map shows across: a robot spinning on the spot is seen at a robot's scale
MIN_SIDE_RATIO = 0.25  # of a map's shorter side to its longer: a 70 m pull is not drawn as a hairline
HEADINGS = 8  # heading arrows along a track
Point = Tuple[float, float]


# ---- values ------------------------------------------------------------------------------------------
def number(value: Any) -> Optional[float]:
    """The value as a float if it is a finite number (not a bool), else None."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        return None
    return float(value) if math.isfinite(value) else None


def why_not(value: Any) -> str:
    """Why a metric has no number, from what results.json holds in its place."""
    if value is None:
        return "no result"
    return str(value)


def direction(metric: str) -> int:
    """+1 when more of a metric is better, -1 when less is, 0 for words; a metric of one surface of
    several (``max_pull_n.mud``) is its metric's."""
    return DIRECTIONS.get(metric.split(".", 1)[0], 0)


def direction_word(metric: str) -> str:
    return {+1: "larger is better", -1: "smaller is better"}.get(direction(metric), "")


@dataclass(frozen=True)
class Metric:
    """One column of the results (``scenario.metric``): every candidate's value as results.json holds it."""

    column: str
    scenario: str
    name: str
    values: Tuple[Tuple[str, Any], ...]  # (candidate, value: a number, a word, "n/a: why", "failed: why", None)

    @property
    def numeric(self) -> bool:
        """Whether any candidate has a number for it (a metric of words is shown, not plotted)."""
        return any(number(v) is not None for _, v in self.values)

    @property
    def direction(self) -> int:
        return direction(self.name)

    def value(self, candidate: str) -> Any:
        return dict(self.values).get(candidate)


def metrics(results: Mapping[str, Any], study: Study) -> List[Metric]:
    """Every column of the results table, in its order (report_table's)."""
    table = rows(results, study)
    out = []
    for k, column in enumerate(columns(study)):
        scenario, name = column.split(".", 1)
        out.append(Metric(column, scenario, name, tuple((row[0], row[3 + k]) for row in table)))
    return out


def best(metric: Metric) -> Tuple[str, ...]:
    """The candidates with the row's best value (ties: all); none for a metric without a direction, with
    fewer than two numbers, or with all its numbers equal."""
    numbers = [(name, number(v)) for name, v in metric.values if number(v) is not None]
    if metric.direction == 0 or len(numbers) < 2:
        return ()
    if len({v for _, v in numbers}) == 1:
        return ()
    top = max(metric.direction * v for _, v in numbers)
    return tuple(name for name, v in numbers if metric.direction * v == top)


# ---- sweeps ------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Sweep:
    """The candidates of one sweep (a family): each one's values of the swept key paths."""

    family: str
    key_paths: Tuple[str, ...]
    members: Tuple[Tuple[str, Tuple[float, ...]], ...]  # (candidate, its values in key_paths' order)


def sweeps(study: Study, names: Sequence[str]) -> List[Sweep]:
    """The study's sweeps, in file order, of the candidates that have results (``names``)."""
    families: Dict[str, List[Candidate]] = {}
    for candidate in study.candidates:
        if candidate.family and candidate.swept and candidate.name in names:
            families.setdefault(candidate.family, []).append(candidate)
    out = []
    for family, members in families.items():
        key_paths = tuple(k for k, _ in members[0].swept)
        out.append(Sweep(family, key_paths, tuple((c.name, tuple(v for _, v in c.swept)) for c in members)))
    return out


def combination(key_paths: Sequence[str], values: Sequence[float]) -> str:
    """``y=0.75, r_wheel=0.25``: a combination of swept values by the key paths' last parts."""
    return ", ".join(f"{k.split('.')[-1]}={v:g}" for k, v in zip(key_paths, values))


# ---- Pareto front ------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ParetoPlane:
    """Every candidate with numbers for both columns, which of them are the front, and the others."""

    x: Metric
    y: Metric
    points: Tuple[Tuple[str, float, float], ...]  # (candidate, x, y)
    front: Tuple[int, ...]  # indices into points
    missing: Tuple[Tuple[str, str], ...]  # (candidate, why it has no point)


def check_pareto(pareto: Tuple[str, str], study: Study) -> None:
    """ValueError unless both are columns of the study's results with a direction (DIRECTIONS)."""
    known = columns(study)
    if len(pareto) != 2:
        raise ValueError(f"pareto must be two columns, not {list(pareto)}")
    for column in pareto:
        if column not in known:
            raise ValueError(f"pareto: {column!r} is not a column of this study's results: {', '.join(known)}")
        if not direction(column.split(".", 1)[1]):
            raise ValueError(f"pareto: {column!r} is not a metric with a better direction (DIRECTIONS)")


def pareto_plane(results: Mapping[str, Any], study: Study, pareto: Tuple[str, str]) -> ParetoPlane:
    check_pareto(pareto, study)
    by_column = {m.column: m for m in metrics(results, study)}
    mx, my = by_column[pareto[0]], by_column[pareto[1]]
    points, missing = [], []
    for name, _ in mx.values:
        x, y = number(mx.value(name)), number(my.value(name))
        if x is None or y is None:
            bad = mx.value(name) if x is None else my.value(name)
            missing.append((name, why_not(bad)))
        else:
            points.append((name, x, y))
    front = pareto_front([(x, y) for _, x, y in points], (mx.direction, my.direction))
    return ParetoPlane(mx, my, tuple(points), tuple(front), tuple(missing))


# ---- tracks and the map of their world ----------------------------------------------------------------
@dataclass(frozen=True)
class Drive:
    label: str  # "climb 14 deg"
    outcome: str  # "ok", "traction", ...
    x: Tuple[float, ...]  # [m] world frame
    y: Tuple[float, ...]
    yaw: Tuple[float, ...] = ()  # [rad] as many as x, or none


@dataclass(frozen=True)
class Tracks:
    """A tracks file: the world its map shows (the file's) and the drives."""

    world: Mapping[str, Any]
    drives: Tuple[Drive, ...]


def parse_tracks(data: Any) -> Tracks:
    """A tracks file's contents (``{"world": {...}, "tracks": [{"label", "outcome", "t", "x", "y",
    "yaw"}]}``); ValueError saying what is wrong."""
    if not isinstance(data, Mapping) or not isinstance(data.get("tracks"), list):
        raise ValueError("not a mapping with a list of tracks")
    drives = []
    for k, track in enumerate(data["tracks"]):
        if not isinstance(track, Mapping):
            raise ValueError(f"track {k} is not a mapping")
        xs, ys = track.get("x"), track.get("y")
        if not isinstance(xs, list) or not isinstance(ys, list) or len(xs) != len(ys):
            raise ValueError(f"track {k}: x and y must be lists of one length")
        if not all(number(v) is not None for v in xs + ys):
            raise ValueError(f"track {k}: x and y must be finite numbers")
        yaw = track.get("yaw")
        if yaw is not None and (
            not isinstance(yaw, list) or len(yaw) != len(xs) or not all(number(v) is not None for v in yaw)
        ):
            raise ValueError(f"track {k}: yaw must be as many finite numbers as x")
        label, outcome = str(track.get("label", "")), str(track.get("outcome", ""))
        drives.append(Drive(label, outcome, tuple(xs), tuple(ys), tuple(yaw or ())))
    world = data.get("world")
    if not isinstance(world, Mapping) or not world:  # an older file: the first track's own world
        world = next((t["world"] for t in data["tracks"] if isinstance(t.get("world"), Mapping)), {})
    return Tracks(world, tuple(drives))


@dataclass(frozen=True)
class Shape:
    """One thing of a world's plan. kind: "slope" (its footprint), "slope_top", "solid" (an object,
    a wall), "area" (a patch), "circle" (points: its centre; radius), "outline" (anything else: the
    box around it)."""

    kind: str
    points: Tuple[Point, ...]
    colour: Optional[Tuple[float, ...]] = None
    radius: float = 0.0


@dataclass(frozen=True)
class WorldMap:
    shapes: Tuple[Shape, ...]
    plants: Tuple[Tuple[Tuple[Point, ...], Tuple[float, ...]], ...]  # (each rows entry's plants, its colour)
    description: str = ""


def _rectangle(x: float, y: float, yaw: float, half_u: float, half_v: float) -> Tuple[Point, ...]:
    c, s = math.cos(yaw), math.sin(yaw)
    corners = ((-half_u, -half_v), (half_u, -half_v), (half_u, half_v), (-half_u, half_v))
    return tuple((x + c * u - s * v, y + s * u + c * v) for u, v in corners)


def convex_hull(points: Sequence[Point]) -> Tuple[Point, ...]:
    """The convex hull, counter-clockwise (monotone chain); a box of two points for a diagonal's ends."""
    pts = sorted(set((float(x), float(y)) for x, y in points))
    if len(pts) == 2:
        (x0, y0), (x1, y1) = pts
        pts = sorted({(x0, y0), (x1, y0), (x1, y1), (x0, y1)})
    if len(pts) < 3:
        return tuple(pts)

    def cross(o: Point, a: Point, b: Point) -> float:
        return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])

    lower: List[Point] = []
    upper: List[Point] = []
    for p in pts:
        while len(lower) >= 2 and cross(lower[-2], lower[-1], p) <= 0:
            lower.pop()
        lower.append(p)
    for p in reversed(pts):
        while len(upper) >= 2 and cross(upper[-2], upper[-1], p) <= 0:
            upper.pop()
        upper.append(p)
    return tuple(lower[:-1] + upper[:-1])


def world_map(world: Any) -> WorldMap:
    """The plan of a parsed world (:class:`thorvald_sim.world.WorldConfig`): hills as their footprint
    and top, plants as points, objects and walls as their outline, anything else as the box around it."""
    shapes: List[Shape] = []
    for slope in world.slopes:
        half = slope.footprint_length / 2
        shapes.append(Shape("slope", _rectangle(slope.x, slope.y, slope.yaw, half, slope.width / 2)))
        shapes.append(
            Shape("slope_top", _rectangle(slope.x, slope.y, slope.yaw, slope.top_length / 2, slope.width / 2))
        )
    for patch in world.patches:
        shapes.append(Shape("area", tuple(patch.corners()), patch.rgba))
    for ob in world.objects:
        if ob.shape == "box":
            shapes.append(Shape("solid", _rectangle(ob.x, ob.y, ob.yaw, ob.size_x / 2, ob.size_y / 2), ob.rgba))
        elif ob.shape in ("cylinder", "sphere") and (ob.shape == "sphere" or (ob.roll == 0.0 and ob.pitch == 0.0)):
            shapes.append(Shape("circle", ((ob.x, ob.y),), ob.rgba, ob.radius))
        else:
            shapes.append(Shape("solid", convex_hull(_footprint("objects", ob)), ob.rgba))
    for wall in world.walls:
        shapes.append(
            Shape("solid", _rectangle(wall.x, wall.y, wall.yaw, wall.length / 2, wall.thickness / 2), wall.rgba)
        )
    drawn = {"slopes", "patches", "objects", "walls", "rows"}
    for kind in element_kinds():
        if kind.section in drawn:
            continue
        for element in world.elements(kind.section):
            shapes.append(Shape("outline", convex_hull(_footprint(kind.section, element))))
    plants = tuple((tuple(p for line in plant_positions(rows) for p in line), tuple(rows.rgba)) for rows in world.rows)
    return WorldMap(tuple(shapes), plants, world.description)


def _footprint(section: str, element: Any) -> List[Point]:
    kind = next(k for k in element_kinds() if k.section == section)
    return list(kind.footprint(element)) if kind.footprint else []


def outcome_colours(outcomes: Sequence[str]) -> Dict[str, str]:
    """A colour an outcome: "ok" always the same blue, the others in sorted order from a palette."""
    others = sorted(set(outcomes) - {"ok"})
    out = {"ok": OK_TRACK}
    for k, outcome in enumerate(others):
        out[outcome] = OTHER_TRACKS[k % len(OTHER_TRACKS)]
    return out


def view(drives: Sequence[Drive], plan: Optional[WorldMap], reach: float = 15.0) -> Tuple[Point, Point]:
    """The plot's (x, y) limits: the tracks and the map, but no more than ``reach`` [m] beyond the
    tracks (a 100 m field around a 5 m drive would hide it); at least MIN_VIEW across, and the shorter
    side at least MIN_SIDE_RATIO of the longer."""
    xs = [v for d in drives for v in d.x]
    ys = [v for d in drives for v in d.y]
    mx: List[float] = []
    my: List[float] = []
    if plan is not None:
        for shape in plan.shapes:
            for px, py in shape.points:
                mx += [px - shape.radius, px + shape.radius]
                my += [py - shape.radius, py + shape.radius]
        for plants, _ in plan.plants:
            mx += [p[0] for p in plants]
            my += [p[1] for p in plants]
    if xs:
        lo_x, hi_x, lo_y, hi_y = min(xs), max(xs), min(ys), max(ys)
        if mx:
            lo_x = max(min(lo_x, *mx), lo_x - reach)
            hi_x = min(max(hi_x, *mx), hi_x + reach)
            lo_y = max(min(lo_y, *my), lo_y - reach)
            hi_y = min(max(hi_y, *my), hi_y + reach)
    elif mx:
        lo_x, hi_x, lo_y, hi_y = min(mx), max(mx), min(my), max(my)
    else:
        lo_x, hi_x, lo_y, hi_y = -1.0, 1.0, -1.0, 1.0
    margin = max(0.5, 0.05 * max(hi_x - lo_x, hi_y - lo_y))
    (lo_x, hi_x), (lo_y, hi_y) = (lo_x - margin, hi_x + margin), (lo_y - margin, hi_y + margin)
    least = max(MIN_VIEW, MIN_SIDE_RATIO * max(hi_x - lo_x, hi_y - lo_y))
    grow_x, grow_y = max(0.0, least - (hi_x - lo_x)) / 2, max(0.0, least - (hi_y - lo_y)) / 2
    return (lo_x - grow_x, hi_x + grow_x), (lo_y - grow_y, hi_y + grow_y)


# ---- plots (writing) ---------------------------------------------------------------------------------
@dataclass(frozen=True)
class Plot:
    """A plot written to DIR/plots: its file, what the page says of it."""

    path: str
    caption: str


def _figure(width: float, height: float) -> Figure:
    fig = Figure(figsize=(width, height), dpi=DPI, layout="constrained")
    FigureCanvasAgg(fig)
    return fig


def _save(fig: Figure, path: str) -> None:
    fig.savefig(path, format="png", dpi=DPI, metadata=PNG_METADATA)


def _footnote(fig: Figure, text: str, colour: str) -> None:
    """A note under the plot, left-aligned, wrapped; the layout makes room for it."""
    wrapped = "\n".join(textwrap.fill(line, 120) for line in text.splitlines())
    fig.supxlabel(wrapped, x=0.01, ha="left", fontsize=7, color=colour)


def _short(text: str, length: int = 60) -> str:
    text = " ".join(text.split())
    return text if len(text) <= length else text[: length - 1] + "…"


def _axis_label(metric: Metric) -> str:
    word = direction_word(metric.name)
    return metric.column + (f"  ({word})" if word else "")


def plot_metric(metric: Metric, path: str) -> None:
    """Bars across the candidates (the first on top); a candidate without a number: a gap saying why."""
    names = [n for n, _ in metric.values]
    fig = _figure(6.4, 1.1 + 0.32 * max(len(names), 2))
    ax = fig.add_subplot()
    values = [number(v) for _, v in metric.values]
    found = [v for v in values if v is not None]
    lo, hi = min(0.0, *found), max(0.0, *found)
    span = (hi - lo) or 1.0
    for i, ((_, raw), v) in enumerate(zip(metric.values, values)):
        if v is None:
            ax.text(0.0, i, "  " + _short(why_not(raw)), va="center", ha="left", color=GAP, style="italic", fontsize=8)
            continue
        ax.barh(i, v, color=BAR, height=0.6)
        ax.text(v, i, f" {_text(v)} ", va="center", ha="left" if v >= 0 else "right")
    ax.set_yticks(range(len(names)), names)
    ax.set_ylim(len(names) - 0.5, -0.5)
    ax.set_xlim(lo - (0.15 * span if lo < 0 else 0.0), hi + 0.15 * span)
    ax.grid(axis="y", visible=False)
    ax.axvline(0.0, color="black", linewidth=0.8)
    ax.set_xlabel(_axis_label(metric))
    ax.set_title(f"{metric.scenario}: {metric.name}")
    _save(fig, path)


def plot_sweep(sweep: Sweep, metric: Metric, path: str) -> None:
    """The metric against the first swept value; with more key paths swept, a line per combination of
    the others. A member without a number: a cross on the axis, its reason in the note below."""
    fig = _figure(6.4, 4.2)
    ax = fig.add_subplot()
    groups: Dict[Tuple[float, ...], List[Tuple[float, str]]] = {}
    for name, values in sweep.members:
        groups.setdefault(values[1:], []).append((values[0], name))
    notes = []
    for k, (rest, members) in enumerate(groups.items()):
        colour = SERIES[k % len(SERIES)]
        label = combination(sweep.key_paths[1:], rest) if rest else None
        line = sorted((x, number(metric.value(n))) for x, n in members)  # a gap breaks the line (NaN)
        ax.plot([x for x, _ in line], [math.nan if v is None else v for _, v in line], "o-", color=colour, label=label)
        for x, name in members:
            if number(metric.value(name)) is None:
                ax.plot([x], [0.0], "x", color=colour, markersize=9, transform=ax.get_xaxis_transform(), clip_on=False)
                where = combination(sweep.key_paths, dict(sweep.members)[name])
                notes.append(f"{where}: {_short(why_not(metric.value(name)), 50)}")
    if len(groups) > 1:
        ax.legend(
            fontsize=7, ncol=2 if len(groups) > 6 else 1, title=", ".join(k.split(".")[-1] for k in sweep.key_paths[1:])
        )
    ax.set_xlabel(sweep.key_paths[0])
    ax.set_ylabel(_axis_label(metric))
    ax.set_title(f"{sweep.family}: {metric.column}")
    if notes:
        shown = notes[:6] + ([f"... and {len(notes) - 6} more"] if len(notes) > 6 else [])
        _footnote(fig, "x, no value: " + "; ".join(shown), GAP)
    _save(fig, path)


def plot_pareto(plane: ParetoPlane, path: str) -> None:
    """Every candidate in the plane of two metrics, the front in colour and joined up."""
    fig = _figure(6.4, 4.8)
    ax = fig.add_subplot()
    on_front = set(plane.front)
    rest = [p for i, p in enumerate(plane.points) if i not in on_front]
    front = sorted(plane.points[i] for i in plane.front) if plane.front else []
    front.sort(key=lambda p: (p[1], p[2]))
    if rest:
        ax.plot([p[1] for p in rest], [p[2] for p in rest], "o", color="#999999", label="dominated")
    if front:
        ax.plot([p[1] for p in front], [p[2] for p in front], "o-", color=FRONT, markersize=7, label="Pareto front")
    for name, x, y in plane.points:
        ax.annotate(name, (x, y), xytext=(4, 4), textcoords="offset points", fontsize=7)
    ax.set_xlabel(_axis_label(plane.x))
    ax.set_ylabel(_axis_label(plane.y))
    ax.set_title("Pareto front")
    ax.margins(0.12)
    if plane.points:
        ax.legend(fontsize=8)
    if plane.missing:
        text = "; ".join(f"{n}: {_short(why, 40)}" for n, why in plane.missing[:6])
        _footnote(fig, "not in the plane: " + text, GAP)
    _save(fig, path)


def plot_tracks(title: str, tracks: Tracks, plan: Optional[WorldMap], note: str, path: str) -> None:
    """The drives over the plan of the file's world, coloured by outcome, in metres at equal scale
    (the figure as high as the view needs: a long narrow drive is a long narrow plot)."""
    (x0, x1), (y0, y1) = view(tracks.drives, plan)
    fig = _figure(6.4, min(7.5, max(2.4, 0.9 + 5.5 * (y1 - y0) / (x1 - x0))))
    ax = fig.add_subplot()
    if plan is not None:
        for shape in plan.shapes:
            _draw_shape(ax, shape)
        for plants, colour in plan.plants:
            if plants:
                ax.scatter([p[0] for p in plants], [p[1] for p in plants], s=4, color=colour[:3], linewidths=0)
    colours = outcome_colours([d.outcome for d in tracks.drives])
    labelled = set()
    for drive in tracks.drives:
        colour = colours[drive.outcome]
        label = None if drive.outcome in labelled else (drive.outcome or "(no outcome)")
        labelled.add(drive.outcome)
        ax.plot(drive.x, drive.y, "-", color=colour, linewidth=1.4, label=label)
        if drive.yaw:
            step = max(1, len(drive.yaw) // HEADINGS)
            k = list(range(0, len(drive.yaw), step))
            arrow = 0.04 * max(x1 - x0, y1 - y0)
            ax.quiver([drive.x[i] for i in k], [drive.y[i] for i in k],
                      [arrow * math.cos(drive.yaw[i]) for i in k], [arrow * math.sin(drive.yaw[i]) for i in k],
                      color=colour, angles="xy", scale_units="xy", scale=1.0, width=0.003, alpha=0.7)  # fmt: skip
        if drive.x:
            ax.plot(drive.x[:1], drive.y[:1], "o", color=colour, markersize=4, markerfacecolor="white")
            ax.plot(drive.x[-1:], drive.y[-1:], "o" if drive.outcome == "ok" else "X", color=colour, markersize=5)
            if drive.outcome != "ok" and drive.label:
                ax.annotate(drive.label, (drive.x[-1], drive.y[-1]), xytext=(4, -10), textcoords="offset points",
                            fontsize=7, color=colour)  # fmt: skip
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title)
    if tracks.drives:
        ax.legend(fontsize=7, loc="best", title="outcome", title_fontsize=7)
    lines = []
    if plan is not None and plan.description:
        lines.append("map: " + _short(plan.description, 70))
    if note:
        lines.append(note)
    if lines:
        _footnote(fig, "\n".join(lines), "#444444")
    _save(fig, path)


def _draw_shape(ax: Any, shape: Shape) -> None:
    colour = tuple(shape.colour[:3]) if shape.colour else "#888888"
    if shape.kind == "slope":
        ax.add_patch(Polygon(shape.points, closed=True, facecolor=SLOPE, alpha=0.25, edgecolor=SLOPE, linewidth=1))
    elif shape.kind == "slope_top":
        ax.add_patch(Polygon(shape.points, closed=True, facecolor=SLOPE, alpha=0.35, edgecolor="none"))
    elif shape.kind == "solid":
        ax.add_patch(
            Polygon(shape.points, closed=True, facecolor=colour, alpha=0.6, edgecolor="#333333", linewidth=0.8)
        )
    elif shape.kind == "area":
        ax.add_patch(Polygon(shape.points, closed=True, facecolor=colour, alpha=0.3, edgecolor="none"))
    elif shape.kind == "circle":
        ax.add_patch(Circle(shape.points[0], shape.radius, facecolor=colour, alpha=0.6, edgecolor="#333333"))
    elif len(shape.points) >= 3:
        ax.add_patch(Polygon(shape.points, closed=True, fill=False, edgecolor="#777777", linestyle="--"))


# ---- the page (pure) ---------------------------------------------------------------------------------
@dataclass(frozen=True)
class Image:
    """An image for the page: its PNG's bytes, its caption ("" for none: a plot has its title) and alt text."""

    caption: str
    png: bytes
    alt: str = ""


@dataclass(frozen=True)
class Sections:
    """What the page shows beyond the table: the images of each section, and notes."""

    pictures: Tuple[Image, ...] = ()
    metric_plots: Tuple[Image, ...] = ()
    sweep_plots: Tuple[Image, ...] = ()
    pareto: Optional[Image] = None
    pareto_text: str = ""
    tracks: Tuple[Tuple[str, Tuple[Image, ...]], ...] = ()  # (candidate, its scenarios' maps)
    notes: Tuple[str, ...] = ()  # what could not be shown, and why


CSS = """
body { font-family: "DejaVu Sans", Arial, Helvetica, sans-serif; color: #222; background: #fff;
       margin: 0 auto; padding: 1em 2em; max-width: 1250px; line-height: 1.4; }
h1 { font-size: 1.6em; margin-bottom: 0.2em; }
h2 { font-size: 1.25em; border-bottom: 1px solid #bbb; margin-top: 1.6em; }
h3 { font-size: 1.05em; margin-bottom: 0.3em; }
p.meta, p.note, ul.notes { color: #555; font-size: 0.9em; }
nav { font-size: 0.9em; }
nav a { margin-right: 1em; }
.scroll { overflow-x: auto; }
table.results { border-collapse: collapse; font-size: 0.85em; }
table.results th, table.results td { border: 1px solid #ccc; padding: 0.2em 0.5em; vertical-align: top; }
table.results thead th { background: #eee; }
table.results th.metric { text-align: left; font-weight: normal; white-space: nowrap; }
table.results td { text-align: right; }
table.results td.text { text-align: left; }
table.results td.none { text-align: left; color: #999; font-style: italic; font-size: 0.9em; max-width: 22em; }
table.results td.best { font-weight: bold; }
table.results tr.scenario th { background: #f5f5f5; text-align: left; }
table.results tr.scenario .what { font-weight: normal; color: #555; }
td.ok { color: #17612a; text-align: left; }
td.failed { color: #a03020; text-align: left; max-width: 22em; }
td.pending { color: #886600; text-align: left; }
.figures { display: flex; flex-wrap: wrap; gap: 1em; }
figure { margin: 0; max-width: 100%; break-inside: avoid; page-break-inside: avoid; }
figure img { max-width: 100%; height: auto; border: 1px solid #ddd; }
figure.plot { width: calc(50% - 0.5em); min-width: 360px; }
figure.picture { width: 340px; }
figcaption { font-size: 0.85em; color: #444; }
pre { background: #f6f6f6; border: 1px solid #ddd; padding: 0.8em; overflow-x: auto; font-size: 0.85em; }
@media print {
  body { max-width: none; padding: 0; }
  nav { display: none; }
  .scroll { overflow: visible; }
  h2 { break-after: avoid; page-break-after: avoid; }
  figure.plot { width: 48%; }
}
"""
# Counts the page's images once it has loaded, for a browser test: data-images-loaded and
# data-images-broken on <body>
SCRIPT = """
window.addEventListener("load", function () {
  var loaded = 0, broken = 0;
  for (var i = 0; i < document.images.length; i++) {
    var im = document.images[i];
    if (im.complete && im.naturalWidth > 0) { loaded++; } else { broken++; }
  }
  document.body.setAttribute("data-images-loaded", String(loaded));
  document.body.setAttribute("data-images-broken", String(broken));
});
"""


def data_uri(png: bytes) -> str:
    return "data:image/png;base64," + base64.b64encode(png).decode("ascii")


def _e(text: Any) -> str:
    return html.escape(str(text), quote=True)


def _figure_html(image: Image, kind: str) -> str:
    alt = image.alt or image.caption
    caption = f"<figcaption>{_e(image.caption)}</figcaption>" if image.caption else ""
    return f'<figure class="{kind}"><img src="{data_uri(image.png)}" alt="{_e(alt)}">{caption}</figure>'


def _status_class(status: str) -> str:
    if status == "ok":
        return "ok"
    return "failed" if status.startswith("failed") else "pending"


def table_html(results: Mapping[str, Any], study: Study) -> str:
    """The results as the terminal's table: a column a candidate, a row a metric, grouped by scenario;
    a failed scenario's reason in its first row; the best value of a row in bold."""
    names = list(results["candidates"])
    entries = results["candidates"]
    head = "".join(f"<th>{_e(n)}</th>" for n in names)
    lines = [f'<table class="results"><thead><tr><th></th>{head}</tr></thead><tbody>']

    def row(label: str, cells: Sequence[str]) -> None:
        lines.append(f'<tr><th class="metric">{label}</th>{"".join(cells)}</tr>')

    row(
        "status",
        [f'<td class="{_status_class(str(entries[n]["status"]))}">{_e(entries[n]["status"])}</td>' for n in names],
    )
    row("mass_kg", [_value_cell(entries[n].get("mass_kg")) for n in names])
    if any(entries[n].get("swept") for n in names):
        swept = [dict(entries[n].get("swept") or {}) for n in names]
        row("swept", [f'<td class="text">{_e(combination(list(s), list(s.values())))}</td>' for s in swept])
    if any(entries[n].get("payload_kg") for n in names):
        row("payload_kg", [_value_cell(entries[n].get("payload_kg")) for n in names])
    scenario = None
    for metric in metrics(results, study):
        if metric.scenario != scenario:
            scenario = metric.scenario
            what = SCENARIOS[scenario].what if scenario in SCENARIOS else ""
            lines.append(
                f'<tr class="scenario"><th colspan="{len(names) + 1}">{_e(scenario)}'
                + (f'<span class="what">: {_e(what)}</span>' if what else "")
                + "</th></tr>"
            )
            first = True
        tops = set(best(metric))
        cells = []
        for name in names:
            value = metric.value(name)
            if isinstance(value, str) and value.startswith("failed") and not first:
                value = "failed"
            cells.append(_value_cell(value, name in tops))
        arrow = {+1: " ↑", -1: " ↓"}.get(metric.direction, "")
        row(_e(metric.name) + arrow, cells)
        first = False
    lines.append("</tbody></table>")
    return "\n".join(lines)


def _value_cell(value: Any, is_best: bool = False) -> str:
    """A number as the terminal's table shows it; words in full (the page has room for a reason)."""
    if number(value) is not None:
        return ('<td class="best">' if is_best else "<td>") + f"{_e(_text(value))}</td>"
    if value is None:
        return '<td class="none">-</td>'
    text = " ".join(str(value).split())
    return f'<td class="{"none" if text.startswith(("n/a", "failed")) else "text"}">{_e(text)}</td>'


def page_html(results: Mapping[str, Any], study: Study, sections: Sections) -> str:
    """The whole page: its images already PNG bytes; the same arguments give the same text."""
    description = study.description or results.get("study", {}).get("description", "")
    title = description or f"Design study {os.path.basename(study.source)}"
    names = list(results["candidates"])
    ok = sum(1 for n in names if results["candidates"][n]["status"] == "ok")
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f"<title>{_e(title)}</title>",
        f"<style>{CSS}</style>",
        f"<script>{SCRIPT}</script>",
        "</head><body>",
        f"<h1>{_e(title)}</h1>",
        f'<p class="meta">Design study {_e(os.path.basename(study.source))}, seed {study.seed}: '
        f"{len(names)} candidates ({ok} ok), scenarios {_e(', '.join(s for s, _ in study.scenarios))}.</p>",
    ]
    contents = [("results", "Results")]
    if sections.pictures:
        contents.append(("candidates", "Candidates"))
    if sections.metric_plots:
        contents.append(("metrics", "Metrics"))
    if sections.sweep_plots:
        contents.append(("sweeps", "Sweeps"))
    if sections.pareto is not None:
        contents.append(("pareto", "Pareto front"))
    if sections.tracks:
        contents.append(("tracks", "Tracks"))
    contents.append(("study", "Study file"))
    parts.append("<nav>" + "".join(f'<a href="#{a}">{_e(t)}</a>' for a, t in contents) + "</nav>")

    parts.append('<h2 id="results">Results</h2>')
    parts.append(
        '<p class="note">A column a candidate, a row a metric; ↑ larger is better, ↓ smaller is better, '
        'the best of a row in bold. The scenarios:</p><ul class="notes">'
        + "".join(
            f"<li><b>{_e(s)}</b>: {_e(SCENARIOS[s].what if s in SCENARIOS else '')}</li>" for s, _ in study.scenarios
        )
        + "</ul>"
    )
    parts.append(f'<div class="scroll">{table_html(results, study)}</div>')
    if sections.pictures:
        parts.append('<h2 id="candidates">Candidates</h2>')
        parts.append(
            '<div class="figures">' + "".join(_figure_html(i, "picture") for i in sections.pictures) + "</div>"
        )
    if sections.metric_plots:
        parts.append('<h2 id="metrics">Metrics</h2>')
        parts.append(
            '<div class="figures">' + "".join(_figure_html(i, "plot") for i in sections.metric_plots) + "</div>"
        )
    if sections.sweep_plots:
        parts.append('<h2 id="sweeps">Sweeps</h2>')
        parts.append(
            '<div class="figures">' + "".join(_figure_html(i, "plot") for i in sections.sweep_plots) + "</div>"
        )
    if sections.pareto is not None:
        parts.append('<h2 id="pareto">Pareto front</h2>')
        if sections.pareto_text:
            parts.append(f'<p class="note">{_e(sections.pareto_text)}</p>')
        parts.append('<div class="figures">' + _figure_html(sections.pareto, "plot") + "</div>")
    if sections.tracks:
        parts.append('<h2 id="tracks">Tracks</h2>')
        parts.append(
            '<p class="note">Each drive of a scenario in plan view, over the map of the world in its tracks '
            "file (the last drive's: the drives of a series may have had other worlds, e.g. steeper ramps on "
            "the same footprint); shaded: hills (darker: their tops), dots: plants.</p>"
        )
        for name, images in sections.tracks:
            parts.append(f"<h3>{_e(name)}</h3>")
            parts.append('<div class="figures">' + "".join(_figure_html(i, "plot") for i in images) + "</div>")
    if sections.notes:
        parts.append('<ul class="notes">' + "".join(f"<li>{_e(n)}</li>" for n in sections.notes) + "</ul>")
    parts.append('<h2 id="study">Study file</h2>')
    parts.append(f'<p class="meta">{_e(study.source)}</p>')
    parts.append(f"<pre>{_e(study.text)}</pre>")
    parts.append("</body></html>")
    return "\n".join(parts) + "\n"


# ---- writing -----------------------------------------------------------------------------------------
def write_report(out_dir: str, results: Mapping, study: Study, pareto: Optional[Tuple[str, str]] = None) -> str:
    """Writes DIR/plots/*.png and DIR/report.html from the results (results.json's contents) and the
    study; returns the page's path. pareto: two columns ("gradeability.max_climb_deg",
    "turning.turning_diameter_m") whose front to plot (ValueError if either is no column with a direction)."""
    if pareto is not None:
        check_pareto(pareto, study)
    plots_dir = os.path.join(out_dir, PLOTS)
    os.makedirs(plots_dir, exist_ok=True)
    names = list(results["candidates"])
    written: List[str] = []
    notes: List[str] = []
    with matplotlib.rc_context(RC):
        metric_plots = []
        by_column = {}
        for metric in metrics(results, study):
            by_column[metric.column] = metric
            if not metric.numeric:
                continue
            path = os.path.join(plots_dir, f"metric_{metric.column}.png")
            plot_metric(metric, path)
            written.append(path)
            metric_plots.append(Plot(path, f"{metric.column} ({direction_word(metric.name)})"
                                     if direction_word(metric.name) else metric.column))  # fmt: skip
        sweep_plots = []
        for sweep in sweeps(study, names):
            members = [n for n, _ in sweep.members]
            for metric in by_column.values():
                if not any(number(metric.value(n)) is not None for n in members):
                    continue
                path = os.path.join(plots_dir, f"sweep_{safe_name(sweep.family)}_{metric.column}.png")
                plot_sweep(sweep, metric, path)
                written.append(path)
                sweep_plots.append(Plot(path, f"{sweep.family}: {metric.column} against {', '.join(sweep.key_paths)}"))
        pareto_plot, pareto_text = None, ""
        if pareto is not None:
            plane = pareto_plane(results, study, pareto)
            path = os.path.join(plots_dir, "pareto.png")
            plot_pareto(plane, path)
            written.append(path)
            pareto_plot = Plot(path, f"{pareto[0]} against {pareto[1]}")
            front = [plane.points[i][0] for i in plane.front]
            pareto_text = f"On the front of {pareto[0]} ({direction_word(plane.x.name)}) and {pareto[1]} " + (
                f"({direction_word(plane.y.name)}): {', '.join(front) if front else 'none'}."
            )
        track_plots: List[Tuple[str, List[Plot]]] = []
        for name in names:
            plots = []
            for scenario, _ in study.scenarios:
                source = os.path.join(TRACKS, safe_name(name), scenario + ".json")
                if not os.path.isfile(os.path.join(out_dir, source)):
                    continue
                path = os.path.join(plots_dir, f"tracks_{safe_name(name)}_{scenario}.png")
                problem = _track_plot(f"{name}: {scenario}", out_dir, source, path)
                if problem:
                    notes.append(f"{name}: {scenario}: tracks not shown: {problem}")
                    continue
                written.append(path)
                plots.append(Plot(path, f"{name}: {scenario}"))
            if plots:
                track_plots.append((name, plots))
    _remove_stale(plots_dir, written)

    pictures = []
    for name in names:
        path = os.path.join(out_dir, PICTURES, safe_name(name) + ".png")
        png = _read_png(path)
        if png is not None:
            status = results["candidates"][name]["status"]
            robot = os.path.basename(str(results["candidates"][name].get("robot") or ""))
            pictures.append(Image(f"{name}: {robot} ({status})", png, f"picture of {name}"))
        elif os.path.exists(path):
            notes.append(f"{name}: picture not shown: {os.path.relpath(path, out_dir)} is not a PNG")
    sections = Sections(
        pictures=tuple(pictures),
        metric_plots=tuple(_image(p) for p in metric_plots),
        sweep_plots=tuple(_image(p) for p in sweep_plots),
        pareto=_image(pareto_plot) if pareto_plot else None,
        pareto_text=pareto_text,
        tracks=tuple((n, tuple(_image(p) for p in plots)) for n, plots in track_plots),
        notes=tuple(notes),
    )
    page = os.path.join(out_dir, REPORT)
    with open(page + ".part", "w", encoding="utf-8") as f:
        f.write(page_html(results, study, sections))
    os.replace(page + ".part", page)
    return page


def _track_plot(title: str, out_dir: str, source: str, path: str) -> str:
    """Plots one tracks file (source, relative to out_dir); what went wrong ("" if nothing): a file that
    cannot be read is a note on the page, not the end of the report. A world that cannot be parsed:
    the tracks without a map. The page names files relative to DIR, so that it does not change with
    DIR's place."""
    try:
        with open(os.path.join(out_dir, source), encoding="utf-8") as f:
            tracks = parse_tracks(json.load(f))
    except OSError as e:
        return f"{source}: {e.strerror or type(e).__name__}"
    except ValueError as e:
        return f"{source}: {_short(str(e), 120)}"
    plan, note = None, ""
    if tracks.world:
        try:
            plan = world_map(parse_world(dict(tracks.world), source="the world"))
        except (ThorvaldModelError, ValueError, TypeError, KeyError) as e:
            note = "no map: " + _short(str(e).splitlines()[-1] if str(e) else type(e).__name__, 90)
    plot_tracks(title, tracks, plan, note, path)
    return ""


_OURS = re.compile(r"^(?:(?:metric|sweep|tracks)_.*|pareto)\.png$")


def _remove_stale(plots_dir: str, written: Sequence[str]) -> None:
    """Removes the plots an earlier report of DIR wrote that this one did not (a candidate renamed)."""
    keep = {os.path.basename(p) for p in written}
    for name in sorted(os.listdir(plots_dir)):
        if _OURS.match(name) and name not in keep:
            os.remove(os.path.join(plots_dir, name))


def _read_png(path: str) -> Optional[bytes]:
    try:
        with open(path, "rb") as f:
            data = f.read()
    except OSError:
        return None
    return data if data.startswith(b"\x89PNG\r\n\x1a\n") else None


def _image(plot: Plot) -> Image:
    """A plot for the page: its title is in the image, its caption the alt text."""
    with open(plot.path, "rb") as f:
        return Image("", f.read(), plot.caption)


__all__ = [
    "DIRECTIONS",
    "TEXT_METRICS",
    "Drive",
    "Metric",
    "ParetoPlane",
    "Sweep",
    "Tracks",
    "WorldMap",
    "metrics",
    "page_html",
    "pareto_plane",
    "parse_tracks",
    "sweeps",
    "world_map",
    "write_report",
]
