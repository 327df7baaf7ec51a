"""A design study's report: ``DIR/report.html``, one page that opens offline and prints, and the plots
it shows in ``DIR/plots/``.

What is on the page: the study's description; the results table (a column a candidate, a row a
metric, as the terminal's table, with each candidate's status, the best value of a row in bold); the
headland's turns, a row each (whether it works, its headland, the plants it touched, its time); each
metric that has a quasi-static prediction drawn beside it on one chart (``compare_*.png``: the last
try held, on to the first that failed, the prediction, and the prediction for the robot as simulated),
with a sentence for each candidate whose two are more than the study's step apart saying why
(:mod:`thorvald_design.report_views`); a picture of each candidate (``DIR/pictures/<safe name>.png``,
when the runs made one); a bar chart of each other numeric metric across the candidates (a candidate
without a value: a gap with its reason); for a sweep, each numeric metric against the swept value;
the Pareto front of two metrics when asked for; each candidate's drives (``DIR/tracks/<safe
name>/<scenario>.json``, when the runs wrote them), drawn as what they were: a turn with its ISO 789-3
circles (the outermost wheel's path, the turning and clearance diameters), the headland's turns a
colour each with the plants they touched ringed, a series of tries (ramps, steps, side slopes) from
the side with how far each got, anything else over a plan of its world; and the study file as written.

Why one page with everything in it (the plots as base64 data URIs, the CSS inline, no script but a
counter of loaded images): a study's results are passed around as a file and opened on a laptop on a
farm, so nothing it needs may be elsewhere; the same inputs give the same bytes (no dates, no
random ids), so a report is compared and kept like any other result.

Pure: what is plotted (:func:`metrics`, :func:`sweeps`, :func:`pareto_plane`: its front is
:func:`thorvald_design.optimise.pareto_front`, the package's one; the comparisons, circles, side
views and turns of :mod:`thorvald_design.report_views`), the plan of a world (:func:`world_map`) and
the page (:func:`page_html`).
Writing: the plots (matplotlib's Agg canvas, no pyplot) and the page (:func:`write_report`).
"""

import base64
import html
import json
import math
import os
import re
import textwrap
from dataclasses import dataclass, field
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

import matplotlib
import matplotlib.cm
import matplotlib.colors
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Circle, Polygon

from thorvald_model.errors import ThorvaldModelError
from thorvald_sim.world import element_kinds, parse_world
from thorvald_sim.world.kinds.rows import plant_positions

from .metrics import convex_hull
from .optimise import pareto_front
from .report_table import _text, columns, rows
from .report_views import (
    Comparison,
    SideTry,
    TurnRow,
    TurnView,
    circle,
    comparisons,
    disagreement,
    disagrees,
    headland_rows,
    side_series,
    side_try,
    try_text,
    turn_colour_index,
    turn_legend,
    turn_view,
)
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
    t: Tuple[float, ...] = ()  # [s] as many as x, or none (each of these: an older file has none)
    z: Tuple[float, ...] = ()  # [m] base_link's height
    pitch: Tuple[float, ...] = ()  # [rad] nose up positive
    roll: Tuple[float, ...] = ()  # [rad]
    world: Mapping[str, Any] = field(default_factory=dict)  # its own world (a series' tries differ)
    marks: Mapping[str, Any] = field(default_factory=dict)  # what the scenario said to draw beside it


@dataclass(frozen=True)
class Tracks:
    """A tracks file: the world its map shows (the file's) and the drives."""

    world: Mapping[str, Any]
    drives: Tuple[Drive, ...]


def parse_tracks(data: Any) -> Tracks:
    """A tracks file's contents (``{"world": {...}, "tracks": [{"label", "outcome", "world", "marks",
    "t", "x", "y", "yaw", "z", "pitch", "roll"}]}``, all but x and y optional); ValueError saying what
    is wrong."""
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
        more = {}
        for key in ("yaw", "t", "z", "pitch", "roll"):
            values = track.get(key)
            if values is not None and (
                not isinstance(values, list) or len(values) != len(xs) or not all(number(v) is not None for v in values)
            ):
                raise ValueError(f"track {k}: {key} must be as many finite numbers as x")
            more[key] = tuple(values or ())
        for key in ("world", "marks"):
            if track.get(key) is not None and not isinstance(track.get(key), Mapping):
                raise ValueError(f"track {k}: {key} must be a mapping")
            more[key] = dict(track.get(key) or {})
        label, outcome = str(track.get("label", "")), str(track.get("outcome", ""))
        drives.append(Drive(label, outcome, tuple(xs), tuple(ys), **more))
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


