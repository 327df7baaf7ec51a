"""The design study's report (thorvald_design.report): the Pareto front on points whose front is known,
the metrics' directions, the plan of a world, the tracks files, and the report itself: every plot it
should write, one page that needs nothing outside itself, the same bytes twice; then a real small
study's report, and the page in headless Chromium (every image loaded, something drawn)."""

import dataclasses
import json
import math
import os
import re
import shutil
import struct
import subprocess
import tempfile

import pytest
from hypothesis import given
from hypothesis import strategies as st
from PIL import Image

from thorvald_design.errors import ReportError, SearchError
from thorvald_design.geometry import convex_hull, rectangle
from thorvald_design.optimise import pareto_front
from thorvald_design.report import write_report
from thorvald_design.report.plan import view, world_map
from thorvald_design.report.table import best, metrics, pareto_plane, sweeps
from thorvald_design.report.tracks import parse_tracks
from thorvald_design.runs import safe_name
from thorvald_design.scenarios import LARGER, SCENARIOS, SMALLER, declared
from thorvald_design.scenarios.driving import ramp_world
from thorvald_design.study import Candidate, Study
from thorvald_sim.world import parse_world

CHROMIUM = "/usr/bin/chromium"


# ---- the Pareto front ---------------------------------------------------------------------------------
pytestmark = pytest.mark.long(20)  # [s] in all: the parallel run starts it early


@pytest.mark.parametrize(
    ("points", "directions", "front"),
    [
        ([], (1, 1), []),
        ([(3.0, 4.0)], (1, 1), [0]),
        ([(1, 1), (2, 2), (1, 3), (3, 0)], (1, 1), [1, 2, 3]),  # (2, 2) beats (1, 1)
        ([(1, 1), (2, 2), (1, 3), (3, 0)], (-1, -1), [0, 3]),  # smaller is better: (1, 1) beats (2, 2), (1, 3)
        # climb [deg] larger better, turning diameter [m] smaller better: (19, 3.5) loses to (20, 3.0)
        ([(20, 3.0), (25, 4.0), (18, 2.5), (19, 3.5)], (1, -1), [0, 1, 2]),
        ([(1, 2), (1, 3)], (1, 1), [1]),  # equal in one, better in the other: dominated
        ([(1, 1), (1, 1)], (1, 1), [0, 1]),  # equal points dominate neither
        ([(1, 1), (1, 1), (2, 2)], (1, 1), [2]),
        ([(5,), (7,), (7,), (2,)], (1,), [1, 2]),  # one metric: its best, ties all
        ([(1, 2, 3), (3, 2, 1), (2, 2, 2), (1, 1, 1)], (1, 1, 1), [0, 1, 2]),
        ([(0, 0), (-1, 5)], (1, -1), [0]),
    ],
)
def test_pareto_front_known_answers(points, directions, front):
    assert pareto_front(points, directions) == front


@pytest.mark.parametrize(
    ("points", "directions", "message"),
    [
        ([(1, 2)], (1, 0), "directions must be"),
        ([(1, 2), (1, 2, 3)], (1, 1), "point 1 has 3 coordinates"),
        ([(1, float("nan"))], (1, 1), "not finite"),
        ([(1, "a")], (1, 1), "not finite"),
        ([(True, 1)], (1, 1), "not finite"),
    ],
)
def test_pareto_front_refuses_what_it_cannot_rank(points, directions, message):
    with pytest.raises(SearchError, match=message):
        pareto_front(points, directions)


def dominates(a, b, directions):
    sa = [d * v for d, v in zip(directions, a)]
    sb = [d * v for d, v in zip(directions, b)]
    return all(x >= y for x, y in zip(sa, sb)) and any(x > y for x, y in zip(sa, sb))


@given(
    st.integers(1, 3).flatmap(
        lambda n: st.tuples(
            st.lists(st.tuples(*[st.integers(-5, 5)] * n), max_size=25), st.tuples(*[st.sampled_from((1, -1))] * n)
        )
    )
)
def test_pareto_front_is_what_nothing_beats_and_beats_the_rest(case):
    points, directions = case
    front = pareto_front(points, directions)
    assert front == sorted(set(front))
    for i, p in enumerate(points):
        beaten = any(dominates(q, p, directions) for q in points)
        assert (i in front) == (not beaten)
        if beaten:  # a dominated point is dominated by a point of the front (domination is transitive)
            assert any(dominates(points[j], p, directions) for j in front)
    # the order of the points does not change which are on the front
    back = pareto_front(points[::-1], directions)
    assert sorted(len(points) - 1 - i for i in back) == front


