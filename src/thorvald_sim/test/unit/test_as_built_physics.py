"""The simulator builds the as-built robot: true radii roll farther, homing errors turn the wheels,
the encoders report whole counts and whole motor rpm, reports come late, a load weighs.

Expected figures come from the as-built values and the configuration (the CAN codec's scalings), not
from the simulator's output: a wheel 1 % larger covers 1 % more ground at the same turning rate; a
steering module homed 0.02 rad off points the robot's path 0.02 rad off its heading.
"""

import math
import os

import pybullet as p
import pytest

from thorvald_base.can.protocol import DriveScaling
from thorvald_model import load_robot_config
from thorvald_model.description import generate_urdf
from thorvald_sim.physics.as_built import AsBuilt, BuiltDrive, DriveAsBuilt, SimAsBuilt, as_configured, for_simulator
from thorvald_sim.physics.robot import Pose2D, yaw_of
from thorvald_sim.physics.simulation import Simulation, SpawnError
from thorvald_sim.world import parse_world

HERE = os.path.dirname(os.path.abspath(__file__))
CONFIGS = os.path.abspath(os.path.join(HERE, "..", "..", "..", "thorvald_model", "config"))
STD = os.path.join(CONFIGS, "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
FLAT = parse_world({"ground": {"lateral_friction": 0.9}}, "flat")
CONFIG = load_robot_config(STD)
URDF = generate_urdf(STD)


def built(scale=1.0, offset=0.0, encoders=False, delay=0.0, mass_offset=0.0):
    """The standard robot with every wheel scale times its radius and every module homed offset off."""
    drives = tuple(DriveAsBuilt(f"drive{i}", d.r_wheel * scale, offset) for i, d in enumerate(CONFIG.drives))
    radii = tuple(d.r_wheel for d in CONFIG.drives)
    return for_simulator(AsBuilt("test", drives, encoders, delay, mass_offset, radii), CONFIG)


@pytest.fixture
def sim():
    client = p.connect(p.DIRECT)
    yield Simulation(client, FLAT)
    p.disconnect(client)


def run(sim, seconds):
    for _ in range(round(seconds / sim.dt)):
        sim.step()


def straight(sim, robot, speed=0.5, seconds=4.0):
    """Commands every wheel straight at speed [m/s]; returns (distance along x, across, heading change,
    rim speeds the encoders report) over the last seconds - 1 s (the first second accelerates)."""
    n = len(robot.wheels)
    robot.command([0.0] * n, [speed] * n)
    run(sim, 1.0)
    (x0, y0, _), q0 = robot.world_pose()
    run(sim, seconds - 1.0)
    (x1, y1, _), q1 = robot.world_pose()
    return x1 - x0, y1 - y0, yaw_of(q1) - yaw_of(q0), [s.speed for s in robot.drive_states(sim.time)]


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_as_configured_is_the_ideal_robot(sim):
    ideal = sim.spawn("a", URDF, Pose2D(), as_built=for_simulator(as_configured(CONFIG), CONFIG))
    plain = sim.spawn("b", URDF, Pose2D(0.0, 4.0))
    a, b = straight(sim, ideal), straight(sim, plain)
    assert a[0] == pytest.approx(b[0], abs=1e-6) and a[3] == pytest.approx(b[3], abs=1e-9)


def test_wheels_one_percent_larger_cover_one_percent_more_ground(sim):
    ideal = sim.spawn("ideal", URDF, Pose2D())
    larger = sim.spawn("larger", URDF, Pose2D(0.0, 4.0), as_built=built(scale=1.01))
    n = len(ideal.wheels)
    for robot in (ideal, larger):
        robot.command([0.0] * n, [0.5] * n)
    run(sim, 1.0)
    start = [r.world_pose()[0][0] for r in (ideal, larger)]
    run(sim, 4.0)
    moved = [r.world_pose()[0][0] - s for r, s in zip((ideal, larger), start)]
    # the same turning rate (0.5 m/s over the configured radius), 1 % more rim: 1 % farther
    assert moved[1] / moved[0] == pytest.approx(1.01, abs=0.001)
    # both report 0.5 m/s: the controller converts with the configured radius
    for robot in (ideal, larger):
        assert [s.speed for s in robot.drive_states(sim.time)] == pytest.approx([0.5] * n, abs=0.005)


def test_a_uniform_steering_offset_points_the_path_off_the_heading(sim):
    offset = 0.02  # [rad]
    robot = sim.spawn("r", URDF, Pose2D(), as_built=built(offset=offset))
    # spawned standing straight, the modules read minus their homing error
    assert [s.steering for s in robot.drive_states(sim.time)] == pytest.approx([-offset] * 4, abs=1e-3)
    robot.command([0.0] * 4, [0.0] * 4)
    run(sim, 0.5)
    # commanded straight, the controllers read 0 while the wheels stand at the offset
    assert [s.steering for s in robot.drive_states(sim.time)] == pytest.approx([0.0] * 4, abs=1e-3)
    assert [s.steering for s in robot._joint_drive_states()] == pytest.approx([offset] * 4, abs=1e-3)
    dx, dy, turned, _ = straight(sim, robot)
    # every wheel at the same angle: the robot crabs at that angle without turning
    assert math.atan2(dy, dx) == pytest.approx(offset, abs=0.002)
    assert abs(turned) < 0.002


def test_a_commanded_angle_lands_offset_and_reads_as_commanded(sim):
    offset = -0.05
    robot = sim.spawn("r", URDF, Pose2D(), as_built=built(offset=offset))
    n = len(robot.wheels)
    robot.command([0.3] * n, [0.0] * n)
    run(sim, 2.0)
    joints = [s.steering for s in robot._joint_drive_states()]
    assert joints == pytest.approx([0.3 + offset] * n, abs=0.005)
    assert [s.steering for s in robot.drive_states(sim.time)] == pytest.approx([0.3] * n, abs=0.005)


def test_encoders_report_whole_counts_and_whole_rpm(sim):
    robot = sim.spawn("r", URDF, Pose2D(), as_built=built(encoders=True))
    n = len(robot.wheels)
    robot.command([0.123] * n, [0.37] * n)
    run(sim, 2.0)
    scaling = DriveScaling.of(CONFIG.drives[0])
    for s in robot.drive_states(sim.time):
        counts = s.steering * scaling.counts_per_radian
        rpm = s.speed / scaling.wheel_speed(1.0)
        wheel = s.wheel_angle * scaling.wheel_counts_per_radian
        assert counts == pytest.approx(round(counts), abs=1e-6) and s.steering == pytest.approx(0.123, abs=0.005)
        assert rpm == pytest.approx(round(rpm), abs=1e-6) and s.speed == pytest.approx(0.37, abs=0.005)
        assert wheel == pytest.approx(round(wheel), abs=1e-6)
    # one motor rpm at the rim: 1 / 42 turn a minute of a 0.2 m wheel (the standard robot's figures)
    d = CONFIG.drives[0]
    assert scaling.wheel_speed(1.0) == pytest.approx(2 * math.pi * d.r_wheel / 60.0 / d.prp_gr_rt)
    assert scaling.counts_per_radian == pytest.approx(d.str_enc_ppr * 4 * d.str_gr_rt / (2 * math.pi))


def test_reports_come_delay_late(sim):
    delay = 0.05
    robot = sim.spawn("r", URDF, Pose2D(), as_built=built(delay=delay))
    twin = sim.spawn("twin", URDF, Pose2D(0.0, 4.0))
    n = len(robot.wheels)
    for r in (robot, twin):
        r.command([0.0] * n, [0.5] * n)
    reported, truth = [], []
    for _ in range(round(1.0 / sim.dt)):
        sim.step()
        reported.append((sim.time, robot.drive_states(sim.time)[0].wheel_angle))
        truth.append((sim.time, twin.drive_states()[0].wheel_angle))
    # what robot reports at t is what its twin (the same robot, built ideally) measured at t - delay
    lookup = dict((round(t, 6), a) for t, a in truth)
    for t, angle in reported[100:]:
        assert angle == pytest.approx(lookup[round(t - delay, 6)], abs=1e-3)


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_a_load_weighs(sim):
    light = sim.spawn("light", URDF, Pose2D())
    heavy = sim.spawn("heavy", URDF, Pose2D(0.0, 4.0), as_built=built(mass_offset=50.0))
    assert p.getDynamicsInfo(heavy.body, -1)[0] == pytest.approx(p.getDynamicsInfo(light.body, -1)[0] + 50.0)


def test_an_as_built_of_another_robot_is_refused(sim):
    three = SimAsBuilt("x", (BuiltDrive(0.2, 0.0),) * 3)
    with pytest.raises(SpawnError, match="3 drives, the description 4"):
        sim.spawn("r", URDF, Pose2D(), as_built=three)
    assert "r" not in sim.robots


def test_the_spawn_request_carries_it_as_json():
    b = built(scale=1.005, offset=0.003, encoders=True, delay=0.02, mass_offset=10.0)
    assert SimAsBuilt.from_json(b.to_json(), 4) == b
    with pytest.raises(ValueError, match="2 drives, the description 4"):
        SimAsBuilt.from_json(SimAsBuilt("x", (BuiltDrive(0.2, 0.0),) * 2).to_json(), 4)
    with pytest.raises(ValueError, match="not readable"):
        SimAsBuilt.from_json("{", 4)
    bad = b.to_json().replace('"r_wheel": 0.2', '"r_wheel": -0.2', 1)
    with pytest.raises(ValueError, match="radii > 0"):
        SimAsBuilt.from_json(bad, 4)