# ---- turning: ISO 789-3's circles -----------------------------------------------------------------------
def _circle_label(ax: Any, centre: Point, diameter: float, *, angle: float, text: str, colour: str) -> None:
    """text beside the circle of a diameter about centre, at angle [deg] from +x, away from the circle."""
    a = math.radians(angle)
    where = (centre[0] + 0.5 * diameter * math.cos(a), centre[1] + 0.5 * diameter * math.sin(a))
    ha = "left" if math.cos(a) >= 0 else "right"
    va = "bottom" if math.sin(a) >= 0 else "top"
    offset = (3 * math.cos(a), 3 * math.sin(a))
    ax.annotate(text, where, xytext=offset, textcoords="offset points", fontsize=7, color=colour, ha=ha, va=va)


def plot_turning(title: str, tracks: Tracks, turns: Sequence[Optional[TurnView]], path: str) -> Figure:
    """Each turn of a turning scenario in plan (ISO 789-3): the outermost wheel's path, the circle it
    describes (the turning diameter), the circle of the robot's outermost point (the clearance
    diameter), the turn's centre, base_link's path, and the robot's outline where the steady turn
    began. A robot spinning on the spot has its base_link still and its wheels on a circle about it."""
    # as high as a square map and the legend under it need (a line a turn and five for the line styles)
    fig = _figure(6.4, 7.0 + 0.17 * (len(tracks.drives) + 5))
    ax = fig.add_subplot()
    xs: List[float] = []
    ys: List[float] = []
    for k, (drive, turn) in enumerate(zip(tracks.drives, turns)):
        colour = SERIES[k % len(SERIES)]
        ax.plot(drive.x, drive.y, "-", color=colour, linewidth=0.8, alpha=0.6)
        xs += list(drive.x)
        ys += list(drive.y)
        if turn is None:
            continue
        r = 0.5 * turn.clearance_diameter
        xs += [turn.centre[0] - r, turn.centre[0] + r]
        ys += [turn.centre[1] - r, turn.centre[1] + r]
        # the legend by turn: its outermost wheel and both diameters; the line styles' legend once
        label = (f"{drive.label}: {turn.outer_wheel}'s path, turning diameter {turn.turning_diameter:.2f} m, "
                 f"clearance diameter {turn.clearance_diameter:.2f} m")  # fmt: skip
        ax.plot(*turn.wheel_path, "-", color=colour, linewidth=2.2, alpha=0.8, label=label)
        ax.plot(*circle(turn.centre, turn.turning_diameter), "--", color=colour, linewidth=1.0)
        ax.plot(*circle(turn.centre, turn.clearance_diameter), ":", color=colour, linewidth=1.4)
        ax.plot([turn.centre[0]], [turn.centre[1]], "+", color=colour, markersize=10, markeredgewidth=1.5)
        if k == 0:
            if len(turn.outline) >= 3:
                ax.add_patch(Polygon(turn.outline, closed=True, facecolor="#999999", alpha=0.25, edgecolor="#555555",
                                     linewidth=0.8))  # fmt: skip
            ax.plot(*turn.outer_point, "*", color="#333333", markersize=9)
            for diameter, angle in ((turn.turning_diameter, -40.0), (turn.clearance_diameter, 40.0)):
                _circle_label(ax, turn.centre, diameter, angle=angle, text=f"Ø {diameter:.2f} m", colour=colour)
        ax.plot(*turn.outer_wheel_at, "o", color=colour, markersize=5, markeredgecolor="black", markeredgewidth=0.5)
    grey = "#555555"
    ax.plot([], [], "-", color=grey, linewidth=0.8, label="base_link's path")
    ax.plot([], [], "--", color=grey, linewidth=1.0, label="the outermost wheel's circle (turning diameter)")
    ax.plot([], [], ":", color=grey, linewidth=1.4, label="the outermost point's circle (clearance diameter)")
    ax.plot([], [], "+", color=grey, markersize=9, linestyle="none", label="the turn's centre")
    robot = "the robot where the steady turn began: its outermost wheel (dot) and point (star)"
    ax.fill([], [], facecolor="#999999", alpha=0.25, edgecolor=grey, label=robot)
    lo_x, hi_x = (min(xs), max(xs)) if xs else (-1.0, 1.0)
    lo_y, hi_y = (min(ys), max(ys)) if ys else (-1.0, 1.0)
    margin = max(0.3, 0.08 * max(hi_x - lo_x, hi_y - lo_y))
    ax.set_xlim(lo_x - margin, hi_x + margin)
    ax.set_ylim(lo_y - margin, hi_y + margin)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title)
    fig.legend(fontsize=6.5, loc="outside lower center", ncol=1)
    _save(fig, path)
    return fig  # for a test to read what it draws


