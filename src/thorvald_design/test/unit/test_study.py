"""thorvald_design.study: a study file read and checked as a robot file is (pure)."""

import os
import textwrap

import pytest
import yaml

from thorvald_design.report.table import columns
from thorvald_design.study import MAX_CANDIDATES, load_study, parse_study
from thorvald_model.config import parse_robot_config
from thorvald_model.errors import ConfigError


def study(text: str, tmp_path=None):
    return parse_study(yaml.safe_load(textwrap.dedent(text)), "study.yaml", base_dir=str(tmp_path or "."))


def problems(text: str, tmp_path=None) -> str:
    with pytest.raises(ConfigError) as e:
        study(text, tmp_path)
    return str(e.value)


def test_a_study_names_its_candidates_and_its_scenarios_with_their_defaults():
    s = study(
        """
        description: two robots
        candidates:
          std: {robot: thorvald_ii_4wd4ws_std}
          fwd: {robot: thorvald_ii_1wd1ws_fwd, as_built: "field:3"}
        scenarios:
          gradeability: {surface: grass}
          turning:
        """
    )
    assert [c.name for c in s.candidates] == ["std", "fwd"]
    assert s.candidates[1].as_built == "field:3"
    assert [name for name, _ in s.scenarios] == ["gradeability", "turning"]
    grade = dict(s.scenarios)["gradeability"]
    assert grade["surface"] == "grass" and grade["speed"] == 0.5 and grade["step_deg"] == 2.0
    assert dict(s.scenarios)["turning"]["speed"] == pytest.approx(2.0 / 3.6)


@pytest.mark.slow  # every combination's robot file loaded and checked
def test_a_sweep_is_one_candidate_a_combination_and_star_keeps_each_entrys_sign():
    s = study(
        """
        candidates:
          wide:
            robot: thorvald_ii_4wd4ws_std
            sweep: {"motor_drives.*.y": [0.45, 0.6], "motor_drives.drive0.r_wheel": [0.2, 0.25]}
        scenarios: {turning: {}}
        """
    )
    names = [c.name for c in s.candidates]
    assert names == ["wide[y=0.45,r_wheel=0.2]", "wide[y=0.45,r_wheel=0.25]", "wide[y=0.6,r_wheel=0.2]",
                     "wide[y=0.6,r_wheel=0.25]"]  # fmt: skip
    last = s.candidates[-1]
    assert last.family == "wide" and last.swept == (("motor_drives.*.y", 0.6), ("motor_drives.drive0.r_wheel", 0.25))
    config = parse_robot_config(last.robot_data)
    assert sorted(d.y for d in config.drives) == [-0.6, -0.6, 0.6, 0.6]  # the right wheels stay on the right
    assert [d.r_wheel for d in config.drives] == [0.25, 0.2, 0.2, 0.2]


def test_a_payload_is_a_box_of_its_mass_on_the_frame():
    s = study(
        """
        candidates:
          loaded: {robot: thorvald_ii_4wd4ws_std, payload: {mass: 80, x: 0.1, z: 0.9}}
        scenarios: {turning: {}}
        """
    )
    config = parse_robot_config(s.candidates[0].robot_data)
    part = config.frame_parts[-1]
    assert (part.shape, part.mass, part.x, part.y, part.z) == ("box", 80.0, 0.1, 0.0, 0.9)


def test_a_robot_file_is_found_from_the_study_files_folder(tmp_path):
    robot = tmp_path / "robots" / "mine.yaml"
    robot.parent.mkdir()
    robot.write_text("motor_drives: {drive0: {node: 1, x: 0.5, y: 0.3}, drive1: {node: 2, x: 0.5, y: -0.3},"
                     " drive2: {node: 3, x: -0.5, y: 0.3}, drive3: {node: 4, x: -0.5, y: -0.3}}\n")  # fmt: skip
    (tmp_path / "study.yaml").write_text("candidates: {mine: {robot: robots/mine.yaml}}\nscenarios: {turning: {}}\n")
    s = load_study(str(tmp_path / "study.yaml"))
    assert s.candidates[0].robot_file == str(robot)
    assert "candidates: {mine" in s.text


