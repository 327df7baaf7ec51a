"""The report's plots (``DIR/plots/*.png``): matplotlib's Agg canvas, no pyplot, the same bytes for the
same inputs (no date, no software version, a fixed font and hash salt). What each draws is worked out
before drawing (:mod:`thorvald_design.report.views`, :mod:`thorvald_design.report.plan`,
:mod:`thorvald_design.report.table`); this module only draws it.
"""

import math
import textwrap
from dataclasses import dataclass
from typing import Any, Dict, List, Optional, Sequence, Tuple

import matplotlib
import matplotlib.cm
import matplotlib.colors
import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import Circle, Polygon

from ..geometry import Point
from .plan import Shape, WorldMap, outcome_colours, view
from .table import Column, ParetoPlane, Sweep, _text, combination, direction_word, number, why_not
from .tracks import Tracks
from .views import (
    Comparison,
    SideTry,
    TurnView,
    circle,
    disagrees,
    side_series,
    try_text,
    turn_colour_index,
    turn_legend,
)

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
SERIES = ("#0072b2", "#d55e00", "#009e73", "#cc79a7", "#e69f00", "#56b4e9", "#7f7f7f", "#000000")
SLOPE = "#b08850"
HEADINGS = 8  # heading arrows along a track


# ---- a plot, its figure and its file -----------------------------------------------------------------
@dataclass(frozen=True)
class Plot:
    """A plot written to DIR/plots: its file, what the page says of it."""

    path: str
    caption: str


def _plan_axes(ax, xs: Tuple[float, float], ys: Tuple[float, float], title: str) -> None:
    """A plan view's axes: the extent xs by ys, one metre the same both ways, the axes named."""
    ax.set_xlim(*xs)
    ax.set_ylim(*ys)
    ax.set_aspect("equal", adjustable="box")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title)


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


def _axis_label(metric: Column) -> str:
    word = direction_word(metric.column)
    return metric.column + (f"  ({word})" if word else "")


def plot_metric(metric: Column, path: str) -> None:
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


def plot_sweep(sweep: Sweep, metric: Column, path: str) -> None:
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
    _plan_axes(ax, (x0, x1), (y0, y1), title)
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
    _plan_axes(ax, (lo_x - margin, hi_x + margin), (lo_y - margin, hi_y + margin), title)
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
    _plan_axes(ax, (x0, x1), (y0, y1), title)
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


__all__ = [
    "GAP",
    "RC",
    "Plot",
    "plot_comparison",
    "plot_headland",
    "plot_metric",
    "plot_pareto",
    "plot_side",
    "plot_sweep",
    "plot_tracks",
    "plot_turning",
    "side_exaggeration",
]
