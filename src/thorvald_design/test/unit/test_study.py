"""thorvald_design.study: a study file read and checked as a robot file is (pure)."""

import os
import textwrap

import pytest
import yaml

from thorvald_design.report_table import columns
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
         "candidates.a.robot: 'thorvald_ii_4wd4ws_sdt': no example robot of that name"),
        ("candidates: {a: {robot: missing.yaml}}\nscenarios: {turning: {}}",
         "candidates.a.robot: 'missing.yaml': no such file"),
        ("candidates: {a: {robt: thorvald_ii_4wd4ws_std}}\nscenarios: {turning: {}}",
         "candidates.a.robt: 'thorvald_ii_4wd4ws_std': unknown key (did you mean 'robot'?)"),
        ("candidates: {'a b': {robot: thorvald_ii_4wd4ws_std}}\nscenarios: {turning: {}}",
         "candidates.a b: <missing>: must be letters, digits"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std, sweep: {'motor_drives.*.y': [0.3, x]}}}\n"
         "scenarios: {turning: {}}", "'x' is not a finite number"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std, sweep: {'motor_drive.*.y': [0.3]}}}\n"
         "scenarios: {turning: {}}", "the robot file has no section 'motor_drive' (did you mean 'motor_drives'?)"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std, sweep: {'motor_drives.drive9.y': [0.3]}}}\n"
         "scenarios: {turning: {}}", "has no entry 'drive9'"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std, sweep: {'motor_drives.*.r_wheel': [-0.2]}}}\n"
         "scenarios: {turning: {}}", "makes a robot the robot files' rules refuse"),
        ("candidates: {a: {robot: thorvald_ii_4wd4ws_std, payload: {mass: -3}}}\nscenarios: {turning: {}}",
         "candidates.a.payload.mass: -3: must be >= 0"),
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


@pytest.mark.parametrize("name", sorted(f for f in os.listdir(STUDIES) if f.endswith(".yaml")))
def test_every_shipped_study_is_a_valid_study_with_its_command_in_its_header(name):
    path = os.path.join(STUDIES, name)
    study = load_study(path)
    assert study.candidates and study.scenarios
    assert f"studies/{name} --out /tmp/{name[:-5]}" in study.text  # the comment a user copies