@pytest.mark.parametrize(
    "text, expected",
    [
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std}}\nscenarios: {gradability: {}}",
         "scenarios.gradability: {}: unknown key (did you mean 'gradeability'?)"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std}}\nscenarios: {gradeability: {surfce: mud}}",
         "scenarios.gradeability.surfce: 'mud': unknown key (did you mean 'surface'?)"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std}}\nscenarios: {gradeability: {surface: lava}}",
         "scenarios.gradeability.surface: 'lava': must be one of tarmac"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std}}\nscenarios: {drawbar: {surfaces: [grass, lava]}}",
         "scenarios.drawbar.surfaces: ['grass', 'lava']: must be one of tarmac"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std}}\nscenarios: {drawbar: {surfaces: [mud, mud]}}",
         "or a list of them (each once)"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std}}\nscenarios: {drawbar: {surface: 3}}",
         "scenarios.drawbar.surface: 3: must be a string or a list of strings"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std}}\nscenarios: {drawbar: {surface: []}}",
         "scenarios.drawbar.surface: []: must be a string or a list of strings"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std}}\nscenarios: {drawbar: {surfaces: [mud]}}\n"
         "pareto: [drawbar.max_pull_n.mud, drawbar.max_pull_n]",
         "pareto[0]: 'drawbar.max_pull_n.mud': is not a metric of the study's scenarios (did you mean "
         "'drawbar.max_pull_n'?)"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std}}\nscenarios: {gradeability: {start_deg: 30, max_deg: 20}}",
         "scenarios.gradeability.max_deg: 20.0: must be >= start_deg (30)"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_sdt}}\nscenarios: {turning: {}}",
         "candidates.a.robot: 'thorvald_ii_4wd4ws_sdt': no example robot of that name (did you mean "
         "'thorvald_ii_4wd4ws_std'?); the examples: thorvald_ii_1wd1ws_fwd, "),
        ("candidates: {a: {robot: missing.yaml}}\nscenarios: {turning: {}}",
         "candidates.a.robot: 'missing.yaml': no such file"),
        ("candidates: {a: {robt: thorvald_ii_4wd4ws_std}}\nscenarios: {turning: {}}",
         "candidates.a.robt: 'thorvald_ii_4wd4ws_std': unknown key (did you mean 'robot'?)"),
        ("candidates: {'a b': {robot: thorvald_ii_4wd4ws_std}}\nscenarios: {turning: {}}",
         "candidates.a b: <missing>: must be letters, digits"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std, sweep: {'motor_drives.*.y': [0.3, x]}}}\n"
         "scenarios: {turning: {}}", "'x' is not a finite number"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std, sweep: {'motor_drive.*.y': [0.3]}}}\n"
         "scenarios: {turning: {}}", "candidates.a.sweep.motor_drive.*.y: [0.3]: the robot files' schema has no "
         "section 'motor_drive': a sweep of it would change nothing (did you mean 'motor_drives'?)"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std, sweep: {'suspensions.*.travel': [0.1]}}}\n"
         "scenarios: {turning: {}}", "candidates.a.sweep.suspensions.*.travel: 0.1: the robot file has no section "
         "'suspensions'"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std, sweep: {'motor_drives.drive9.y': [0.3]}}}\n"
         "scenarios: {turning: {}}", "has no entry 'drive9'"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std, sweep: {'motor_drives.*.r_wheel': [-0.2]}}}\n"
         "scenarios: {turning: {}}", "makes a robot the robot files' rules refuse"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std, payload: {mass: -3}}}\nscenarios: {turning: {}}",
         "candidates.a.payload.mass: -3: must be >= 0"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std, payload: {mas: 80}}}\nscenarios: {turning: {}}",
         "candidates.a.payload.mas: 80: unknown key (did you mean 'mass'?)"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std, payload: {mass: 80, height: 1}}}\nscenarios: {turning: {}}",
         "candidates.a.payload.height: 1: unknown key (known keys: mass, x, y, z)"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std}}\nscenarios: {turning: {}}\nsede: 3",
         "sede: 3: unknown key (did you mean 'seed'?)"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std}}", "scenarios: <missing>: is required"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std}}\nscenarios: {turning: {}}\n"
         "pareto: [turning.turning_diameter, turning.clearance_diameter_m]",
         "pareto[0]: 'turning.turning_diameter': is not a metric of the study's scenarios (did you mean "
         "'turning.turning_diameter_m'?)"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std}}\nscenarios: {turning: {}}\npareto: turning",
         "pareto: 'turning': must be a list of two metrics"),
    ],
)  # fmt: skip
def test_a_broken_study_names_the_key_path_the_value_and_the_rule(text, expected):
    assert expected in problems(text)