# ---- the headland: a colour a turn, the plants it touched ---------------------------------------------
TOUCHED = "#c00000"


def plot_headland(title: str, tracks: Tracks, plan: Optional[WorldMap], note: str, path: str) -> Figure:
    """The turns of a headland scenario over its rows, a colour each, the legend by turn (whether it
    works, its headland, the plants it touched, its time) and a ring round each plant it touched."""
    (x0, x1), (y0, y1) = view(tracks.drives, plan, reach=3.0)
    turns = len(tracks.drives) + (1 if any(d.marks.get("touched") for d in tracks.drives) else 0)
    fig = _figure(6.4, min(9.0, max(3.0, 1.2 + 5.6 * (y1 - y0) / (x1 - x0))) + 0.2 * turns)
    ax = fig.add_subplot()
    if plan is not None:
        for shape in plan.shapes:
            _draw_shape(ax, shape)
        for plants, colour in plan.plants:
            if plants:
                ax.scatter([p[0] for p in plants], [p[1] for p in plants], s=5, color=colour[:3], linewidths=0)
    ax.axvline(0.0, color="#777777", linewidth=0.8, linestyle="--")
    ax.annotate("the rows' end", (0.0, 1.0), xycoords=("data", "axes fraction"), xytext=(3, -10),
                textcoords="offset points", fontsize=7, color="#555555")  # fmt: skip
    rings = 0
    for drive in tracks.drives:
        turn = str(drive.marks.get("turn") or drive.label)
        colour = SERIES[turn_colour_index(turn) % len(SERIES)]
        legend = turn_legend(drive.marks) if drive.marks.get("turn") else f"{drive.label}: {drive.outcome}"
        ax.plot(drive.x, drive.y, "-", color=colour, linewidth=1.5, label=legend)
        if drive.x:
            works = drive.marks.get("works", drive.outcome == "ok")
            ax.plot(drive.x[-1:], drive.y[-1:], "o" if works else "X", color=colour, markersize=5)
        touched = [p for p in drive.marks.get("touched") or [] if isinstance(p, list) and len(p) == 2]
        if touched:
            ax.scatter([p[0] for p in touched], [p[1] for p in touched], s=55, facecolors="none", edgecolors=colour,
                       linewidths=1.3, zorder=5)  # fmt: skip
            rings += len(touched)
    if rings:  # one legend entry for the rings, in no turn's colour
        ax.scatter([], [], s=55, facecolors="none", edgecolors="#333333", linewidths=1.3,
                   label="a plant touched (ringed in its turn's colour)")  # fmt: skip
    ax.set_xlim(x0, x1)
    ax.set_ylim(y0, y1)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title)
    if tracks.drives:
        fig.legend(fontsize=7, loc="outside lower center", title="turn", title_fontsize=7)
    if note:
        _footnote(fig, note, "#444444")
    _save(fig, path)
    return fig  # for a test to read what it draws


# ---- a series of tries, from the side -----------------------------------------------------------------
SERIES_MAP = "viridis"


SIDE_RATIO = 0.3  # a side view's height over its width, at least, where heights are exaggerated to get it
MAX_EXAGGERATION = 20.0


def side_exaggeration(width: float, height: float) -> float:
    """How many times a side view draws heights larger than lengths: 1 where the view is at least
    SIDE_RATIO as high as it is wide, else the least whole number (or half) that makes it so, at most
    MAX_EXAGGERATION (a 2 cm step over 4 m)."""
    if width <= 0.0 or height <= 0.0 or height >= SIDE_RATIO * width:
        return 1.0
    need = SIDE_RATIO * width / height
    return min(MAX_EXAGGERATION, math.ceil(need * 2.0) / 2.0)


