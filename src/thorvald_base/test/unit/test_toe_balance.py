"""The toe search (thorvald_base.calibration.toe_balance) on synthetic legs: a rigid frame whose wheels
scrub by how far each one's toe lies from the motion the frame follows, each costing resistance in
proportion to its load; and the offsets' patterns the frame follows for free (the gauge)."""

import math

import numpy as np
import pytest

from thorvald_base.calibration.toe_balance import (
    TOE_ROUNDS,
    ToeSearch,
    resistance,
    searched,
    toe_gauge,
    toe_legs,
    vertex,
)
from thorvald_base.calibration.torque_balance import Leg
from thorvald_base.errors import CalibrationError
from thorvald_model import load_robot_config
from thorvald_model.description import package_file

ASYM = load_robot_config(package_file("config", "thorvald_ii_6wd6ws_asym", "thorvald_ii_6wd6ws_asym.yaml"))
TALL = load_robot_config(package_file("config", "thorvald_ii_4wd2ws_tall", "thorvald_ii_4wd2ws_tall.yaml"))
DIFF = load_robot_config(package_file("config", "thorvald_ii_2wd_diff", "thorvald_ii_2wd_diff.yaml"))
ONE = load_robot_config(package_file("config", "thorvald_ii_1wd1ws_fwd", "thorvald_ii_1wd1ws_fwd.yaml"))
TRUE = np.radians([0.347, -0.245, -0.051, 0.289, -0.472, -0.067])  # field:1's modules, homed off
LOADS = np.array([264.0, 519.0, 489.0, 519.0, 287.0, 486.0])  # [N] its wheels' shares of the frame


def frame_resistance(offsets, config=ASYM, true=TRUE, loads=LOADS, slope=0.00025):
    """[N m] a frame's resistance: each wheel scrubs by its toe beyond the motion the frame follows (the
    offsets' error off the gauge's patterns), at a cost per degree in proportion to its load."""
    g = toe_gauge(config)
    e = np.asarray(offsets) - true
    toe = e - g @ (g.T @ e)
    return float(np.sum(slope * loads * np.abs(np.degrees(toe))))


def search_on(config, start, measure):
    search = ToeSearch(config, start)
    legs = 0
    while not search.done:
        search.record(measure(search.offsets()))
        legs += 1
    return search, legs


def test_the_patterns_the_frame_follows_are_a_crab_and_an_arc_of_the_steered_drives():
    g = toe_gauge(ASYM)
    assert g.shape == (6, 2) and np.allclose(g.T @ g, np.eye(2))
    x = np.array([d.x for d in ASYM.drives])
    for pattern in (np.ones(6), x):  # each lies in the gauge: nothing of it is left outside
        assert np.allclose(pattern - g @ (g.T @ pattern), 0.0)
    # two drives steer in front of a fixed axle: only their turning alike (an arc about that axle)
    g = toe_gauge(TALL)
    steered = [d.steerable for d in TALL.drives]
    assert g.shape == (4, 1) and np.allclose(g[~np.array(steered)], 0.0)
    assert np.allclose(np.abs(g[np.array(steered), 0]), math.sqrt(0.5))
    assert toe_gauge(DIFF).shape[1] == 0


def test_the_search_drives_three_legs_per_steered_drive_and_round_and_none_without_a_toe():
    assert searched(ASYM) == (0, 1, 2, 3, 4, 5) and toe_legs(ASYM) == 3 * TOE_ROUNDS * 6
    assert searched(TALL) == (0, 1) and toe_legs(TALL) == 3 * TOE_ROUNDS * 2
    assert searched(DIFF) == () and toe_legs(DIFF) == 0  # nothing steers
    assert searched(ONE) == () and toe_legs(ONE) == 0  # one steered drive: the frame follows it
    with pytest.raises(CalibrationError, match="no toe"):
        ToeSearch(DIFF, [0.0, 0.0])


@pytest.mark.parametrize("d", [0.0, 0.3, -0.7, 1.0, -1.0])
def test_the_vertex_of_a_v_through_three_legs(d):
    step, slope, floor = 0.005, 40.0, 0.2

    def v(x):
        return floor + slope * abs(x - d * step)

    assert vertex(v(-step), v(0.0), v(step), step) == pytest.approx(d * step, abs=1e-12)


def test_a_vertex_beyond_the_step_is_one_step_and_no_v_is_the_lower_side_or_nothing():
    step = 0.005
    assert vertex(1.0, 0.9, 0.8, step) == pytest.approx(step)  # falling all the way: the vertex is further
    assert vertex(0.8, 0.9, 1.0, step) == pytest.approx(-step)
    assert vertex(0.5, 0.9, 0.6, step) == step * -1  # the middle above both sides: the lower side
    assert vertex(1.0, 0.9, 1.0, step) == 0.0  # the middle lowest, the sides alike: stay
    assert vertex(0.9, 0.9, 0.9, step) == 0.0  # flat: nothing to follow


def test_the_search_finds_the_toe_and_keeps_the_crab_and_the_arc_it_started_with():
    g = toe_gauge(ASYM)
    rng = np.random.default_rng(1)
    toe = np.radians(rng.uniform(-0.5, 0.5, 6))
    start = TRUE + toe - g @ (g.T @ toe) + g @ np.array([0.002, -0.001])  # the gauge off too: ground truth's
    search, legs = search_on(ASYM, start, frame_resistance)
    found = np.asarray(search.result)
    assert legs == search.legs == toe_legs(ASYM)
    e = found - TRUE
    assert np.degrees(np.max(np.abs(e - g @ (g.T @ e)))) < 0.02  # [deg] of the toe, from 0.5
    assert np.allclose(g.T @ found, g.T @ start, atol=1e-15)  # the crab and the arc as they started
    assert frame_resistance(found) < 0.05 * frame_resistance(start)
    assert [m.drive for m in search.moves] == list(range(6)) * TOE_ROUNDS
    assert all(abs(m.move) <= m.step + 1e-15 for m in search.moves)


def test_a_resistance_that_does_not_depend_on_the_toe_moves_nothing():
    search, _ = search_on(ASYM, TRUE, lambda offsets: 0.4)
    assert np.allclose(search.result, TRUE)


def test_the_resistance_is_the_wheels_mean_torque_against_the_travel():
    forwards = Leg((0.2,) * 3, 0.2, (0.1, 0.3, 0.5))
    back = Leg((0.2,) * 3, -0.2, (-0.1, -0.3, -0.5))
    assert resistance(forwards) == pytest.approx(0.3) and resistance(back) == pytest.approx(0.3)


def test_the_search_refuses_what_it_cannot_use():
    with pytest.raises(CalibrationError, match="6 drives"):
        ToeSearch(ASYM, [0.0] * 4)
    with pytest.raises(CalibrationError, match="positive step"):
        ToeSearch(ASYM, [0.0] * 6, step=0.0)
    search = ToeSearch(ASYM, [0.0] * 6)
    with pytest.raises(CalibrationError, match="nan"):
        search.record(float("nan"))
    for _ in range(search.legs):
        search.record(1.0)
    assert search.done and search.offsets() == search.result
    with pytest.raises(CalibrationError, match="done"):
        search.record(1.0)