@pytest.mark.parametrize(
    "key_path, values, expected",
    [
        # issue 45: ran every combination with a warning for each drive, and the results were the same
        ("motor_drives.*.width", "[0.5, 0.6]", "candidates.a.sweep.motor_drives.*.width: [0.5, 0.6]: the robot files' "
         "schema has no key 'width' in motor_drives entries: nothing reads it, so a sweep of it would change nothing "
         "(did you mean 'w_wheel'?)"),
        ("motor_drives.*.radius", "[0.2, 0.25]", "no key 'radius' in motor_drives entries: nothing reads it, so a "
         "sweep of it would change nothing (did you mean 'r_wheel'?)"),
        ("motor_drives.*.track", "[0.5, 0.6]", "(did you mean 'y'?)"),
        ("motor_drives.drive0.r_wheeel", "[0.2, 0.25]", "no key 'r_wheeel' in motor_drives entries: nothing reads it, "
         "so a sweep of it would change nothing (did you mean 'r_wheel'?)"),
        ("batteries.*.capacty", "[50, 80]", "(did you mean 'capacity'?)"),
        ("motor_drives.*.zz", "[1, 2]", "(the keys of motor_drives entries: leg_mesh, node, prp_enc_ppr, "),
        ("lidar_front.a.x", "[1, 2]", "candidates.a.sweep.lidar_front.a.x: [1, 2]: the robot files' schema has no "
         "section 'lidar_front': a sweep of it would change nothing (its sections: motor_drives, batteries, "),
        ("frame_parts.part0.shape", "[1, 2]", "candidates.a.sweep.frame_parts.part0.shape: [1, 2]: frame_parts "
         "entries' 'shape' is not a number (a sweep's values are numbers)"),
    ],
)  # fmt: skip
def test_a_sweep_of_a_key_the_schema_does_not_know_is_refused_with_did_you_mean(key_path, values, expected, caplog):
    """A robot file may keep keys of its owner's, but a study's candidate has no xacro of its own that
    could read one: a sweep of it would run every combination for nothing."""
    text = problems(
        f"candidates: {{a: {{robot: thorvald_ii_4wd4ws_std, sweep: {{'{key_path}': {values}}}}}}}\n"
        "scenarios: {turning: {}}"
    )
    assert expected in text
    assert "1 problem)" in text
    assert "kept as it is" not in caplog.text  # refused before any combination was made and loaded


def test_the_refusal_names_the_study_file_and_nothing_is_made(tmp_path, caplog):
    path = tmp_path / "study.yaml"
    path.write_text("candidates:\n  wide:\n    robot: thorvald_ii_4wd4ws_std\n"
                    "    sweep: {'motor_drives.*.width': [0.5, 0.6]}\nscenarios: {turning: {}}\n")  # fmt: skip
    with pytest.raises(ConfigError) as e:
        load_study(str(path))
    assert str(e.value).splitlines()[1].strip().startswith(f"{path}: candidates.wide.sweep.motor_drives.*.width: ")
    assert caplog.records == []