# ---- what is plotted ------------------------------------------------------------------------------------
def test_every_metric_of_every_scenario_has_a_direction_or_is_words():
    """Each scenario declares its metrics (the report keeps no table of its own): a number has a unit
    and a direction, a word neither; a metric of one surface of several is its metric's."""
    directions = set()
    for kind in SCENARIOS.values():
        for metric in kind.metrics:
            assert metric.words or metric.direction in (LARGER, SMALLER), (kind.name, metric.name)
            assert bool(metric.unit) != metric.words and metric.meaning, (kind.name, metric.name)
            assert declared(f"{kind.name}.{metric.name}") is metric
            directions.add(metric.direction)
    assert directions == {1, -1, 0}
    words = {"gradeability.surface", "gradeability.limited_by", "gradeability.predicted_limited_by",
             "turning.turn", "headland.turn", "drawbar.limited_by", "drawbar.surface"}  # fmt: skip
    assert {f"{k.name}.{m.name}" for k in SCENARIOS.values() for m in k.metrics if m.words} == words
    for column in ("gradeability.max_climb_deg", "gradeability.max_descent_deg", "side_slope.max_traverse_deg",
                   "side_slope.static_overturning_deg", "drawbar.max_pull_n", "drawbar.max_pull_n.mud",
                   "obstacle.max_step_m", "energy.range_km"):  # fmt: skip
        assert declared(column).direction == 1, column
    for column in ("turning.turning_diameter_m", "turning.clearance_diameter_m", "side_slope.drift_per_m",
                   "headland.min_headland_m", "headland.plants_touched", "energy.wh_per_km", "energy.wh_per_ha",
                   "energy.peak_current_a", "rails.odometry_error_pct"):  # fmt: skip
        assert declared(column).direction == -1, column
    assert declared("gradeability.nothing") is None and declared("nothing.max_climb_deg") is None


GRADEABILITY = {"surface": "grass", "speed": 0.5}
TURNING = {"surface": "tarmac"}


def candidate(name, swept=(), family=""):
    return Candidate(name, f"/robots/{name}.yaml", {}, swept=tuple(swept), family=family)


def entry(status, scenarios, swept=None, mass=177.0):
    return {"status": status, "mass_kg": mass, "robot": "/robots/x.yaml", "swept": swept or {}, "payload_kg": 0.0,
            "scenarios": scenarios}  # fmt: skip


def grade(climb, limited_by="traction", descent=20.0):
    return {"surface": "grass", "max_climb_deg": climb, "limited_by": limited_by, "max_descent_deg": descent,
            "predicted_climb_deg": 25.0, "predicted_limited_by": "traction", "predicted_descent_deg": 30.0,
            "climbs": [[10.0, "ok"]]}  # fmt: skip


def turn(diameter, clearance=None, kind="spin"):
    return {"turning_diameter_m": diameter, "clearance_diameter_m": clearance or diameter + 0.4, "turn": kind}


STUDY_TEXT = """\
description: "Wheel track <and> payload & co"
seed: 4
candidates:
  std: {robot: thorvald_ii_4wd4ws_std}
  wide: {robot: thorvald_ii_4wd4ws_std, sweep: {"motor_drives.*.y": [0.6, 0.75, 0.9]}}
  broken: {robot: broken.yaml}
scenarios:
  gradeability: {surface: grass, speed: 0.5}
  turning: {}
"""


