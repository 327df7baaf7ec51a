"""Searching a candidate's design space instead of sweeping it: a multi-objective search over the
candidate's sweep that runs a few of its combinations, chosen from the results of those already run,
where a sweep runs every one. The study file's ``optimise:`` section that asks for it is read and
checked in :mod:`thorvald_design.optimise_spec`.

A sweep of k values of each of n key paths is k^n candidates, each through every scenario; past a few
key paths that is more runs than a day holds (the study refuses more than ``MAX_CANDIDATES``). A
search runs ``trials`` combinations, and stops a combination's runs at the first requirement it
fails::

    optimise:
      candidate: wide            # a candidate with a sweep: the sweep is the search space
      objectives: {gradeability.max_climb_deg: max, turning.turning_diameter_m: min}   # 2 or 3
      requirements: {gradeability.max_climb_deg: ">= 15", headland.min_headland_m: "<= 6"}   # hard
      trials: 20

The candidate's sweep gives each key path's values: a list is the choices (categorical, as the sweep
would run them); ``{min: 0.5, max: 1.0}`` (:func:`thorvald_design.optimise_spec.parse_range`) is a
continuous range, which only a search can take. A requirement is ``">= NUMBER"``, ``"<= NUMBER"``,
``"> NUMBER"`` or ``"< NUMBER"``, quoted: YAML reads a bare ``>`` as the start of a folded block.

``trials`` counts combinations run: the sampler may propose one already tried, which is told its
earlier results again at no runs (runs are deterministic: the study's seed fixes sensor noise and
the as-built draw), and the search goes on until ``trials`` different combinations have been tried,
every combination of a smaller space, or the sampler has proposed ``MAX_ASKS`` times as many.

Why optuna: a well-kept, widely used library with multi-objective samplers that take categorical and
continuous key paths alike and are seeded (the same study gives the same trials), and an ask-and-tell
interface that leaves the runs to us: each trial's combination is asked for, run here scenario by
scenario, and its objectives told back. Of its samplers, NSGA-II (``NSGAIISampler``, Deb et al. 2002)
is the textbook multi-objective algorithm, but a genetic algorithm needs generations of a population
(optuna's default is 50: a search of fewer trials is random sampling). Multivariate TPE
(``TPESampler(multivariate=True)``; multi-objective TPE, Ozaki et al. 2020) finds more of the front
for the runs at a design study's budgets: on synthetic fronts of 20 points (400 combinations, 2
objectives) and 49 (343, 3 objectives), averaged over 6 to 8 seeds, 100 trials of TPE found 18.6 of
the 20 where NSGA-II found 13.5 (population 20) to 16.9 (population 4) and random sampling 4.1; 80
trials, 31 of the 49 where NSGA-II found 22 to 26 and random sampling 12. TPE also learns from pruned
trials (it counts them among the worse), which NSGA-II ignores.

Pruning: optuna's pruning API (``Trial.report``, ``Trial.should_prune``) is for one objective only and
raises for several. A trial that fails a requirement, or whose objective is not a number (``"n/a:
..."``, ``"failed: ..."``), is told to the study as ``TrialState.PRUNED`` with no values (``study.tell(
trial, state=TrialState.PRUNED)``), which a multi-objective study accepts: it is on no front
(``study.best_trials`` holds complete trials only). Its remaining scenarios are not run: the runs
saved; the requirements' scenarios are best first in the order the search is given.

Pure but for the runs: ``evaluate`` runs them (the simulator, in the study). optuna is imported on
first use (0.1 s after numpy, 0.2 s alone: SQLAlchemy and alembic come with it), so reading a study
file does not pay for it, nor a study without ``optimise:`` need it installed. What this module
refuses is a :class:`~thorvald_design.errors.SearchError`.
"""

import itertools
import math
import warnings
from dataclasses import dataclass
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple, Union

from .errors import SearchError
from .optimise_spec import DIRECTIONS, OptimiseSpec, Range
from .scenarios import SCENARIOS

MAX_ASKS = 10  # [proposals a trial] the sampler may propose combinations already tried: so many in all at most


