"""What the report's figures carry (thorvald_design.report.views, and the plots drawn from it): a
measured limit beside its prediction and the sentence the page says only where they are more than
the study's step apart; a turn's ISO 789-3 circles and its outermost wheel's path, a spin's included;
the headland's turns a colour and a legend entry each, the plants they touched ringed; a series of
tries from the side, how far each got. Synthetic tracks whose answers are known in closed form; no
simulation (each plot about 0.2 s)."""

import math

import matplotlib
import numpy as np
import pytest

from thorvald_design.report.page import turns_html
from thorvald_design.report.plan import world_map
from thorvald_design.report.plots import (
    GAP,
    RC,
    plot_comparison,
    plot_headland,
    plot_side,
    plot_turning,
    side_exaggeration,
)
from thorvald_design.report.tracks import Drive, parse_tracks
from thorvald_design.report.views import (
    circle,
    comparisons,
    disagreement,
    disagrees,
    ground_height,
    headland_rows,
    pairings,
    section_direction,
    side_series,
    side_try,
    try_text,
    turn_legend,
    turn_view,
)
from thorvald_design.scenarios.driving import ramp_world
from thorvald_design.scenarios.obstacle import step_world
from thorvald_design.scenarios.side_slope import side_slope_world
from thorvald_design.study import Candidate, Study
from thorvald_sim.world import parse_world


# ---- measured against predicted ----------------------------------------------------------------------------
def study_of(scenarios):
    return Study(
        source="/studies/s.yaml",
        description="",
        seed=0,
        candidates=tuple(Candidate(n, f"/robots/{n}.yaml", {}) for n in ("near", "tricycle", "gone")),
        scenarios=scenarios,
        text="",
    )


def grade(climb, predicted, climbs, as_simulated=None):
    out = {"surface": "grass", "max_climb_deg": climb, "limited_by": "tipping", "max_crest_deg": climb,
           "max_descent_deg": 16.0, "predicted_climb_deg": predicted, "predicted_limited_by": "tipping",
           "predicted_descent_deg": 16.7, "climbs": climbs, "descents": [[2.0, "ok"], [18.0, "ran away"]]}  # fmt: skip
    if as_simulated is not None:
        out["as_simulated"] = as_simulated
    return out


# the drive-patterns study's rear-driven tricycle, as the study measured it: 12 held, 14 tipped, 15.45
# predicted; with the simulated robot's centre of mass 14.37, rolling too 13.17 (quasi_static's figures)
TRICYCLE = grade(
    12.0,
    15.45,
    [[10.0, "ok", "ok"], [12.0, "ok", "ok"], [14.0, "tipping", "tipping"]],
    {"com_height_m": 0.4988, "simulated_com_height_m": 0.5381,
     "with_com": {"predicted_climb_deg": 14.37, "predicted_descent_deg": 16.47},
     "with_com_and_rolling": {"predicted_climb_deg": 13.17, "predicted_descent_deg": 16.73, "rolling_offset_m": 0.012}},
)  # fmt: skip


def results_of(near_predicted=13.1, tricycle=TRICYCLE):
    return {
        "candidates": {
            "near": {"status": "ok", "mass_kg": 99.0, "scenarios": {"gradeability": grade(
                12.0, near_predicted, [[12.0, "ok", "ok"], [14.0, "traction", "traction"]])}},
            "tricycle": {"status": "ok", "mass_kg": 88.0, "scenarios": {"gradeability": tricycle}},
            "gone": {"status": "failed: cannot be built: x", "mass_kg": None,
                     "scenarios": {"gradeability": "failed: cannot be built: x"}},
        }
    }  # fmt: skip


STEP2 = (("gradeability", {"surface": "grass", "step_deg": 2.0}),)