@pytest.mark.parametrize(
    "robot, sweep, expected",
    [
        # the differential robot's two drives are type 1: a fixed leg, no steering
        ("thorvald_ii_2wd_diff", "{'motor_drives.*.str_lim': [1.0, 2.0]}",
         "candidates.a.sweep.motor_drives.*.str_lim: [1.0, 2.0]: a[str_lim=1] and a[str_lim=2] make the same robot: "
         "a drive that does not steer (type 1) has a fixed leg: nothing reads its steering keys (drive0, drive1)"),
        ("thorvald_ii_2wd_diff", "{'motor_drives.*.y': [0.3, 0.35], 'motor_drives.drive0.str_motor_kt': [0.1, 0.2]}",
         "candidates.a.sweep.motor_drives.drive0.str_motor_kt: [0.1, 0.2]: a[y=0.3,str_motor_kt=0.1] and "
         "a[y=0.3,str_motor_kt=0.2] make the same robot: a drive that does not steer (type 1) has a fixed leg: "
         "nothing reads its steering keys (drive0)"),
        # the standard robot's second enclosure holds no battery (with_battery: 0)
        ("thorvald_ii_4wd4ws_std", "{'batteries.bat1.capacity': [50, 100]}",
         "a[capacity=50] and a[capacity=100] make the same robot: an enclosure without a KC battery (type 0, or "
         "with_battery 0) holds no pack (bat1)"),
        # the front-driven robot's support wheels are fixed
        ("thorvald_ii_1wd1ws_fwd", "{'passive_wheels.*.caster_offset': [0.05, 0.1]}",
         "make the same robot: a fixed wheel has no caster trail (passive0, passive1)"),
        # numbers that differ past the 6 digits a candidate's name keeps would give two candidates one name
        ("thorvald_ii_4wd4ws_std", "{'motor_drives.*.y': [0.6, 0.6000001]}",
         "candidates.a.sweep.motor_drives.*.y: [0.6, 0.6000001]: 0.6 and 0.6000001 would name one candidate "
         "(y=0.6): names keep 6 significant digits"),
    ],
)  # fmt: skip
@pytest.mark.slow  # every combination's robot file loaded and checked
def test_a_sweep_whose_combinations_make_the_same_robot_is_refused(robot, sweep, expected):
    text = problems(f"candidates: {{a: {{robot: {robot}, sweep: {sweep}}}}}\nscenarios: {{turning: {{}}}}")
    assert expected in text and "1 problem)" in text


def test_a_key_read_by_some_of_the_entries_it_sets_is_a_sweep():
    """The front-driven robot's one drive steers: its str_lim is read, so the two robots differ."""
    s = study("candidates: {a: {robot: thorvald_ii_1wd1ws_fwd, sweep: {'motor_drives.*.str_lim': [1.0, 2.0]}}}\n"
              "scenarios: {turning: {}}")  # fmt: skip
    assert [c.name for c in s.candidates] == ["a[str_lim=1]", "a[str_lim=2]"]
    assert [parse_robot_config(c.robot_data).drives[0].str_lim for c in s.candidates] == [1.0, 2.0]


def test_swept_integers_and_flags_are_written_as_the_file_writes_them():
    s = study("candidates: {a: {robot: thorvald_ii_4wd4ws_std, sweep: {'batteries.bat1.with_battery': [0, 1],"
              " 'motor_drives.drive0.prp_enc_ppr': [2048]}}}\nscenarios: {turning: {}}")  # fmt: skip
    fitted = [parse_robot_config(c.robot_data).batteries[1].with_battery for c in s.candidates]
    assert fitted == [False, True]
    drive0 = s.candidates[0].robot_data["motor_drives"]["drive0"]["prp_enc_ppr"]
    assert drive0 == 2048 and isinstance(drive0, int)


@pytest.mark.slow  # every combination's robot file loaded and checked
def test_a_searched_range_that_changes_nothing_is_refused():
    """A range no sweep expands: its min and max, the other key paths at their first, must differ."""
    text = problems(
        "candidates: {a: {robot: thorvald_ii_2wd_diff, sweep: {'motor_drives.*.y': [0.3, 0.35],"
        " 'motor_drives.*.str_sim_v': {min: 1, max: 4}}}}\nscenarios: {turning: {}}\n"
        "optimise: {candidate: a, objectives: {turning.turning_diameter_m: min, turning.clearance_diameter_m: min}}"
    )
    assert (
        "candidates.a.sweep.motor_drives.*.str_sim_v: [1.0, 4.0]: the range's min and max, 1 and 4, make the same "
        "robot: a drive that does not steer (type 1) has a fixed leg" in text
    )
    searched = study(
        "candidates: {a: {robot: thorvald_ii_2wd_diff, sweep: {'motor_drives.*.y': {min: 0.3, max: 0.4}}}}\n"
        "scenarios: {turning: {}}\n"
        "optimise: {candidate: a, objectives: {turning.turning_diameter_m: min, turning.clearance_diameter_m: min}}"
    )
    assert searched.space is not None and searched.candidates == ()