def made_study():
    """A study of a plain candidate, a sweep of three and one that cannot be built, and its results:
    numbers, words, n/a, a failed scenario, a failed candidate."""
    y = "motor_drives.*.y"
    study = Study(
        source="/studies/wheel_track.yaml",
        description="Wheel track <and> payload & co",
        seed=4,
        candidates=(
            candidate("std"),
            candidate("wide[y=0.6]", [(y, 0.6)], "wide"),
            candidate("wide[y=0.75]", [(y, 0.75)], "wide"),
            candidate("wide[y=0.9]", [(y, 0.9)], "wide"),
            candidate("broken"),
        ),
        scenarios=(("gradeability", GRADEABILITY), ("turning", TURNING)),
        text=STUDY_TEXT + "# <script>alert('x')</script>\n",
    )
    built = "failed: cannot be built: motor_drives.drive0.r_wheel: must be > 0"
    results = {
        "study": {"description": study.description, "seed": 4, "scenarios": ["gradeability", "turning"]},
        "candidates": {
            "std": entry("ok", {"gradeability": grade(26.0), "turning": turn(1.25)}),
            "wide[y=0.6]": entry("ok", {"gradeability": grade(24.0), "turning": turn(1.6)}, {y: 0.6}),
            "wide[y=0.75]": entry(
                "failed: turning: broke: ZeroDivisionError (turning.py:80)",
                {
                    "gradeability": grade(22.0, descent="n/a: descent: false"),
                    "turning": "failed: broke: ZeroDivisionError (turning.py:80)",
                },
                {y: 0.75},
            ),
            "wide[y=0.9]": entry("ok", {"gradeability": grade(20.0, "tipping"), "turning": turn(2.2)}, {y: 0.9}),
            "broken": entry(built, {"gradeability": built, "turning": built}, mass=None),
        },
    }
    return study, results


def test_metrics_are_the_tables_columns_with_every_candidates_value():
    study, results = made_study()
    found = {m.column: m for m in metrics(results, study)}
    assert list(found) == [f"{s}.{m}" for s, _ in study.scenarios for m in SCENARIOS[s].results]
    climb = found["gradeability.max_climb_deg"]
    assert climb.numeric and climb.direction == 1
    assert climb.value("std") == 26.0 and climb.value("broken").startswith("failed: cannot be built")
    assert best(climb) == ("std",)
    assert best(found["turning.turning_diameter_m"]) == ("std",)  # smaller is better
    assert best(found["gradeability.predicted_climb_deg"]) == ()  # all equal: no best
    assert not found["gradeability.limited_by"].numeric and not found["turning.turn"].numeric
    assert found["gradeability.max_descent_deg"].value("wide[y=0.75]") == "n/a: descent: false"
    assert found["turning.turning_diameter_m"].value("wide[y=0.75]").startswith("failed: broke")


def test_sweeps_are_the_families_in_file_order():
    study, results = made_study()
    (sweep,) = sweeps(study, list(results["candidates"]))
    assert sweep.family == "wide" and sweep.key_paths == ("motor_drives.*.y",)
    assert sweep.members == (("wide[y=0.6]", (0.6,)), ("wide[y=0.75]", (0.75,)), ("wide[y=0.9]", (0.9,)))
    assert sweeps(study, ["std"]) == []  # only candidates that have results


def test_pareto_plane_takes_the_candidates_with_both_numbers():
    study, results = made_study()
    plane = pareto_plane(results, study, ("gradeability.max_climb_deg", "turning.turning_diameter_m"))
    assert [p[0] for p in plane.points] == ["std", "wide[y=0.6]", "wide[y=0.9]"]
    assert [plane.points[i][0] for i in plane.front] == ["std"]  # steepest climb and tightest turn
    assert [m[0] for m in plane.missing] == ["wide[y=0.75]", "broken"]
    with pytest.raises(ReportError, match="not a column"):
        pareto_plane(results, study, ("gradeability.max_climb_deg", "drawbar.max_pull_n"))
    with pytest.raises(ReportError, match="better direction"):
        pareto_plane(results, study, ("gradeability.max_climb_deg", "gradeability.limited_by"))


# ---- the plan of a world, tracks files --------------------------------------------------------------------
def corners(points):
    return sorted((round(x, 9), round(y, 9)) for x, y in points)


def test_world_map_of_a_ramp_rows_and_a_box():
    world = ramp_world("grass", math.radians(20.0), 3.0, 2.0)  # footprint 0..8 along x, 10 across
    world["rows"] = {"row0": {"x": 10.0, "y": -1.0, "count": 3, "spacing": 1.0, "length": 2.0, "plant_spacing": 0.5}}
    world["objects"] = {"object0": {"shape": "box", "x": -2.0, "y": 3.0, "size_x": 2.0, "size_y": 1.0, "size_z": 0.5}}
    world["walls"] = {"wall0": {"x": 0.0, "y": 8.0, "length": 4.0, "height": 1.0, "thickness": 0.2}}
    plan = world_map(parse_world(world))
    kinds = [s.kind for s in plan.shapes]
    assert kinds == ["slope", "slope_top", "solid", "solid"]
    slope, top, box, wall = plan.shapes
    assert corners(slope.points) == corners([(0.0, -5.0), (8.0, -5.0), (8.0, 5.0), (0.0, 5.0)])
    assert corners(top.points) == corners([(3.0, -5.0), (5.0, -5.0), (5.0, 5.0), (3.0, 5.0)])
    assert corners(box.points) == corners([(-3.0, 2.5), (-1.0, 2.5), (-1.0, 3.5), (-3.0, 3.5)])
    assert corners(wall.points) == corners([(-2.0, 7.9), (2.0, 7.9), (2.0, 8.1), (-2.0, 8.1)])
    ((plants, _),) = plan.plants
    assert len(plants) == 3 * 5  # 3 rows, a plant every 0.5 m over 2 m
    assert (10.0, -1.0) in plants and (12.0, 1.0) in plants


