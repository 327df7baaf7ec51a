"""A study's results as a table, and each of its columns as the report sees it.

The table: on the terminal (a row a metric, a column a candidate) and as ``results.csv`` (a row a
candidate, a column a metric: ``SCENARIO.METRIC``). A column (:class:`Column`): every candidate's
value as results.json holds it, and its metric's declaration (:func:`thorvald_design.scenarios.declared`:
which way is better, for the page's arrows, the best of a row and the Pareto front's directions); the
candidates of a sweep; the Pareto plane of two columns (its front is
:func:`thorvald_design.optimise.pareto_front`, the package's one).

Pure.
"""

import csv
import math
from dataclasses import dataclass
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

from ..errors import ReportError
from ..optimise import pareto_front
from ..scenarios import SCENARIOS, declared
from ..study import Candidate, Study


# ---- the table -----------------------------------------------------------------------------------------
def columns(study) -> List[str]:
    """The study's columns ``SCENARIO.METRIC``: each scenario's metrics, as its parameters give them."""
    return [f"{s}.{m}" for s, params in study.scenarios for m in SCENARIOS[s].columns(params)]


def rows(results: Mapping[str, Any], study) -> List[List[Any]]:
    out = []
    for name, entry in results["candidates"].items():
        row = [name, entry["status"], entry["mass_kg"]]
        for column in columns(study):
            scenario, metric = column.split(".", 1)
            value = entry["scenarios"].get(scenario)
            row.append(value.get(metric) if isinstance(value, Mapping) else value)
        out.append(row)
    return out


def write_csv(path: str, results: Mapping[str, Any], study) -> None:
    with open(path, "w", newline="", encoding="utf-8") as f:
        out = csv.writer(f)
        out.writerow(["candidate", "status", "mass_kg", *columns(study)])
        out.writerows(["" if v is None else v for v in row] for row in rows(results, study))


def results_table(results: Mapping[str, Any], study) -> str:
    """The results as a text table: a row a metric, a column a candidate (candidates are few, metrics many)."""
    names = list(results["candidates"])
    body = rows(results, study)
    lines = [["", *names], ["status", *[r[1] for r in body]], ["mass_kg", *[_text(r[2]) for r in body]]]
    for k, column in enumerate(columns(study)):
        lines.append([column, *[_text(r[3 + k]) for r in body]])
    widths = [max(len(line[i]) for line in lines) for i in range(len(lines[0]))]
    return "\n".join("  ".join(cell.ljust(w) for cell, w in zip(line, widths)).rstrip() for line in lines)


CELL = 40  # [characters] of a text cell on the terminal (results.json and the CSV keep it whole)


def _text(value: Any) -> str:
    if value is None:
        return "-"
    if isinstance(value, float):
        return f"{value:.3g}" if abs(value) < 1000 else f"{value:.0f}"
    text = " ".join(str(value).split())
    return text if len(text) <= CELL else text[: CELL - 3] + "..."


# ---- a column's values ---------------------------------------------------------------------------------
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


def direction(column: str) -> int:
    """+1 when more of a column's metric is better, -1 when less is, 0 for words (its scenario's
    declaration); a metric of one surface of several (``drawbar.max_pull_n.mud``) is its metric's."""
    metric = declared(column)
    return metric.direction if metric is not None else 0


def direction_word(column: str) -> str:
    return {+1: "larger is better", -1: "smaller is better"}.get(direction(column), "")


@dataclass(frozen=True)
class Column:
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
        return direction(self.column)

    def value(self, candidate: str) -> Any:
        return dict(self.values).get(candidate)


def metrics(results: Mapping[str, Any], study: Study) -> List[Column]:
    """Every column of the results table, in its order (:func:`columns`')."""
    table = rows(results, study)
    out = []
    for k, column in enumerate(columns(study)):
        scenario, name = column.split(".", 1)
        out.append(Column(column, scenario, name, tuple((row[0], row[3 + k]) for row in table)))
    return out


def best(metric: Column) -> Tuple[str, ...]:
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

    x: Column
    y: Column
    points: Tuple[Tuple[str, float, float], ...]  # (candidate, x, y)
    front: Tuple[int, ...]  # indices into points
    missing: Tuple[Tuple[str, str], ...]  # (candidate, why it has no point)


def check_pareto(pareto: Tuple[str, str], study: Study) -> None:
    """ReportError unless both are columns of the study's results whose metric has a better direction
    (its scenario's declaration)."""
    known = columns(study)
    if len(pareto) != 2:
        raise ReportError(f"pareto must be two columns, not {list(pareto)}")
    for column in pareto:
        if column not in known:
            raise ReportError(f"pareto: {column!r} is not a column of this study's results: {', '.join(known)}")
        if not direction(column):
            rule = "is not a metric with a better direction (its scenario declares none)"
            raise ReportError(f"pareto: {column!r} {rule}")


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


__all__ = [
    "CELL",
    "Column",
    "ParetoPlane",
    "Sweep",
    "best",
    "check_pareto",
    "columns",
    "combination",
    "direction",
    "direction_word",
    "metrics",
    "number",
    "pareto_plane",
    "results_table",
    "rows",
    "sweeps",
    "why_not",
    "write_csv",
]
