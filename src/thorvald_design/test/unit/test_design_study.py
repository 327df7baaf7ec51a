"""rosrun thorvald_design design_study, end to end: two candidates through every scenario, the results
checked against the quasi-static limits and the closed forms, and repeated to the byte on a Dask cluster."""

import csv
import json
import math
import os
import shutil
import subprocess

import pytest

from thorvald_design.design import design_of
from thorvald_model.description import package_file

pytestmark = pytest.mark.long(150)  # studies run end to end

STUDY = """\
description: "two robots, every scenario, short"
seed: 3
pareto: [gradeability.max_climb_deg, turning.turning_diameter_m]
candidates:
  std: {robot: thorvald_ii_4wd4ws_std}
  fwd: {robot: thorvald_ii_1wd1ws_fwd}
scenarios:
  gradeability: {surface: grass, start_deg: 6, step_deg: 8, max_deg: 30}
  side_slope: {surface: grass, start_deg: 10, step_deg: 10, max_deg: 30, distance: 3}
  turning: {settle: 2}
  headland: {row_spacing: 0.75}
  obstacle: {start_m: 0.06, step_m: 0.06, max_m: 0.18}
  drawbar: {surfaces: [grass, tarmac], step_n: 100, hold_s: 1.5}
  rails: {rail_length: 2}
  energy: {rows: 3, row_length: 6, speed: 1.0}
"""
KEYS = {
    "gradeability": {"surface", "max_climb_deg", "limited_by", "max_descent_deg"},
    "side_slope": {"max_traverse_deg", "static_overturning_deg", "drift_per_m"},
    "turning": {"turning_diameter_m", "clearance_diameter_m"},
    "drawbar": {"max_pull_n", "surface", "max_pull_n.grass", "max_pull_n.tarmac", "limited_by.tarmac"},
    "headland": {"min_headland_m", "turn", "plants_touched"},
    "obstacle": {"max_step_m"},
    "energy": {"wh_per_km", "wh_per_ha", "peak_current_a", "range_km"},
    "rails": {"odometry_error_pct", "odometry_error_pct_without_switch"},
}


def design_study(*args, timeout=600):
    return subprocess.run(
        ["rosrun", "thorvald_design", "design_study", *args], capture_output=True, text=True, timeout=timeout
    )


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    """The study run twice into two folders, on local worker processes (--jobs 2), then on a local Dask
    cluster of two worker processes (--scheduler): (the first's results, its folder, the second's
    folder, the second's process)."""
    from distributed import LocalCluster  # noqa: PLC0415

    root = tmp_path_factory.mktemp("study")
    path = root / "study.yaml"
    path.write_text(STUDY)
    first = design_study(str(path), "--out", str(root / "first"), "--jobs", "2")
    assert first.returncode == 0, first.stderr[-3000:]
    with LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, host="127.0.0.1", dashboard_address=None
    ) as cluster:
        second = design_study(str(path), "--out", str(root / "second"), "--scheduler", cluster.scheduler_address)
    assert second.returncode == 0, second.stderr[-3000:]
    with open(root / "first" / "results.json", encoding="utf-8") as f:
        return json.load(f), root / "first", root / "second", second


def example(name):
    return design_of(name, package_file("config", name, name + ".yaml"))


