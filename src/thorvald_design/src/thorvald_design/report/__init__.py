"""A design study's report: ``DIR/report.html``, one page that opens offline and prints, and the plots
it shows in ``DIR/plots/``.

What is on the page: the study's description; the results table (a column a candidate, a row a
metric, as the terminal's table, with each candidate's status, the best value of a row in bold); the
headland's turns, a row each (whether it works, its headland, the plants it touched, its time); each
metric that has a quasi-static prediction drawn beside it on one chart (``compare_*.png``: the last
try held, on to the first that failed, the prediction, and the prediction for the robot as simulated),
with a sentence for each candidate whose two are more than the study's step apart saying why
(:mod:`thorvald_design.report.views`); a picture of each candidate (``DIR/pictures/<safe name>.png``,
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

Its parts: the table and what each column holds, its direction read from the scenario's declared
metric (:mod:`thorvald_design.report.table`); the tracks files read back
(:mod:`thorvald_design.report.tracks`); the plan of a world (:mod:`thorvald_design.report.plan`);
what each figure shows, worked out before drawing: a limit beside its prediction, circles, side views,
turns (:mod:`thorvald_design.report.views`); the plots (:mod:`thorvald_design.report.plots`,
matplotlib's Agg canvas, no pyplot); the page (:mod:`thorvald_design.report.page`, pure). Here:
writing them all from DIR's files (:func:`write_report`).

The report knows no scenario by name but the headland's turns table: a metric's unit, direction and
prediction are its scenario's declaration (:mod:`thorvald_design.scenarios`), and what a drive's plot
shows is what its tracks file's marks say (a turn's circles, a headland's turns, a series' tries).
"""

import json
import os
import re
from typing import Any, Collection, Dict, List, Mapping, Optional, Sequence, Tuple

import matplotlib

from thorvald_model.errors import ThorvaldModelError
from thorvald_sim.world import parse_world

from ..runs import safe_name
from ..study import Study
from .page import Image, Sections, page_html
from .plan import world_map
from .plots import (
    RC,
    Plot,
    _short,
    plot_comparison,
    plot_headland,
    plot_metric,
    plot_pareto,
    plot_side,
    plot_sweep,
    plot_tracks,
    plot_turning,
)
from .table import _text, check_pareto, direction_word, metrics, number, pareto_plane, sweeps
from .tracks import Tracks, parse_tracks
from .views import Comparison, SideTry, comparisons, disagreement, headland_rows, side_try, turn_view

REPORT = "report.html"
PLOTS = "plots"
PICTURES = "pictures"
TRACKS = "tracks"


# ---- writing -----------------------------------------------------------------------------------------
def tracks_plot_path(out_dir: str, name: str, scenario: str) -> str:
    """Where the plot of one run's tracks goes: DIR/plots/tracks_<candidate>_<scenario>.png."""
    return os.path.join(out_dir, PLOTS, f"tracks_{safe_name(name)}_{scenario}.png")


def draw_tracks(out_dir: str, name: str, scenario: str) -> str:
    """Draws the plot of one run's tracks (DIR/tracks/<candidate>/<scenario>.json), the one the page
    shows for it; what went wrong ("" if nothing). A study's worker draws it as its run ends, so that
    the plots are drawn on every worker while the runs go on, not one after another after the last."""
    path = tracks_plot_path(out_dir, name, scenario)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with matplotlib.rc_context(RC):
        return _track_plot(f"{name}: {scenario}", out_dir, _tracks_source(name, scenario), path)


def _tracks_source(name: str, scenario: str) -> str:
    return os.path.join(TRACKS, safe_name(name), scenario + ".json")


def write_report(
    out_dir: str,
    results: Mapping,
    study: Study,
    pareto: Optional[Tuple[str, str]] = None,
    drawn: Collection[Tuple[str, str]] = (),
) -> str:
    """Writes DIR/plots/*.png and DIR/report.html from the results (results.json's contents) and the
    study; returns the page's path. pareto: two columns ("gradeability.max_climb_deg",
    "turning.turning_diameter_m") whose front to plot (ReportError if either is no column with a direction).
    drawn: the (candidate, scenario) runs whose tracks plot :func:`draw_tracks` drew from their
    tracks as they are now (this study's runs, drawn in its workers): kept, not drawn again."""
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
            metric_plots.append(Plot(path, f"{metric.column} ({direction_word(metric.column)})"
                                     if direction_word(metric.column) else metric.column))  # fmt: skip
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
            pareto_text = f"On the front of {pareto[0]} ({direction_word(plane.x.column)}) and {pareto[1]} " + (
                f"({direction_word(plane.y.column)}): {', '.join(front) if front else 'none'}."
            )
        track_plots: List[Tuple[str, List[Plot]]] = []
        for name in names:
            plots = []
            for scenario, _ in study.scenarios:
                source = _tracks_source(name, scenario)
                if not os.path.isfile(os.path.join(out_dir, source)):
                    continue
                path = tracks_plot_path(out_dir, name, scenario)
                if (name, scenario) in drawn and os.path.isfile(path):
                    problem = ""
                else:
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
    except ValueError as e:  # not JSON (json's ValueError), or not a tracks file (ReportError)
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


__all__ = ["PICTURES", "PLOTS", "REPORT", "TRACKS", "draw_tracks", "tracks_plot_path", "write_report"]
