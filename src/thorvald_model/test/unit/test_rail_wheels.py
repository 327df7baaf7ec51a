"""A drive's flanged rail wheel beside its tyre (paper 3.1: the greenhouse robot's double wheels): the
keys and their rules, and the description's tread and flanges; a robot without one is unchanged."""

import math
import os
import re
import xml.etree.ElementTree as ET
from typing import Dict, List

import pytest
import yaml
from model_test_helpers import PKG, four_drives

from thorvald_model import config_to_dict, load_robot_config, with_drive_param
from thorvald_model.config import RUNTIME_DRIVE_KEYS, parse_robot_config
from thorvald_model.description import generate_urdf
from thorvald_model.errors import ConfigError, Problem
from thorvald_model.values import RAIL_FLANGE_DEPTH, RAIL_FLANGE_WIDTH

# the design studies' greenhouse robot (thorvald_design/studies/robots): not an example robot of the paper's
GREENHOUSE = os.path.join(PKG, "..", "thorvald_design", "studies", "robots", "greenhouse_rails.yaml")
STD = os.path.join(PKG, "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
PIPE_RADIUS = 0.0255  # [m] of a 51 mm greenhouse heating pipe
PIPE_TOP = 0.1 + PIPE_RADIUS  # [m] above the floor: centres at 0.1 m (worlds/greenhouse.yaml)


def railed(r_wheel=0.2, rail_r_wheel=0.15, rail_offset=0.13, **extra) -> Dict:
    """A valid 4WD4WS robot whose every drive has a rail wheel, inboard of its tyre."""
    drives = four_drives()
    for d in drives.values():
        d.update(r_wheel=r_wheel, rail_r_wheel=rail_r_wheel, rail_offset=rail_offset * (1 if d["y"] < 0 else -1))
        d.update(extra)
    return {"base_calculator": "pltf_clc_std::PltfClcStd", "motor_drives": drives}


def problems_of(data) -> List[Problem]:
    with pytest.raises(ConfigError) as e:
        parse_robot_config(data, "robot.yaml")
    return e.value.problems


def problem_at(data, path: str) -> Problem:
    found = [p for p in problems_of(data) if p.path == path]
    assert found, path
    return found[0]


# --- the keys ---------------------------------------------------------------------------------
def test_a_drive_has_no_rail_wheel_unless_its_file_gives_one():
    drive = load_robot_config(STD).drives[0]
    assert (drive.rail_r_wheel, drive.rail_offset, drive.rail_w_wheel) == (0.0, 0.0, 0.06)
    assert not drive.has_rail_wheel and drive.rail_flange_radius == 0.0
    # geometry, not a parameter base_driver may change while it runs (r_wheel is the one it switches)
    assert not {"rail_r_wheel", "rail_w_wheel", "rail_offset"} & set(RUNTIME_DRIVE_KEYS)
    assert "r_wheel" in RUNTIME_DRIVE_KEYS


def test_the_greenhouse_robot_runs_its_rail_wheels_on_pipes_0_55_m_apart():
    config = load_robot_config(GREENHOUSE)
    assert len(config.drives) == 4 and all(d.steerable and d.has_rail_wheel for d in config.drives)
    assert sorted({round(d.y + d.rail_offset, 9) for d in config.drives}) == [-0.275, 0.275]
    for d in config.drives:
        assert abs(d.y) > abs(d.y + d.rail_offset)  # the tyre outboard of its rail wheel
        # on a pipe the tyre clears the floor; on the floor the rail wheel and its flanges clear it
        assert d.r_wheel < PIPE_TOP + d.rail_r_wheel
        assert d.rail_flange_radius < d.r_wheel
        assert d.rail_w_wheel > 2.0 * PIPE_RADIUS  # a pipe fits between the flanges
    # the step onto the pipes: base_link 0.0755 m higher than on the floor
    assert PIPE_TOP + config.drives[0].rail_r_wheel - config.drives[0].r_wheel == pytest.approx(0.0755)


# --- the rules --------------------------------------------------------------------------------
def test_rail_wheels_within_their_rules_load():
    config = parse_robot_config(railed())
    assert [d.rail_r_wheel for d in config.drives] == [0.15] * 4
    assert [d.rail_offset for d in config.drives] == [0.13, 0.13, -0.13, -0.13]


def test_a_negative_rail_wheel_radius_is_refused():
    data = railed()
    data["motor_drives"]["drive0"]["rail_r_wheel"] = -0.1
    assert "must be >= 0" in problem_at(data, "motor_drives.drive0.rail_r_wheel").rule


@pytest.mark.parametrize("rail_r_wheel", [0.19, 0.18, 0.25])
def test_the_rail_wheel_and_its_flanges_are_smaller_than_the_tyre(rail_r_wheel):
    """0 < rail_r_wheel < r_wheel, and by the flanges' depth: the flanges clear the floor on the tyre."""
    problem = problem_at(railed(rail_r_wheel=rail_r_wheel), "motor_drives.drive0.rail_r_wheel")
    assert f"must be < r_wheel - {RAIL_FLANGE_DEPTH:g} = 0.18 m" in problem.rule
    assert parse_robot_config(railed(rail_r_wheel=0.179)).drives[0].rail_flange_radius == 0.199


def test_r_wheel_may_be_the_rail_wheels_while_it_rides_the_rails():
    """base_driver's set_drive_params validates each change as a file: r_wheel = rail_r_wheel is the
    robot on its rails, and back again the robot on the floor."""
    config = parse_robot_config(railed())
    on_rails = with_drive_param(config, 0, "r_wheel", 0.15)
    assert on_rails.drives[0].r_wheel == on_rails.drives[0].rail_r_wheel == 0.15
    assert with_drive_param(on_rails, 0, "r_wheel", 0.2).drives[0].r_wheel == 0.2
    with pytest.raises(ConfigError):  # a tyre smaller than its rail wheel is not that state
        with_drive_param(config, 0, "r_wheel", 0.14)


@pytest.mark.parametrize("offset", [0.0, 0.05, 0.119, -0.119])
def test_the_rail_wheel_stands_beside_the_tyre_not_in_it(offset):
    """|rail_offset| >= w_wheel / 2 + rail_w_wheel / 2 + the flange's width = 0.08 + 0.03 + 0.01."""
    data = railed()
    data["motor_drives"]["drive1"]["rail_offset"] = offset
    problem = problem_at(data, "motor_drives.drive1.rail_offset")
    assert "must be at least 0.12 m either way" in problem.rule and "beside the tyre" in problem.rule
    data["motor_drives"]["drive1"]["rail_offset"] = -0.12  # outboard of the tyre is allowed too
    assert parse_robot_config(data).drives[1].rail_offset == -0.12


def test_a_drive_without_a_rail_wheel_has_no_rail_offset():
    data = {"base_calculator": "pltf_clc_std::PltfClcStd", "motor_drives": four_drives()}
    data["motor_drives"]["drive2"]["rail_offset"] = 0.13
    assert "no rail wheel" in problem_at(data, "motor_drives.drive2.rail_offset").rule


def test_steered_rail_wheels_must_not_hit_each_other_as_they_turn():
    """The tyres alone reach hypot(0.2, 0.08) = 0.215 m as they turn, 0.431 m for two: 0.45 m apart
    they pass. A rail wheel 0.13 m beside each reaches hypot(0.17, 0.13 + 0.04) = 0.240 m."""
    plain = {"base_calculator": "pltf_clc_std::PltfClcStd", "motor_drives": four_drives()}
    data = railed()
    for robot in (plain, data):
        robot["motor_drives"]["drive1"]["x"] = robot["motor_drives"]["drive0"]["x"] + 0.45
    parse_robot_config(plain)
    problem = problem_at(data, "motor_drives.drive1")
    reach = 2.0 * math.hypot(0.17, 0.17)
    assert f"less than the {reach:.3f} m their footprints reach" in problem.rule


def test_the_rail_keys_round_trip_through_the_files_format():
    config = load_robot_config(GREENHOUSE)
    again = parse_robot_config(yaml.safe_load(yaml.safe_dump(config_to_dict(config))), config.source)
    assert again == config


# --- the description --------------------------------------------------------------------------
def wheel_link(urdf: str, n: int) -> ET.Element:
    root = ET.fromstring(urdf)
    return next(link for link in root.findall("link") if link.get("name") == f"wheel{n}_link")


def cylinders(link: ET.Element, kind: str) -> List[Dict]:
    """Each visual or collision cylinder of a link: its name, radius, length and y along the axle."""
    out = []
    for element in link.findall(kind):
        cylinder = element.find("geometry/cylinder")
        if cylinder is not None:
            xyz = [float(v) for v in element.find("origin").get("xyz").split()]
            rpy = [float(v) for v in element.find("origin").get("rpy").split()]
            assert rpy == pytest.approx([math.pi / 2.0, 0.0, 0.0])  # along the wheel's axle, the link's y
            out.append(
                {
                    "name": element.get("name"),
                    "r": float(cylinder.get("radius")),
                    "h": float(cylinder.get("length")),
                    "y": xyz[1],
                }
            )
    return out


def test_the_wheel_link_carries_the_rail_wheels_tread_between_two_flanges():
    config = load_robot_config(GREENHOUSE)
    urdf = generate_urdf(GREENHOUSE)
    for n, d in enumerate(config.drives):
        link = wheel_link(urdf, n)
        collisions = cylinders(link, "collision")
        tyre, hub, tread, *flanges = collisions
        assert (tyre["name"], tyre["r"], tyre["h"], tyre["y"]) == (None, 0.2, 0.16, 0.0)
        assert hub["name"] is None and hub["r"] < d.rail_r_wheel
        assert (tread["name"], tread["r"], tread["h"], tread["y"]) == ("rail_tread", 0.15, 0.06, d.rail_offset)
        assert [f["name"] for f in flanges] == ["rail_flange", "rail_flange"]
        assert all(f["r"] == 0.17 and f["h"] == RAIL_FLANGE_WIDTH for f in flanges)
        inner = sorted(abs(f["y"] - d.rail_offset) - f["h"] / 2.0 for f in flanges)
        assert inner == pytest.approx([0.03, 0.03])  # the tread's edges: a 51 mm pipe fits between them
        assert 2.0 * inner[0] > 2.0 * PIPE_RADIUS
        # nothing of the rail wheel within the tyre's width
        assert min(abs(c["y"]) - c["h"] / 2.0 for c in (tread, *flanges)) >= d.w_wheel / 2.0
        # the visuals draw the same discs
        assert [(c["r"], c["h"], c["y"]) for c in cylinders(link, "visual")] == [
            (c["r"], c["h"], c["y"]) for c in collisions
        ]


@pytest.mark.slow  # a description generated through xacro for every example robot
def test_a_robot_without_rail_wheels_is_described_as_before(tmp_path):
    """Rail keys at their defaults, written out or not, change nothing of the description (the
    goldens of test_urdf.py hold every example robot to it)."""
    with open(STD) as f:
        data = yaml.safe_load(f)
    for d in data["motor_drives"].values():
        d.update(rail_r_wheel=0.0, rail_w_wheel=0.06, rail_offset=0.0)
    written = tmp_path / "thorvald_ii_4wd4ws_std.yaml"
    written.write_text(yaml.safe_dump(data))
    urdf = without_comments(generate_urdf(STD))
    assert without_comments(generate_urdf(str(written))) == urdf
    assert "rail_" not in urdf


def without_comments(urdf: str) -> str:
    """The description without its comments (xacro's banner names the file it was made from)."""
    return re.sub(r"<!--.*?-->", "", urdf, flags=re.DOTALL)
