"""A new scenario is one module and one registry line. This test module is the module (its parameters,
its procedure, its metrics declared with their units, directions, meanings and the prediction one is
to agree with: ``HITCH``) and ``registered(HITCH)`` the line: the study file's keys and checks,
results.json, the terminal's table, the CSV, a search's objectives and the report follow it, the
report's arrows, best values, Pareto plane and measured-against-predicted chart from its declaration.
No simulator: its procedure is arithmetic on a stand-in for a candidate's design."""

import csv
import os
from types import SimpleNamespace

import pytest
import yaml

from thorvald_design.errors import ScenarioError, StudyError
from thorvald_design.optimise_spec import parse_optimise
from thorvald_design.report import write_report
from thorvald_design.report.table import results_table, write_csv
from thorvald_design.runs import empty_results, merge
from thorvald_design.scenarios import LARGER, SCENARIOS, WORDS, Metric, Prediction, ScenarioKind, registered
from thorvald_design.study import parse_study
from thorvald_model.schema import Key

# ---- the scenario's module -------------------------------------------------------------------------------
KEYS = (
    Key("step_kg", float, 50.0, check=lambda v: v > 0.0, rule="must be > 0 [kg]"),
    Key("max_kg", float, 400.0, check=lambda v: v > 0.0, rule="must be > 0 [kg]"),
    Key("hitch_x", float, -1.2, rule="[m] in base_link, behind the rear wheels"),
)
METRICS = (
    Metric(
        "max_lift_kg", "kg", LARGER, "the heaviest tool lifted on the rear hitch, the front wheels down",
        Prediction("predicted_lift_kg", "step_kg", "lifts", "lifted", "a tool swings as it is lifted"),
    ),
    Metric("limited_by", "", WORDS, "what stopped the next lift"),
    Metric("predicted_lift_kg", "kg", LARGER, "the static lift the robot's weight ahead of its rear wheels balances"),
)  # fmt: skip
FAILED = "front wheels lifted"


def procedure(lab, design, params):
    """Tools of step_kg, step_kg heavier each, lifted on a hitch at hitch_x [m]; the front wheels stay
    down while the tool's moment about the rear wheels' contacts, m (rear - hitch_x), is at most the
    robot's weight's, M (com_x - rear): the static lift. A stand-in for a simulated lift holds
    ``design.give`` of it (a loose hitch swings)."""
    predicted = design.mass * (design.com_x - design.rear) / (design.rear - params["hitch_x"])
    lifts, held, k = [], 0.0, 1
    while k * params["step_kg"] <= params["max_kg"]:
        mass = k * params["step_kg"]
        ok = mass <= design.give * predicted
        lifts.append([mass, "ok" if ok else FAILED])
        if not ok:
            break
        held, k = mass, k + 1
    limited = FAILED if lifts[-1][1] != "ok" else "none: the heaviest tool tried"
    return {"max_lift_kg": held, "limited_by": limited, "predicted_lift_kg": round(predicted, 2), "lifts": lifts}


HITCH = ScenarioKind(
    name="hitch",
    what="the heaviest tool lifted on the rear hitch before the front wheels lift",
    keys=KEYS,
    metrics=METRICS,
    procedure=procedure,
)

# ---- a study of it -----------------------------------------------------------------------------------------
STUDY = """\
description: "a new scenario's study"
candidates:
  std: {robot: thorvald_ii_4wd4ws_std}
  loose: {robot: thorvald_ii_4wd4ws_std}
pareto: [hitch.max_lift_kg, hitch.predicted_lift_kg]
scenarios:
  hitch: {step_kg: 50}
"""
# the standard robot's mass [kg], its centre of mass over base_link, its rear wheels 0.6 m behind: the
# static lift on a hitch 1.2 m behind base_link is 177 x 0.6 / 0.6 = 177 kg
DESIGNS = {
    "std": SimpleNamespace(mass=177.0, com_x=0.0, rear=-0.6, give=1.0),  # holds 150, lifts at 200: within a step
    "loose": SimpleNamespace(mass=177.0, com_x=0.0, rear=-0.6, give=0.6),  # 106: holds 100, 77 kg below
}


def study_and_results():
    study = parse_study(yaml.safe_load(STUDY), "/studies/hitch.yaml", text=STUDY)
    results = empty_results(study)
    params = dict(study.scenarios)["hitch"]
    for name, design in DESIGNS.items():
        run = {"candidate": name, "scenario": "hitch", "mass_kg": design.mass}
        merge(results, {**run, "result": HITCH.procedure(None, design, params)}, study)
    return study, results


def test_the_scenario_is_in_the_registry_for_the_with_block_only():
    assert "hitch" not in SCENARIOS
    with registered(HITCH):
        assert SCENARIOS["hitch"] is HITCH and HITCH.results == ("max_lift_kg", "limited_by", "predicted_lift_kg")
        with pytest.raises(ScenarioError, match="'hitch' is registered twice"):
            with registered(HITCH):
                pass
        with pytest.raises(ScenarioError, match="'turning' is registered twice"):
            with registered(SCENARIOS["turning"]):
                pass
    assert "hitch" not in SCENARIOS
    with pytest.raises(StudyError, match=r"scenarios\.hitch: .*unknown key"):
        parse_study(yaml.safe_load(STUDY), "/studies/hitch.yaml")


