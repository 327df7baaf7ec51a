"""The report's page (``DIR/report.html``), pure: the results, the study and the images (PNG bytes)
in, one HTML text out, the same for the same arguments.
"""

import base64
import html
import os
from dataclasses import dataclass
from typing import Any, Mapping, Optional, Sequence, Tuple

from ..scenarios import SCENARIOS
from ..study import Study
from .table import _text, best, combination, metrics, number
from .views import TurnRow


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
