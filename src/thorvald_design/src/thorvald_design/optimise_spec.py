"""A study file's ``optimise:`` section, read and checked (every problem with its key path, value and
rule, as the rest of the study file): which candidate's sweep a search explores, its objectives, its
hard requirements and how many combinations to try; and a sweep's ``{min, max}`` range, which only a
search runs. The search itself is :mod:`thorvald_design.optimise`.

::

    optimise:
      candidate: wide            # a candidate with a sweep: the sweep is the search space
      objectives: {gradeability.max_climb_deg: max, turning.turning_diameter_m: min}   # 2 or 3
      requirements: {gradeability.max_climb_deg: ">= 15", headland.min_headland_m: "<= 6"}   # hard
      trials: 20

The metrics are the scenarios' declared ones (:mod:`thorvald_design.scenarios`). A requirement is
``">= NUMBER"``, ``"<= NUMBER"``, ``"> NUMBER"`` or ``"< NUMBER"``, quoted: YAML reads a bare ``>`` as
the start of a folded block.

Pure: the study file's values in, frozen values out.
"""

import difflib
import math
import operator
import re
from dataclasses import dataclass
from typing import Any, List, Mapping, Optional, Sequence, Tuple

from thorvald_model.errors import MISSING, Problem
from thorvald_model.schema import Key, parse_entry, short, unknown_key_rule

from .scenarios import SCENARIOS

MAX_TRIALS = 1000  # [combinations] at most a few scenarios each: a week of runs on one machine
DEFAULT_TRIALS = 20
DIRECTIONS = {"max": "maximize", "min": "minimize"}  # an objective's, as optuna names them
OPERATORS = {">=": operator.ge, "<=": operator.le, ">": operator.gt, "<": operator.lt}
REQUIREMENT_RULE = "must be '>= NUMBER', '<= NUMBER', '> NUMBER' or '< NUMBER' (quoted: YAML reads a bare > as a block)"
_REQUIREMENT = re.compile(r"^\s*(>=|<=|>|<)\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*$")

KEYS = (
    Key("candidate", str),
    Key("trials", int, DEFAULT_TRIALS, check=lambda v: 1 <= v <= MAX_TRIALS, rule=f"must be in [1, {MAX_TRIALS}]"),
)
KNOWN = ("candidate", "objectives", "requirements", "trials")
RANGE_KEYS = (Key("min", float), Key("max", float))


@dataclass(frozen=True)
class Range:
    """A key path's continuous range [min, max] (the sweep's ``{min: ..., max: ...}``)."""

    min: float
    max: float


@dataclass(frozen=True)
class Requirement:
    """A hard requirement on a metric: ``metric op bound``, e.g. gradeability.max_climb_deg >= 15."""

    metric: str  # SCENARIO.METRIC
    op: str  # ">=", "<=", ">" or "<"
    bound: float

    def met(self, value: Any) -> bool:
        """Whether a metric's value meets it; a value that is not a finite number never does."""
        return _number(value) and OPERATORS[self.op](value, self.bound)

    def __str__(self) -> str:
        return f"{self.metric} {self.op} {self.bound:g}"


@dataclass(frozen=True)
class OptimiseSpec:
    """A study file's ``optimise:`` section, checked."""

    candidate: str  # the candidate whose sweep is the search space
    objectives: Tuple[Tuple[str, str], ...]  # (SCENARIO.METRIC, "max" or "min"), in file order
    requirements: Tuple[Requirement, ...] = ()
    trials: int = DEFAULT_TRIALS  # combinations to run (different ones)

    @property
    def metrics(self) -> Tuple[str, ...]:
        """Every metric the search reads: the objectives', then the requirements' not among them."""
        names = [m for m, _ in self.objectives]
        return tuple(names + [r.metric for r in self.requirements if r.metric not in names])


def parse_optimise(
    raw: Any,
    path: str,
    problems: List[Problem],
    *,
    candidates: Optional[Mapping[str, Any]] = None,
    scenarios: Optional[Sequence[str]] = None,
) -> Optional[OptimiseSpec]:
    """The ``optimise:`` section (``raw``, ``MISSING`` or None when the file has none: None), checked:
    a :class:`Problem` (key path, value, rule) appended to ``problems`` for each broken rule; None if
    any of the section's own.

    candidates: the study file's ``candidates`` section as read; when given, the named candidate must
    be one of them and have a sweep. scenarios: the study's scenario names; when given, every metric
    must be of one of them. Without either, the metrics are checked against the registry only.
    """
    if raw is MISSING or raw is None:
        return None
    found = len(problems)
    if not isinstance(raw, Mapping):
        problems.append(Problem(path, short(raw), "must be a mapping: candidate, objectives, requirements, trials"))
        return None
    for key in raw:
        if key not in KNOWN:
            problems.append(Problem(f"{path}.{key}", short(raw[key]), unknown_key_rule(key, KNOWN)))
    plain = {k: v for k, v in raw.items() if k in ("candidate", "trials")}
    values = parse_entry(plain, path, KEYS, problems)
    if values is not None and isinstance(candidates, Mapping):
        _check_candidate(values["candidate"], candidates, f"{path}.candidate", problems)
    objectives = _objectives(raw.get("objectives", MISSING), f"{path}.objectives", scenarios, problems)
    requirements = _requirements(raw.get("requirements", MISSING), f"{path}.requirements", scenarios, problems)
    if values is None or len(problems) > found:
        return None
    return OptimiseSpec(values["candidate"], objectives, requirements, values["trials"])


