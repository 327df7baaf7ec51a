"""What a spawn is refused before anything starts: every file kind past the YAML bounds (one clean
line from its loader), malformed as-built specs, names that are not legal ROS names; and
check_as_built, the command that checks an as-built robot without the simulator. Pure: no pybullet
client, no ROS master."""

import math
import os
import subprocess
import time

import pytest

from thorvald_base.calibration import load_calibration
from thorvald_model import load_robot_config
from thorvald_model.datum import load_datum
from thorvald_model.errors import ConfigError
from thorvald_model.schema import MAX_YAML_DEPTH
from thorvald_sim.physics.as_built import MAX_SEED, as_built_for, draw_as_built, is_profile_spec, load_as_built
from thorvald_sim.spawn.names import model_name_problem, namespace_problem
from thorvald_sim.world import load_world

HERE = os.path.dirname(os.path.abspath(__file__))
CONFIGS = os.path.abspath(os.path.join(HERE, "..", "..", "..", "thorvald_model", "config"))
STD_PATH = os.path.join(CONFIGS, "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
DIFF_PATH = os.path.join(CONFIGS, "thorvald_ii_2wd_diff", "thorvald_ii_2wd_diff.yaml")
STD = load_robot_config(STD_PATH)

# "Billion laughs": 9 levels of 10 aliases of the level before, 10^9 scalars in about 400 bytes
BOMB = "lol:\n  a: &a [lol, lol, lol, lol, lol, lol, lol, lol, lol, lol]\n" + "".join(
    f"  {name}: &{name} [{', '.join(['*' + prev] * 10)}]\n" for prev, name in zip("abcdefgh", "bcdefghi")
)
DEEP = "lol: " + "[" * 5000 + "]" * 5000 + "\n"

# each file kind, its loader (the robot it is for where it needs one) and what its files hold
LOADERS = {
    "robot": load_robot_config,
    "world": load_world,
    "as-built": lambda path: load_as_built(path, STD),
    "calibration": lambda path: load_calibration(path, STD),
    "datum": load_datum,
}


def text_of(path):
    with open(path, encoding="utf-8") as f:
        return f.read()


VALID = {
    "robot": text_of(STD_PATH),
    "world": "gravity: 9.81\n",
    "as-built": "delay: 0.02\n",
    "calibration": "motor_drives:\n  drive0: {r_wheel: 0.2011}\n",
    "datum": "datum: [53.268642, -0.524509, 0.0]\n",
}


@pytest.mark.slow  # files past the YAML bounds, each read to its limit
@pytest.mark.parametrize("kind", sorted(LOADERS))
@pytest.mark.parametrize("past", ["bomb", "deep"])
def test_every_file_kind_past_the_yaml_bounds_gets_one_clean_line(tmp_path, kind, past):
    path = tmp_path / f"{kind}.yaml"
    path.write_text(VALID[kind])
    LOADERS[kind](str(path))  # a valid file of the kind...
    path.write_text(VALID[kind] + (BOMB if past == "bomb" else DEEP))  # ...with the bomb under a key of the user's
    start = time.perf_counter()
    with pytest.raises(ConfigError) as info:
        LOADERS[kind](str(path))
    assert time.perf_counter() - start < 0.5
    text = str(info.value)
    assert "\n" not in text and text.startswith(f"{path}: refused at line "), text
    rule = "values with its aliases expanded" if past == "bomb" else f"nested deeper than {MAX_YAML_DEPTH} levels"
    assert rule in text


# ---- as-built specs ----------------------------------------------------------------------------
SEED_RULE = f"field:SEED: SEED must be a whole number from 0 to {MAX_SEED} (an integer seed), e.g. field:7"


MALFORMED_SEEDS = [
    *("field:--1", "field:", "field", "field:abc", "field:1.5", "field:-3", "field:+3", "field:1e3", "field:²"),
    *("field:0x10", f"field:{MAX_SEED + 1}", "field:" + "9" * 100000),
]


@pytest.mark.parametrize("spec", MALFORMED_SEEDS, ids=lambda spec: spec[:20])
def test_a_malformed_seed_is_refused_with_the_rule(spec):
    start = time.perf_counter()
    with pytest.raises(ConfigError) as info:
        as_built_for(spec, STD)
    assert time.perf_counter() - start < 0.1  # a seed of 100000 digits is refused unread
    text = str(info.value)
    assert "\n" not in text and text.endswith(": " + SEED_RULE), text
    # the spec leads the line, cut when long
    assert text.startswith(spec + ": ") if len(spec) <= 60 else text.startswith("'field:999")


def test_an_unknown_profile_is_named_with_the_known_ones():
    with pytest.raises(ConfigError) as info:
        as_built_for("nosuch:3", STD)
    assert str(info.value) == (
        "nosuch:3: no as-built profile 'nosuch' (the profiles: field, rigid, workshop) and no file of that name"
    )


def test_seeds_at_the_bounds_are_drawn():
    # 0 and 2^64 - 1: both ends of the range; the source keeps the spec as given
    assert draw_as_built("field:0", STD).source == "field:0"
    assert draw_as_built(f"field:{MAX_SEED}", STD) != draw_as_built("field:0", STD)
    assert draw_as_built("field: 7", STD) == draw_as_built("field: 7", STD)


def test_a_file_whose_name_looks_like_a_profile_is_a_file(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "mine:3").write_text("delay: 0.01\n")
    # a known profile, or a NAME:... that names no file (a misspelt profile, said so)
    assert is_profile_spec("field:3") and is_profile_spec("nosuch:3")
    assert not is_profile_spec("mine:3") and as_built_for("mine:3", STD).delay == 0.01
    assert not is_profile_spec("robots/field.yaml") and not is_profile_spec("x.yaml")
    (tmp_path / "mine:3").unlink()
    assert is_profile_spec("mine:3")


def test_spawn_robot_refuses_a_malformed_seed_with_a_config_error():
    import argparse  # noqa: PLC0415

    from thorvald_sim.spawn.spawn_robot import read_as_built  # noqa: PLC0415

    with pytest.raises(ConfigError, match="SEED must be a whole number"):
        read_as_built(argparse.Namespace(as_built="field:--1", robot_model=STD_PATH))


# ---- names -------------------------------------------------------------------------------------
@pytest.mark.parametrize("name", ["robot_1", "thorvald_001", "Thorvald", "a", "robot-1", "unit_box.0", "1robot"])
def test_a_model_name_as_gazebo_takes_it(name):
    assert model_name_problem(name) is None


@pytest.mark.parametrize("name", ["a b", "-robot", ".robot", "/robot", "robot/1", "ä", "robot\n", "~r", "r" * 256])
def test_a_model_name_that_would_break_the_lines_naming_it(name):
    problem = model_name_problem(name)
    assert problem.startswith("model name ") and "must be letters, digits" in problem, problem


def test_a_model_name_must_be_given_and_is_shown_cut():
    assert model_name_problem("") == "a robot needs a name: -model NAME"
    assert model_name_problem(None) == "a robot needs a name: -model NAME"
    long = model_name_problem("a b" * 10**6)
    assert long.startswith("model name 'a ba b") and len(long) < 300  # 60 characters of the name


@pytest.mark.parametrize("namespace", ["", "/", "robot_1", "/robot_1", "/robot_1/", "/fleet/robot_1"])
def test_a_legal_namespace(namespace):
    assert namespace_problem(namespace) is None


@pytest.mark.parametrize("namespace", ["/bad ns", "a//b", "1robot", "robot-1", "ä", "/r\n", "/r.s"])
def test_a_namespace_that_is_not_a_legal_ros_name(namespace):
    problem = namespace_problem(namespace)
    assert problem.startswith(f"robot namespace {namespace!r}: must be a legal ROS name"), problem


def test_the_namespace_rule_is_ros_own():
    import rosgraph.names  # noqa: PLC0415

    # rosgraph checks the first character of the whole name only: /1robot and /ä pass, as in ROS
    for namespace in ["/1robot", "/ä", "/a/b/", "a b", "//a", "", "/", "r2"]:
        assert (namespace_problem(namespace) is None) == rosgraph.names.is_legal_name(namespace), namespace


def test_a_private_namespace_is_refused():
    assert namespace_problem("~robot").endswith("must not be private (~): it would be the simulator's")


def test_spawn_robot_parses_names_with_the_rules(capsys):
    from thorvald_sim.spawn.spawn_robot import parse_args  # noqa: PLC0415

    args = parse_args(["-param", "robot_description", "-model", "robot_1", "-robot_namespace", "/robot_1"])
    assert (args.model, args.robot_namespace) == ("robot_1", "/robot_1")
    for argv, says in (
        (["-model", "robot_1", "-robot_namespace", "/bad ns"], "argument -robot_namespace: robot namespace '/bad ns'"),
        (["-model", "a b"], "argument -model: model name 'a b': must be letters, digits"),
        (["-model", ""], "argument -model: a robot needs a name"),
    ):
        with pytest.raises(SystemExit) as info:
            parse_args(["-param", "robot_description", *argv])
        assert info.value.code == 2
        assert says in capsys.readouterr().err


def test_the_simulators_spawn_service_refuses_the_names_before_anything():
    from thorvald_msgs.srv import SpawnRobotRequest  # noqa: PLC0415
    from thorvald_sim.node.services import SimulatorServices  # noqa: PLC0415

    class Untouchable:
        """Simulator services that fail the test if the spawn goes past its checks."""

        def __getattr__(self, name):
            raise AssertionError(f"srv_spawn used self.{name} for a request it must refuse")

    def spawn(model, namespace):
        request = SpawnRobotRequest(model_name=model, robot_namespace=namespace, robot_description="<robot/>")
        return SimulatorServices.srv_spawn(Untouchable(), request)

    response = spawn("robot_1", "/bad ns")
    assert not response.success and response.message.startswith("robot namespace '/bad ns': must be a legal ROS")
    response = spawn("a b", "/robot_1")
    assert not response.success and response.message.startswith("model name 'a b': must be letters, digits")
    assert spawn("", "/robot_1").message == "a robot needs a name: -model NAME"
    assert spawn("robot_1", "~mine").message.endswith("must not be private (~): it would be the simulator's")


# ---- check_as_built ------------------------------------------------------------------------------
def check_as_built(*args):
    return subprocess.run(
        ["rosrun", "thorvald_sim", "check_as_built", *args], capture_output=True, text=True, timeout=60
    )


@pytest.mark.slow  # a process per case: the command as a user types it
def test_check_as_built_summarises_a_valid_file(tmp_path):
    path = tmp_path / "built.yaml"
    path.write_text(
        "motor_drives:\n  drive0: {r_wheel: 0.2015, steering_offset: 0.004}\n"
        "encoders: true\ndelay: 0.02\nmass_offset: 30\n"
    )
    proc = check_as_built(str(path), "--robot-model", STD_PATH)
    assert proc.returncode == 0 and proc.stderr == "", proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[0] == f"{path}: valid as-built robot of thorvald_ii_4wd4ws_std.yaml"
    assert "delay     20 ms" in proc.stdout and "load      30 kg" in proc.stdout
    d = STD.drives[0]
    # drive0: 0.2015 against 0.2: +1.50 mm, +0.75 %; 0.004 rad = 0.229 deg. The encoders' counts at
    # the joint: 360 / (1024 x 4 x 42.857) = 0.0021 deg steering, 360 / (1024 x 4 x 42) = 0.0021 deg
    # wheel; one motor rpm: 1 / 42 x pi / 30 x 0.2 m = 0.499 mm/s
    steering_count = 360 / (d.str_enc_ppr * 4 * d.str_gr_rt)
    wheel_count = 360 / (d.prp_enc_ppr * 4 * d.prp_gr_rt)
    speed_step = 1 / d.prp_gr_rt * math.pi / 30 * d.r_wheel * 1000
    (row,) = [line.split() for line in lines if line.strip().startswith("drive0")]
    assert row == [
        "drive0",
        "0.20150",
        "0.20000",
        "+1.50",
        "+0.75",
        "+0.229",
        f"{steering_count:.4f}",
        f"{wheel_count:.4f}",
        f"{speed_step:.3f}",
    ]
    (row,) = [line.split() for line in lines if line.strip().startswith("drive3")]
    assert row[1:6] == ["0.20000", "0.20000", "+0.00", "+0.00", "+0.000"]


@pytest.mark.slow  # a process per case: the command as a user types it
def test_check_as_built_takes_a_profile_and_says_a_drive_does_not_steer():
    proc = check_as_built("field:3", "--robot-model", DIFF_PATH, "--json")
    assert proc.returncode == 0, proc.stderr
    import json  # noqa: PLC0415

    summary = json.loads(proc.stdout)
    drawn = draw_as_built("field:3", load_robot_config(DIFF_PATH))
    assert summary["as_built"] == "field:3" and summary["loaded"] == drawn.loaded
    assert [d["r_wheel"] for d in summary["drives"]] == [d.r_wheel for d in drawn.drives]
    assert all(not d["steerable"] and d["steering_count"] == 0 for d in summary["drives"])
    text = check_as_built("field:3", "--robot-model", DIFF_PATH).stdout
    assert "tyres     loaded" in text


@pytest.mark.slow  # a process per case: the command as a user types it
def test_check_as_built_lists_every_problem_on_stderr_and_exits_2(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_text("motor_drives:\n  drive9: {r_wheel: 0.2}\n  drive0: {steering_offset: 0.9}\ndelay: 7\n")
    proc = check_as_built(str(path), "--robot-model", STD_PATH)
    assert proc.returncode == 2 and proc.stdout == ""
    assert "Traceback" not in proc.stderr
    lines = proc.stderr.splitlines()
    assert lines[0] == f"{path}: invalid as-built file (3 problems):"
    assert f"  {path}: delay: 7: must be in [0, 1.0] s" in lines
    assert any("motor_drives.drive9" in line and "is not a drive of the robot" in line for line in lines)
    assert f"  {path}: motor_drives.drive0.steering_offset: 0.9: must be within +-0.2 rad" in lines


@pytest.mark.parametrize(
    "args, says",
    [
        (["field:--1", "--robot-model", STD_PATH], "field:--1: " + SEED_RULE),
        (["nosuch:3", "--robot-model", STD_PATH], "no as-built profile 'nosuch'"),
        (["field:1", "--robot-model", "/nonexistent/robot.yaml"], "cannot read the robot configuration"),
    ],
)
@pytest.mark.slow  # a process per case: the command as a user types it
def test_check_as_built_refuses_a_bad_spec_or_robot_file_in_one_line(args, says):
    proc = check_as_built(*args)
    assert proc.returncode == 2 and proc.stdout == ""
    assert len(proc.stderr.splitlines()) == 1 and says in proc.stderr, proc.stderr


@pytest.mark.slow  # a process per case: the command as a user types it
def test_check_as_built_refuses_a_bomb_in_one_line(tmp_path):
    path = tmp_path / "bomb.yaml"
    path.write_text(BOMB)
    proc = check_as_built(str(path), "--robot-model", STD_PATH)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert proc.stderr.startswith(f"{path}: refused at line 6, column ") and len(proc.stderr.splitlines()) == 1
