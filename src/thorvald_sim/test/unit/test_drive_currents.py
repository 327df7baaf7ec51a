"""Each drive's motor currents: the simulator's joints' motor torques through the drive's motors and gears
(thorvald_model.motors, the constants the description's simulator block carries from the robot file),
handed to base_driver's measured drives, whose motor controllers report them (motor_controller_data)."""

import re

import pybullet as p
import pytest

from thorvald_model import load_robot_config
from thorvald_model.description import generate_urdf, package_file
from thorvald_model.motors import Motor, propulsion_motor, steering_motor, winding_current
from thorvald_sim.physics.as_built import BuiltDrive, SimAsBuilt
from thorvald_sim.physics.description import DescriptionError, parse_description
from thorvald_sim.physics.robot import Pose2D
from thorvald_sim.physics.simulation import Simulation
from thorvald_sim.tools.runner import RobotSession, RunOptions
from thorvald_sim.world import load_world, resolve_world

ASYM = package_file("config", "thorvald_ii_6wd6ws_asym", "thorvald_ii_6wd6ws_asym.yaml")
DIFF = package_file("config", "thorvald_ii_2wd_diff", "thorvald_ii_2wd_diff.yaml")


def test_the_description_carries_each_drives_motors_from_the_robot_file():
    config = load_robot_config(ASYM)
    description = parse_description(generate_urdf(ASYM))
    for drive, joints in zip(config.drives, description.drives):
        assert joints.propulsion_motor == propulsion_motor(drive)
        assert joints.steering_motor == steering_motor(drive)


def test_a_description_without_motor_constants_gets_the_robot_files_defaults():
    # an older generator's <drive> (or another's): a Thorvald module's motors, as a robot file naming none
    urdf = re.sub(r' (prp|str)_(motor_kt|motor_r|motor_i0|gr_rt|gear_eff)="[^"]*"', "", generate_urdf(DIFF))
    assert "prp_motor_kt" not in urdf
    (d0, _) = parse_description(urdf).drives
    assert d0.propulsion_motor == Motor(0.14, 0.25, 0.6, 42.0, 0.9)
    assert d0.steering_motor == Motor(0.14, 0.4, 0.4, 42.8571429, 0.85)
    broken = generate_urdf(DIFF).replace('prp_gear_eff="0.9"', 'prp_gear_eff="1.5"', 1)
    with pytest.raises(DescriptionError, match=r"drive 0: motor: gear_efficiency 1.5: must be in \(0, 1\]"):
        parse_description(broken)


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_a_larger_wheel_brakes_and_the_others_push_and_the_controllers_report_the_currents():
    """Six drives straight ahead at 0.8 m/s on flat ground, base_driver told drive0's wheel is 0.2 %
    larger than it is: it turns drive0's wheel 0.2 % slower than the ground goes by, so the other five
    push the robot and drive0's wheel, dragged along, brakes against them. Measured: -9.47 N m at
    drive0 (-0.85 A: beyond its no-load current, the other way) and +1.8 to +2.0 N m on the others
    (0.94 to 0.97 A), balancing to 0 (nothing else resists on flat ground)."""
    with RobotSession(ASYM, RunOptions()) as s:
        config = s.config
        s.core.set_drive_params([(0, "r_wheel", config.drives[0].r_wheel * 1.002)])
        s.run(2.0, lambda t: (0.8, 0.0, 0.0))  # at speed from about 0.6 s (a 1.5 m/s^2 ramp)
        loads = s.robot.motor_torques()
        controllers = s.core.handle.controllers(s.time)
    torques = [m.wheel_torque for m in loads]
    assert torques[0] < -5.0 and all(1.0 < tau < 3.0 for tau in torques[1:]), torques
    assert sum(torques) == pytest.approx(0.0, abs=0.5)
    assert all(m.wheel_rate == pytest.approx(0.8 / 0.2, rel=0.01) for m in loads)
    assert len(controllers) == 6 and all(len(c.motor_vars) == 2 for c in controllers)
    prop = [c.motor_vars[0] for c in controllers]
    steer = [c.motor_vars[1] for c in controllers]
    # what base_driver's controllers report is the motor model applied to the joints at that instant
    for drive, load, pr, st in zip(config.drives, loads, prop, steer):
        assert pr[3] == pytest.approx(winding_current(propulsion_motor(drive), load.wheel_torque, load.wheel_rate))
        assert st[3] == pytest.approx(winding_current(steering_motor(drive), load.steering_torque, load.steering_rate))
        # relative power: the torque the current carries over the wheel's limit (1.6 N m x 42 = 67.2 N m)
        assert pr[4] == pytest.approx(load.wheel_torque / drive.max_wheel_torque)
    i0 = config.drives[0].prp_motor_i0
    amps = [p[3] for p in prop]
    assert amps[0] < 0.0  # braking harder than the motor's friction: the current turns round
    assert all(a > i0 for a in amps[1:])
    # the speeds are the measured rim speeds, drive0's read with the radius base_driver now has
    assert prop[0][1] == pytest.approx(0.8 * 1.002, rel=0.01) and prop[1][1] == pytest.approx(0.8, rel=0.01)


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_as_built_the_currents_come_as_late_as_the_drive_states():
    client = p.connect(p.DIRECT)
    try:
        sim = Simulation(client, load_world(resolve_world("flat")))
        config = load_robot_config(DIFF)
        delay = 0.05  # [s]: 12 steps at 240 Hz
        built = SimAsBuilt("test", tuple(BuiltDrive(d.r_wheel, 0.0) for d in config.drives), delay=delay)
        robot = sim.spawn("r", generate_urdf(DIFF), Pose2D(), as_built=built)
        robot.command([0.0, 0.0], [0.5, 0.5])  # from rest: the currents change while the wheels ramp up
        motors = [propulsion_motor(d) for d in config.drives]
        taken, reported = {}, []
        for _ in range(round(0.5 / sim.dt)):
            sim.step()
            now = round(sim.time, 6)
            taken[now] = [
                winding_current(m, x.wheel_torque, x.wheel_rate) for m, x in zip(motors, robot.motor_torques())
            ]
            reported.append((now, robot.drive_currents(sim.time)))
        assert len({tuple(c) for c in taken.values()}) > 10  # they did change
        for now, currents in reported[20:]:
            assert [c[0] for c in currents] == taken[round(now - delay, 6)]
            assert [c[1] for c in currents] == [0.0, 0.0]  # type-1 drives do not steer
    finally:
        p.disconnect(client)
