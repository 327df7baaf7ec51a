"""The Gazebo API's side in a world (thorvald_sim.gazebo.bodies) through an Engine, in pybullet, no ROS
master: a robot teleported stands where it was put, its wheels on the ground; a teleport into the
ground is refused and changes nothing; models of the API spawned, pushed by wrenches over windows of
simulated time, turned by joint efforts, weightless without gravity, put back by a reset; the states
the topics publish; time set back to zero ends every wrench."""

import math
import os

import pytest
from models_fixtures import box_sdf, gate_sdf

from thorvald_model.description import generate_urdf
from thorvald_sim.gazebo import frames
from thorvald_sim.gazebo.bodies import MAX_SINK, MODEL_FRAME, STATES_LINKS, STATES_MODELS, Job
from thorvald_sim.models import parse_sdf_model
from thorvald_sim.physics.engine import EVERYTHING, Engine, WorldSettings
from thorvald_sim.physics.robot import Pose2D
from thorvald_sim.world import parse_world

pytestmark = pytest.mark.slow  # pybullet: seconds of simulation

CONFIGS = os.path.join(os.path.dirname(os.path.abspath(__file__)), *[".."] * 3, "thorvald_model", "config")
STANDARD = os.path.join(CONFIGS, "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")


def yaw_q(yaw):
    return (0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2))


@pytest.fixture
def engine():
    e = Engine(WorldSettings(world=parse_world({}, "flat")))
    yield e
    e.close()


def run(engine, seconds, reads=None):
    for _ in range(round(seconds / engine.sim.dt)):
        engine.step({}, reads or {}, False)


def ask(engine, *request):
    answer = engine.handle(("gazebo", *request))
    assert answer[0] == "answer"
    return answer[1]


def spawn_robot(engine, name="thorvald_001", pose=None):
    reply = engine.spawn(name, generate_urdf(STANDARD, tf_prefix=name + "/"), pose or Pose2D(), None)
    assert reply[0] == "spawned", reply
    return reply[1]


def spawn_model(engine, name, sdf, position=(0.0, 0.0, 0.0), q=frames.IDENTITY):
    answer = ask(engine, "spawn_model", name, parse_sdf_model(sdf, name), (position, q))
    assert isinstance(answer, dict), answer
    return answer


def test_a_robot_teleported_stands_where_it_was_put_on_its_wheels(engine):
    info = spawn_robot(engine)
    assert info["entity"]["links"][0][:2] == ("thorvald_001/base_link", -1)
    run(engine, 1.0)
    (start, _), _, _ = ask(engine, "state", "thorvald_001", MODEL_FRAME)
    assert start[:2] == pytest.approx((0.0, 0.0), abs=0.01)
    height = start[2]  # base_link's height standing on its wheels
    target = ((5.0, 2.0, height + 0.02), yaw_q(math.pi / 2))
    assert ask(engine, "teleport", "thorvald_001", MODEL_FRAME, target, ((0, 0, 0), (0, 0, 0)), False) is None
    run(engine, 2.0)
    (position, q), linear, angular = ask(engine, "state", "thorvald_001", MODEL_FRAME)
    assert position == pytest.approx((5.0, 2.0, height), abs=0.01)
    assert frames.euler_of(q)[2] == pytest.approx(math.pi / 2, abs=0.01)
    assert max(abs(v) for v in linear + angular) < 0.01  # at rest on the ground


def test_a_teleport_into_the_ground_is_refused_and_moves_nothing(engine):
    spawn_robot(engine)
    run(engine, 0.5)
    before = ask(engine, "state", "thorvald_001", MODEL_FRAME)[0]
    down = ((5.0, 2.0, -1.0), frames.IDENTITY)
    why = ask(engine, "teleport", "thorvald_001", MODEL_FRAME, down, ((0, 0, 0),) * 2, False)
    assert "inside the ground" in why and f"at most {MAX_SINK:g} m" in why
    after = ask(engine, "state", "thorvald_001", MODEL_FRAME)[0]
    assert after[0] == pytest.approx(before[0], abs=1e-9)
    run(engine, 0.5)  # and it carries on standing
    assert ask(engine, "state", "thorvald_001", MODEL_FRAME)[0][0] == pytest.approx(before[0], abs=0.005)


def test_a_link_teleported_takes_its_model_along(engine):
    info = spawn_robot(engine)
    run(engine, 0.5)
    link = next(index for name, index, _ in info["entity"]["links"] if "wheel" in name and index >= 0)
    here = ask(engine, "state", "thorvald_001", MODEL_FRAME)[0]
    there = ask(engine, "state", "thorvald_001", link)[0]
    offset = frames.seen_from(there, here)  # the link in the model frame
    target = ((3.0, -1.0, there[0][2] + 0.02), there[1])
    assert ask(engine, "teleport", "thorvald_001", link, target, ((0, 0, 0),) * 2, False) is None
    moved = ask(engine, "state", "thorvald_001", link)[0]
    assert moved[0] == pytest.approx(target[0], abs=1e-6)
    model = ask(engine, "state", "thorvald_001", MODEL_FRAME)[0]
    assert frames.seen_from(moved, model)[0] == pytest.approx(offset[0], abs=1e-6)