def test_the_comparisons_are_the_measured_metrics_with_a_prediction_and_the_studys_step():
    found = comparisons(results_of(), study_of(STEP2))
    assert [(c.column, c.predicted_column) for c in found] == [
        ("gradeability.max_climb_deg", "gradeability.predicted_climb_deg"),
        ("gradeability.max_descent_deg", "gradeability.predicted_descent_deg"),
    ]
    climb = found[0]
    assert climb.step == 2.0 and [r.candidate for r in climb.rows] == ["near", "tricycle", "gone"]
    near, tricycle, gone = climb.rows
    assert (near.measured, near.predicted, near.failed_at, near.failed_how) == (12.0, 13.1, 14.0, "traction")
    assert (tricycle.failed_at, tricycle.failed_how) == (14.0, "tipping")
    assert (tricycle.with_com, tricycle.with_com_and_rolling, tricycle.rolling_offset) == (14.37, 13.17, 0.012)
    assert gone.measured.startswith("failed") and not gone.numbers
    # a descent's tries: the first failed one
    assert found[1].rows[1].failed_at == 18.0 and found[1].rows[1].failed_how == "ran away"
    # every pairing's metric is one its scenario reports: the four the scenarios declare
    from thorvald_design.scenarios import SCENARIOS  # noqa: PLC0415

    found = pairings()
    for p in found:
        assert p.measured in SCENARIOS[p.scenario].results and p.predicted in SCENARIOS[p.scenario].results
    assert [(p.scenario, p.measured, p.predicted, p.step, p.unit) for p in found] == [
        ("gradeability", "max_climb_deg", "predicted_climb_deg", "step_deg", "deg"),
        ("gradeability", "max_descent_deg", "predicted_descent_deg", "step_deg", "deg"),
        ("side_slope", "max_traverse_deg", "static_overturning_deg", "step_deg", "deg"),
        ("drawbar", "max_pull_n", "predicted_pull_n", "step_n", "N"),
    ]


def test_the_page_says_a_limit_and_its_prediction_disagree_only_beyond_the_step_and_why():
    climb = comparisons(results_of(), study_of(STEP2))[0]
    near, tricycle, gone = climb.rows
    assert not disagrees(climb, near) and disagreement(climb, near) == ""  # 1.1 deg apart: within the step
    assert not disagrees(climb, gone) and disagreement(climb, gone) == ""
    assert disagrees(climb, tricycle)  # 3.45 deg apart
    text = disagreement(climb, tricycle)
    assert text.startswith("tricycle: climbed 12 deg (the 14 deg try: tipping), predicted 15.45 deg (tipping): ")
    assert "3.45 deg apart, more than the study's step of 2 deg" in text
    # why: the simulated robot's centre of mass (3.9 cm higher), then the rolling resistance's moment, and
    # the prediction with both lies between the try held (12) and the one that failed (14)
    assert "0.538 m above the ground, 3.9 cm above its description's 0.499 m" in text
    assert "with it the prediction is 14.37 deg" in text
    assert (
        "12 mm ahead of its contact" in text
        and "13.17 deg, between the last try held and the first that failed" in text
    )
    # with a step of 4 degrees the same numbers agree: no sentence
    wide = comparisons(results_of(), study_of((("gradeability", {"step_deg": 4.0}),)))[0]
    assert not any(disagrees(wide, r) for r in wide.rows) and disagreement(wide, wide.rows[1]) == ""
    # just over the step, and the prediction below the measured: the simulated robot did better
    near_over = comparisons(results_of(near_predicted=9.9), study_of(STEP2))[0]
    text = disagreement(near_over, near_over.rows[0])
    assert "2.1 deg apart" in text and "did better than the model allows" in text
    # exactly a step apart is not more than the step
    assert not disagrees(*_row(comparisons(results_of(near_predicted=14.0), study_of(STEP2))[0], 0))


def _row(comparison, k):
    return comparison, comparison.rows[k]


def test_without_the_simulated_robots_figures_the_sentence_gives_the_scenarios_own_causes():
    bare = {k: v for k, v in TRICYCLE.items() if k != "as_simulated"}
    climb = comparisons(results_of(tricycle=bare), study_of(STEP2))[0]
    text = disagreement(climb, climb.rows[1])
    assert "Why: a soft ramp sinks most under the most loaded wheel" in text and "centre of mass" not in text
    # figures that move the prediction too little are not named as the cause, but given
    small = dict(TRICYCLE, as_simulated={
        "com_height_m": 0.4988, "simulated_com_height_m": 0.5, "with_com": {"predicted_climb_deg": 15.4},
        "with_com_and_rolling": {"predicted_climb_deg": 15.3, "rolling_offset_m": 0.003},
    })  # fmt: skip
    climb = comparisons(results_of(tricycle=small), study_of(STEP2))[0]
    text = disagreement(climb, climb.rows[1])
    assert "cm above its description's" not in text and "mm ahead" not in text
    assert "(The robot as simulated, its centre of mass and rolling resistance: 15.3 deg.)" in text


