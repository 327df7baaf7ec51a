"""thorvald_design.optimise_spec and thorvald_design.optimise: the study file's optimise: section, and
the search on a synthetic study whose Pareto front is known in closed form (no simulator: ``evaluate``
is arithmetic).

The synthetic study: a track of 0.5 to 0.9 m and a wheel radius of 0.2 to 0.3 m (15 combinations);
climb [deg] = 10 + 20 (track - 0.5) + 40 (r_wheel - 0.2), turning diameter [m] = 2 track + 1. The
diameter depends on the track alone and the climb grows with the radius, so at each track the
largest wheel is best; across tracks both grow, so none of those dominates another: the front
(climb max, diameter min) is the five combinations of r_wheel 0.3. Climbs are even numbers from 10
to 22; requiring >= 15 takes the 6 combinations of climb 10 to 14 away, track 0.5 among them: the
front is then the four of r_wheel 0.3 and track 0.6 to 0.9.
"""

import json
import math
import subprocess
import sys
from typing import Any, Dict, List, Optional, Tuple

import pytest
import yaml

from thorvald_design.optimise import OptimiseResult, Trial, compare, full_sweep, grid, optimise, pareto_front
from thorvald_design.optimise_spec import (
    REQUIREMENT_RULE,
    OptimiseSpec,
    Range,
    Requirement,
    parse_optimise,
    parse_range,
)
from thorvald_model.errors import MISSING, Problem

TRACK, R_WHEEL = "motor_drives.*.y", "motor_drives.*.r_wheel"
TRACKS = (0.5, 0.6, 0.7, 0.8, 0.9)
RADII = (0.2, 0.25, 0.3)
SPACE = ((TRACK, TRACKS), (R_WHEEL, RADII))
ORDER = ("gradeability", "turning")
CLIMB, DIAMETER = "gradeability.max_climb_deg", "turning.turning_diameter_m"
OBJECTIVES = ((CLIMB, "max"), (DIAMETER, "min"))
TRUE_FRONT = {((TRACK, t), (R_WHEEL, 0.3)) for t in TRACKS}
TRUE_FRONT_CLIMB_15 = {((TRACK, t), (R_WHEEL, 0.3)) for t in TRACKS if t >= 0.6}


def climb(track: float, r_wheel: float) -> float:
    return 10 + 20 * (track - 0.5) + 40 * (r_wheel - 0.2)


class Synthetic:
    """evaluate(values, scenario) of the synthetic study; every call recorded."""

    def __init__(self, strings: Optional[Dict[Tuple[float, float], Any]] = None):
        self.calls: List[Tuple[Tuple[float, float], str]] = []
        self.strings = strings or {}  # (track, r_wheel) -> what gradeability gives instead of numbers

    def __call__(self, values: Dict[str, float], scenario: str):
        point = (values[TRACK], values[R_WHEEL])
        self.calls.append((point, scenario))
        if scenario == "gradeability":
            if point in self.strings:
                return self.strings[point]
            return {"max_climb_deg": climb(*point), "limited_by": "traction"}
        return {"turning_diameter_m": 2 * point[0] + 1, "turn": "spin"}


def spec(trials: int = 15, requirements=()) -> OptimiseSpec:
    return OptimiseSpec("wide", OBJECTIVES, tuple(requirements), trials)


def front_values(result: OptimiseResult):
    return {result.trials[n].values for n in result.front}


# ---- the study file's section -----------------------------------------------------------------------
OBJ = "objectives: {gradeability.max_climb_deg: max, turning.turning_diameter_m: min}"
CANDIDATES = {"wide": {"robot": "thorvald_ii_4wd4ws_std", "sweep": {TRACK: [0.6, 0.9]}}, "std": {"robot": "x"}}


def parsed(text: str, **kwargs) -> Tuple[Any, List[Problem]]:
    problems: List[Problem] = []
    return parse_optimise(yaml.safe_load(text), "optimise", problems, **kwargs), problems