def parse_range(raw: Any, path: str, problems: List[Problem]) -> Optional[Range]:
    """A sweep's ``{min: NUMBER, max: NUMBER}`` (min < max) at key path ``path``; None (problems
    appended) if it is not one."""
    if not isinstance(raw, Mapping):
        problems.append(Problem(path, short(raw), "must be a list of values or a range {min: NUMBER, max: NUMBER}"))
        return None
    values = parse_entry(raw, path, RANGE_KEYS, problems)
    if values is None:
        return None
    if not values["min"] < values["max"]:
        problems.append(Problem(f"{path}.max", raw.get("max"), f"must be > min ({values['min']:g})"))
        return None
    return Range(values["min"], values["max"])


def _check_candidate(name: str, candidates: Mapping[str, Any], path: str, problems: List[Problem]) -> None:
    if name not in candidates:
        known = [str(k) for k in candidates]
        close = _close(name, known)
        hint = f"did you mean '{close}'?" if close else "the study's candidates: " + ", ".join(known)
        problems.append(Problem(path, name, f"no candidate of that name ({hint})"))
        return
    entry = candidates[name]
    if not isinstance(entry, Mapping) or not entry.get("sweep"):
        rule = "the candidate has no sweep: its sweep's lists (or {min, max} ranges) are the search space"
        problems.append(Problem(path, name, rule))


def _objectives(
    raw: Any, path: str, scenarios: Optional[Sequence[str]], problems: List[Problem]
) -> Tuple[Tuple[str, str], ...]:
    if raw is MISSING:
        problems.append(Problem(path, MISSING, "is required: 2 or 3 of SCENARIO.METRIC: max or min"))
        return ()
    if not isinstance(raw, Mapping) or not 2 <= len(raw) <= 3:
        problems.append(Problem(path, short(raw), "must be a mapping of 2 or 3 of SCENARIO.METRIC: max or min"))
        return ()
    out = []
    for metric, direction in raw.items():
        where = f"{path}.{metric}"
        if not _metric_ok(metric, direction, where, scenarios, problems):
            continue
        if direction not in DIRECTIONS:
            problems.append(Problem(where, short(direction), "must be max or min"))
            continue
        out.append((str(metric), direction))
    return tuple(out)


def _requirements(
    raw: Any, path: str, scenarios: Optional[Sequence[str]], problems: List[Problem]
) -> Tuple[Requirement, ...]:
    if raw is MISSING or raw is None:
        return ()
    if not isinstance(raw, Mapping):
        problems.append(Problem(path, short(raw), "must be a mapping of SCENARIO.METRIC: '>= NUMBER' (or <=, >, <)"))
        return ()
    out = []
    for metric, text in raw.items():
        where = f"{path}.{metric}"
        if not _metric_ok(metric, text, where, scenarios, problems):
            continue
        m = _REQUIREMENT.match(text) if isinstance(text, str) else None
        if m is None:
            problems.append(Problem(where, short(text), REQUIREMENT_RULE))
            continue
        out.append(Requirement(str(metric), m.group(1), float(m.group(2))))
    return tuple(out)


def _metric_ok(metric: Any, value: Any, path: str, scenarios: Optional[Sequence[str]], problems: List[Problem]) -> bool:
    columns = [f"{name}.{result}" for name, kind in SCENARIOS.items() for result in kind.results]
    if metric not in columns:
        problems.append(Problem(path, short(value), unknown_key_rule(metric, columns)))
        return False
    scenario = str(metric).split(".")[0]
    if scenarios is not None and scenario not in scenarios:
        rule = f"the study has no scenario {scenario!r} (its scenarios: {', '.join(scenarios) or 'none'})"
        problems.append(Problem(path, short(value), rule))
        return False
    return True


def _close(name: str, known: Sequence[str]) -> Optional[str]:
    close = difflib.get_close_matches(name, sorted(known), n=1, cutoff=0.6)
    return close[0] if close else None


def _number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


__all__ = [
    "DEFAULT_TRIALS",
    "DIRECTIONS",
    "MAX_TRIALS",
    "REQUIREMENT_RULE",
    "OptimiseSpec",
    "Range",
    "Requirement",
    "parse_optimise",
    "parse_range",
]