# ---- the search ---------------------------------------------------------------------------------------
Space = Sequence[Tuple[str, Union[Sequence[float], Range]]]  # (key path, its choices or range), in order
Metrics = Mapping[str, Any]  # a run's metrics by name (results.json's), or "failed: why" for the whole run
Evaluate = Callable[[Dict[str, float], str], Union[Metrics, str]]


@dataclass(frozen=True)
class Trial:
    """One combination the search tried."""

    number: int  # its index in OptimiseResult.trials
    values: Tuple[Tuple[str, float], ...]  # (key path, value), in the space's order (as Candidate.swept)
    metrics: Dict[str, Any]  # SCENARIO.METRIC -> value, of the scenarios it got to
    state: str  # "complete" or "pruned"
    reason: str = ""  # why it was pruned: the requirement it failed, or the objective that is no number
    objectives: Optional[Tuple[float, ...]] = None  # in the spec's order; None when pruned
    runs: int = 0  # evaluate calls it made
    saved: int = 0  # scenarios it did not get to, being pruned


@dataclass(frozen=True)
class OptimiseResult:
    objectives: Tuple[Tuple[str, str], ...]
    trials: Tuple[Trial, ...]
    front: Tuple[int, ...]  # the complete trials on the Pareto front found, by number
    runs: int  # evaluate calls in all
    asked: int  # combinations the sampler proposed, those proposed again included

    @property
    def saved(self) -> int:
        """Runs pruning spared (the scenarios pruned trials did not get to)."""
        return sum(t.saved for t in self.trials)

    def as_dict(self) -> Dict[str, Any]:
        """For results.json: plain lists and mappings."""
        return {
            "objectives": dict(self.objectives),
            "runs": self.runs,
            "saved": self.saved,
            "asked": self.asked,
            "front": list(self.front),
            "trials": [
                {
                    "number": t.number,
                    "values": dict(t.values),
                    "state": t.state,
                    "reason": t.reason,
                    "runs": t.runs,
                    "saved": t.saved,
                    "metrics": dict(t.metrics),
                }
                for t in self.trials
            ],
        }


def optimise(
    spec: OptimiseSpec, space: Space, evaluate: Evaluate, scenario_order: Sequence[str], seed: int = 0
) -> OptimiseResult:
    """Searches the space for the Pareto front of the spec's objectives among the combinations that
    meet its requirements: ``spec.trials`` combinations chosen by optuna's multivariate TPE, seeded.

    Each trial's combination (key path -> value) is run scenario by scenario in ``scenario_order``:
    ``evaluate(values, scenario)`` gives the run's metrics by name (``max_climb_deg``), or a string
    for a run that failed whole (as :func:`thorvald_design.runs.run_one`'s ``result``). After each
    scenario the requirements and objectives of its metrics are checked, and the trial is pruned at
    the first that fails: its later scenarios are not run. The front is ``study.best_trials``, one
    trial a combination. SearchError for a space or scenario order the spec does not fit (a metric of
    a scenario not in the order, an empty space)."""
    optuna = _optuna()
    distributions = _distributions(space, optuna)
    scenarios = list(scenario_order)
    for metric in spec.metrics:
        if metric.split(".")[0] not in scenarios:
            raise SearchError(f"optimise: {metric} is of no scenario in the order {scenarios}")
    study = optuna.create_study(directions=[DIRECTIONS[d] for _, d in spec.objectives], sampler=_sampler(seed))
    size = _grid_size(space)
    wanted = spec.trials if size is None else min(spec.trials, size)
    tried: Dict[Tuple[float, ...], Trial] = {}
    asked = 0
    while len(tried) < wanted and asked < MAX_ASKS * spec.trials:
        ask = study.ask(distributions)
        asked += 1
        values = {key: float(ask.params[key]) for key in distributions}
        trial = tried.get(tuple(values.values()))
        if trial is None:  # a combination not tried yet: its runs
            trial = _run_trial(len(tried), values, spec, scenarios, evaluate)
            tried[tuple(values.values())] = trial
        if trial.objectives is None:
            study.tell(ask, state=optuna.trial.TrialState.PRUNED)
        else:
            study.tell(ask, list(trial.objectives))
    trials = tuple(tried.values())
    front = sorted({tried[tuple(float(t.params[k]) for k in distributions)].number for t in study.best_trials})
    return OptimiseResult(spec.objectives, trials, tuple(front), sum(t.runs for t in trials), asked)


