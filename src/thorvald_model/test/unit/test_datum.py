"""model.launch's datum_file (a robot_localization datum file) reaches the simulator through the
description's simulator block (thorvald_model.datum, the xacro's <datum>, thorvald_sim.physics.description)."""

import math
import os
import xml.etree.ElementTree as ET

import pytest

from thorvald_model.datum import Datum, load_datum, parse_datum
from thorvald_model.description import generate_urdf
from thorvald_model.errors import ConfigError

HERE = os.path.dirname(os.path.abspath(__file__))
STD = os.path.join(HERE, "..", "..", "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")


def test_a_datum_file_in_robot_localizations_format(tmp_path):
    path = tmp_path / "datum.yaml"
    path.write_text("datum: [53.268642, -0.524509, 1.5708, map, base_link]\n")
    datum = load_datum(str(path))
    assert (datum.latitude, datum.longitude, datum.yaw) == (53.268642, -0.524509, 1.5708)
    # ENU yaw 90 degrees (x north) is hector's compass heading 0
    assert datum.compass_heading == pytest.approx(0.0, abs=1e-3)
    assert Datum(0.0, 0.0, 0.0).compass_heading == 90.0


@pytest.mark.parametrize(
    "data, path, rule",
    [
        ({}, "datum", "must be [latitude, longitude, heading]"),
        ({"datum": [1.0, 2.0]}, "datum", "must be [latitude, longitude, heading]"),
        ({"datum": [91.0, 2.0, 0.0]}, "datum[0] (latitude)", "must be in [-90, 90] [deg]"),
        ({"datum": [1.0, "east", 0.0]}, "datum[1] (longitude)", "must be a number"),
        ({"datum": [1.0, 2.0, math.inf]}, "datum[2] (heading)", "must be a number"),
    ],
)
def test_a_bad_datum_names_the_key_and_the_rule(data, path, rule):
    with pytest.raises(ConfigError) as e:
        parse_datum(data, "here.yaml")
    problem = e.value.problems[0]
    assert problem.path == path and rule in problem.rule
    assert "here.yaml" in str(e.value)


def test_the_datum_is_written_into_the_simulator_block(tmp_path):
    path = tmp_path / "datum.yaml"
    path.write_text("datum: [53.268642, -0.524509, 0.0]\naltitude: 12.5\n")
    block = ET.fromstring(generate_urdf(STD, datum_file=str(path))).find("gazebo/plugin/datum")
    values = {k: float(v) for k, v in block.attrib.items()}
    assert values == {"latitude": 53.268642, "longitude": -0.524509, "yaw": 0.0, "altitude": 12.5}
    assert ET.fromstring(generate_urdf(STD)).find("gazebo/plugin/datum") is None


@pytest.mark.slow  # a description generated through xacro
def test_a_broken_datum_file_stops_the_model_with_the_loaders_message(tmp_path):
    path = tmp_path / "datum.yaml"
    path.write_text("datum: [95, 0, 0]\n")
    with pytest.raises(ConfigError) as e:
        generate_urdf(STD, datum_file=str(path))
    assert "datum[0] (latitude)" in str(e.value) and str(path) in str(e.value)
