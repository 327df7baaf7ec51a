"""A study's results as a table: on the terminal, and as ``results.csv`` (one row a candidate, one
column a metric: ``SCENARIO.METRIC``). Pure."""

import csv
from typing import Any, List, Mapping

from .scenarios import SCENARIOS


def columns(study) -> List[str]:
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