def test_models_spawned_fall_rest_and_are_listed_with_their_links(engine):
    box = spawn_model(engine, "box", box_sdf(), (1.0, 0.0, 1.0))
    assert [name for name, _, _ in box["links"]] == ["link"]
    assert box["links"][0][2] == ("collision",)
    gate = spawn_model(engine, "gate", gate_sdf(), (0.0, 3.0, 0.0))
    assert [name for name, _, _ in gate["joints"]] == ["hinge"]
    run(engine, 1.5)
    (position, _), _, _ = ask(engine, "state", "box", MODEL_FRAME)
    assert position == pytest.approx((1.0, 0.0, 0.1), abs=0.005)  # resting on its 0.2 m height
    models, links = engine.gazebo.states(STATES_MODELS | STATES_LINKS)
    assert set(models) == {"box", "gate"} and len(links["gate"]) == 2
    again = ask(engine, "spawn_model", "box", parse_sdf_model(box_sdf(), "box"), ((0, 0, 0), frames.IDENTITY))
    assert again == "a model named 'box' exists already"


def test_a_wrench_acts_over_its_window_of_simulated_time_only(engine):
    spawn_model(engine, "box", box_sdf(mass=2.0), (0.0, 0.0, 0.1))
    run(engine, 0.5)
    now = engine.sim.time
    # 3 times its weight up, from 0.5 s ahead for 0.25 s: nothing before, a rise, a fall back
    ask(engine, "add_wrench", Job("box", -1, (0.0, 0.0, 3 * 2.0 * 9.81), (0, 0, 0), now + 0.5, 0.25))
    run(engine, 0.45)
    assert ask(engine, "state", "box", MODEL_FRAME)[0][0][2] == pytest.approx(0.1, abs=0.003)
    run(engine, 0.3)
    assert ask(engine, "state", "box", MODEL_FRAME)[0][0][2] > 0.15  # net 2 g up for 0.25 s: 0.12 m up
    run(engine, 1.5)
    assert ask(engine, "state", "box", MODEL_FRAME)[0][0][2] == pytest.approx(0.1, abs=0.005)
    assert engine.gazebo.wrenches == []  # over, and gone


def test_a_wrench_until_cleared_and_cleared(engine):
    spawn_model(engine, "box", box_sdf(mass=2.0), (0.0, 0.0, 0.1))
    ask(engine, "gravity", (0.0, 0.0, 0.0))
    ask(engine, "add_wrench", Job("box", -1, (2.0, 0.0, 0.0), (0, 0, 0), 0.0, -1.0))  # 1 m/s^2 along x
    run(engine, 1.0)
    (_, linear, _) = ask(engine, "state", "box", MODEL_FRAME)
    assert linear[0] == pytest.approx(1.0, rel=0.05)
    ask(engine, "clear_wrenches", "box", None)
    run(engine, 0.5)
    assert ask(engine, "state", "box", MODEL_FRAME)[1][0] == pytest.approx(linear[0], rel=0.05)  # coasting


def test_a_joint_effort_swings_the_gate_and_stops_when_cleared(engine):
    info = spawn_model(engine, "gate", gate_sdf(damping=0.0), (0.0, 0.0, 0.0))
    hinge = info["joints"][0][1]
    assert ask(engine, "joint_state", "gate", hinge) == pytest.approx((0.0, 0.0), abs=1e-6)
    ask(engine, "add_effort", Job("gate", hinge, (2.0, 0.0, 0.0), (0, 0, 0), 0.0, 0.5))
    run(engine, 0.5)
    position, rate = ask(engine, "joint_state", "gate", hinge)
    assert rate > 0.2 and position > 0.05  # turned the way the effort pushes (about +z)
    ask(engine, "configure", "gate", {hinge: -0.3})
    assert ask(engine, "joint_state", "gate", hinge) == pytest.approx((-0.3, 0.0), abs=1e-9)


def test_without_gravity_a_box_hangs_where_it_was_put(engine):
    assert ask(engine, "gravity") == pytest.approx((0.0, 0.0, -9.81))
    ask(engine, "gravity", (0.0, 0.0, 0.0))
    assert engine.sim.gravity == (0.0, 0.0, 0.0)
    spawn_model(engine, "box", box_sdf(), (0.0, 0.0, 2.0))
    run(engine, 1.0)
    assert ask(engine, "state", "box", MODEL_FRAME)[0][0][2] == pytest.approx(2.0, abs=1e-6)


