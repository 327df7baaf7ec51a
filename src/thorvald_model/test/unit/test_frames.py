"""tf_prefix in both of the original's conventions (reconstruction notes, section 6): the newer
files concatenate ``thorvald_001/``, the older ones pass ``thorvald_001`` and the generator inserted
the slash. Both must name the same frames and joints."""

import os
import subprocess
import sys
import xml.etree.ElementTree as ET

import pytest
from urdf_helpers import PKG

from thorvald_model.description import generate_urdf
from thorvald_model.frames import normalize_tf_prefix

STD = os.path.join(PKG, "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
DIFF = os.path.join(PKG, "config", "thorvald_ii_2wd_diff", "thorvald_ii_2wd_diff.yaml")


@pytest.mark.parametrize(
    "given, expected",
    [
        ("", ""),
        (None, ""),
        ("/", ""),
        ("thorvald_001", "thorvald_001/"),
        ("thorvald_001/", "thorvald_001/"),
        ("/thorvald_001", "thorvald_001/"),
        ("/thorvald_001/", "thorvald_001/"),
        ("fleet/robot_1", "fleet/robot_1/"),
        (" robot_1 ", "robot_1/"),
    ],
)
def test_normalize_tf_prefix(given, expected):
    assert normalize_tf_prefix(given) == expected


def names(urdf):
    tree = ET.fromstring(urdf)
    return sorted(e.get("name") for e in tree if e.tag in ("link", "joint"))


@pytest.mark.slow  # a description generated through xacro for every example robot
@pytest.mark.parametrize("config", [STD, DIFF], ids=["std", "diff"])
def test_both_conventions_give_one_description(config):
    newer = generate_urdf(config, tf_prefix="thorvald_001/", robot_name="thorvald_001")
    older = generate_urdf(config, tf_prefix="thorvald_001", robot_name="thorvald_001")
    assert older == newer
    all_names = names(newer)
    assert "thorvald_001/base_link" in all_names
    assert all(n.startswith("thorvald_001/") and "//" not in n for n in all_names)
    block = ET.fromstring(newer).find("gazebo/plugin")
    assert block.findtext("odometryFrame") == "thorvald_001/odom"
    assert block.findtext("robotBaseFrame") == "thorvald_001/base_link"


@pytest.mark.slow  # a process per case: the command as a user types it
def test_the_xacro_command_takes_the_older_convention(tmp_path):
    """The command users' launch files run (our xacro wrapper) normalises the prefix too."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([os.path.join(PKG, "src"), os.environ.get("PYTHONPATH", "")]))
    out = subprocess.run(
        [
            sys.executable,
            "-m",
            "thorvald_model.xacro_wrapper",
            os.path.join(PKG, "urdf", "thorvald_model.xacro"),
            "robot_config:=" + STD,
            "tf_prefix:=thorvald_001",
            "robot_name:=thorvald_001",
        ],
        capture_output=True,
        text=True,
        env=env,
    )
    assert out.returncode == 0, out.stderr
    assert names(out.stdout) == names(generate_urdf(STD, tf_prefix="thorvald_001/", robot_name="thorvald_001"))