@pytest.mark.slow  # the statics or the report of every example robot, or a plot
def test_the_comparison_chart_draws_measured_and_predicted_on_one_chart_and_marks_the_disagreement(tmp_path):
    climb = comparisons(results_of(), study_of(STEP2))[0]
    with matplotlib.rc_context(RC):
        fig = plot_comparison(climb, str(tmp_path / "c.png"))
    (ax,) = [a for a in fig.axes]
    assert [t.get_text() for t in ax.get_yticklabels()] == ["near", "tricycle (!)", "gone"]
    assert [t.get_color() for t in ax.get_yticklabels()][1] == GAP
    bars = [(round(b.get_x(), 6), round(b.get_width(), 6)) for b in ax.patches]
    assert (0.0, 12.0) in bars and (12.0, 2.0) in bars  # held 12, on to the 14 that failed
    predicted = [ln for ln in ax.lines if ln.get_marker() == "D" and ln.get_markerfacecolor() != "none"]
    assert sorted(float(ln.get_xdata()[0]) for ln in predicted) == [13.1, 15.45]
    hollow = [ln for ln in ax.lines if ln.get_marker() == "D" and ln.get_markerfacecolor() == "none"]
    assert [float(ln.get_xdata()[0]) for ln in hollow] == [13.17]  # the robot as simulated, rolling
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "predicted (quasi-static)" in labels and "measured: the last try held" in labels
    assert "(!): more than the study's step (2 deg) apart" in labels
    assert any("failed: cannot be built" in t.get_text() for t in ax.texts)  # a gap says why
    assert (tmp_path / "c.png").stat().st_size > 5000


# ---- a turn's circles --------------------------------------------------------------------------------------
def spin_drive(label="turn left", way=1.0):
    """A robot spinning on the spot about (1, 2) at 0.5 rad/s, its outermost wheel at (0.5, 0.3) in
    base_link: that wheel's path is a circle of diameter 2 hypot(0.5, 0.3) about the spot."""
    t = [0.1 * k for k in range(130)]
    wheel = math.hypot(0.5, 0.3)
    marks = {"centre": [1.0, 2.0], "outer_wheel": ["drive1", 0.5, 0.3], "outer_point": [0.6, 0.45],
             "turning_diameter_m": round(2 * wheel, 3), "clearance_diameter_m": 1.5,
             "outline": [[-0.6, -0.45], [0.6, -0.45], [0.6, 0.45], [-0.6, 0.45]], "steady_from_s": 2.0}  # fmt: skip
    return {"label": label, "outcome": "ok", "t": t, "x": [1.0] * 130, "y": [2.0] * 130,
            "yaw": [way * 0.5 * s for s in t], "marks": marks}  # fmt: skip


def test_a_spins_wheel_path_is_a_circle_about_the_spot_of_the_turning_diameter():
    drive = parse_tracks({"tracks": [spin_drive()]}).drives[0]
    turn = turn_view(drive)
    xs, ys = turn.wheel_path
    radii = np.hypot(np.asarray(xs) - 1.0, np.asarray(ys) - 2.0)
    assert radii == pytest.approx(math.hypot(0.5, 0.3), abs=1e-9)  # a circle about the spot, not a point
    assert 2 * radii.max() == pytest.approx(turn.turning_diameter, abs=1e-3)
    cx, cy = circle(turn.centre, turn.clearance_diameter)
    assert np.hypot(cx - 1.0, cy - 2.0) == pytest.approx(0.75)
    # the outline and outermost point where the steady turn began (t = 2 s: yaw 1 rad)
    c, s = math.cos(1.0), math.sin(1.0)
    assert turn.outer_point == pytest.approx((1.0 + c * 0.6 - s * 0.45, 2.0 + s * 0.6 + c * 0.45))
    assert len(turn.outline) == 4 and turn.outer_wheel == "drive1"
    assert turn_view(parse_tracks({"tracks": [dict(spin_drive(), marks={})]}).drives[0]) is None