def test_convex_hull_and_the_view_of_a_spin():
    assert convex_hull([(0, 0), (1, 0), (1, 1), (0, 1), (0.5, 0.5)]) == ((0, 0), (1, 0), (1, 1), (0, 1))
    assert convex_hull([(0, 0), (2, 1)]) == ((0, 0), (2, 0), (2, 1), (0, 1))  # a box's diagonal
    # the one rectangle: anticlockwise from (-u, -v), turned about its centre
    turned = rectangle(1.0, 2.0, math.pi / 2, 2.0, 0.5)
    assert corners(turned) == corners([(0.5, 0.0), (1.5, 0.0), (1.5, 4.0), (0.5, 4.0)])
    assert rectangle(0.0, 0.0, 0.0, 2.0, 1.0) == ((-2.0, -1.0), (2.0, -1.0), (2.0, 1.0), (-2.0, 1.0))
    tracks = parse_tracks({"tracks": [{"x": [0.0, 0.01], "y": [0.0, 0.0], "yaw": [0.0, 3.0]}]})
    (x0, x1), (y0, y1) = view(tracks.drives, None)
    assert x1 - x0 >= 4.0 and y1 - y0 >= 4.0  # a spin on the spot is seen at a robot's scale


def test_parse_tracks_takes_the_files_world_and_says_what_is_wrong():
    world = {"ground": {"surface": "grass"}}
    drive = {"label": "climb 4 deg", "outcome": "ok", "t": [0, 0.1], "x": [0, 1], "y": [0, 0], "yaw": [0, 0]}
    tracks = parse_tracks({"world": world, "tracks": [drive]})
    assert tracks.world == world and tracks.drives[0].label == "climb 4 deg" and tracks.drives[0].x == (0, 1)
    older = parse_tracks({"tracks": [{"x": [0], "y": [0], "world": world}]})  # no file world: the first track's
    assert older.world == world
    for bad, message in [
        ([], "not a mapping"),
        ({"tracks": [{"x": [0, 1], "y": [0]}]}, "one length"),
        ({"tracks": [{"x": [0, None], "y": [0, 1]}]}, "finite numbers"),
        ({"tracks": [{"x": [0, 1], "y": [0, 1], "yaw": [0]}]}, "yaw"),
        ({"tracks": ["a"]}, "not a mapping"),
    ]:
        with pytest.raises(ReportError, match=message):
            parse_tracks(bad)


# ---- the report ----------------------------------------------------------------------------------------------
def track(label, outcome, xs, ys, yaws=None):
    n = len(xs)
    return {"label": label, "outcome": outcome, "t": [0.1 * i for i in range(n)], "x": xs, "y": ys,
            "yaw": yaws if yaws is not None else [0.0] * n}  # fmt: skip