def test_a_section_names_the_candidate_its_objectives_requirements_and_trials():
    result, problems = parsed(
        """
        candidate: wide
        objectives: {gradeability.max_climb_deg: max, turning.turning_diameter_m: min, drawbar.max_pull_n: max}
        requirements:
          {gradeability.max_climb_deg: ">= 15", turning.turning_diameter_m: "<=6", drawbar.max_pull_n: "> 1e3"}
        trials: 40
        """,
        candidates=CANDIDATES,
        scenarios=["gradeability", "turning", "drawbar"],
    )
    assert problems == []
    assert result == OptimiseSpec(
        "wide",
        ((CLIMB, "max"), (DIAMETER, "min"), ("drawbar.max_pull_n", "max")),
        (
            Requirement(CLIMB, ">=", 15.0),
            Requirement(DIAMETER, "<=", 6.0),
            Requirement("drawbar.max_pull_n", ">", 1000),
        ),
        40,
    )
    assert str(result.requirements[0]) == "gradeability.max_climb_deg >= 15"
    assert result.requirements[0].met(15.0) and not result.requirements[0].met(14.9)
    assert not result.requirements[0].met("n/a: no slope") and not result.requirements[0].met(math.nan)


def test_requirements_are_optional_and_trials_default_to_20():
    result, problems = parsed(f"{{candidate: wide, {OBJ}}}")
    assert problems == [] and result.requirements == () and result.trials == 20


def test_no_section_is_no_search_and_no_problem():
    problems: List[Problem] = []
    assert parse_optimise(MISSING, "optimise", problems) is None
    assert parse_optimise(None, "optimise", problems) is None
    assert problems == []


@pytest.mark.parametrize(
    "text, path, rule",
    [
        (f"{{candidate: wide, {OBJ}, trails: 5}}", "optimise.trails", "unknown key (did you mean 'trials'?)"),
        ("{candidate: wide, objectives: {gradeability.max_climb: max, turning.turning_diameter_m: min}}",
         "optimise.objectives.gradeability.max_climb", "unknown key (did you mean 'gradeability.max_climb_deg'?)"),
        ("{candidate: wide, objectives: {gradeability.max_climb_deg: maximise, turning.turning_diameter_m: min}}",
         "optimise.objectives.gradeability.max_climb_deg", "must be max or min"),
        ("{candidate: wide, objectives: {gradeability.max_climb_deg: max}}",
         "optimise.objectives", "must be a mapping of 2 or 3 of SCENARIO.METRIC: max or min"),
        ("{candidate: wide}", "optimise.objectives", "is required: 2 or 3 of SCENARIO.METRIC: max or min"),
        (f"{{{OBJ}}}", "optimise.candidate", "is required"),
        (f"{{candidate: wide, {OBJ}, requirements: {{gradeability.max_climb_deg: at least 15}}}}",
         "optimise.requirements.gradeability.max_climb_deg", REQUIREMENT_RULE),
        (f"{{candidate: wide, {OBJ}, requirements: {{gradeability.max_climb_deg: 15}}}}",
         "optimise.requirements.gradeability.max_climb_deg", REQUIREMENT_RULE),
        (f"{{candidate: wide, {OBJ}, requirements: [gradeability.max_climb_deg]}}",
         "optimise.requirements", "must be a mapping of SCENARIO.METRIC: '>= NUMBER' (or <=, >, <)"),
        (f"{{candidate: wide, {OBJ}, requirements: {{weeding.gap_m: '<= 6'}}}}",
         "optimise.requirements.weeding.gap_m", "unknown key (known keys: "),
        (f"{{candidate: wide, {OBJ}, trials: 0}}", "optimise.trials", "must be in [1, 1000]"),
        (f"{{candidate: wide, {OBJ}, trials: many}}", "optimise.trials", "must be an integer"),
        (f"{{candidate: wdie, {OBJ}}}", "optimise.candidate", "no candidate of that name (did you mean 'wide'?)"),
        (f"{{candidate: zzz, {OBJ}}}", "optimise.candidate",
         "no candidate of that name (the study's candidates: wide, std)"),
        (f"{{candidate: std, {OBJ}}}", "optimise.candidate", "the candidate has no sweep"),
        (f"{{candidate: wide, {OBJ}, requirements: {{drawbar.max_pull_n: '>= 500'}}}}",
         "optimise.requirements.drawbar.max_pull_n",
         "the study has no scenario 'drawbar' (its scenarios: gradeability, turning)"),
        ("[candidate, wide]", "optimise", "must be a mapping: candidate, objectives, requirements, trials"),
    ],
)  # fmt: skip
def test_a_broken_section_names_the_key_path_and_the_rule(text, path, rule):
    result, problems = parsed(text, candidates=CANDIDATES, scenarios=["gradeability", "turning"])
    assert result is None
    assert any(p.path == path and p.rule.startswith(rule) for p in problems), problems


