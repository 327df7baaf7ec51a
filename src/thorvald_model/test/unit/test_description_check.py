"""The generated description normalised and checked: generate_urdf, its command line, the xacro
wrapper model.launch runs, and check_config --model-extras / --tf-prefix."""

import json
import os
import subprocess
import sys
import xml.etree.ElementTree as ET

import pytest
from urdf_helpers import FIGURE5, PKG, structural_differences

from thorvald_model.check_config import main as check_config
from thorvald_model.description import generate_urdf
from thorvald_model.errors import UrdfCheckError

STD = os.path.join(PKG, "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
DATA = os.path.join(PKG, "test", "data")
SLASHED = os.path.join(DATA, "extras_leading_slash.xacro")
MISSING_LINK = os.path.join(DATA, "extras_missing_link.xacro")
FIXED_PREFIX = os.path.join(DATA, "extras_fixed_prefix.xacro")
XACRO = os.path.join(PKG, "urdf", "thorvald_model.xacro")
ENV = dict(os.environ, PYTHONPATH=os.pathsep.join([os.path.join(PKG, "src"), os.environ.get("PYTHONPATH", "")]))
MISSING_LINE = "joint lidar_joint/parent: 'base_lnk': link does not exist (closest: base_link"


def run_module(module, *args):
    return subprocess.run([sys.executable, "-m", module, *args], capture_output=True, text=True, env=ENV, timeout=120)


@pytest.mark.parametrize(
    "tf_prefix, prefix",
    # the extras write /base_link, /thorvald_001/base_link and /thorvald_001//base_link
    [("", ""), ("thorvald_001", "thorvald_001/"), ("thorvald_001/", "thorvald_001/")],
)
def test_extras_written_with_a_leading_slash_attach_to_the_robots_links(tf_prefix, prefix):
    tree = ET.fromstring(generate_urdf(STD, tf_prefix=tf_prefix, model_extras=SLASHED))
    links = [link.get("name") for link in tree.findall("link")]
    assert prefix + "lidar_link" in links
    assert not [n for n in links if n.startswith("/") or "//" in n]
    (joint,) = [j for j in tree.findall("joint") if j.get("name").endswith("lidar_joint")]
    assert joint.find("parent").get("link") == prefix + "base_link"
    assert joint.find("child").get("link") == prefix + "lidar_link"
    # a joint name is no frame: kept as written
    assert joint.get("name") == "/" + (tf_prefix + "/" if tf_prefix else "") + "lidar_joint"
    assert tree.find(f"gazebo[@reference='{prefix}lidar_link']") is not None


@pytest.mark.slow  # a description generated through xacro for every example robot
def test_an_extras_joint_naming_a_missing_link_stops_generation_naming_joint_link_and_closest():
    with pytest.raises(UrdfCheckError) as info:
        generate_urdf(STD, model_extras=MISSING_LINK)
    ((problem),) = info.value.problems
    assert (problem.path, problem.value) == ("joint lidar_joint/parent", "base_lnk")
    assert problem.rule.startswith("link does not exist (closest: base_link")
    assert f"{MISSING_LINK}: {MISSING_LINE}" in str(info.value)


def test_extras_written_for_another_prefix_say_which_link_was_meant():
    # /thorvald_001/base_link is thorvald_001/base_link: no such link in a robot generated without a prefix
    with pytest.raises(UrdfCheckError) as info:
        generate_urdf(STD, model_extras=FIXED_PREFIX)
    rules = {(p.path, p.value): p.rule for p in info.value.problems}
    assert rules[("joint lidar_joint/parent", "thorvald_001/base_link")].startswith(
        "link does not exist (closest: base_link"
    )
    # and with that prefix it is the robot's own base_link
    tree = ET.fromstring(generate_urdf(STD, tf_prefix="thorvald_001", model_extras=FIXED_PREFIX))
    assert tree.find("joint[@name='lidar_joint']/parent").get("link") == "thorvald_001/base_link"


@pytest.mark.slow  # a process per case: the command as a user types it
def test_generate_urdf_cli_prints_the_problems_and_exits_2(tmp_path):
    out = tmp_path / "robot.urdf"
    result = run_module("thorvald_model.generate_urdf", STD, "--extras", MISSING_LINK, "-o", str(out))
    assert result.returncode == 2
    assert result.stdout == "" and "Traceback" not in result.stderr
    assert f"{MISSING_LINK}: {MISSING_LINE}" in result.stderr
    assert not out.exists()


@pytest.mark.slow  # a process per case: the command as a user types it
def test_xacro_wrapper_prints_the_problems_writes_nothing_and_exits_2(tmp_path):
    out = tmp_path / "robot.urdf"
    result = run_module(
        "thorvald_model.xacro_wrapper", XACRO, "robot_config:=" + STD, "model_extras:=" + MISSING_LINK, "-o", str(out)
    )
    assert result.returncode == 2, result.stderr
    assert result.stdout == "" and "Traceback" not in result.stderr
    assert f"{MISSING_LINK}: {MISSING_LINE}" in result.stderr
    assert not out.exists()


@pytest.mark.slow  # a process per case: the command as a user types it
def test_xacro_wrapper_normalises_as_generate_urdf_does():
    result = run_module(
        "thorvald_model.xacro_wrapper", XACRO, "robot_config:=" + STD, "model_extras:=" + SLASHED, "tf_prefix:=r1"
    )
    assert result.returncode == 0, result.stderr
    tree = ET.fromstring(result.stdout.encode())
    assert tree.find("joint[@name='/r1/lidar_joint']/parent").get("link") == "r1/base_link"
    assert structural_differences(tree, ET.fromstring(generate_urdf(STD, tf_prefix="r1", model_extras=SLASHED))) == []


@pytest.mark.slow  # a process per case: the command as a user types it
def test_xacro_wrapper_lists_dependencies_without_checking():
    result = run_module(
        "thorvald_model.xacro_wrapper", "--deps", XACRO, "robot_config:=" + STD, "model_extras:=" + MISSING_LINK
    )
    assert result.returncode == 0, result.stderr
    assert MISSING_LINK in result.stdout.split()


def test_check_config_reports_the_extras_problems_and_exits_2(capsys):
    assert check_config([STD, "--model-extras", MISSING_LINK]) == 2
    assert f"{MISSING_LINK}: {MISSING_LINE}" in capsys.readouterr().err


@pytest.mark.slow  # a description generated through xacro for every example robot
def test_check_config_summarises_the_checked_description(capsys):
    assert check_config([STD, "--model-extras", SLASHED, "--tf-prefix", "thorvald_001/"]) == 0
    out = capsys.readouterr().out
    line = next(line for line in out.splitlines() if line.startswith("  description"))
    links = ET.fromstring(generate_urdf(STD, tf_prefix="thorvald_001/")).findall("link")
    # the robot's links and the lidar's; a tree: one joint fewer than links
    assert (
        line
        == f"  description {len(links) + 1} links, {len(links)} joints, root thorvald_001/base_link, with {SLASHED}"
    )


def test_check_config_tf_prefix_alone_checks_the_description(capsys):
    assert check_config(["--json", FIGURE5, "--tf-prefix", "r1"]) == 0
    (row,) = json.loads(capsys.readouterr().out)
    assert row["description"]["root"] == "r1/base_link"
    assert row["description"]["extras"] == ""


def test_check_config_reports_a_missing_extras_file(tmp_path, capsys):
    assert check_config([STD, "--model-extras", str(tmp_path / "nope.xacro")]) == 2
    err = capsys.readouterr().err
    assert "nope.xacro" in err and STD in err


def test_check_config_without_the_options_does_not_generate(capsys):
    assert check_config([STD]) == 0
    assert "description" not in capsys.readouterr().out