@pytest.mark.slow  # two studies of 8 runs each, in worker processes and on a Dask cluster
def test_every_candidate_has_every_scenarios_metrics(study):
    results, first, _, done = study
    assert set(results["candidates"]) == {"std", "fwd"}
    for name, entry in results["candidates"].items():
        assert entry["status"] == "ok", (name, entry["status"])
        robot = {"std": "thorvald_ii_4wd4ws_std", "fwd": "thorvald_ii_1wd1ws_fwd"}[name]
        assert entry["mass_kg"] == pytest.approx(example(robot).mass, abs=1e-3)
        for scenario, keys in KEYS.items():
            assert keys <= set(entry["scenarios"][scenario]), (name, scenario)
    with open(first / "results.csv", newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    assert [r["candidate"] for r in rows] == ["std", "fwd"]
    assert (
        float(rows[0]["gradeability.max_climb_deg"])
        == results["candidates"]["std"]["scenarios"]["gradeability"]["max_climb_deg"]
    )
    assert "gradeability.max_climb_deg" in done.stdout and "[16/16]" in done.stderr  # the table, the progress
    assert (first / "report.html").stat().st_size > 100_000 and (first / "plots" / "pareto.png").is_file()
    for name in ("std", "fwd"):  # what the report draws: a picture of each, the tracks of each run
        assert (first / "pictures" / f"{name}.png").stat().st_size > 10_000
        tracks = json.loads((first / "tracks" / name / "gradeability.json").read_text())
        assert [t["label"] for t in tracks["tracks"]][:2] == ["climb 6 deg", "climb 14 deg"]


@pytest.mark.slow
def test_the_climbs_agree_with_the_quasi_static_limits(study):
    """The steepest ramp climbed (a lower bound, a step below the first failed) brackets the quasi-static
    limit the weight distribution, grip and motors give, to 2 degrees."""
    results = study[0]
    for name in ("std", "fwd"):
        grade = results["candidates"][name]["scenarios"]["gradeability"]
        climbed, failed = grade["max_climb_deg"], grade["climbs"][-1][0]
        assert grade["climbs"][-1][1] != "ok"
        assert climbed - 2.0 <= grade["predicted_climb_deg"] <= failed + 2.0, (name, grade)
        assert grade["limited_by"] == grade["predicted_limited_by"] == "traction", (name, grade)
    # all-wheel drive climbs further than front-wheel drive, as the hardware paper's incline trial found
    std = results["candidates"]["std"]["scenarios"]["gradeability"]
    fwd = results["candidates"]["fwd"]["scenarios"]["gradeability"]
    assert std["max_climb_deg"] >= fwd["max_climb_deg"] + 8.0


@pytest.mark.slow
def test_the_pull_agrees_with_the_quasi_static_limit_on_each_surface(study):
    results, first, _, done = study
    for name in ("std", "fwd"):
        pull = results["candidates"][name]["scenarios"]["drawbar"]
        # the headline is the first surface's; every surface has its own
        assert pull["surface"] == "grass" and pull["max_pull_n"] == pull["max_pull_n.grass"], (name, pull)
        for kind in ("grass", "tarmac"):
            held, predicted = pull[f"max_pull_n.{kind}"], pull[f"predicted_pull_n.{kind}"]
            # held is a multiple of the 100 N step, the largest one held: within 5 % and a step of the limit
            assert held <= predicted * 1.05 + 1.0, (name, kind, pull)
            assert held + 100.0 >= predicted * 0.95, (name, kind, pull)
        # tarmac grips better than grass (0.9 against 0.55): it pulls more, up to its motors' limit
        assert pull["max_pull_n.tarmac"] > pull["max_pull_n.grass"], (name, pull)
        assert pull["predicted_pull_n.tarmac"] > pull["predicted_pull_n.grass"], (name, pull)
    with open(first / "results.csv", newline="", encoding="utf-8") as f:
        row = next(csv.DictReader(f))
    assert (
        float(row["drawbar.max_pull_n.tarmac"])
        == results["candidates"]["std"]["scenarios"]["drawbar"]["max_pull_n.tarmac"]
    )
    assert "drawbar.max_pull_n.tarmac" in done.stdout


@pytest.mark.slow
def test_turning_diameters_are_the_closed_forms(study):
    """std spins on the spot: its outermost contact is a corner wheel, hypot(0.547, 0.30) from the centre;
    fwd turns about its rear axle's middle, 0.9 m behind its front wheel."""
    results = study[0]
    std = results["candidates"]["std"]["scenarios"]["turning"]
    fwd = results["candidates"]["fwd"]["scenarios"]["turning"]
    assert std["turn"] == "spin" and fwd["turn"] == "about the axle line"
    assert std["turning_diameter_m"] == pytest.approx(2.0 * math.hypot(0.547, 0.30), abs=0.03)
    assert fwd["turning_diameter_m"] == pytest.approx(1.8, abs=0.03)
    for turn in (std, fwd):
        assert turn["clearance_diameter_m"] > turn["turning_diameter_m"]


@pytest.mark.slow
def test_side_slopes_are_held_only_below_the_static_overturning_angle(study):
    results = study[0]
    for name in ("std", "fwd"):
        side = results["candidates"][name]["scenarios"]["side_slope"]
        assert side["max_traverse_deg"] <= side["static_overturning_deg"] + 15.0
        held = [t for t in side["traverses"] if all(way[0] == "ok" for way in t[1:])]
        assert all(t[0] <= side["max_traverse_deg"] for t in held)
    fwd = results["candidates"]["fwd"]["scenarios"]["side_slope"]
    # the tricycle's battery side is its weak side: 5.7 degrees, and its traverse with that side downhill tips
    assert fwd["static_overturning_deg"] == pytest.approx(5.72, abs=0.1)
    assert fwd["traverses"][0][2][0] == "tipping"


@pytest.mark.slow
def test_headland_turns_are_the_ones_each_robot_can_make(study):
    """std (every wheel steers, it spins) makes U, crab and spin turns without touching a plant; fwd
    (fixed rear wheels, 0.45 m from its turn's centre to base_link) cannot U-turn between 0.75 m rows and
    makes an omega turn, its centred front wheel running along the row's plants."""
    results = study[0]
    std = results["candidates"]["std"]["scenarios"]["headland"]
    fwd = results["candidates"]["fwd"]["scenarios"]["headland"]
    assert {t for t, r in std["turns"].items() if isinstance(r, dict) and r["works"]} == {"U", "crab", "spin"}
    assert std["plants_touched"] == 0 and std["turn"] in ("U", "crab")
    assert fwd["turns"]["U"].startswith("n/a: its tightest turn") and fwd["turns"]["crab"].startswith("n/a")
    assert fwd["turn"] == "omega" and fwd["plants_touched"] > 0
    for turn in (std, fwd):  # the robot must leave the rows whole before it turns
        assert turn["min_headland_m"] > 1.0


@pytest.mark.slow
def test_steps_and_energy(study):
    results = study[0]
    std, fwd = (results["candidates"][n]["scenarios"] for n in ("std", "fwd"))
    assert 0.06 <= std["obstacle"]["max_step_m"] < 0.2  # below its wheels' axles
    assert fwd["obstacle"]["max_step_m"] <= std["obstacle"]["max_step_m"]
    energy = std["energy"]
    assert energy["wh_per_km"] == pytest.approx(energy["energy_wh"] / (energy["distance_m"] / 1000.0), rel=1e-3)
    assert 20.0 < energy["wh_per_km"] < 300.0 and 0.99 < energy["end_soc"] < 1.0
    # its 4.8 kWh pack at this rate: range = capacity / (Wh per km), give or take the pack's internal loss
    assert energy["range_km"] == pytest.approx(4800.0 / energy["wh_per_km"], rel=0.05)
    # neither has rail wheels: the greenhouse robot's scenario says so (its own test drives it: test_rails.py)
    assert std["rails"]["odometry_error_pct"] == "n/a: its drives have no rail wheels"
    # the tricycle tips over in the tight headland turn at 1 m/s (v^2 / R = 2 m/s^2 > g tan 5.7 deg)
    assert fwd["energy"]["wh_per_km"].startswith("n/a: it tipped over")


@pytest.mark.slow  # once on local worker processes, once on a Dask cluster: the study fixture
def test_the_same_study_gives_the_same_files_byte_for_byte(study):
    _, first, second, _ = study
    for name in ("results.json", "results.csv", "candidates/std.yaml", "candidates/fwd.yaml", "report.html"):
        assert (first / name).read_bytes() == (second / name).read_bytes(), name


@pytest.mark.slow
def test_resume_keeps_what_is_done_and_runs_the_rest(study, tmp_path):
    _, first, _, _ = study
    out = tmp_path / "resumed"
    shutil.copytree(first, out)
    results = json.loads((out / "results.json").read_text())
    del results["candidates"]["fwd"]["scenarios"]["turning"]
    (out / "results.json").write_text(json.dumps(results, indent=2) + "\n")
    study_file = tmp_path / "study.yaml"
    study_file.write_text(STUDY)
    done = design_study(str(study_file), "--out", str(out), "--resume", "--jobs", "1")
    assert done.returncode == 0, done.stderr[-2000:]
    assert "1 runs" in done.stderr or "7 already in" in done.stderr
    assert (out / "results.json").read_bytes() == (first / "results.json").read_bytes()
    # its tracks plots drawn by the report (the kept runs') and by the worker (the run again) are the
    # ones the first study's workers drew, to the byte: the page embeds them (the page ends with the
    # study file's path, which differs)
    pages = [(folder / "report.html").read_bytes().split(b'<h2 id="study">')[0] for folder in (out, first)]
    assert pages[0] == pages[1] and b"fwd: turning" in pages[0]


@pytest.mark.slow  # a process
def test_a_broken_study_is_refused_before_anything_runs(tmp_path):
    path = tmp_path / "study.yaml"
    path.write_text("candidates: {a: {robot: thorvald_ii_4wd4ws_std}}\nscenarios: {turnng: {}}\n")
    done = design_study(str(path), "--out", str(tmp_path / "out"), timeout=120)
    assert done.returncode == 2
    assert "scenarios.turnng: {}: unknown key (did you mean 'turning'?)" in done.stderr
    assert "Traceback" not in done.stderr and not os.path.exists(tmp_path / "out")


@pytest.mark.slow  # a process: the command as a user types it
def test_a_sweep_that_would_change_nothing_is_refused_before_anything_runs(tmp_path):
    """Issue 45: a sweep of a key no robot file has ran every combination with a warning a drive, and
    gave identical results."""
    path = tmp_path / "study.yaml"
    path.write_text(
        "candidates:\n  wide:\n    robot: thorvald_ii_4wd4ws_std\n"
        '    sweep: {"motor_drives.*.width": [0.5, 0.6]}\n'
        "scenarios: {turning: {settle: 1}}\n"
    )
    done = design_study(str(path), "--out", str(tmp_path / "out"), timeout=120)
    assert done.returncode == 2, done.stderr[-2000:]
    assert (
        f"{path}: candidates.wide.sweep.motor_drives.*.width: [0.5, 0.6]: the robot files' schema has no key "
        "'width' in motor_drives entries: nothing reads it, so a sweep of it would change nothing "
        "(did you mean 'w_wheel'?)" in done.stderr
    )
    assert "Traceback" not in done.stderr and "kept as it is" not in done.stderr
    assert " scenarios = " not in done.stderr and done.stdout == ""  # no run started: none announced, no table
    assert not os.path.exists(tmp_path / "out")


@pytest.mark.slow  # a process
def test_a_mistyped_example_robot_gets_did_you_mean(tmp_path):
    path = tmp_path / "study.yaml"
    path.write_text("candidates: {a: {robot: thorvald_ii_2wd_dif}}\nscenarios: {turning: {}}\n")
    done = design_study(str(path), "--out", str(tmp_path / "out"), timeout=120)
    assert done.returncode == 2 and "Traceback" not in done.stderr
    assert (
        "candidates.a.robot: 'thorvald_ii_2wd_dif': no example robot of that name (did you mean "
        "'thorvald_ii_2wd_diff'?); the examples: thorvald_ii_1wd1ws_fwd" in done.stderr
    )
    assert not os.path.exists(tmp_path / "out")


@pytest.mark.slow  # a process
def test_a_candidate_that_cannot_be_built_fails_alone(tmp_path):
    """A candidate whose as-built file is missing is reported failed with its reason; the other runs."""
    path = tmp_path / "study.yaml"
    path.write_text(
        "candidates: {good: {robot: thorvald_ii_4wd4ws_std},"
        " bad: {robot: thorvald_ii_4wd4ws_std, as_built: no_such_as_built.yaml}}\n"
        "scenarios: {turning: {settle: 1}}\n"
    )
    done = design_study(str(path), "--out", str(tmp_path / "out"), "--jobs", "2", timeout=300)
    results = json.loads((tmp_path / "out" / "results.json").read_text())
    assert results["candidates"]["good"]["status"] == "ok", done.stderr[-2000:]
    status = results["candidates"]["bad"]["status"]
    assert status.startswith("failed: cannot be built: ") and "no_such_as_built.yaml" in status, status
    assert done.returncode == 0  # one candidate ran: the study did what it could


SEARCH = """\
seed: 1
candidates:
  track:
    robot: thorvald_ii_4wd4ws_std
    sweep: {"motor_drives.*.y": [0.3, 0.45, 0.75]}
scenarios:
  headland: {row_spacing: 0.75, turns: crab}
  turning: {settle: 1}
optimise:
  candidate: track
  objectives: {turning.clearance_diameter_m: min, headland.plants_touched: min}
  requirements: {headland.plants_touched: "<= 10"}
  trials: 2
"""


@pytest.mark.slow  # a search and a sweep: 8 runs
def test_a_search_finds_the_sweeps_front_with_fewer_runs(tmp_path):
    """The track width for 0.75 m rows: at y = 0.75 the wheels ride the neighbouring rows (plants run over,
    pruned by the requirement); of the others, the narrower turns in the smaller circle."""
    path = tmp_path / "search.yaml"
    path.write_text(SEARCH)
    done = design_study(str(path), "--out", str(tmp_path / "out"), "--optimise", "--against-sweep")
    assert done.returncode == 0, done.stderr[-3000:]
    out = json.loads((tmp_path / "out" / "optimise.json").read_text())
    assert out["scenario_order"] == ["headland", "turning"]  # the requirement's scenario first: pruning saves runs
    search, comparison = out["search"], out["comparison"]
    assert len(search["trials"]) == 2 and comparison["runs"]["sweep"] == 6
    assert comparison["runs"]["search"] < comparison["runs"]["sweep"]
    for trial in search["trials"]:
        if trial["values"]["motor_drives.*.y"] == 0.75:
            assert trial["state"] == "pruned" and "headland.plants_touched" in trial["reason"]
    sweep_front = out["sweep"]["front"]
    assert sweep_front == [{"motor_drives.*.y": 0.3}]  # the narrowest: the smallest circle, no plant touched
    assert comparison["front"]["dominated"] == 0
    assert "search: 2 combinations" in done.stdout


@pytest.mark.slow  # a process
def test_optimise_without_a_section_is_refused(tmp_path):
    path = tmp_path / "study.yaml"
    path.write_text("candidates: {a: {robot: thorvald_ii_4wd4ws_std}}\nscenarios: {turning: {}}\n")
    done = design_study(str(path), "--out", str(tmp_path / "out"), "--optimise", timeout=120)
    assert done.returncode == 2 and "--optimise needs an optimise: section" in done.stderr


@pytest.mark.slow
def test_a_study_runs_on_a_dask_cluster_to_the_same_results(study):
    """The study's second run, on a local Dask cluster of two workers (--scheduler), gives the results
    the first gave on local worker processes (every file, byte for byte: the test above)."""
    _, first, second, done = study
    assert "2 Dask workers at tcp://127.0.0.1:" in done.stderr
    assert (second / "results.json").read_bytes() == (first / "results.json").read_bytes()


@pytest.mark.slow  # a process
def test_an_unreachable_scheduler_is_one_clean_error(tmp_path):
    path = tmp_path / "study.yaml"
    path.write_text("candidates: {a: {robot: thorvald_ii_4wd4ws_std}}\nscenarios: {turning: {}}\n")
    address = ("--scheduler", "tcp://127.0.0.1:9", "--scheduler-timeout", "1")  # 10 s by default
    done = design_study(str(path), "--out", str(tmp_path / "out"), *address, timeout=120)
    assert done.returncode == 2 and "cannot reach the scheduler tcp://127.0.0.1:9" in done.stderr
    assert "Traceback" not in done.stderr