def test_every_problem_of_a_section_is_reported_at_once():
    _, problems = parsed(
        "{candidate: wdie, objectives: {gradeability.max_climb: max, turning.turning_diameter_m: up},"
        " requirements: {gradeability.max_climb_deg: '=> 15'}, trials: -1, seed: 3}",
        candidates=CANDIDATES,
    )
    assert [p.path for p in problems] == [
        "optimise.seed",
        "optimise.trials",
        "optimise.candidate",
        "optimise.objectives.gradeability.max_climb",
        "optimise.objectives.turning.turning_diameter_m",
        "optimise.requirements.gradeability.max_climb_deg",
    ]


def test_a_range_is_min_and_max():
    problems: List[Problem] = []
    assert parse_range({"min": 0.5, "max": "1.0"}, "candidates.wide.sweep.motor_drives.*.y", problems) == Range(
        0.5, 1.0
    )
    assert problems == []


@pytest.mark.parametrize(
    "raw, path, rule",
    [
        ({"min": 1.0, "max": 0.5}, "s.max", "must be > min (1)"),
        ({"min": 0.5, "max": 0.5}, "s.max", "must be > min (0.5)"),
        ({"min": 0.5}, "s.max", "is required"),
        ({"min": 0.5, "mx": 1.0}, "s.mx", "unknown key (did you mean 'max'?)"),  # and s.max is required
        ({"min": "wide", "max": 1.0}, "s.min", "must be a finite number"),
        ({"min": 0.5, "max": float("inf")}, "s.max", "must be a finite number"),
        ("0.5 to 1", "s", "must be a list of values or a range {min: NUMBER, max: NUMBER}"),
    ],
)
def test_a_broken_range_names_the_key_path_and_the_rule(raw, path, rule):
    problems: List[Problem] = []
    assert parse_range(raw, "s", problems) is None
    assert next((p.path, p.rule) for p in problems) == (path, rule)


# ---- the search -----------------------------------------------------------------------------------------
def test_the_same_seed_gives_the_same_trials_and_another_seed_others():
    first = optimise(spec(10), SPACE, Synthetic(), ORDER, seed=3)
    again = optimise(spec(10), SPACE, Synthetic(), ORDER, seed=3)
    other = optimise(spec(10), SPACE, Synthetic(), ORDER, seed=4)
    assert first == again
    assert [t.values for t in first.trials] != [t.values for t in other.trials]


def test_trials_are_different_combinations_each_run_through_every_scenario():
    evaluate = Synthetic()
    result = optimise(spec(10), SPACE, evaluate, ORDER, seed=0)
    assert len(result.trials) == 10 == len({t.values for t in result.trials})
    assert result.asked >= 10 and result.runs == 20 == len(evaluate.calls)
    assert all(t.state == "complete" and t.runs == 2 and t.saved == 0 for t in result.trials)
    for t in result.trials:
        (_, track), (_, r_wheel) = t.values
        assert t.objectives == (climb(track, r_wheel), 2 * track + 1)
        assert t.metrics == {CLIMB: climb(track, r_wheel), "gradeability.limited_by": "traction",
                             DIAMETER: 2 * track + 1, "turning.turn": "spin"}  # fmt: skip


def test_a_trial_that_fails_a_requirement_is_pruned_and_runs_no_more_scenarios():
    evaluate = Synthetic()
    result = optimise(spec(15, [Requirement(CLIMB, ">=", 15)]), SPACE, evaluate, ORDER, seed=0)
    assert len(result.trials) == 15  # every combination
    pruned = [t for t in result.trials if t.state == "pruned"]
    assert {(dict(t.values)[TRACK], dict(t.values)[R_WHEEL]) for t in pruned} == {
        (p, r) for p in TRACKS for r in RADII if climb(p, r) < 15
    }
    for t in pruned:
        point = (dict(t.values)[TRACK], dict(t.values)[R_WHEEL])
        assert [s for p, s in evaluate.calls if p == point] == ["gradeability"]  # turning never ran
        assert t.runs == 1 and t.saved == 1 and t.objectives is None
        assert t.reason.startswith("gradeability.max_climb_deg = 1") and t.reason.endswith(": not >= 15")
        assert DIAMETER not in t.metrics
    assert len(pruned) == 6 and result.saved == 6
    assert result.runs == len(evaluate.calls) == 15 * 2 - 6
    assert not set(result.front) & {t.number for t in pruned}