def _side_extent(found: Sequence[SideTry]) -> Tuple[float, float, float, float, float]:
    """(s from, s to, z from, z to, the heights' exaggeration) of a side view's panel."""
    x_lo = min(float(np.min(t.ground[0])) for t in found)
    x_hi = max(float(np.max(t.ground[0])) for t in found)
    z_all = np.concatenate([np.concatenate([t.ground[1], t.path[1]]) for t in found])
    z_lo, z_hi = float(np.min(z_all)), float(np.max(z_all))
    pad = 0.08 * max(z_hi - z_lo, 0.05)
    z_lo, z_hi = z_lo - pad, z_hi + 4.0 * pad  # room above for the legend
    return x_lo, x_hi, z_lo, z_hi, side_exaggeration(x_hi - x_lo, z_hi - z_lo)


LABEL_BOX = {"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.75}  # a label over lines
SIDE_AXES_WIDTH = 4.9  # [in] of a side view's axes in its 6.4 in figure (the rest: labels, the colour bar)


def plot_side(title: str, tries: Sequence[SideTry], note: str, path: str) -> Figure:
    """A series' tries seen from the side (a panel a series: climbs and descents, steps up and down, a
    side slope each way): the ground of each try's world along the drive (or across a hill's face for
    a drive along its contour) and base_link's path over it, in a colour by the try's angle or height;
    how each ended and how far it got beside the last held and every failed one. Each panel is as high
    as its heights need at their exaggeration, so the panel fills its width."""
    groups = side_series(tries)
    extents = [_side_extent(found) for _, found in groups]
    heights = [SIDE_AXES_WIDTH * (z1 - z0) * k / (x1 - x0) for x0, x1, z0, z1, k in extents]
    fig = _figure(6.4, sum(h + 1.0 for h in heights) + (0.4 if note else 0.0))
    grid = fig.add_gridspec(len(groups), 1, height_ratios=[h + 1.0 for h in heights])
    cmap = matplotlib.colormaps[SERIES_MAP]
    for g, (name, found) in enumerate(groups):
        ax = fig.add_subplot(grid[g, 0])
        x_lo, x_hi, z_lo, z_hi, exaggeration = extents[g]
        values = [t.value for t in found]
        lo, hi = min(values), max(values)
        norm = matplotlib.colors.Normalize(vmin=lo, vmax=hi if hi > lo else lo + 1.0)
        held = [t for t in found if t.ok]
        labelled = {id(t) for t in found if not t.ok} | ({id(held[-1])} if held else set())
        if len(found) <= 2:
            labelled = {id(t) for t in found}
        for one in found:
            colour = cmap(0.9 * norm(one.value))  # not the palest yellow: it vanishes on white
            ax.plot(*one.ground, "-", color=colour, linewidth=0.8, alpha=0.7)
            s, z = one.path
            ax.plot(s, z, "-", color=colour, linewidth=2.0)
            end = int(np.argmax(s)) if one.section == "along" and not one.ok else len(s) - 1
            ax.plot([s[end]], [z[end]], "o" if one.ok else "X", color=colour, markersize=6 if one.ok else 8,
                    markeredgecolor="black" if not one.ok else colour, markeredgewidth=0.6)  # fmt: skip
            if id(one) in labelled:
                ink = colour if one.ok else "black"
                ax.annotate(try_text(one), (s[end], z[end]), xytext=(5, 4 if one.ok else -12),
                            textcoords="offset points", fontsize=7, color=ink, bbox=LABEL_BOX)  # fmt: skip
        unit = found[0].unit
        if hi > lo:  # a colour bar of the tries' values (one try: its label says it)
            mappable = matplotlib.cm.ScalarMappable(norm=norm, cmap=matplotlib.colors.ListedColormap(
                cmap(np.linspace(0.0, 0.9, 256))))  # fmt: skip
            bar = fig.colorbar(mappable, ax=ax, pad=0.01, fraction=0.04)
            bar.set_label("angle [deg]" if unit == "deg" else f"height [{unit}]", fontsize=7)
            bar.ax.tick_params(labelsize=7)
        ax.set_xlim(x_lo, x_hi)
        ax.set_ylim(z_lo, z_hi)
        ax.set_aspect(exaggeration, adjustable="box")
        across = found[0].section == "across"
        ax.set_xlabel("across the hill's face, up it [m] (0: its foot)" if across
                      else "along the drive [m] (0: the hill's foot or the step's edge)")  # fmt: skip
        ax.set_ylabel("height [m]" + ("" if exaggeration == 1.0 else f" (drawn x{exaggeration:g})"))
        ax.set_title(f"{title}: {name}" if len(groups) > 1 else title, fontsize=9)
        ax.plot([], [], "o", color="#555555", label="held")
        ax.plot([], [], "X", color="#555555", markeredgecolor="black", label="failed")
        ax.plot([], [], "-", color="#555555", linewidth=2.0, label="base_link's path")
        ax.plot([], [], "-", color="#555555", linewidth=0.8, label="the ground of the try")
        ax.legend(fontsize=6.5, loc="upper left", ncol=2)
    if note:
        _footnote(fig, note, "#444444")
    _save(fig, path)
    return fig  # for a test to read what it draws


# ---- measured against predicted -----------------------------------------------------------------------
MEASURED_LIGHT = "#a9c3dc"
AS_SIMULATED = "#555555"


def plot_comparison(comparison: Comparison, path: str) -> Figure:
    """Each candidate's measured limit (the last try held, and on to the first that failed) and its
    quasi-static prediction on one chart, with the prediction for the robot as simulated where the
    results have it; a candidate whose two are more than the study's step apart is marked."""
    rows = comparison.rows
    fig = _figure(6.4, 1.6 + 0.42 * max(len(rows), 2))
    ax = fig.add_subplot()
    p = comparison.pairing
    found = []
    for row in rows:
        found += [v for v in (number(row.measured), number(row.predicted), row.failed_at, row.with_com_and_rolling)
                  if v is not None]  # fmt: skip
    hi = max([*found, 0.0]) or 1.0
    labelled = set()

    def once(label: str) -> Optional[str]:
        if label in labelled:
            return None
        labelled.add(label)
        return label

    names = []
    for i, row in enumerate(rows):
        bad = disagrees(comparison, row)
        names.append(row.candidate + (" (!)" if bad else ""))
        measured, predicted = number(row.measured), number(row.predicted)
        if measured is None:
            why = row.measured if row.measured is not None else row.predicted
            ax.text(0.0, i, "  " + _short(why_not(why)), va="center", ha="left", color=GAP, style="italic", fontsize=8)
        else:
            ax.barh(i, measured, color=BAR, height=0.5, label=once("measured: the last try held"))
            if row.failed_at is not None and row.failed_at > measured:
                ax.barh(i, row.failed_at - measured, left=measured, color=MEASURED_LIGHT, height=0.5, hatch="///",
                        edgecolor="white", linewidth=0.0, label=once("on to the first try that failed"))  # fmt: skip
            # the measured value at the bar's root: its end is where the prediction's marker sits
            inside = measured > 0.08 * hi
            ax.text(0.0 if inside else measured, i, f" {_text(measured)} ", va="center", ha="left", fontsize=7,
                    color="white" if inside else BAR)  # fmt: skip
        if predicted is not None:
            ax.plot([predicted], [i], "D", color=FRONT, markersize=7, markeredgecolor="black", markeredgewidth=0.5,
                    label=once("predicted (quasi-static)"), zorder=5)  # fmt: skip
            ax.annotate(f"{_text(predicted)}", (predicted, i), xytext=(6, -3), textcoords="offset points",
                        fontsize=7, color=FRONT, bbox=LABEL_BOX)  # fmt: skip
        if row.with_com_and_rolling is not None and predicted is not None and row.with_com_and_rolling != predicted:
            ax.plot([row.with_com_and_rolling], [i], "D", markerfacecolor="none", markeredgecolor=AS_SIMULATED,
                    markersize=7, label=once("predicted for the robot as simulated, rolling"), zorder=5)  # fmt: skip
    ax.set_yticks(range(len(rows)), names)
    for tick, row in zip(ax.get_yticklabels(), rows):
        if disagrees(comparison, row):
            tick.set_color(GAP)
    ax.set_ylim(len(rows) - 0.5, -0.5)
    ax.set_xlim(0.0, 1.18 * hi)
    ax.grid(axis="y", visible=False)
    ax.set_xlabel(f"{comparison.column} against {comparison.predicted_column} [{p.unit}]")
    ax.set_title(f"{p.scenario}: {p.measured}{comparison.suffix}, measured and predicted")
    if comparison.step is not None:
        ax.plot([], [], " ", label=f"(!): more than the study's step ({_text(comparison.step)} {p.unit}) apart")
    fig.legend(fontsize=7, loc="outside lower center", ncol=2)
    _save(fig, path)
    return fig  # for a test to read what it draws


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
    # (chart, what the page says of each candidate whose measured limit and prediction disagree, a note
    # when none does) of each measured metric with a quasi-static prediction
    comparisons: Tuple[Tuple[Image, Tuple[str, ...], str], ...] = ()
    turns: Tuple[TurnRow, ...] = ()  # the headland's turns, every candidate's


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
.compare { display: flex; flex-wrap: wrap; gap: 1em; align-items: flex-start; margin-bottom: 1em; }
.compare figure.plot { flex: 0 1 54%; width: auto; min-width: 360px; }
.compare .why { flex: 1 1 300px; font-size: 0.88em; }
.compare .why li { margin-bottom: 0.5em; }
p.disagree, li.disagree { color: #7a2410; }
table.turns td.works { color: #17612a; }
table.turns td.fails { color: #a03020; }
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


def turns_html(turns: Sequence[TurnRow]) -> str:
    """The headland's turns, a row each: the candidate, the turn, whether it works, its headland, the
    plants it touched and its time (results.json's ``headland.turns``); a turn not tried, why."""
    head = "<tr><th>candidate</th><th>turn</th><th>works</th><th>headland [m] ↓</th><th>plants touched ↓</th>"
    head += "<th>time [s]</th></tr>"
    lines = [f'<table class="results turns"><thead>{head}</thead><tbody>']
    for row in turns:
        cells = [f'<th class="metric">{_e(row.candidate)}</th>', f'<td class="text">{_e(row.turn)}</td>']
        if row.note:
            cells.append(f'<td class="none" colspan="4">{_e(" ".join(row.note.split()))}</td>')
        else:
            works = "yes" if row.works else "no"
            cells.append(f'<td class="{"works" if row.works else "fails"}">{works}</td>')
            for value in (row.headland_m, row.plants_touched, row.time_s):
                cells.append(_value_cell(value))
        lines.append("<tr>" + "".join(cells) + "</tr>")
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
    if sections.turns:
        contents.append(("turns", "Headland turns"))
    if sections.comparisons:
        contents.append(("predicted", "Measured and predicted"))
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
    if sections.turns:
        parts.append('<h2 id="turns">Headland turns</h2>')
        parts.append(
            '<p class="note">Every turn each candidate tried out of a row and into the next: whether it ends in '
            "the target row heading back along it, the headland it needs (the furthest any point of the robot "
            "went beyond the rows' end), the plants its wheels (and its frame, for plants taller than its "
            "clearance) touched, and how long it took. The narrowest that works touching the fewest plants is "
            "the results' headland.</p>"
        )
        parts.append(f'<div class="scroll">{turns_html(sections.turns)}</div>')
    if sections.comparisons:
        parts.append('<h2 id="predicted">Measured and predicted</h2>')
        parts.append(
            '<p class="note">Each limit the simulation measures in steps beside the quasi-static limit its '
            "weight distribution, grip and motors give. The measured value is the last try held: a prediction "
            "the simulation bears out lies between it and the first try that failed, at most a step above it. "
            "Where the two are more than the study's step apart, the page says so and why.</p>"
        )
        for image, sentences, note in sections.comparisons:
            why = "".join(f'<li class="disagree">{_e(t)}</li>' for t in sentences)
            text = f"<ul>{why}</ul>" if why else (f'<p class="note">{_e(note)}</p>' if note else "")
            parts.append(f'<div class="compare">{_figure_html(image, "plot")}<div class="why">{text}</div></div>')
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
            '<p class="note">Each scenario\'s drives as what they were. A turn (ISO 789-3): the outermost '
            "wheel's path, the circle it describes (the turning diameter, dashed) and the circle of the robot's "
            "outermost point (the clearance diameter, dotted), about the turn's centre. The headland: a colour "
            "a turn, the plants each touched ringed. A series of tries (ramps, steps, side slopes): from the "
            "side, each try's ground and base_link's path over it, coloured by the try's angle or height, with "
            "how far the last held and every failed try got. Anything else in plan, over the map of the world "
            "in its tracks file (shaded: hills, darker their tops; dots: plants).</p>"
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
        compare_plots = []
        compared = set()
        for comparison in comparisons(results, study):
            p = comparison.pairing  # a surface's column, and the headline that is the first surface's
            compared |= {comparison.column, comparison.predicted_column, f"{p.scenario}.{p.measured}"}
            compared |= {f"{p.scenario}.{p.predicted}"}
            if not any(number(r.measured) is not None or number(r.predicted) is not None for r in comparison.rows):
                continue
            path = os.path.join(plots_dir, f"compare_{comparison.column}.png")
            plot_comparison(comparison, path)
            written.append(path)
            caption = f"{comparison.column} (measured) and {comparison.predicted_column} (quasi-static)"
            compare_plots.append((Plot(path, caption), *_comparison_text(comparison)))
        metric_plots = []
        by_column = {}
        for metric in metrics(results, study):
            by_column[metric.column] = metric
            if not metric.numeric or metric.column in compared:  # drawn beside its prediction instead
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
        comparisons=tuple((_image(p), sentences, note) for p, sentences, note in compare_plots),
        turns=tuple(headland_rows(results)) if any(s == "headland" for s, _ in study.scenarios) else (),
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


def _comparison_text(comparison: Comparison) -> Tuple[Tuple[str, ...], str]:
    """What the page says beside a comparison's chart: a sentence for each candidate whose measured value
    and prediction disagree; where none does, a note that all are within the step."""
    sentences = tuple(t for t in (disagreement(comparison, r) for r in comparison.rows) if t)
    p = comparison.pairing
    if sentences or comparison.step is None or not any(r.numbers for r in comparison.rows):
        return sentences, ""
    note = f"Every candidate's {p.measured}{comparison.suffix} is within the study's step "
    note += f"({_text(comparison.step)} {p.unit}) of its prediction."
    return sentences, note


def _track_plot(title: str, out_dir: str, source: str, path: str) -> str:
    """Plots one tracks file (source, relative to out_dir); what went wrong ("" if nothing): a file that
    cannot be read is a note on the page, not the end of the report. A world that cannot be parsed:
    the tracks without a map. The page names files relative to DIR, so that it does not change with
    DIR's place.

    What the drives' marks say picks the plot: a turning scenario's turns (:func:`plot_turning`), a
    headland's (:func:`plot_headland`), the tries of a series seen from the side (:func:`plot_side`);
    anything else, or an older file without marks, the drives over the plan of the world."""
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
    turns = [turn_view(d) for d in tracks.drives]
    if any(turns):
        plot_turning(title, tracks, turns, path)
        return ""
    if any(d.marks.get("turn") for d in tracks.drives):
        plot_headland(title, tracks, plan, note, path)
        return ""
    tries = _side_tries(tracks)
    if tries:
        plot_side(title, tries, "", path)
        return ""
    plot_tracks(title, tracks, plan, note, path)
    return ""


def _side_tries(tracks: Tracks) -> List[SideTry]:
    """The drives that are tries of a series, each over its own world (parsed once per world; a world
    the parser refuses: the path alone, on flat ground)."""
    worlds: Dict[str, Any] = {}
    out = []
    for drive in tracks.drives:
        if not drive.marks.get("series"):
            continue
        data = dict(drive.world or tracks.world)
        key = json.dumps(data, sort_keys=True)
        if key not in worlds:
            try:
                worlds[key] = parse_world(data, source="the world") if data else None
            except (ThorvaldModelError, ValueError, TypeError, KeyError):
                worlds[key] = None
        one = side_try(drive, worlds[key])
        if one is not None:
            out.append(one)
    return out


_OURS = re.compile(r"^(?:(?:metric|compare|sweep|tracks)_.*|pareto)\.png$")


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
