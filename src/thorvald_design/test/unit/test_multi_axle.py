"""Robots of more than three wheels on a rigid frame: how the simulator shares their weight, and why
their climb agrees with the quasi-static limit.

A rigid frame on more than three wheels is statically indeterminate: on rigid ground it stands on
whichever wheels touch first, so the loads depend on the solver and the wheels that carry most stall
first. On a soft surface (a surface kind's sinkage) every contact is a spring of the same stiffness,
and the loads become the linear model's (:func:`thorvald_design.quasi_static.normal_loads`), which is
what the quasi-static limits assume: grass and soil sink, so their ramps do too."""

import math

import pytest

from thorvald_design.design import design_of
from thorvald_design.lab import Lab
from thorvald_design.quasi_static import normal_loads
from thorvald_design.scenarios.driving import flat_world, heading_hold, ramp_world
from thorvald_design.scenarios.gradeability import GRADEABILITY, KEYS, ramp_run
from thorvald_model.description import package_file

SIX, NINE = "thorvald_ii_6wd6ws_asym", "thorvald_ii_9wd9ws"


def robot_file(name):
    return package_file("config", name, name + ".yaml")


@pytest.mark.slow  # the statics or the report of every example robot, or a plot
@pytest.mark.parametrize("name", [SIX, NINE])
def test_on_soft_ground_a_rigid_frame_shares_its_weight_as_the_linear_model_says(name):
    design = design_of(name, robot_file(name))
    predicted = normal_loads(design.layout, 0.0)
    with Lab(robot_file(name)).session(flat_world("grass")) as session:
        session.run(2.0, lambda t: (0.0, 0.0, 0.0))
        loads = session.wheel_loads()
    assert sum(loads) == pytest.approx(design.mass * 9.81, rel=0.01)
    mean = sum(predicted) / len(predicted)
    for measured, model in zip(loads, predicted):
        assert measured == pytest.approx(model, abs=0.03 * mean)


@pytest.mark.slow  # 12 s of physics, 1 s
def test_on_a_soft_incline_the_load_shifts_downhill_as_the_model_says():
    design = design_of(SIX, robot_file(SIX))
    angle = math.radians(14.0)
    run = ramp_run(design, {"ramp_length": 3.0})
    world = ramp_world("grass", angle, run, design.length + 1.0)
    # on the incline with every wheel: the rear wheel past the foot, the front one short of the crest
    middle = (run + design.rear - design.front) / 2.0
    samples = []
    with Lab(robot_file(SIX)).session(world, x=-(design.front + 0.5)) as session:
        session.run(1.0, lambda t: (0.0, 0.0, 0.0))

        def stop(s) -> bool:
            if abs(s.track[-1].x - middle) < 0.3:
                samples.append(s.wheel_loads())
            return s.track[-1].x > middle + 0.3

        session.run(60.0, heading_hold(session, 0.0, 0.5), stop)
    assert len(samples) > 10
    loads = [sum(column) / len(samples) for column in zip(*samples)]
    predicted = normal_loads(design.layout, angle)
    mean = sum(predicted) / len(predicted)
    for measured, model in zip(loads, predicted):
        assert measured == pytest.approx(model, abs=0.08 * mean)
    # the rear axle (x < 0) carries more than the front one now
    rear = [n for n, (_, x, _) in zip(loads, design.contacts) if x < -0.1]
    front = [n for n, (_, x, _) in zip(loads, design.contacts) if x > 0.1]
    assert min(rear) > max(front)


@pytest.mark.slow  # two climbs, 40 s of physics, 3 s
def test_six_wheels_climb_what_the_quasi_static_limit_says_and_their_crest_is_the_breakover():
    design = design_of(SIX, robot_file(SIX))
    params = {k.name: k.default for k in KEYS}
    params.update(surface="grass", start_deg=26.0, step_deg=2.0, max_deg=28.0, descent=False)
    result = GRADEABILITY.procedure(Lab(robot_file(SIX)), design, params)
    # every wheel driven, the grip holds the slope: tan(theta) = mu = 0.55 on grass
    assert result["predicted_climb_deg"] == pytest.approx(math.degrees(math.atan(0.55)), abs=0.1)
    assert result["predicted_limited_by"] == "traction"
    # the incline itself: within a step of the limit (on a rigid ramp the same robot stalled at 16)
    assert result["max_climb_deg"] >= result["predicted_climb_deg"] - params["step_deg"]
    # the crest: the middle axle carries the whole robot there and its two motors cannot lift it
    assert [c[:2] for c in result["climbs"]] == [[26.0, "ok"], [28.0, "ok"]]
    assert result["climbs"][0][2] != "ok" and result["max_crest_deg"] == 0.0
