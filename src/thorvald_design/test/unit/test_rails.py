"""The rails scenario (paper 3.1: the greenhouse robot switches the wheel diameter base_driver calculates
with between the floor and the heating pipes): the greenhouse robot driven onto the pipes, along them
and back, with the switch and without it, against the closed form of the odometry's error."""

import math
import os
from typing import Any, Dict

import pytest

from thorvald_design.design import design_of
from thorvald_design.lab import Lab
from thorvald_design.scenarios.rails import KEYS, RAILS, RESULTS, rails_world
from thorvald_model.description import package_file
from thorvald_sim.world import parse_world

HERE = os.path.dirname(os.path.abspath(__file__))
NAME = "greenhouse_rails"
ROBOT = os.path.join(HERE, "..", "..", "studies", "robots", NAME + ".yaml")
PARAMS: Dict[str, Any] = {k.name: k.default for k in KEYS}  # 10 m along 51 mm pipes 0.55 m apart


def example(name):
    path = ROBOT if name == NAME else package_file("config", name, name + ".yaml")
    return design_of(name, path)


@pytest.fixture(scope="module")
def drove():
    """The scenario's result and its lab (the drives' worlds and tracks): about 130 s simulated, 5 s."""
    lab = Lab(ROBOT)
    return RAILS.procedure(lab, example(NAME), PARAMS), lab


class NoLab:
    def session(self, *args, **kwargs):
        raise AssertionError("a robot the scenario cannot drive is not simulated")


@pytest.mark.slow  # a design built from a robot file and its description
def test_a_robot_without_rail_wheels_gets_no_metric():
    result = RAILS.procedure(NoLab(), example("thorvald_ii_4wd4ws_std"), PARAMS)
    assert result == {name: "n/a: its drives have no rail wheels" for name in RESULTS}


def test_the_world_sinks_the_pipes_ends_in_a_hill_the_flanges_pass_over():
    design = example(NAME)
    geometry, why = rails_world(design, PARAMS)
    assert why == "" and geometry.gauge == pytest.approx(0.55) and geometry.centre == pytest.approx(0.0)
    world = geometry.world("concrete", PARAMS)
    parse_world(world, "rails")  # a valid world file
    hill, pipes = world["slopes"]["slope0"], world["rails"]["rail0"]
    d = design.config.drives[0]
    # on the hill's top the flanges' bottom is 1 cm over the pipes' tops
    assert hill["height"] + d.r_wheel - d.rail_flange_radius == pytest.approx(0.1 + 0.0255 + 0.01)
    # the pipes start under the top and run past where the robot turns back
    top = (hill["x"] - hill["top_length"] / 2.0, hill["x"] + hill["top_length"] / 2.0)
    assert top[0] < pipes["x"] - pipes["length"] / 2.0 < top[1]
    assert pipes["x"] + pipes["length"] / 2.0 > geometry.turn + max(x.x for x in design.config.drives) + 0.5


def closed_form(lab: Lab, label: str) -> Dict[str, float]:
    """The odometry's distance error [%] without the switch, from the geometry of the drive's world and
    where it turned back: each drive reports r / r_rail times its true speed on the pipes, so the
    odometry's distance exceeds the true one by (r / r_rail - 1) times the drives' mean distance on
    them. A drive x_k ahead of base_link is on the pipes from where its rail wheel lands, x_land (its
    centre r / cos a over the far face when that face is h_p + r_rail - r / cos a high), to the
    turnaround x_turn + x_k, out and back: base_link drove 2 x_turn from the origin and back."""
    drive = next(d for d in lab.drives if d.label == label)
    hill, pipes = drive.world["slopes"]["slope0"], drive.world["rails"]["rail0"]
    config = example(NAME).config
    r, r_rail = config.drives[0].r_wheel, config.drives[0].rail_r_wheel
    a = hill["angle"]
    top_end = hill["x"] + hill["top_length"] / 2.0
    h_land = pipes["height"] + pipes["radius"] + r_rail - r / math.cos(a)
    x_land = top_end + (hill["height"] - h_land) / math.tan(a)
    x_turn = max(q.x for q in drive.track)
    mean_x = sum(d.x for d in config.drives) / len(config.drives)
    share = (x_turn + mean_x - x_land) / x_turn
    error = 100.0 * (r / r_rail - 1.0) * share
    return {"error_pct": error, "share": share, "x_land": x_land, "x_turn": x_turn, "mean_x": mean_x}


@pytest.mark.slow
def test_with_the_switch_the_odometry_keeps_its_distance(drove):
    result, lab = drove
    assert abs(result["odometry_error_pct"]) < 1.0, result
    assert result["switches"] == 4  # front pair on, rear pair on, rear pair off, front pair off
    assert result["turnaround_error_m"] < 0.05 and result["end_point_error_m"] < 0.05
    # out and back, a little more over the hill's faces
    assert result["distance_m"] == pytest.approx(2.0 * closed_form(lab, "rails, diameter switched")["x_turn"], rel=0.01)


@pytest.mark.slow
def test_without_the_switch_the_odometry_overshoots_by_the_closed_form(drove):
    result, lab = drove
    expected = closed_form(lab, "rails, diameter kept")
    # 0.2 m tyres on 0.15 m rail wheels: a third of the 80 % on the pipes
    assert expected["share"] == pytest.approx(0.8, abs=0.02)
    assert result["odometry_error_pct_without_switch"] == pytest.approx(expected["error_pct"], rel=0.05)
    assert result["predicted_error_pct_without_switch"] == pytest.approx(expected["error_pct"], rel=0.02)
    assert result["rail_share_without_switch"] == pytest.approx(expected["share"], rel=0.02)
    # out, (r / r_rail - 1) = a third too long over the drives' mean distance on the pipes; back, the
    # same taken off again
    out = expected["x_turn"] + expected["mean_x"] - expected["x_land"]
    assert out > 10.0 and result["turnaround_error_m_without_switch"] == pytest.approx(out / 3.0, rel=0.05)
    assert result["end_point_error_m_without_switch"] < 0.2


@pytest.mark.slow
@pytest.mark.parametrize("label", ["rails, diameter switched", "rails, diameter kept"])
def test_the_robot_stays_on_the_pipes(drove, label):
    """Every drive on the pipes (base_link past the rear drive's landing by 5 cm, short of the
    turnaround): base_link within 2 cm of the pipes' centre line, at the rail-wheel step's height, level."""
    _, lab = drove
    expected = closed_form(lab, label)
    drive = next(d for d in lab.drives if d.label == label)
    assert drive.outcome == "ok"
    rear = -min(d.x for d in example(NAME).config.drives)
    riding = [q for q in drive.track if expected["x_land"] + rear + 0.05 < q.x < expected["x_turn"] - 0.05]
    assert len(riding) > 1000
    step = 0.1 + 0.0255 + 0.15 - 0.2
    assert max(abs(q.y) for q in riding) < 0.02
    assert all(abs(q.z - step) < 0.003 and abs(q.pitch) < 0.01 and abs(q.roll) < 0.01 for q in riding)
    assert abs(drive.track[-1].x) < 0.1 and abs(drive.track[-1].z) < 0.003  # back on the floor at the start