def write_runs_files(out_dir, results):
    """What the runs write beside results.json: a picture of most candidates, tracks of some (one file
    that is not JSON, one world the simulator's parser refuses)."""
    os.makedirs(os.path.join(out_dir, "pictures"))
    for k, name in enumerate(results["candidates"]):
        if name == "broken":
            continue
        picture = Image.new("RGB", (240, 180), (190, 210, 235))
        picture.paste((60 + 30 * k, 90, 60), (40 + 10 * k, 70, 200, 140))
        picture.save(os.path.join(out_dir, "pictures", safe_name(name) + ".png"))
    ramp = ramp_world("grass", math.radians(24.0), 3.0, 2.0)
    xs = [-2.0 + 0.25 * i for i in range(40)]
    files = {
        ("std", "gradeability"): {"world": ramp, "tracks": [track("climb 22 deg", "ok", xs, [0.0] * 40),
                                                            track("climb 24 deg", "traction", xs[:15], [0.0] * 15)]},
        ("std", "turning"): {"world": {"ground": {"surface": "tarmac"}}, "tracks": [
            track("turn left", "ok", [0.3 * math.cos(a / 10) for a in range(63)],
                  [0.3 * math.sin(a / 10) for a in range(63)], [a / 10 + math.pi / 2 for a in range(63)])]},
        ("wide[y=0.6]", "gradeability"): {"world": {"slopes": {"slope0": {"angle": -1}}},
                                          "tracks": [track("climb 20 deg", "ok", xs, [0.0] * 40)]},
    }  # fmt: skip
    for (name, scenario), data in files.items():
        path = os.path.join(out_dir, "tracks", safe_name(name), scenario + ".json")
        os.makedirs(os.path.dirname(path), exist_ok=True)
        with open(path, "w", encoding="utf-8") as f:
            json.dump(data, f)
    path = os.path.join(out_dir, "tracks", safe_name("wide[y=0.9]"), "turning.json")
    os.makedirs(os.path.dirname(path))
    with open(path, "w", encoding="utf-8") as f:
        f.write('{"tracks": [')  # cut off: a note on the page, not the end of the report


def png_chunks(data):
    assert data.startswith(b"\x89PNG\r\n\x1a\n")
    i, out = 8, []
    while i < len(data):
        (n,) = struct.unpack(">I", data[i : i + 4])
        out.append(data[i + 4 : i + 8].decode("ascii"))
        i += 12 + n
    return out


def files_under(root):
    """{path under root: its bytes} of every file."""
    out = {}
    for folder, _, names in os.walk(root):
        for name in names:
            path = os.path.join(folder, name)
            with open(path, "rb") as f:
                out[os.path.relpath(path, root)] = f.read()
    return out


def check_page_is_self_contained(page):
    assert "http://" not in page and "https://" not in page
    sources = re.findall(r"""\bsrc\s*=\s*["']?([^"' >]*)""", page, re.IGNORECASE)
    assert sources, "no images"
    for source in sources:
        assert source.startswith("data:image/png;base64,"), source[:80]
    for link in re.findall(r"""\bhref\s*=\s*["']?([^"' >]*)""", page, re.IGNORECASE):
        assert link.startswith("#"), f"a link out of the page: {link}"
    assert "<link" not in page and "@import" not in page and "url(" not in page


@pytest.fixture(scope="module")
def made_report(tmp_path_factory):
    """The made study's report with everything: pictures, tracks, a sweep, a Pareto plane (about 2 s)."""
    study, results = made_study()
    out = tmp_path_factory.mktemp("report") / "study"
    out.mkdir()
    write_runs_files(str(out), results)
    os.makedirs(out / "plots")
    (out / "plots" / "metric_gone.png").write_bytes(b"an earlier report's")
    (out / "plots" / "notes.txt").write_text("someone's own")
    page = write_report(str(out), results, study, pareto=("gradeability.max_climb_deg", "turning.turning_diameter_m"))
    return study, results, out, page


