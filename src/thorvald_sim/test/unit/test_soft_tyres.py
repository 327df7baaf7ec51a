"""An as-built robot's soft tyres (thorvald_sim.physics.as_built ``tyre_deflection``, the field profile's loaded
tyres): a frame of more than three wheels stands on all of them, as it does on pneumatic tyres, where
rigid tyres of radii a millimetre apart left it on two."""

import numpy as np
import pytest

from thorvald_base.verification import plan_named
from thorvald_model import ConfigError, load_robot_config
from thorvald_model.description import package_file
from thorvald_sim.bullet import pybullet as p
from thorvald_sim.physics.as_built import SimAsBuilt, as_built_for, draw_as_built, parse_as_built
from thorvald_sim.tools.runner import RobotSession, RunOptions, commands_from_plan, run_robot

ASYM = package_file("config", "thorvald_ii_6wd6ws_asym", "thorvald_ii_6wd6ws_asym.yaml")


def loads(as_built: str):
    with RobotSession(ASYM, RunOptions(as_built=as_built)) as s:
        s.run(2.0, lambda t: (0.0, 0.0, 0.0))
        return s.robot.wheel_loads(), s.robot.world_pose()[0][2]


def rigid_copy(tmp_path, spec: str) -> str:
    """The profile's draw as a file, its tyres rigid."""
    built = as_built_for(spec, load_robot_config(ASYM))
    lines = ["tyre_deflection: 0.0", "encoders: true", "motor_drives:"]
    lines += [f"  {d.name}: {{r_wheel: {d.r_wheel!r}, steering_offset: {d.steering_offset!r}}}" for d in built.drives]
    path = tmp_path / "rigid.yaml"
    path.write_text("\n".join(lines) + "\n")
    return str(path)


def test_the_field_profiles_tyres_give_three_times_their_radius_drop():
    config = load_robot_config(ASYM)
    built = draw_as_built("field:3", config)
    assert built.tyre_deflection == pytest.approx(3.0 * built.loaded * 0.2)
    assert 0.006 <= built.tyre_deflection <= 0.012  # 1 to 2 % of 0.2 m, three times
    assert not built.ideal


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_on_soft_tyres_every_wheel_carries_load_on_rigid_ones_two_carry_the_robot(tmp_path):
    soft, z_soft = loads("field:3")
    rigid, z_rigid = loads(rigid_copy(tmp_path, "field:3"))
    assert sum(soft) == pytest.approx(sum(rigid), rel=0.01)  # the robot's weight either way
    assert min(soft) > 0.04 * sum(soft)  # every one of six wheels carries its part (131 to 754 N measured)
    assert sorted(rigid)[3] < 1.0  # four wheels in the air, or nearly (the two largest tyres carry it)
    assert z_soft < z_rigid - 0.003  # the frame sits lower on the tyres' deflection


def test_the_as_built_file_takes_a_tyre_deflection_checked():
    config = load_robot_config(ASYM)
    assert parse_as_built({"tyre_deflection": 0.01}, config).tyre_deflection == 0.01
    assert parse_as_built({}, config).tyre_deflection == 0.0
    with pytest.raises(ConfigError, match=r"tyre_deflection: -0.01: must be in \[0, 0.1\] m"):
        parse_as_built({"tyre_deflection": -0.01}, config, "f.yaml")


def test_the_spawn_request_carries_the_tyres_and_reads_one_without_them():
    built = SimAsBuilt("x", (), 0.0, 0.0, 0.011)
    assert SimAsBuilt.from_json(built.to_json()).tyre_deflection == 0.011
    old = '{"source": "x", "drives": [], "delay": 0.0, "mass_offset": 0.0}'  # from a simulator before them
    assert SimAsBuilt.from_json(old).tyre_deflection == 0.0


DIFF = package_file("config", "thorvald_ii_2wd_diff", "thorvald_ii_2wd_diff.yaml")


def turned_on_the_field_route(as_built: str):
    """[deg] the differential robot's heading through the field route on tarmac_gravel (unwrapped):
    the largest it reached, and where it ended."""
    config = load_robot_config(DIFF)
    commands = commands_from_plan(plan_named("field", config)[1], start=0.5)
    run = run_robot(DIFF, commands, RunOptions(world="tarmac_gravel", as_built=as_built))
    turned = np.degrees(np.unwrap([0.0] + [sample.yaw for sample in run.ground_truth]))
    return float(np.max(np.abs(turned))), float(turned[-1])


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_a_differential_robot_on_pneumatic_tyres_drives_its_field_route_on_rigid_ones_it_spins():
    """Its four wheels on soft tyres, casters too: none leaves the ground in a U turn. On rigid tyres
    of radii 0.5 mm apart the frame stood on three, lifted the light drive wheel in the second U turn
    and spun on the spot for the rest of the route (thousands of degrees)."""
    most, end = turned_on_the_field_route("workshop:4")
    assert most < 200.0 and abs(end) < 45.0  # U turns to 180 and back; the route ends heading as it began
    most_rigid, _ = turned_on_the_field_route("rigid:4")  # the same radii
    assert most_rigid > 720.0


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_a_casters_wheel_carries_load_on_soft_tyres_too():
    with RobotSession(DIFF, RunOptions(as_built="field:4")) as s:
        s.run(2.0, lambda t: (0.0, 0.0, 0.0))
        body, c = s.robot.body, s.client
        casters = [s.robot.joint_index[j.name] for j in s.robot.description.passive_wheels]
        contacts = [p.getContactPoints(bodyA=body, linkIndexA=j, physicsClientId=c) for j in casters]
        caster_loads = [sum(point[9] for point in points) for points in contacts]  # normal forces [N]
        drives = s.robot.wheel_loads()
        wheels = casters + [w for w, _, _ in s.robot.wheels]
        stiffness = [p.getDynamicsInfo(body, j, physicsClientId=c)[9] for j in wheels]
    assert len(set(stiffness)) == 1 and stiffness[0] > 0  # every wheel's tyre alike, the casters' too
    assert min(caster_loads) > 0.1 * sum(caster_loads + drives)  # each caster carries its part
