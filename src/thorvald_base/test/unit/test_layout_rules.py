"""Each calculator declares the layouts it can serve (BaseCalculator.layout_rules), checked after the
rules every calculator shares (thorvald_model.layout, which the loader checks): by base_driver when
it loads the calculator, by check_config, and for a calculator of another package the same way."""

import dataclasses

import pytest

from thorvald_base.kinematics import BaseCalculator
from thorvald_base.plugins import calculator_layout_problems, load_calculator
from thorvald_model import ConfigError, parse_robot_config
from thorvald_model.errors import Problem


def std_drive(node, x, y, **extra):
    d = {"node": node, "x": x, "y": y, "type": 0}
    d.update(extra)
    return d


def four_ws():
    drives = {
        "drive0": std_drive(1, -0.547, -0.30),
        "drive1": std_drive(2, 0.547, -0.30),
        "drive2": std_drive(3, -0.547, 0.30),
        "drive3": std_drive(4, 0.547, 0.30),
    }
    return {"base_calculator": "pltf_clc_std::PltfClcStd", "motor_drives": drives}


def assert_problem(data, path, *words):
    """The file loads (the shared rules hold), and its calculator refuses it at path, with every word;
    base_driver's loading of the calculator says the same as a problem of the file."""
    config = parse_robot_config(data, "robot.yaml")
    problems = calculator_layout_problems(config)
    matching = [p for p in problems if p.path == path]
    assert matching, f"no problem at {path}; got {[(p.path, p.rule) for p in problems]}"
    for word in words:
        assert any(word in p.rule for p in matching), (word, [p.rule for p in matching])
    with pytest.raises(ConfigError) as info:
        load_calculator(config)
    assert [p.path for p in info.value.problems] == [p.path for p in problems]
    assert "robot.yaml: " + path in str(info.value)


def test_standard_calculator_needs_two_steered_drives_or_a_fixed_axle():
    robot = four_ws()
    robot["motor_drives"] = {"drive0": std_drive(1, 0.5, 0.0)}
    robot["passive_wheels"] = {"passive0": {"type": "caster", "x": -0.5, "y": 0.3}}
    assert_problem(robot, "base_calculator", "single steered drive", "pltf_clc_1wd::PltfClc1WD")


def diff_robot():
    return {
        "base_calculator": "pltf_clc_2wdiff::PltfClc2WDiff",
        "motor_drives": {"drive0": std_drive(1, 0.0, -0.3, type=1), "drive1": std_drive(1, 0.0, 0.3, type=1)},
        "passive_wheels": {"passive0": {"type": "caster", "x": -0.6, "y": 0.0}},
    }


def test_differential_calculator_serves_two_type1_drives():
    assert calculator_layout_problems(parse_robot_config(diff_robot())) == []
    robot = diff_robot()
    # a steered drive beside the pair: every shared rule holds, the differential calculator refuses
    robot["motor_drives"]["drive2"] = std_drive(2, 0.6, 0.0)
    assert_problem(robot, "base_calculator", "exactly two type-1 drives")


def one_wheel_robot(drive_x=0.6):
    return {
        "base_calculator": "pltf_clc_1wd::PltfClc1WD",
        "motor_drives": {"drive0": std_drive(1, drive_x, 0.0)},
        "passive_wheels": {
            "passive0": {"type": "fixed", "x": -0.4, "y": 0.35},
            "passive1": {"type": "fixed", "x": -0.4, "y": -0.35},
        },
    }


def test_one_wheel_calculator_needs_fixed_wheels():
    assert calculator_layout_problems(parse_robot_config(one_wheel_robot())) == []
    robot = one_wheel_robot()
    del robot["passive_wheels"]
    assert_problem(robot, "base_calculator", "needs fixed passive wheels")


@pytest.mark.slow  # every example robot's layout checked
def test_one_wheel_drive_must_not_stand_on_the_axle():
    assert_problem(one_wheel_robot(drive_x=-0.4), "motor_drives.drive0", "axle line")


def test_one_wheel_calculator_serves_one_steered_drive():
    robot = four_ws()
    robot["base_calculator"] = "pltf_clc_1wd::PltfClc1WD"
    assert_problem(robot, "base_calculator", "exactly one type-0")


class FrontAxleOnly(BaseCalculator):
    """A calculator of another package: it serves robots whose drives all stand ahead of base_link."""

    name = "third_party::FrontAxleOnly"

    @classmethod
    def layout_rules(cls, drives, passive_wheels, axle):
        return [
            Problem(f"motor_drives.{d.name}.x", d.x, "this calculator needs every drive ahead of base_link")
            for d in drives
            if d.x <= 0
        ]


def test_a_third_party_calculator_gets_the_same_checks():
    robot = four_ws()
    robot["base_calculator"] = f"{__name__}:FrontAxleOnly"
    assert_problem(robot, "motor_drives.drive0.x", "ahead of base_link")
    # the shared rules come first, for it as for ours: two fixed wheels on different axle lines
    drives = list(parse_robot_config(four_ws()).drives)
    drives[0] = dataclasses.replace(drives[0], type=1)
    drives[2] = dataclasses.replace(drives[2], type=1, x=-0.3)
    (problem,) = FrontAxleOnly.layout_problems(drives)
    assert problem.path == "motor_drives.drive2" and "share one axle line" in problem.rule