def test_a_scenario_that_is_not_whole_is_refused_when_it_is_made():
    with pytest.raises(ScenarioError, match="max_lift_kg's prediction predicted_kg is none of its metrics"):
        ScenarioKind("bad", "", KEYS, (Metric("max_lift_kg", "kg", LARGER, "", Prediction("predicted_kg", "s")),),
                     procedure)  # fmt: skip
    with pytest.raises(ScenarioError, match="max_lift_kg's step kg is none of its parameters"):
        lift = Metric("max_lift_kg", "kg", LARGER, "", Prediction("predicted_lift_kg", "kg"))
        ScenarioKind("bad", "", KEYS, (lift, METRICS[2]), procedure)
    with pytest.raises(ScenarioError, match="declared twice"):
        ScenarioKind("bad", "", KEYS, (METRICS[1], METRICS[1]), procedure)
    with pytest.raises(ScenarioError, match="a number needs its unit"):
        Metric("max_lift_kg", "", LARGER, "")
    with pytest.raises(ScenarioError, match="a word has no unit"):
        Metric("limited_by", "kg", WORDS, "")
    with pytest.raises(ScenarioError, match=r"must be \+1, -1 or 0"):
        Metric("max_lift_kg", "kg", 2, "")


def test_its_study_results_table_and_search_follow_it(tmp_path):
    with registered(HITCH):
        study, results = study_and_results()
        assert study.scenarios == (("hitch", {"step_kg": 50.0, "max_kg": 400.0, "hitch_x": -1.2}),)
        std = results["candidates"]["std"]
        assert std["status"] == "ok" and std["scenarios"]["hitch"]["max_lift_kg"] == 150.0
        assert results["candidates"]["loose"]["scenarios"]["hitch"]["lifts"][-1] == [150.0, FAILED]
        write_csv(str(tmp_path / "results.csv"), results, study)
        with open(tmp_path / "results.csv", newline="", encoding="utf-8") as f:
            rows = list(csv.reader(f))
        assert rows[0] == ["candidate", "status", "mass_kg", "hitch.max_lift_kg", "hitch.limited_by",
                           "hitch.predicted_lift_kg"]  # fmt: skip
        assert rows[2] == ["loose", "ok", "177.0", "100.0", FAILED, "177.0"]
        table = {line.split()[0]: line.split()[1:] for line in results_table(results, study).splitlines()[1:]}
        assert table["hitch.max_lift_kg"] == ["150", "100"] and table["hitch.predicted_lift_kg"] == ["177", "177"]
        # its rules and its metrics, as every scenario's: a key's rule, a search's objectives
        with pytest.raises(StudyError, match=r"scenarios\.hitch\.step_kg: -1: must be > 0 \[kg\]"):
            parse_study({**yaml.safe_load(STUDY), "scenarios": {"hitch": {"step_kg": -1}}})
        problems = []
        spec = parse_optimise({"candidate": "std", "objectives": {"hitch.max_lift_kg": "max", "hitch.predicted_lift_kg":
                               "max"}}, "optimise", problems, scenarios=["hitch"])  # fmt: skip
        assert problems == [] and spec.metrics == ("hitch.max_lift_kg", "hitch.predicted_lift_kg")
        # a Pareto plane needs metrics with a better direction: a word's is refused with the file
        words = {**yaml.safe_load(STUDY), "pareto": ["hitch.limited_by", "hitch.max_lift_kg"]}
        with pytest.raises(StudyError, match=r"pareto\[0\]: 'hitch.limited_by': is a metric of words"):
            parse_study(words, "/studies/hitch.yaml")


@pytest.mark.slow  # a report: three plots
def test_its_metrics_are_in_the_report_as_it_declares_them(tmp_path):
    with registered(HITCH):
        study, results = study_and_results()
        page = write_report(str(tmp_path), results, study, pareto=study.pareto)
    plots = sorted(os.listdir(tmp_path / "plots"))
    # measured beside its prediction on one chart (no plot of either alone), no plot of a word
    assert plots == ["compare_hitch.max_lift_kg.png", "pareto.png"]
    with open(page, encoding="utf-8") as f:
        text = f.read()
    assert "<li><b>hitch</b>: the heaviest tool lifted on the rear hitch before the front wheels lift</li>" in text
    assert '<th class="metric">max_lift_kg ↑</th><td class="best">150</td><td>100</td>' in text  # larger is better
    assert '<th class="metric">limited_by</th><td class="text">front wheels lifted</td>' in text  # a word: no arrow
    # the page says where the lift and its prediction are more than the study's step apart, and why: the
    # scenario's declared unit, series, verb and what else parts them
    assert (
        '<li class="disagree">loose: lifted 100 kg (the 150 kg try: front wheels lifted), predicted 177 kg: 77 kg '
        "apart, more than the study&#x27;s step of 50 kg. Why: a tool swings as it is lifted.</li>" in text
    )
    assert "std: lifted" not in text
    assert "On the front of hitch.max_lift_kg (larger is better) and hitch.predicted_lift_kg (larger is better)" in text
