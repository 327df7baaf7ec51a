"""thorvald_model.examples: a robot as every tool takes it, an example robot's name or a file (pure)."""

import glob
import os

import pytest

from thorvald_model.description import package_file
from thorvald_model.errors import UnknownRobotError
from thorvald_model.examples import closest_robot, example_robot_file, example_robots, names_a_file, robot_file

CONFIGS = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "config")
ON_DISK = sorted(os.path.basename(os.path.dirname(p)) for p in glob.glob(os.path.join(CONFIGS, "*", "*.yaml")))


def test_the_examples_are_the_config_folders_robots():
    assert example_robots() == tuple(ON_DISK)
    assert len(ON_DISK) == 10  # the paper's Figure 5, 7 and 10 (a) to (h)


@pytest.mark.parametrize("name", ON_DISK)
def test_an_examples_name_is_its_file(name):
    assert example_robot_file(name) == package_file("config", name, name + ".yaml")
    assert robot_file(name) == example_robot_file(name)


@pytest.mark.parametrize(
    "value, is_file",
    [("thorvald_ii_4wd4ws_std", False), ("my_robot.yaml", True), ("my_robot.yml", True), ("robots/mine", True),
     ("./mine", True), ("thorvald_ii_4wd4ws_std.yaml", True)],
)  # fmt: skip
def test_a_yaml_suffix_or_a_path_names_a_file(value, is_file):
    assert names_a_file(value) is is_file


def test_a_file_is_found_from_the_base_folder_as_given():
    assert robot_file("robots/mine.yaml", "/studies") == "/studies/robots/mine.yaml"
    assert robot_file("/abs/mine.yaml", "/studies") == "/abs/mine.yaml"
    assert robot_file("~/mine.yaml") == os.path.expanduser("~/mine.yaml")
    # a file is the loader's to find, with the reason: no lookup among the examples
    assert robot_file("thorvald_ii_4wd4ws_std.yaml", "/nowhere") == "/nowhere/thorvald_ii_4wd4ws_std.yaml"


@pytest.mark.parametrize(
    "name, meant",
    [
        ("thorvald_ii_4wd4ws_sdt", "thorvald_ii_4wd4ws_std"),  # a typing mistake
        ("Thorvald_II_4WD4WS_STD", "thorvald_ii_4wd4ws_std"),
        ("4wd4ws_std", "thorvald_ii_4wd4ws_std"),  # the part the tables name them by
        ("std", "thorvald_ii_4wd4ws_std"),
        ("9wd", "thorvald_ii_9wd9ws"),
        ("thorvald_ii_6wd6ws_susb", "thorvald_ii_6wd6ws_susp"),
        ("thorvald_2wd_diff", "thorvald_ii_2wd_diff"),
        ("6wd6ws", None),  # asym or susp: a guess would mislead
        ("thorvald_ii_6wd6ws", None),  # not 9wd9ws, which is closer letter by letter
        ("nine", None),
    ],
)
def test_did_you_mean_names_the_one_example_meant(name, meant):
    assert closest_robot(name, ON_DISK) == meant


def test_an_unknown_name_is_refused_with_did_you_mean_and_the_list():
    with pytest.raises(UnknownRobotError) as e:
        example_robot_file("thorvald_ii_4wd4ws_sdt")
    message = str(e.value)
    assert message.startswith("'thorvald_ii_4wd4ws_sdt': no example robot of that name (did you mean ")
    assert "'thorvald_ii_4wd4ws_std'?); the examples: " + ", ".join(ON_DISK) in message
    assert "a robot file is a path ending in .yaml" in message and "\n" not in message
    assert e.value.rule == message[len("'thorvald_ii_4wd4ws_sdt': ") :] and e.value.name == "thorvald_ii_4wd4ws_sdt"
    assert isinstance(e.value, LookupError)


@pytest.mark.parametrize("name", ["", ".", "..", "config"])
def test_no_name_reaches_outside_an_examples_folder(name):
    with pytest.raises(UnknownRobotError):
        example_robot_file(name)