def test_a_robot_its_calculator_cannot_serve_is_refused(tmp_path):
    (tmp_path / "four.yaml").write_text(
        'base_calculator: "pltf_clc_2wdiff::PltfClc2WDiff"\n'
        "motor_drives: {drive0: {node: 1, x: 0.5, y: 0.3}, drive1: {node: 2, x: 0.5, y: -0.3},"
        " drive2: {node: 3, x: -0.5, y: 0.3}, drive3: {node: 4, x: -0.5, y: -0.3}}\n"
    )
    text = problems("candidates: {a: {robot: four.yaml}}\nscenarios: {turning: {}}", tmp_path)
    assert "makes a robot the robot files' rules refuse" in text and "exactly two type-1 drives" in text


def test_every_problem_is_reported_at_once():
    text = problems("candidates: {a: {robot: nothing_like_it}}\nscenarios: {turning: {speed: 9}, drawbar: {step_n: 0}}")
    assert "3 problems" in text
    assert (
        "scenarios.turning.speed: 9" in text and "scenarios.drawbar.step_n: 0" in text and "candidates.a.robot" in text
    )


def test_a_sweep_too_large_for_a_machine_is_refused():
    values = [round(0.3 + 0.001 * k, 3) for k in range(17)]
    text = problems(
        f"candidates: {{a: {{robot: thorvald_ii_4wd4ws_std, sweep: {{'motor_drives.*.y': {values},"
        f" 'motor_drives.*.r_wheel': {[round(0.15 + 0.001 * k, 3) for k in range(16)]}}}}}}}\n"
        "scenarios: {turning: {}}"
    )
    assert f"candidates.a.sweep: <missing>: the sweep makes 272 candidates: at most {MAX_CANDIDATES}" in text


def test_drawbar_takes_one_surface_or_several_and_each_has_its_columns():
    one = parse_study(
        yaml.safe_load("candidates: {a: {robot: thorvald_ii_4wd4ws_std}}\nscenarios: {drawbar: {surface: mud}}")
    )
    several = parse_study(
        yaml.safe_load(
            "candidates: {a: {robot: thorvald_ii_4wd4ws_std}}\nscenarios: {drawbar: {surfaces: [tarmac, mud]}}\n"
            "pareto: [drawbar.max_pull_n.mud, drawbar.max_pull_n.tarmac]"
        )
    )
    assert dict(one.scenarios)["drawbar"]["surface"] == ("mud",)
    assert dict(several.scenarios)["drawbar"]["surface"] == ("tarmac", "mud")
    assert columns(one) == ["drawbar.max_pull_n", "drawbar.limited_by", "drawbar.predicted_pull_n", "drawbar.surface"]
    assert columns(several)[4:] == [
        "drawbar.max_pull_n.tarmac", "drawbar.limited_by.tarmac", "drawbar.predicted_pull_n.tarmac",
        "drawbar.max_pull_n.mud", "drawbar.limited_by.mud", "drawbar.predicted_pull_n.mud",
    ]  # fmt: skip
    assert several.pareto == ("drawbar.max_pull_n.mud", "drawbar.max_pull_n.tarmac")


STUDIES = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "studies")


@pytest.mark.slow  # every combination's robot file loaded and checked
@pytest.mark.parametrize("name", sorted(f for f in os.listdir(STUDIES) if f.endswith(".yaml")))
def test_every_shipped_study_is_a_valid_study_with_its_command_in_its_header(name):
    path = os.path.join(STUDIES, name)
    study = load_study(path)
    assert study.candidates and study.scenarios
    assert f"studies/{name} --out /tmp/{name[:-5]}" in study.text  # the comment a user copies