def _sampler(seed: int) -> Any:
    """Multivariate TPE (the module's docstring says why), seeded. optuna before 5 calls its
    ``multivariate`` argument experimental, with a warning a search (optuna 4.5 is the last release
    for Python 3.8, Noetic's): that is known here, and not the user's to act on."""
    optuna = _optuna()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", optuna.exceptions.ExperimentalWarning)
        return optuna.samplers.TPESampler(seed=seed, multivariate=True)


def _run_trial(
    number: int, values: Dict[str, float], spec: OptimiseSpec, scenarios: Sequence[str], evaluate: Evaluate
) -> Trial:
    metrics: Dict[str, Any] = {}
    pairs = tuple(values.items())
    for done, scenario in enumerate(scenarios, start=1):
        metrics.update(_named(evaluate(dict(values), scenario), scenario, spec))
        reason = _failure(spec, scenario, metrics)
        if reason:
            return Trial(number, pairs, metrics, "pruned", reason, None, done, len(scenarios) - done)
    objectives = tuple(float(metrics[m]) for m, _ in spec.objectives)
    return Trial(number, pairs, metrics, "complete", "", objectives, len(scenarios), 0)


def _named(result: Union[Metrics, str], scenario: str, spec: OptimiseSpec) -> Dict[str, Any]:
    """A run's metrics as SCENARIO.METRIC; a run that failed whole gives its string to every metric."""
    if isinstance(result, str):
        names = SCENARIOS[scenario].results if scenario in SCENARIOS else ()
        wanted = [m.split(".", 1)[1] for m in spec.metrics if m.split(".")[0] == scenario]
        return {f"{scenario}.{name}": result for name in list(names) + [w for w in wanted if w not in names]}
    if not isinstance(result, Mapping):
        raise SearchError(f"optimise: evaluate gave {type(result).__name__} for {scenario}: a mapping or a string")
    named = {f"{scenario}.{name}": value for name, value in result.items()}
    for metric in spec.metrics:
        if metric.split(".")[0] == scenario and metric not in named:
            raise SearchError(f"optimise: evaluate gave no {metric.split('.', 1)[1]} for {scenario}: {sorted(result)}")
    return named


def _failure(spec: OptimiseSpec, scenario: str, metrics: Mapping[str, Any]) -> str:
    """Why the trial stops after the scenario: the first requirement of its metrics that fails, or
    the first of its objectives that is no number; "" if none."""
    for requirement in spec.requirements:
        if requirement.metric.split(".")[0] == scenario and not requirement.met(metrics[requirement.metric]):
            value = metrics[requirement.metric]
            shown = f"{value:g}" if _number(value) else repr(value)
            return f"{requirement.metric} = {shown}: not {requirement.op} {requirement.bound:g}"
    for metric, _ in spec.objectives:
        if metric.split(".")[0] == scenario and not _number(metrics[metric]):
            return f"{metric} = {metrics[metric]!r}: an objective must be a number"
    return ""


def _grid_size(space: Space) -> Optional[int]:
    """How many combinations a space of choices has; None for one with a range."""
    if any(isinstance(dimension, Range) for _, dimension in space):
        return None
    return math.prod(len(dimension) for _, dimension in space)


def _distributions(space: Space, optuna: Any) -> Dict[str, Any]:
    if not space:
        raise SearchError("optimise: the space is empty (the candidate's sweep names no key path)")
    out = {}
    for key_path, dimension in space:
        if key_path in out:
            raise SearchError(f"optimise: {key_path} is twice in the space")
        if isinstance(dimension, Range):
            if not dimension.min < dimension.max:
                raise SearchError(f"optimise: {key_path}: the range's min must be < its max")
            out[key_path] = optuna.distributions.FloatDistribution(dimension.min, dimension.max)
        else:
            choices = tuple(float(v) for v in dimension)
            if not choices or len(set(choices)) != len(choices):
                raise SearchError(f"optimise: {key_path}: the choices must be values that differ, at least one")
            out[key_path] = optuna.distributions.CategoricalDistribution(choices)
    return out