@pytest.mark.slow  # a report of 18 plots
def test_write_report_writes_every_plot_and_one_page(made_report):
    _, _, out, page = made_report
    assert page == str(out / "report.html")
    plots = sorted(os.listdir(out / "plots"))
    numeric = ["max_climb_deg", "max_descent_deg", "predicted_climb_deg", "predicted_descent_deg"]
    # a measured limit and its prediction on one chart, not two
    expected = ["compare_gradeability.max_climb_deg.png", "compare_gradeability.max_descent_deg.png"]
    expected += ["metric_turning.clearance_diameter_m.png", "metric_turning.turning_diameter_m.png"]
    expected += [f"sweep_wide_gradeability.{m}.png" for m in numeric]
    expected += ["sweep_wide_turning.clearance_diameter_m.png", "sweep_wide_turning.turning_diameter_m.png"]
    expected += ["pareto.png", "tracks_std_gradeability.png", "tracks_std_turning.png"]
    expected += ["tracks_wide_y=0.6__gradeability.png", "notes.txt"]  # the world refused: tracks without a map
    assert plots == sorted(expected)  # no plot of words (limited_by, turn, surface), the stale plot gone
    for name in plots:
        if name.endswith(".png"):
            data = (out / "plots" / name).read_bytes()
            assert set(png_chunks(data)) <= {"IHDR", "pHYs", "IDAT", "IEND"}, name  # no date, no software
    with open(page, encoding="utf-8") as f:
        text = f.read()
    check_page_is_self_contained(text)
    images = re.findall(r'src="data:image/png;base64,([^"]+)"', text)
    assert len(images) == (len(plots) - 1) + 4  # every plot, the four pictures
    # the words and failures in the table, the study file escaped
    for words in ("traction", "tipping", "spin", "n/a: descent: false", "failed: cannot be built", "y=0.75"):
        assert words in text, words
    assert "Wheel track &lt;and&gt; payload &amp; co" in text
    assert '<td class="none">failed: broke: ZeroDivisionError (turning.py:80)</td>' in text  # in full
    assert '<td class="best">26</td>' in text  # std's climb, the steepest
    assert "&lt;script&gt;alert(&#x27;x&#x27;)&lt;/script&gt;" in text and "<script>alert" not in text
    assert "<pre>" + "description: &quot;Wheel track" in text
    assert "On the front of gradeability.max_climb_deg (larger is better) and turning.turning_diameter_m" in text
    assert "wide[y=0.9]: turning: tracks not shown" in text
    assert 'id="predicted"' in text and "apart, more than the study's step" not in text  # the study has no step


HEADLAND_TURNS = {
    "U": {"works": True, "headland_m": 1.95, "plants_touched": 0, "time_s": 20.7},
    "omega": "n/a: a U turn fits: an omega turn would only be longer",
    "spin": {"works": True, "headland_m": 1.88, "plants_touched": 10, "time_s": 26.7},
}


def disagreeing_study(step):
    """A climb 3.45 degrees below its prediction (the drive-patterns study's tricycle) beside one 1.1
    below, in a study whose ramps are step [deg] apart, and a headland's turns."""
    study = Study(
        source="/studies/tricycle.yaml", description="", seed=0,
        candidates=(candidate("near"), candidate("tricycle")),
        scenarios=(("gradeability", {"surface": "grass", "step_deg": step}), ("headland", {})),
        text="",
    )  # fmt: skip

    def scenarios(climb, predicted, failed):
        climbs = [[climb, "ok", "ok"], [failed, "tipping", "tipping"]]
        grade_ = {**grade(climb, "tipping"), "predicted_climb_deg": predicted, "predicted_descent_deg": 20.5,
                  "climbs": climbs, "descents": [[20.0, "ok"], [22.0, "ran away"]]}  # fmt: skip
        headland = {"min_headland_m": 1.88, "turn": "spin", "plants_touched": 10, "turns": HEADLAND_TURNS}
        return {"gradeability": grade_, "headland": headland}

    results = {
        "study": {"description": "", "seed": 0, "scenarios": ["gradeability", "headland"]},
        "candidates": {
            "near": entry("ok", scenarios(12.0, 13.1, 12.0 + step)),
            "tricycle": entry("ok", scenarios(12.0, 15.45, 12.0 + step)),
        },
    }
    return study, results


@pytest.mark.slow  # the statics or the report of every example robot, or a plot
def test_the_page_says_where_a_limit_and_its_prediction_disagree_beyond_the_step_and_not_otherwise(tmp_path):
    study, results = disagreeing_study(2.0)
    with open(write_report(str(tmp_path / "two"), results, study), encoding="utf-8") as f:
        text = f.read()
    plots = os.listdir(tmp_path / "two" / "plots")
    assert "compare_gradeability.max_climb_deg.png" in plots
    assert (
        "metric_gradeability.max_climb_deg.png" not in plots
        and "metric_gradeability.predicted_climb_deg.png" not in plots
    )
    section = text.split('<h2 id="predicted">')[1].split("<h2")[0]
    assert section.count('<li class="disagree">') == 1  # the tricycle's, not near's (1.1 degrees apart)
    assert "tricycle: climbed 12 deg (the 14 deg try: tipping), predicted 15.45 deg (traction): 3.45 deg apart, " \
           "more than the study&#x27;s step of 2 deg." in section  # fmt: skip
    assert "near: climbed" not in section
    assert (
        "Every candidate&#x27;s max_descent_deg is within the study&#x27;s step (2 deg) of its prediction." in section
    )
    # the same results in a study of 4 degree steps: within the step, no sentence
    study, results = disagreeing_study(4.0)
    with open(write_report(str(tmp_path / "four"), results, study), encoding="utf-8") as f:
        text = f.read()
    assert "apart, more than the study" not in text and '<li class="disagree">' not in text
    assert "Every candidate&#x27;s max_climb_deg is within the study&#x27;s step (4 deg) of its prediction." in text
    # the headland's turns, a row each, on the page
    turns = text.split('<h2 id="turns">')[1].split("<h2")[0]
    assert turns.split("<tbody>")[1].count("<tr>") == 6  # three turns of two candidates
    assert '<td class="text">spin</td><td class="works">yes</td><td>1.88</td><td>10</td><td>26.7</td>' in turns
    assert "n/a: a U turn fits: an omega turn would only be longer" in turns
    assert '<a href="#turns">Headland turns</a>' in text and '<a href="#predicted">' in text