def test_a_requirement_of_the_last_scenario_saves_no_runs_but_still_prunes():
    evaluate = Synthetic()
    result = optimise(spec(15, [Requirement(DIAMETER, "<", 2.5)]), SPACE, evaluate, ORDER, seed=0)
    pruned = [t for t in result.trials if t.state == "pruned"]
    assert {dict(t.values)[TRACK] for t in pruned} == {0.8, 0.9}
    assert all(t.runs == 2 and t.saved == 0 for t in pruned) and result.runs == 30
    assert front_values(result) == {((TRACK, t), (R_WHEEL, 0.3)) for t in (0.5, 0.6, 0.7)}


def test_a_metric_that_is_no_number_prunes_the_trial():
    strings = {(0.9, 0.3): {"max_climb_deg": "n/a: slipped at the foot", "limited_by": "traction"},
               (0.8, 0.3): "failed: broke: ZeroDivisionError (gradeability.py:1)"}  # fmt: skip
    evaluate = Synthetic(strings)
    result = optimise(spec(15), SPACE, evaluate, ORDER, seed=0)
    by_point = {(dict(t.values)[TRACK], dict(t.values)[R_WHEEL]): t for t in result.trials}
    assert by_point[0.9, 0.3].state == by_point[0.8, 0.3].state == "pruned"
    assert (
        by_point[0.9, 0.3].reason
        == "gradeability.max_climb_deg = 'n/a: slipped at the foot': an objective must be a number"
    )
    assert by_point[0.8, 0.3].metrics[CLIMB].startswith("failed: broke")
    assert [s for p, s in evaluate.calls if p in strings] == ["gradeability", "gradeability"]
    # with those two gone, nothing dominates (0.9, 0.25) (climb 20, diameter 2.8): they did
    assert ((TRACK, 0.9), (R_WHEEL, 0.25)) in front_values(result)


def test_with_as_many_trials_as_combinations_the_front_found_is_on_the_true_front():
    for seed in range(3):
        result = optimise(spec(15), SPACE, Synthetic(), ORDER, seed=seed)
        assert front_values(result) <= TRUE_FRONT
        assert front_values(result) == TRUE_FRONT  # every combination tried: all of it
        required = optimise(spec(20, [Requirement(CLIMB, ">=", 15)]), SPACE, Synthetic(), ORDER, seed=seed)
        assert front_values(required) == TRUE_FRONT_CLIMB_15 and len(required.trials) == 15


def test_a_smaller_search_finds_points_no_tried_combination_dominates():
    result = optimise(spec(8), SPACE, Synthetic(), ORDER, seed=1)
    complete = [t.objectives for t in result.trials if t.state == "complete"]
    found = [result.trials[n].objectives for n in result.front]
    assert set(pareto_front(complete, [1, -1])) == {complete.index(v) for v in found}


def test_a_range_is_searched_between_its_bounds():
    space = ((TRACK, Range(0.55, 0.85)), (R_WHEEL, RADII))
    result = optimise(spec(12), space, Synthetic(), ORDER, seed=0)
    assert len(result.trials) == 12
    assert all(0.55 <= dict(t.values)[TRACK] <= 0.85 for t in result.trials)
    assert result == optimise(spec(12), space, Synthetic(), ORDER, seed=0)
    with pytest.raises(ValueError, match="is a range: no sweep runs every value of it"):
        grid(space)


def test_a_space_or_order_the_spec_does_not_fit_is_refused():
    with pytest.raises(ValueError, match=r"turning\.turning_diameter_m is of no scenario in the order"):
        optimise(spec(), SPACE, Synthetic(), ["gradeability"])
    with pytest.raises(ValueError, match="the space is empty"):
        optimise(spec(), (), Synthetic(), ORDER)
    with pytest.raises(ValueError, match="evaluate gave no turning_diameter_m for turning"):
        optimise(spec(), SPACE, lambda values, scenario: {"max_climb_deg": 1.0}, ORDER)