def test_a_reset_puts_the_models_back_where_they_were_spawned(engine):
    spawn_robot(engine, pose=Pose2D(-3.0, 0.0, 0.0, 0.0))
    spawn_model(engine, "box", box_sdf(), (1.0, 1.0, 0.1), yaw_q(0.3))
    run(engine, 0.5)
    ask(engine, "teleport", "box", MODEL_FRAME, ((4.0, 4.0, 0.5), frames.IDENTITY), ((1, 0, 0), (0, 0, 0)), False)
    ask(engine, "teleport", "thorvald_001", MODEL_FRAME, ((6.0, 6.0, 0.6), frames.IDENTITY), ((0, 0, 0),) * 2, False)
    run(engine, 0.5)
    assert engine.handle(("reset",)) == ("reset",)
    (position, q), linear, _ = ask(engine, "state", "box", MODEL_FRAME)
    assert position == pytest.approx((1.0, 1.0, 0.1), abs=1e-6)
    assert frames.euler_of(q)[2] == pytest.approx(0.3, abs=1e-6)
    assert linear == pytest.approx((0, 0, 0), abs=1e-9)
    robot = ask(engine, "state", "thorvald_001", MODEL_FRAME)[0][0]
    assert robot[:2] == pytest.approx((-3.0, 0.0), abs=0.01)


def test_the_topics_follow_a_static_model_that_a_request_moves(engine):
    """A static model's state is read once for the topics and kept: a teleport, a reset and a model
    deleted and spawned again under its name are seen at the next read."""
    spawn_model(engine, "post", box_sdf("post", static=True), (1.0, 2.0, 0.1))
    run(engine, 0.1)

    def where():
        models, _ = engine.gazebo.states(STATES_MODELS)
        return models["post"][0][0]

    assert where() == pytest.approx((1.0, 2.0, 0.1), abs=1e-9)
    assert where() == pytest.approx((1.0, 2.0, 0.1), abs=1e-9)
    ask(engine, "teleport", "post", MODEL_FRAME, ((4.0, -1.0, 0.1), frames.IDENTITY), ((0, 0, 0),) * 2, True)
    assert where() == pytest.approx((4.0, -1.0, 0.1), abs=1e-9)
    assert engine.handle(("reset",)) == ("reset",)
    assert where() == pytest.approx((1.0, 2.0, 0.1), abs=1e-9)
    ask(engine, "delete_model", "post")
    spawn_model(engine, "post", box_sdf("post", static=True), (-2.0, 0.0, 0.1))
    assert where() == pytest.approx((-2.0, 0.0, 0.1), abs=1e-9)


def test_time_set_back_to_zero_ends_every_wrench(engine):
    spawn_model(engine, "box", box_sdf(), (0.0, 0.0, 0.1))
    ask(engine, "add_wrench", Job("box", -1, (10.0, 0.0, 0.0), (0, 0, 0), 5.0, 1.0))
    run(engine, 0.25)
    assert engine.handle(("restart_time",)) == ("restarted",)
    assert engine.sim.time == 0.0 and engine.sim.steps == 0
    assert engine.gazebo.wrenches == []


def test_the_states_after_a_step_are_asked_for_or_not_made(engine):
    spawn_robot(engine)
    spawn_model(engine, "box", box_sdf(), (2.0, 0.0, 0.1))
    reply = engine.step({}, {"thorvald_001": EVERYTHING}, False)
    assert reply[5] is None  # nobody subscribed: nothing gathered
    models, links = engine.step({}, {}, False, None, STATES_MODELS)[5]
    assert set(models) == {"thorvald_001", "box"} and links == {}
    models, links = engine.step({}, {}, False, None, STATES_MODELS | STATES_LINKS)[5]
    assert len(links["thorvald_001"]) > 5 and links["box"][0][0] == models["box"][0]


def test_the_imu_reads_the_gravity_the_api_sets(engine):
    probe = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "sensors_probe.xacro")
    urdf = generate_urdf(STANDARD, tf_prefix="thorvald_001/", model_extras=probe)
    assert engine.spawn("thorvald_001", urdf, Pose2D(), None)[0] == "spawned"
    imu = next(s for s in engine.sim.robots["thorvald_001"].sensors if s.spec.kind == "imu")

    def reading():
        run(engine, 0.5)
        return imu.read(engine.sim.time).linear_acceleration

    assert reading() == pytest.approx((0.0, 0.0, 9.81), abs=0.05)  # at rest: 1 g up
    ask(engine, "gravity", (0.0, 0.0, -3.71))
    assert reading() == pytest.approx((0.0, 0.0, 3.71), abs=0.05)
    spawn_robot(engine, "thorvald_002", Pose2D(0.0, 5.0, 0.0, 0.0))  # a robot spawned later reads it too
    urdf2 = generate_urdf(STANDARD, tf_prefix="thorvald_003/", model_extras=probe)
    assert engine.spawn("thorvald_003", urdf2, Pose2D(0.0, -5.0, 0.0, 0.0), None)[0] == "spawned"
    later = next(s for s in engine.sim.robots["thorvald_003"].sensors if s.spec.kind == "imu")
    run(engine, 0.5)
    assert later.read(engine.sim.time).linear_acceleration == pytest.approx((0.0, 0.0, 3.71), abs=0.05)
