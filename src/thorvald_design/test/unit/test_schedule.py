"""thorvald_design.runs: a study's runs start longest first, from an earlier study's timing or the
scenarios' costs (pure: no run is made)."""

import json

from thorvald_design.runs import TIMING, Job, longest_first, read_timing
from thorvald_design.scenarios import SCENARIOS


def job(candidate: str, scenario: str) -> Job:
    return Job(candidate, f"/nowhere/{candidate}.yaml", "", 0, scenario, ())


def test_without_timings_the_scenarios_cost_times_the_drives_orders_the_runs():
    jobs = [job(c, s) for c in ("std", "nine", "diff") for s in ("turning", "gradeability", "rails")]
    drives = {"std": 4, "nine": 9, "diff": 2}
    order = [j.label for j in longest_first(jobs, {}, drives)]
    costs = {j.label: SCENARIOS[j.scenario].cost * drives[j.candidate] / 4 for j in jobs}
    assert [costs[label] for label in order] == sorted(costs.values(), reverse=True)
    assert order[0] == "nine: gradeability"  # the steepest ramps on the robot of most drives
    assert order[-1] in ("diff: rails", "std: rails")
    assert sorted(order) == sorted(j.label for j in jobs)  # every run, once


def test_an_earlier_studys_timing_wins_over_the_guess_and_a_candidate_unread_counts_four_drives():
    jobs = [job("std", "turning"), job("std", "gradeability"), job("broken", "gradeability")]
    timed = {"std: turning": 500.0}  # an earlier study found it the longest
    order = [j.label for j in longest_first(jobs, timed, {"std": 4})]
    assert order == ["std: turning", "std: gradeability", "broken: gradeability"]  # equal guesses keep the order


def test_timing_is_read_from_the_study_folder_and_anything_unreadable_is_no_timing(tmp_path):
    assert read_timing(str(tmp_path)) == {}
    (tmp_path / TIMING).write_text(json.dumps({"runs": [{"run": "std: turning", "wall_s": 1.5, "simulated_s": 20}]}))
    assert read_timing(str(tmp_path)) == {"std: turning": 1.5}
    (tmp_path / TIMING).write_text("{ not json")
    assert read_timing(str(tmp_path)) == {}
    (tmp_path / TIMING).write_text(json.dumps({"runs": [{"wall_s": 1.5}]}))
    assert read_timing(str(tmp_path)) == {}


def test_every_scenario_declares_a_positive_cost():
    assert all(kind.cost > 0 for kind in SCENARIOS.values())
    assert len({kind.cost for kind in SCENARIOS.values()}) > 1  # measured, not left at the default