def _optuna() -> Any:
    """optuna, imported on first use, its INFO lines (one a trial) silenced."""
    import optuna  # noqa: PLC0415 (0.2 s: only a search pays for it)

    optuna.logging.set_verbosity(optuna.logging.WARNING)
    return optuna


def _number(value: Any) -> bool:
    return isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)


# ---- a full sweep's front, and the search against it ---------------------------------------------------
@dataclass(frozen=True)
class SweepFront:
    """Every combination of a space with its metrics, and the Pareto front among those that meet the
    requirements."""

    objectives: Tuple[Tuple[str, str], ...]
    values: Tuple[Tuple[Tuple[str, float], ...], ...]  # each combination's (key path, value)
    metrics: Tuple[Dict[str, Any], ...]  # each combination's SCENARIO.METRIC -> value
    feasible: Tuple[int, ...]  # the combinations that meet the requirements, their objectives numbers
    front: Tuple[int, ...]  # the feasible ones on the Pareto front
    runs: int  # the runs of the sweep (one a combination and scenario)


def grid(space: Space) -> List[Dict[str, float]]:
    """Every combination of a space of choices (key path -> value), in a sweep's order; SearchError
    for a range (no sweep runs one)."""
    for key_path, dimension in space:
        if isinstance(dimension, Range):
            raise SearchError(f"optimise: {key_path} is a range: no sweep runs every value of it")
    keys = [key_path for key_path, _ in space]
    return [dict(zip(keys, (float(v) for v in combo))) for combo in itertools.product(*(d for _, d in space))]


def sweep_front(
    spec: OptimiseSpec, points: Sequence[Tuple[Mapping[str, float], Mapping[str, Any]]], runs: Optional[int] = None
) -> SweepFront:
    """The Pareto front of a full sweep by the spec's objectives and requirements: points are each
    combination's (key path -> value, SCENARIO.METRIC -> value), e.g. a sweep study's results.json
    read back; runs: the sweep's, by default one a scenario a point's metrics are of."""
    feasible = [
        i
        for i, (_, metrics) in enumerate(points)
        if all(r.met(metrics.get(r.metric)) for r in spec.requirements)
        and all(_number(metrics.get(m)) for m, _ in spec.objectives)
    ]
    vectors = [[float(points[i][1][m]) for m, _ in spec.objectives] for i in feasible]
    front = tuple(feasible[j] for j in pareto_front(vectors, _signs(spec.objectives)))
    if runs is None:
        runs = sum(len({name.split(".")[0] for name in metrics}) for _, metrics in points)
    return SweepFront(
        spec.objectives,
        tuple(tuple((k, float(v)) for k, v in values.items()) for values, _ in points),
        tuple(dict(metrics) for _, metrics in points),
        tuple(feasible),
        front,
        runs,
    )


def full_sweep(spec: OptimiseSpec, space: Space, evaluate: Evaluate, scenario_order: Sequence[str]) -> SweepFront:
    """Runs every combination of the space through every scenario (no pruning: a sweep's runs) and
    gives its front: what a search is compared with (:func:`compare`)."""
    points = []
    for values in grid(space):
        metrics: Dict[str, Any] = {}
        for scenario in scenario_order:
            metrics.update(_named(evaluate(dict(values), scenario), scenario, spec))
        points.append((values, metrics))
    return sweep_front(spec, points, runs=len(points) * len(scenario_order))


SIGNS = {"max": +1, "min": -1}  # an objective's direction as pareto_front's