def test_a_result_is_plain_json():
    result = optimise(spec(4, [Requirement(CLIMB, ">=", 15)]), SPACE, Synthetic(), ORDER, seed=0)
    data = json.loads(json.dumps(result.as_dict()))
    assert data["runs"] == result.runs and len(data["trials"]) == 4
    assert data["objectives"] == {CLIMB: "max", DIAMETER: "min"}


# ---- the front and the comparison ---------------------------------------------------------------------
def test_the_front_keeps_what_nothing_dominates():
    points = [(1.0, 1.0), (2.0, 2.0), (2.0, 1.0), (2.0, 1.0), (0.5, 0.5)]
    assert pareto_front(points, [1, -1]) == [2, 3, 4]  # (2, 1) beats (1, 1) and (2, 2); equal ones both stay
    assert pareto_front(points, [-1, -1]) == [4]
    assert pareto_front([(1, 2, 3), (1, 2, 4), (0, 5, 5)], [-1, -1, 1]) == [1, 2]
    assert pareto_front([], [1, -1]) == []


def test_a_full_sweep_runs_every_combination_and_finds_the_true_front():
    evaluate = Synthetic()
    full = full_sweep(spec(requirements=[Requirement(CLIMB, ">=", 15)]), SPACE, evaluate, ORDER)
    assert full.runs == 30 == len(evaluate.calls)
    assert {full.values[i] for i in full.front} == TRUE_FRONT_CLIMB_15
    assert len(full.feasible) == 9


def trial(number: int, track: float, r_wheel: float) -> Trial:
    values = ((TRACK, track), (R_WHEEL, r_wheel))
    objectives = (climb(track, r_wheel), 2 * track + 1)
    return Trial(number, values, {CLIMB: objectives[0], DIAMETER: objectives[1]}, "complete", "", objectives, 2, 0)


def test_compare_counts_the_runs_the_points_found_and_how_far_the_others_are():
    full = full_sweep(spec(requirements=[Requirement(CLIMB, ">=", 15)]), SPACE, Synthetic(), ORDER)
    # found: the front's two ends, and (0.7, 0.25), which (0.7, 0.3) dominates
    search = OptimiseResult(OBJECTIVES, (trial(0, 0.6, 0.3), trial(1, 0.9, 0.3), trial(2, 0.7, 0.25)), (0, 1, 2), 6, 3)
    c = compare(search, full)
    assert c["runs"] == {"search": 6, "sweep": 30, "saved_by_pruning": 0}
    assert c["front"] == {"sweep": 4, "found": 2, "search": 3, "dominated": 1}
    # normalised by the feasible combinations' ranges: climb 16 to 22 (6 deg), diameter 2.2 to 2.8 m
    assert c["scales"] == pytest.approx({CLIMB: 6.0, DIAMETER: 0.6})
    # front in track order 0.6 .. 0.9; 0.7: 2 deg from (0.7, 0.25); 0.8: 2 deg and 0.2 m from (0.9, 0.3)
    assert c["distances"] == pytest.approx([0.0, 1 / 3, math.sqrt(2) / 3, 0.0])
    assert c["max_distance"] == pytest.approx(math.sqrt(2) / 3)
    assert c["mean_distance"] == pytest.approx((1 / 3 + math.sqrt(2) / 3) / 4)


def test_compare_a_search_with_the_sweep_of_its_space():
    requirements = [Requirement(CLIMB, ">=", 15)]
    full = full_sweep(spec(requirements=requirements), SPACE, Synthetic(), ORDER)
    c = compare(optimise(spec(15, requirements), SPACE, Synthetic(), ORDER, seed=0), full)
    assert c["runs"] == {"search": 24, "sweep": 30, "saved_by_pruning": 6}
    assert c["trials"] == {"all": 15, "complete": 9, "pruned": 6}
    assert c["front"] == {"sweep": 4, "found": 4, "search": 4, "dominated": 0}
    assert c["distances"] == [0.0] * 4
    nothing = OptimiseResult(OBJECTIVES, (), (), 0, 0)
    assert compare(nothing, full)["distances"] == [None] * 4 and compare(nothing, full)["max_distance"] is None


@pytest.mark.slow
def test_importing_the_module_does_not_import_optuna():
    code = "import sys, thorvald_design.optimise; print('optuna' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"
