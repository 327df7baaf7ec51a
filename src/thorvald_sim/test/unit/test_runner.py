"""thorvald_sim.tools.runner: a robot driven without ROS (its agreement with the ROS path: tests/test_run_robot.py)."""

import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

from thorvald_model.description import package_file
from thorvald_model.errors import ConfigError
from thorvald_sim.tools.run_robot import build_parser
from thorvald_sim.tools.runner import (
    RunOptions,
    TimedTwist,
    commands_from_plan,
    parse_commands,
    read_commands,
    run_robot,
    stamp_time,
)

STD = package_file("config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
SENSORS = package_file("urdf", "examples", "sensors_example.xacro")


def rows(text):
    return [line.split(",") for line in text.strip().splitlines()]


def test_commands_are_read_from_their_header_in_any_order():
    commands = parse_commands(rows("wz,t,vx,vy\n0.1,0,0.5,0\n0,2.5,0,0.2"))
    assert commands == (TimedTwist(0.0, 0.5, 0.0, 0.1), TimedTwist(2.5, 0.0, 0.2, 0.0))


@pytest.mark.parametrize(
    "text, where, rule",
    [
        ("t,vx,vy\n0,1,2", "line 1", "missing wz"),
        ("t,vx,vy,wz\n0,a,0,0", "line 2.vx", "must be a number"),
        ("t,vx,vy,wz\n0,nan,0,0", "line 2.vx", "must be finite"),
        ("t,vx,vy,wz\n1,0,0,0\n1,0,0,0", "line 3.t", "must be after the line before's (1)"),
        ("t,vx,vy,wz\n-1,0,0,0", "line 2.t", "must be in [0, 86400] [s]"),
        ("t,vx,vy,wz", "", "no command after the header"),
    ],
)
def test_a_broken_commands_file_names_the_line_the_value_and_the_rule(text, where, rule):
    with pytest.raises(ConfigError) as e:
        parse_commands(rows(text), "cmds.csv")
    assert where in str(e.value) and rule in str(e.value)


def test_an_unreadable_commands_file_is_one_clean_error(tmp_path):
    with pytest.raises(ConfigError, match="cannot read the list of commands"):
        read_commands(str(tmp_path / "missing.csv"))
    junk = tmp_path / "junk.csv"
    junk.write_bytes(b"\xff\xfe\x00junk")
    with pytest.raises(ConfigError, match="not a CSV text file"):
        read_commands(str(junk))


def test_times_pass_through_nanoseconds_as_a_ros_stamp_carries_them():
    assert stamp_time(12.9875) == 12.9875
    assert stamp_time(1.0 / 3.0) == 0.333333333  # truncated, as genpy's Time.from_sec
    assert stamp_time(2.0) == 2.0


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_a_robot_drives_its_commands_and_its_odometry_follows(tmp_path):
    # 4 s ahead at 0.5 m/s from t = 0.5 (the wheels ramp at 1.5 m/s^2: 0.33 s), then 1 s standing
    commands = [TimedTwist(0.5, 0.5, 0.0, 0.0), TimedTwist(4.5, 0.0, 0.0, 0.0)]
    run = run_robot(STD, commands, RunOptions(), out_dir=str(tmp_path))
    truth, odometry = run.ground_truth, run.odometry
    assert truth[-1].x == pytest.approx(4 * 0.5 - 0.5 * 0.5 / 1.5 * 0.5, abs=0.1)  # less half the ramps' time
    assert abs(truth[-1].y) < 0.01 and abs(truth[-1].yaw) < 0.01
    assert math.hypot(odometry[-1].x - truth[-1].x, odometry[-1].y - truth[-1].y) < 0.02
    # every control cycle, 50 a second on the simulator's 80 Hz ticks
    assert len(truth) == pytest.approx(50 * run.summary["simulated_s"], abs=2)
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["distance_truth_m"] == pytest.approx(truth[-1].x, abs=0.01)
    assert summary["end_point_difference_m"] < 0.02 and summary["simulated_s"] == pytest.approx(5.5)


@pytest.mark.slow  # two drives of 4 simulated seconds
def test_two_runs_write_the_same_files(tmp_path):
    commands = [TimedTwist(0.5, 0.4, 0.0, 0.0), TimedTwist(3.0, 0.3, 0.1, 0.4), TimedTwist(6.0, 0.0, 0.0, 0.0)]
    for k in (1, 2):
        run_robot(STD, commands, RunOptions(world="tarmac_gravel", as_built="field:3"), out_dir=str(tmp_path / f"r{k}"))
    for name in ("ground_truth.csv", "odometry.csv"):
        assert (tmp_path / "r1" / name).read_bytes() == (tmp_path / "r2" / name).read_bytes(), name


@pytest.mark.slow  # two drives, one measuring every sensor
def test_sensors_are_recorded_only_when_asked(tmp_path):
    commands = [TimedTwist(0.2, 0.3, 0.0, 0.0), TimedTwist(1.0, 0.0, 0.0, 0.0)]
    run_robot(STD, commands, RunOptions(model_extras=SENSORS), out_dir=str(tmp_path / "plain"))
    assert not os.path.exists(tmp_path / "plain" / "sensors")
    run_robot(STD, commands, RunOptions(model_extras=SENSORS, record_sensors=True), out_dir=str(tmp_path / "rec"))
    folder = tmp_path / "rec" / "sensors"
    lidar = np.load(folder / "lidar_front.npz")
    # 2 s at the example lidar's 40 Hz, 1081 beams; its beams' directions kept once
    assert lidar["t"].shape == (80,) and lidar["ranges"].shape == (80, 1, 1081)
    assert lidar["directions"].shape == (1, 1081, 3)
    imu = np.load(folder / "imu.npz")
    assert np.allclose(imu["linear_acceleration"][:, 2].mean(), 9.81, atol=0.2)  # gravity, at rest and driving slowly
    camera = np.load(folder / "camera_front.npz")
    assert camera["image"].shape[1:] == (240, 320, 3) and "rgba" not in camera.files


@pytest.mark.slow  # a process per case: the command as a user types it
def test_the_command_line_writes_its_files_and_refuses_a_broken_commands_file(tmp_path):
    cmds = tmp_path / "cmds.csv"
    cmds.write_text("t,vx,vy,wz\n0.5,0.5,0,0\n2.0,0,0,0\n")
    out = tmp_path / "out"
    argv = [sys.executable, "-m", "thorvald_sim.tools.run_robot", STD, "--commands", str(cmds), "--out", str(out)]
    run = subprocess.run(argv, capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert {"ground_truth.csv", "odometry.csv", "summary.json"} <= set(os.listdir(out))
    assert '"distance_truth_m"' in run.stdout
    cmds.write_text("t,vx,vy,wz\n1.0,0.5,0,0\n0.5,x,0,0\n")
    bad = subprocess.run(argv, capture_output=True, text=True, timeout=300)
    assert bad.returncode == 2 and "Traceback" not in bad.stderr
    assert "line 3.vx: 'x': must be a number" in bad.stderr


@pytest.mark.slow  # a process per case: the command as a user types it
def test_the_command_line_takes_an_example_robots_name_as_the_other_tools_do(tmp_path):
    cmds = tmp_path / "cmds.csv"
    cmds.write_text("t,vx,vy,wz\n0.2,0.5,0,0\n1.2,0,0,0\n")
    out = tmp_path / "out"

    def run_robot_command(robot, out):
        argv = [sys.executable, "-m", "thorvald_sim.tools.run_robot", robot, "--commands", str(cmds), "--out", str(out)]
        return subprocess.run([*argv, "--hold", "0.3"], capture_output=True, text=True, timeout=300)

    run = run_robot_command("thorvald_ii_2wd_diff", out)
    assert run.returncode == 0, run.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["robot"] == package_file("config", "thorvald_ii_2wd_diff", "thorvald_ii_2wd_diff.yaml")
    assert summary["simulated_s"] == pytest.approx(1.5) and summary["distance_truth_m"] == pytest.approx(0.5, abs=0.05)
    misspelt = run_robot_command("thorvald_ii_2wd_dif", tmp_path / "none")
    assert misspelt.returncode == 2 and "Traceback" not in misspelt.stderr
    assert (
        "run_robot: ROBOT 'thorvald_ii_2wd_dif': no example robot of that name (did you mean 'thorvald_ii_2wd_diff'?);"
        " the examples: thorvald_ii_1wd1ws_fwd, " in misspelt.stderr
    )
    assert not os.path.exists(tmp_path / "none")  # refused before anything ran


def test_the_help_documents_every_option_and_the_commands_file():
    parser = build_parser()
    text = parser.format_help()
    for action in parser._actions:
        assert action.help, action.option_strings  # every option says what it is
    for option in ("--world", "--seed", "--calibration", "--model-extras", "--record-sensors", "--as-built", "--hold"):
        assert option in text
    commands = text[text.index("the commands file (--commands):") :]
    for words in ("t,vx,vy,wz", "[m/s]", "[rad/s]", "base_link", "x forward, y left", "holds from its t until the next",
                  "--hold seconds more", "the wheels stand"):  # fmt: skip
        assert words in commands, words
    example = commands[commands.index("    t,vx,vy,wz\n") : commands.index("outputs (DIR):")]
    parsed = parse_commands(rows(example))  # the example is a commands file the runner reads
    assert [c.t for c in parsed] == [0.5, 4.5, 8.5] and parsed[1].wz * 4.0 == pytest.approx(math.pi / 2, abs=1e-4)


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_the_fleet_physics_preset_keeps_the_papers_figures_at_half_the_rate():
    """The fleet preset (120 Hz, 50 solver iterations) against the default (240 Hz) on the paper's
    verification manoeuvre, standard robot on tarmac_gravel: the true paths stay within 0.1 m of
    each other over 80 m and odometry's figures within 0.05 % and 0.05 m (bench/physics_preset.py
    measured 0.01 m, +0.06 against +0.05 %, 0.05 m both)."""
    import pybullet as p  # noqa: PLC0415

    from thorvald_base.verification import plan_for  # noqa: PLC0415
    from thorvald_model import load_robot_config  # noqa: PLC0415
    from thorvald_sim.physics.simulation import Simulation  # noqa: PLC0415
    from thorvald_sim.world import load_world, resolve_world  # noqa: PLC0415

    commands = commands_from_plan(plan_for(load_robot_config(STD))[1], 1.0)
    runs = {
        name: run_robot(STD, commands, RunOptions(world="tarmac_gravel", physics=name)) for name in ("default", "fleet")
    }
    default, fleet = runs["default"], runs["fleet"]
    t = np.array([s.t for s in default.ground_truth])
    apart = max(
        math.hypot(s.x - np.interp(s.t, t, [d.x for d in default.ground_truth]),
                   s.y - np.interp(s.t, t, [d.y for d in default.ground_truth]))
        for s in fleet.ground_truth
    )  # fmt: skip
    assert 0.0 < apart < 0.1  # another physics, nearly the same path
    for run in (default, fleet):
        s = run.summary
        assert s["distance_truth_m"] > 79.0
    errors = [100 * (r.summary["distance_odometry_m"] / r.summary["distance_truth_m"] - 1) for r in (default, fleet)]
    assert abs(errors[0] - errors[1]) < 0.05
    assert abs(default.summary["end_point_difference_m"] - fleet.summary["end_point_difference_m"]) < 0.05
    # the preset is what the engine runs; an explicit rate or iteration count overrides it
    c = p.connect(p.DIRECT)
    try:
        sim = Simulation(c, load_world(resolve_world("flat")), 120.0, solver_iterations=7)
        engine = p.getPhysicsEngineParameters(physicsClientId=c)
        assert engine["fixedTimeStep"] == pytest.approx(1 / 120) and engine["numSolverIterations"] == 7
        assert sim.solver_iterations == 7
        with pytest.raises(ValueError, match="solver_iterations: 0: must be a whole number >= 1"):
            Simulation(c, load_world(resolve_world("flat")), 120.0, solver_iterations=0)
    finally:
        p.disconnect(c)
    with pytest.raises(ValueError, match="physics: 'fast': must be one of default, fleet"):
        run_robot(STD, commands, RunOptions(physics="fast"))