@pytest.mark.slow  # two more reports
def test_write_report_twice_gives_the_same_bytes(made_report, tmp_path):
    study, results, out, _ = made_report
    first = files_under(out)
    write_report(str(out), results, study, pareto=("gradeability.max_climb_deg", "turning.turning_diameter_m"))
    assert files_under(out) == first
    other = tmp_path / "again"  # and in another folder, from scratch
    shutil.copytree(out, other)
    shutil.rmtree(other / "plots")
    os.remove(other / "report.html")
    write_report(str(other), results, study, pareto=("gradeability.max_climb_deg", "turning.turning_diameter_m"))
    again = files_under(other)
    assert {k: v for k, v in again.items() if k != "plots/notes.txt"} == {
        k: v for k, v in first.items() if k != "plots/notes.txt"
    }


@pytest.mark.slow  # the statics or the report of every example robot, or a plot
def test_write_report_of_one_scenario_without_pictures_tracks_or_pareto(tmp_path):
    """The quick one (two plots): what a study without the runs' pictures and tracks gets, twice the same."""
    study, results = made_study()
    study = dataclasses.replace(study, candidates=study.candidates[:2], scenarios=study.scenarios[1:])
    results = {**results, "candidates": {c.name: results["candidates"][c.name] for c in study.candidates}}
    page = write_report(str(tmp_path), results, study)
    assert page == str(tmp_path / "report.html")
    with open(page, encoding="utf-8") as f:
        text = f.read()
    check_page_is_self_contained(text)
    assert sorted(os.listdir(tmp_path / "plots")) == [
        "metric_turning.clearance_diameter_m.png",
        "metric_turning.turning_diameter_m.png",
        "sweep_wide_turning.clearance_diameter_m.png",
        "sweep_wide_turning.turning_diameter_m.png",
    ]
    assert 'id="candidates"' not in text and 'id="tracks"' not in text and 'id="pareto"' not in text
    assert text.count("<img ") == 4 and "spin" in text
    first = files_under(tmp_path)
    write_report(str(tmp_path), results, study)
    assert files_under(tmp_path) == first


def test_write_report_refuses_a_pareto_of_no_columns_before_writing(tmp_path):
    study, results = made_study()
    with pytest.raises(ReportError, match="not a column"):
        write_report(str(tmp_path), results, study, pareto=("gradeability.max_climb_deg", "turning.nothing"))
    assert os.listdir(tmp_path) == []


# ---- a real small study ------------------------------------------------------------------------------------------
REAL_STUDY = """\
description: "a climb and a turn, short"
seed: 2
candidates:
  std: {robot: thorvald_ii_4wd4ws_std}
  wide: {robot: thorvald_ii_4wd4ws_std, sweep: {"motor_drives.*.y": [0.6, 0.8]}}
scenarios:
  gradeability: {surface: grass, start_deg: 10, step_deg: 10, max_deg: 30, descent: false}
  turning: {settle: 1}
"""