def pareto_front(points: Sequence[Sequence[float]], directions: Sequence[int]) -> List[int]:
    """The indices (ascending) of the points no other point dominates: the one Pareto front of the
    package (the search's, the sweep's, the report's plot).

    directions: per coordinate, +1 if larger is better, -1 if smaller is. A point dominates another
    when it is at least as good in every coordinate and better in one; equal points dominate neither,
    so both are on the front. SearchError for a direction not +-1, a point of another length than the
    directions, or a coordinate that is not a finite number.
    """
    if any(d not in (1, -1) for d in directions):
        raise SearchError(f"directions must be +1 or -1, not {list(directions)}")
    scored = []
    for i, point in enumerate(points):
        if len(point) != len(directions):
            raise SearchError(f"point {i} has {len(point)} coordinates, the directions {len(directions)}")
        if not all(_finite(v) for v in point):
            raise SearchError(f"point {i} is not finite numbers: {list(point)}")
        scored.append(tuple(d * float(v) for d, v in zip(directions, point)))
    return [i for i, p in enumerate(scored) if not any(_better(q, p) for q in scored)]


def dominates(a: Sequence[float], b: Sequence[float], directions: Sequence[int]) -> bool:
    """Whether point a dominates point b (directions as :func:`pareto_front`'s)."""
    return _better([d * x for d, x in zip(directions, a)], [d * y for d, y in zip(directions, b)])


def _better(a: Sequence[float], b: Sequence[float]) -> bool:
    return all(x >= y for x, y in zip(a, b)) and any(x > y for x, y in zip(a, b))


def _finite(value: Any) -> bool:
    return not isinstance(value, bool) and isinstance(value, (int, float)) and math.isfinite(value)


def _signs(objectives: Sequence[Tuple[str, str]]) -> List[int]:
    return [SIGNS[d] for _, d in objectives]


def compare(optimised: OptimiseResult, full: SweepFront) -> Dict[str, Any]:
    """The search against the full sweep of its space: the runs each took; how many of the sweep's
    front the search's front holds (the same combination); for each point of the sweep's front, in
    order, its distance to the nearest point of the search's front in objective space, each objective
    divided by its range over the sweep's feasible combinations (0: found; None when the search found
    no front); and how many of the search's front points the sweep's front dominates (combinations
    the search took for the front for want of a better one)."""
    if optimised.objectives != full.objectives:
        raise SearchError("compare: the search and the sweep have different objectives")
    directions = _signs(full.objectives)
    names = [m for m, _ in full.objectives]
    found_points = [optimised.trials[n] for n in optimised.front]
    found_values = {t.values for t in found_points}
    found_vectors = [list(t.objectives or ()) for t in found_points]
    front_vectors = [[float(full.metrics[i][m]) for m in names] for i in full.front]
    feasible_vectors = [[float(full.metrics[i][m]) for m in names] for i in full.feasible]
    scales = []
    for k in range(len(names)):
        column = [v[k] for v in feasible_vectors]
        spread = (max(column) - min(column)) if column else 0.0
        scales.append(spread if spread > 0 else 1.0)
    distances: List[Optional[float]] = []
    for vector in front_vectors:
        if not found_vectors:
            distances.append(None)
            continue
        nearest = min(math.sqrt(sum(((a - b) / s) ** 2 for a, b, s in zip(vector, f, scales))) for f in found_vectors)
        distances.append(nearest)
    known = [d for d in distances if d is not None]
    dominated = sum(any(dominates(f, v, directions) for f in front_vectors) for v in found_vectors)
    return {
        "runs": {"search": optimised.runs, "sweep": full.runs, "saved_by_pruning": optimised.saved},
        "trials": {
            "all": len(optimised.trials),
            "complete": sum(t.state == "complete" for t in optimised.trials),
            "pruned": sum(t.state == "pruned" for t in optimised.trials),
        },
        "front": {
            "sweep": len(full.front),
            "found": sum(full.values[i] in found_values for i in full.front),
            "search": len(found_points),
            "dominated": dominated,
        },
        "distances": distances,
        "max_distance": max(known) if known else None,
        "mean_distance": sum(known) / len(known) if known else None,
        "scales": dict(zip(names, scales)),
    }


__all__ = [
    "OptimiseResult",
    "SweepFront",
    "Trial",
    "compare",
    "dominates",
    "full_sweep",
    "grid",
    "optimise",
    "pareto_front",
    "sweep_front",
]