@pytest.mark.slow  # the statics or the report of every example robot, or a plot
def test_the_turning_plot_carries_both_circles_the_wheel_path_and_both_diameters(tmp_path):
    tracks = parse_tracks({"tracks": [spin_drive(), spin_drive("turn right", -1.0)]})
    turns = [turn_view(d) for d in tracks.drives]
    with matplotlib.rc_context(RC):
        fig = plot_turning("std: turning", tracks, turns, str(tmp_path / "t.png"))
    ax = fig.axes[0]

    def diameter(line):
        x, y = np.asarray(line.get_xdata(), float), np.asarray(line.get_ydata(), float)
        return 2 * float(np.max(np.hypot(x - 1.0, y - 2.0))) if len(x) > 2 else 0.0

    dashed = [diameter(ln) for ln in ax.lines if ln.get_linestyle() == "--" and len(ln.get_xdata())]
    dotted = [diameter(ln) for ln in ax.lines if ln.get_linestyle() == ":" and len(ln.get_xdata())]
    assert dashed == pytest.approx([2 * math.hypot(0.5, 0.3)] * 2, abs=2e-3)  # the turning diameter's circles
    assert dotted == pytest.approx([1.5, 1.5], abs=1e-9)  # the clearance diameter's
    paths = [ln for ln in ax.lines if ln.get_linewidth() > 2.0]
    assert len(paths) == 2 and diameter(paths[0]) == pytest.approx(2 * math.hypot(0.5, 0.3), abs=1e-6)
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert "turn left: drive1's path, turning diameter 1.17 m, clearance diameter 1.50 m" in labels
    assert "turn right: drive1's path, turning diameter 1.17 m, clearance diameter 1.50 m" in labels
    assert {"Ø 1.17 m", "Ø 1.50 m"} <= {t.get_text() for t in ax.texts}
    # the view holds the clearance circle, not a robot's breadth around a spot
    (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
    assert x0 < 0.25 and x1 > 1.75 and y0 < 1.25 and y1 > 2.75


# ---- the headland ------------------------------------------------------------------------------------------
def headland_drive(turn, works, xs, ys, touched):
    n = len(xs)
    return {"label": f"{turn} turn", "outcome": "ok" if works else "failed", "t": [0.1 * k for k in range(n)],
            "x": xs, "y": ys, "yaw": [0.0] * n,
            "marks": {"turn": turn, "works": works, "headland_m": 1.95, "plants_touched": len(touched),
                      "time_s": 20.7, "touched": touched}}  # fmt: skip


def test_the_headland_plot_draws_a_colour_and_a_legend_entry_a_turn_and_rings_the_plants_touched(tmp_path):
    world = {"ground": {"surface": "grass"}, "rows": {"row0": {"x": -4.0, "y": -0.75, "count": 4, "spacing": 0.75,
             "length": 4.0, "plant_spacing": 0.3, "plant_radius": 0.1, "plant_height": 0.4}}}  # fmt: skip
    data = {"world": world, "tracks": [
        headland_drive("U", True, [-3.0, 0.5, 1.0, 0.5, -3.0], [0.0, 0.0, 0.375, 0.75, 0.75], []),
        headland_drive("spin", True, [-3.0, 1.0, 1.0, -3.0], [0.0, 0.0, 0.75, 0.75], [[-0.4, 0.75], [-0.7, 0.75]]),
        headland_drive("omega", False, [-3.0, 2.0], [0.0, 1.0], [[-1.0, 0.0]]),
    ]}  # fmt: skip
    tracks = parse_tracks(data)
    plan = world_map(parse_world(world))
    with matplotlib.rc_context(RC):
        fig = plot_headland("std: headland", tracks, plan, "", str(tmp_path / "h.png"))
    ax = fig.axes[0]
    labels = [t.get_text() for t in fig.legends[0].get_texts()]
    assert labels[:3] == [
        "U: works, headland 1.95 m, 0 plants touched, 21 s",
        "spin: works, headland 1.95 m, 2 plants touched, 21 s",
        "omega: fails, headland 1.95 m, 1 plant touched, 21 s",
    ]
    paths = [ln for ln in ax.lines if ln.get_label() in labels]
    assert len({ln.get_color() for ln in paths}) == 3  # a colour a turn
    rings = [c for c in ax.collections if len(c.get_offsets()) and np.all(c.get_facecolor()[:, 3] == 0)]
    ringed = sorted(tuple(map(float, p)) for c in rings for p in c.get_offsets())
    assert ringed == [(-1.0, 0.0), (-0.7, 0.75), (-0.4, 0.75)]
    spin_colour = next(ln.get_color() for ln in paths if ln.get_label().startswith("spin"))
    spin_ring = next(c for c in rings if len(c.get_offsets()) == 2)
    assert matplotlib.colors.to_hex(spin_ring.get_edgecolor()[0]) == matplotlib.colors.to_hex(spin_colour)
    assert turn_legend({"turn": "crab", "works": True}) == "crab: works"


def test_the_per_turn_table_has_every_turn_of_every_candidate():
    results = {"candidates": {
        "std": {"scenarios": {"headland": {"turns": {
            "U": {"works": True, "headland_m": 1.95, "plants_touched": 0, "time_s": 20.7},
            "omega": "n/a: a U turn fits: an omega turn would only be longer",
            "crab": {"works": True, "headland_m": 1.86, "plants_touched": 3, "time_s": 19.0}}}}},
        "broken": {"scenarios": {"headland": "failed: broke: ValueError (headland.py:1)"}},
        "other": {"scenarios": {}},
    }}  # fmt: skip
    rows = headland_rows(results)
    assert [(r.candidate, r.turn, r.works, r.headland_m, r.plants_touched, r.time_s) for r in rows] == [
        ("std", "U", True, 1.95, 0, 20.7),
        ("std", "omega", None, None, None, None),
        ("std", "crab", True, 1.86, 3, 19.0),
        ("broken", "", None, None, None, None),
    ]
    assert rows[1].note.startswith("n/a: a U turn fits") and rows[3].note.startswith("failed: broke")
    page = turns_html(rows)
    assert page.split("<tbody>")[1].count("<tr>") == 4  # a row a turn tried, one for the failed scenario
    assert '<td class="text">U</td><td class="works">yes</td><td>1.95</td><td>0</td><td>20.7</td>' in page
    assert "n/a: a U turn fits: an omega turn would only be longer" in page and "failed: broke" in page


# ---- from the side -----------------------------------------------------------------------------------------
def climb(angle, outcome, xs, z=None, series="climb"):
    n = len(xs)
    drive = {"label": f"climb {angle:g} deg", "outcome": outcome, "t": [0.1 * k for k in range(n)], "x": xs,
             "y": [0.0] * n, "yaw": [0.0] * n, "world": ramp_world("grass", math.radians(angle), 3.0, 2.0),
             "marks": {"series": series, "value": angle, "unit": "deg", "section": "along"}}  # fmt: skip
    if z is not None:
        drive["z"] = z
    return parse_tracks({"tracks": [drive]}).drives[0]


def test_a_ramps_side_view_is_its_profile_and_the_robots_path_over_it_to_how_far_it_got():
    angle = 10.0
    drive = climb(angle, "tipping", [-1.0 + 0.1 * k for k in range(25)])  # to x = 1.4 on the incline
    world = parse_world(dict(drive.world))
    one = side_try(drive, world)
    assert (one.series, one.value, one.section, one.ok) == ("climb", 10.0, "along", False)
    s, z = one.ground
    t = math.tan(math.radians(angle))
    expected = np.clip(np.minimum(s, 8.0 - s), 0.0, 3.0) * t  # foot at 0, crest at 3, top to 5, down to 8
    assert z == pytest.approx(expected, abs=1e-9)
    assert one.reached == pytest.approx(1.4) and s.min() < -1.0 and s.max() > 8.0  # the whole hill in view
    ps, pz = one.path  # no heights recorded: the path lies on the ground
    assert pz == pytest.approx(np.clip(np.asarray(ps), 0.0, None) * t, abs=1e-3)
    assert try_text(one) == "10°: tipping at 1.40 m"
    # recorded heights are drawn as they are (a robot tipping rises off its path)
    lifted = side_try(climb(angle, "tipping", [0.0, 0.5, 1.0], z=[0.0, 0.3, 0.9]), world)
    assert list(lifted.path[1]) == [0.0, 0.3, 0.9]
    assert side_try(Drive("pull", "ok", (0.0, 1.0), (0.0, 0.0)), world) is None  # not a try of a series


def test_a_steps_and_a_side_slopes_profiles():
    step = parse_world(step_world("tarmac", 0.12, 0.0, 3.0))
    assert ground_height(step, -0.01, 0.0) == 0.0 and ground_height(step, 0.01, 0.0) == pytest.approx(0.12)
    assert ground_height(step, 1.5, 5.0) == 0.0  # beside it
    slope = parse_world(side_slope_world("grass", math.radians(20.0), 4.0, 10.0))
    drive = Drive("20 deg, left side uphill", "ok", (-3.0, 0.0, 2.0), (2.0, 2.0, 2.02), (0.0, 0.0, 0.0),
                  marks={"series": "left side uphill", "value": 20.0, "unit": "deg", "section": "across"})  # fmt: skip
    assert section_direction(slope, drive, "across") == pytest.approx((0.0, 1.0))  # up the face, across the drive
    one = side_try(drive, slope)
    s, z = one.ground
    on_face = (s > 0.0) & (s < 4.0)
    assert z[on_face] == pytest.approx(s[on_face] * math.tan(math.radians(20.0)), abs=1e-9)
    assert one.reached == pytest.approx(3.0 + math.hypot(2.0, 0.02))  # the distance covered, in plan
    assert try_text(one) == "20°: ok, 5.0 m along"


@pytest.mark.slow  # the statics or the report of every example robot, or a plot
def test_the_side_view_draws_a_panel_a_series_and_says_how_far_each_try_got(tmp_path):
    drives = [climb(a, "ok", [-1.0 + 0.2 * k for k in range(40)]) for a in (6.0, 8.0, 10.0)]
    drives.append(climb(12.0, "tipping", [-1.0 + 0.2 * k for k in range(12)]))
    drives.append(climb(8.0, "ok", [5.0 + 0.2 * k for k in range(20)], series="descent"))
    tries = [side_try(d, parse_world(dict(d.world))) for d in drives]
    assert [(name, [t.value for t in found]) for name, found in side_series(tries)] == [
        ("climb", [6.0, 8.0, 10.0, 12.0]),
        ("descent", [8.0]),
    ]
    with matplotlib.rc_context(RC):
        fig = plot_side("rwd: gradeability", tries, "", str(tmp_path / "s.png"))
    panels = [a for a in fig.axes if a.get_title()]
    assert [a.get_title() for a in panels] == ["rwd: gradeability: climb", "rwd: gradeability: descent"]
    texts = [t.get_text() for t in panels[0].texts]
    assert "12°: tipping at 1.20 m" in texts and "10°: ok" in texts  # the failed one and the last held
    assert "6°: ok" not in texts  # the others by their colour
    failed = [ln for ln in panels[0].lines if ln.get_marker() == "X" and len(ln.get_xdata())]
    assert [float(ln.get_xdata()[0]) for ln in failed] == pytest.approx([1.2])  # where it got to
    assert side_exaggeration(10.0, 1.0) == 3.0 and side_exaggeration(4.0, 2.0) == 1.0
    assert side_exaggeration(4.0, 0.0001) == 20.0


def test_a_pull_on_several_surfaces_is_compared_surface_by_surface_not_twice_for_the_first():
    pulls = {"max_pull_n": 275.0, "limited_by": "motor torque", "predicted_pull_n": 273.8, "surface": "grass"}
    for kind, held, predicted in (("grass", 275.0, 273.8), ("tarmac", 325.0, 297.7)):
        pulls.update(
            {f"max_pull_n.{kind}": held, f"limited_by.{kind}": "traction", f"predicted_pull_n.{kind}": predicted}
        )
    study = study_of((("drawbar", {"surface": ("grass", "tarmac"), "step_n": 25.0}),))
    results = {"candidates": {"tricycle": {"status": "ok", "scenarios": {"drawbar": pulls}}}}
    found = comparisons(results, study)
    assert [c.column for c in found] == ["drawbar.max_pull_n.grass", "drawbar.max_pull_n.tarmac"]
    tarmac = found[1]
    assert tarmac.suffix == ".tarmac" and tarmac.rows[0].failed_at == 350.0  # the next pull, which it lost
    assert disagrees(tarmac, tarmac.rows[0]) and not disagrees(found[0], found[0].rows[0])
    assert disagreement(tarmac, tarmac.rows[0]).startswith("tricycle: held 325 N (the 350 N try: traction)")