@pytest.mark.slow  # a study of 6 runs in worker processes, about 20 s
def test_report_of_a_real_study(tmp_path):
    from thorvald_design.runs import read_results  # noqa: PLC0415
    from thorvald_design.study import load_study  # noqa: PLC0415

    path = tmp_path / "study.yaml"
    path.write_text(REAL_STUDY)
    out = tmp_path / "out"
    done = subprocess.run(
        ["rosrun", "thorvald_design", "design_study", str(path), "--out", str(out), "--jobs", "2"],
        capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr[-3000:]
    study, results = load_study(str(path)), read_results(str(out))
    pareto = ("gradeability.max_climb_deg", "turning.turning_diameter_m")
    page = write_report(str(out), results, study, pareto=pareto)
    plots = set(os.listdir(out / "plots"))
    for column in ("turning.turning_diameter_m", "turning.clearance_diameter_m"):
        assert f"metric_{column}.png" in plots and f"sweep_wide_{column}.png" in plots
    assert "compare_gradeability.max_climb_deg.png" in plots and "sweep_wide_gradeability.max_climb_deg.png" in plots
    # what the runs write for the report's turning plots and side views: each turn's centre, outermost
    # wheel and diameters (the results' own), each try's series, heights and world
    turning = json.loads((out / "tracks" / "std" / "turning.json").read_text())
    ways = results["candidates"]["std"]["scenarios"]["turning"]["ways"]
    for track_, way in zip(turning["tracks"], ways):
        assert track_["marks"]["turning_diameter_m"] == way["turning_diameter_m"]
        assert track_["marks"]["clearance_diameter_m"] == way["clearance_diameter_m"]
        assert len(track_["marks"]["outline"]) >= 4 and track_["marks"]["outer_wheel"][0].startswith("drive")
    climbs = json.loads((out / "tracks" / "std" / "gradeability.json").read_text())["tracks"]
    assert [t["marks"]["value"] for t in climbs] == [c[0] for c in results["candidates"]["std"]["scenarios"][
        "gradeability"]["climbs"]]  # fmt: skip
    assert all(len(t["z"]) == len(t["x"]) and t["world"]["slopes"] for t in climbs)
    assert "as_simulated" in results["candidates"]["std"]["scenarios"]["gradeability"]
    assert "pareto.png" in plots and not any("limited_by" in p or ".turn." in p for p in plots)
    # the runs' tracks, when they write them: a map of each
    for name in results["candidates"]:
        for scenario, _ in study.scenarios:
            if (out / "tracks" / safe_name(name) / f"{scenario}.json").is_file():
                assert f"tracks_{safe_name(name)}_{scenario}.png" in plots
    with open(page, encoding="utf-8") as f:
        text = f.read()
    check_page_is_self_contained(text)
    first = files_under(out)
    write_report(str(out), results, study, pareto=pareto)
    assert files_under(out) == first


# ---- in a browser --------------------------------------------------------------------------------------------------
def chromium(tmp_path, *args):
    if not os.path.isfile(CHROMIUM):
        pytest.fail(
            f"{CHROMIUM} is missing: the report's browser test needs Debian's chromium; run the workspace's "
            "setup (it installs it: apt-get install -y chromium)"
        )
    profile = tempfile.mkdtemp(prefix="chromium-", dir=tmp_path)
    command = [CHROMIUM, "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
               "--disable-background-networking", "--disable-component-update", "--disable-sync",
               f"--user-data-dir={profile}", *args]  # fmt: skip
    done = subprocess.run(command, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr[-3000:]
    return done


@pytest.mark.slow  # two Chromium processes, a few seconds
def test_report_in_headless_chromium(made_report, tmp_path):
    _, _, _, page = made_report
    url = "file://" + os.path.abspath(page)
    shot = tmp_path / "screenshot.png"
    chromium(tmp_path, f"--screenshot={shot}", "--window-size=1200,2000", url)
    with Image.open(shot) as im:
        rgb = im.convert("RGB")
        assert rgb.size == (1200, 2000)
        assert rgb.getcolors(maxcolors=1) is None, "the screenshot is one colour"
        grey = rgb.convert("L")
        drawn = sum(n for value, n in enumerate(grey.histogram()) if value < 200)
        assert drawn > 0.01 * 1200 * 2000, f"only {drawn} dark pixels: the page looks empty"
    dom = chromium(tmp_path, "--dump-dom", "--virtual-time-budget=5000", url).stdout
    body = re.search(r"<body[^>]*>", dom)
    assert body, dom[:2000]
    loaded = re.search(r'data-images-loaded="(\d+)"', body.group(0))
    broken = re.search(r'data-images-broken="(\d+)"', body.group(0))
    assert loaded and broken, f"the page's image counter did not run: {body.group(0)}"
    with open(page, encoding="utf-8") as f:
        images = len(re.findall(r"<img\b", f.read()))
    assert images > 0
    assert (int(loaded.group(1)), int(broken.group(1))) == (images, 0)
