"""The scenarios' pure rules: the tightest turn's centre, twists the wheels allow, the trials' series,
the worlds they write (pure: no simulator)."""

import math

import pytest

from thorvald_design.scenarios import SCENARIOS
from thorvald_design.scenarios.driving import Progress, feasible_twist, ramp_world
from thorvald_design.scenarios.gradeability import angles
from thorvald_design.scenarios.headland import field
from thorvald_design.scenarios.kind import Pose
from thorvald_design.scenarios.obstacle import heights, step_world
from thorvald_design.scenarios.side_slope import _traverse_outcome, side_slope_world
from thorvald_design.scenarios.turning import turn_centre, turn_twist
from thorvald_model import load_robot_config
from thorvald_model.description import package_file
from thorvald_sim.world import parse_world


def config(name):
    return load_robot_config(package_file("config", name, name + ".yaml"))


def test_a_robot_whose_wheels_all_steer_spins_about_base_link():
    std = config("thorvald_ii_4wd4ws_std")
    assert turn_centre(std.drives, std.passive_wheels) == ((0.0, 0.0), "spin")


def test_fixed_wheels_put_the_tightest_turns_centre_on_their_axle():
    fwd = config("thorvald_ii_1wd1ws_fwd")  # fixed wheels at x = -0.45
    centre, turn = turn_centre(fwd.drives, fwd.passive_wheels)
    assert centre == pytest.approx((-0.45, 0.0)) and turn == "about the axle line"
    diff = config("thorvald_ii_2wd_diff")
    centre, _ = turn_centre(diff.drives, diff.passive_wheels)
    assert centre == pytest.approx((diff.drives[0].x, 0.0))


def test_a_steering_limit_moves_the_centre_out_until_every_wheel_can_stand():
    tall = config("thorvald_ii_4wd2ws_tall")
    limited = [d if not d.steerable else type(d)(**{**d.__dict__, "str_lim": 0.5}) for d in tall.drives]
    centre, turn = turn_centre(limited, tall.passive_wheels)
    # the inner front wheel (the nearer the centre) at its limit: atan(wheelbase / its lateral distance)
    steered = [math.atan2(abs(d.x - centre[0]), abs(d.y - centre[1])) for d in limited if d.steerable]
    assert max(steered) == pytest.approx(0.5, abs=0.01)
    assert "steering limits" in turn


def test_the_turn_twist_puts_the_furthest_contact_at_the_speed():
    twist = turn_twist((-0.45, 0.0), [(0.45, 0.0), (-0.45, 0.35), (-0.45, -0.35)], 0.5, 1.0)
    assert twist == pytest.approx((0.0, 0.45 * 0.5 / 0.9, 0.5 / 0.9))


def test_a_feasible_twist_keeps_the_fixed_axle_from_sliding():
    fwd = config("thorvald_ii_1wd1ws_fwd")
    vx, vy, wz = feasible_twist(fwd, 1.0, 0.4)
    # the fixed axle's middle (-0.45, 0) moves along x only: vy + wz * (-0.45) = 0
    assert vy - 0.45 * wz == pytest.approx(0.0) and vx == 1.0
    assert feasible_twist(config("thorvald_ii_4wd4ws_std"), 1.0, 0.4) == (1.0, 0.0, 0.4)


def test_the_series_run_from_start_by_step_to_max():
    assert angles({"start_deg": 4.0, "step_deg": 2.0, "max_deg": 10.0}) == [4.0, 6.0, 8.0, 10.0]
    assert heights({"start_m": 0.02, "step_m": 0.04, "max_m": 0.12}) == [0.02, 0.06, 0.1]


@pytest.mark.parametrize(
    "world",
    [
        ramp_world("grass", math.radians(20), 3.0, 2.0),
        side_slope_world("mud", math.radians(15), 4.0, 10.0),
        step_world("tarmac", 0.1, 0.0, 3.0),
        {"ground": {"surface": "grass"}, "rows": field(dict(SCENARIOS["headland"].keys and {
            "row_spacing": 0.75, "next": 2, "plant_spacing": 0.3, "plant_width": 0.2, "plant_height": 0.4}), 5.0)},
    ],
)  # fmt: skip
def test_the_worlds_the_scenarios_write_are_worlds_the_simulator_loads(world):
    loaded = parse_world(world, "<scenario>")
    assert loaded.ground.lateral_friction > 0


def test_a_ramp_rises_at_its_angle_from_its_foot():
    w = parse_world(ramp_world("grass", math.radians(20), 3.0, 2.0), "<ramp>")
    assert w.ground_height(0.0, 0.0) == pytest.approx(0.0, abs=1e-9)
    assert w.ground_height(1.5, 0.0) == pytest.approx(1.5 * math.tan(math.radians(20)), abs=1e-6)
    assert w.ground_height(4.0, 0.0) == pytest.approx(3.0 * math.tan(math.radians(20)), abs=1e-6)


@pytest.mark.parametrize(
    "way, across, outcome",
    [
        # heading +x, the face rising to +y: downhill is -y, to the right
        (1.0, -0.02 * 5, "ok"),
        (1.0, -0.10 * 5, "drifted 0.100 m per m"),
        (1.0, +0.96 * 5, "veered 0.960 m per m uphill"),
        # heading -x: downhill is -y, to the left of the heading
        (-1.0, -0.10 * 5, "drifted 0.100 m per m"),
        (-1.0, +0.10 * 5, "veered 0.100 m per m uphill"),
    ],
)
def test_a_traverse_holds_its_line_either_way(way, across, outcome):
    """A traverse of 5 m that ends `across` m off its line in y: held within max_drift (0.05 m per m)
    of its line, downhill or uphill; the drift reported is signed, downhill positive."""
    heading = 0.0 if way > 0 else math.pi
    poses = [Pose(k * 0.5, way * k * 0.5, across * k / 10, 0.0, 0.0, 0.0, heading) for k in range(11)]
    found, downhill = _traverse_outcome(poses, Progress(ux=way), way, heading, {"distance": 5.0, "max_drift": 0.05})
    assert found == outcome
    assert downhill == pytest.approx(-across / 5)
