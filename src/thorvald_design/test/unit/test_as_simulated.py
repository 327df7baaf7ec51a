"""What a study records to explain a gap between a simulated limit and its prediction, and what the
report draws from: the simulated robot's centre of mass (measured in the simulator), the predictions
of the robot as simulated, standing and rolling, and the tracks files' heights and marks."""

import json
import math
import os
from types import SimpleNamespace

import pytest

from thorvald_design.design import design_of
from thorvald_design.report.tracks import parse_tracks
from thorvald_design.runs import write_tracks
from thorvald_design.scenarios.driving import as_simulated, rolling_offset, simulated_layout
from thorvald_design.scenarios.gradeability import _limits
from thorvald_design.scenarios.kind import Pose
from thorvald_model.description import package_file

TRICYCLE = "thorvald_ii_1wd1ws_rwd"


@pytest.fixture(scope="module")
def tricycle():
    return design_of(TRICYCLE, package_file("config", TRICYCLE, TRICYCLE + ".yaml"))


@pytest.mark.slow  # the statics or the report of every example robot, or a plot
def test_the_simulated_robots_centre_of_mass_is_the_descriptions(tricycle):
    """Measured in the simulator: where the description has it (pybullet's merge of fixed links put it
    3.9 cm higher until the simulator loaded each merged link's mass at its centre)."""
    from thorvald_design.lab import Lab  # noqa: PLC0415 (pybullet)

    lab = Lab(tricycle.robot_file)
    assert lab.centre_of_mass is None
    with lab.session({"ground": {"surface": "tarmac"}}) as session:
        found = session.centre_of_mass
    assert lab.centre_of_mass == found
    assert found == pytest.approx(tricycle.com, abs=1e-4)


def test_the_predictions_of_the_robot_as_simulated(tricycle):
    higher = SimpleNamespace(centre_of_mass=(tricycle.com[0], tricycle.com[1], tricycle.com[2] + 0.0393))
    layout = simulated_layout(tricycle, higher)
    assert layout.height == pytest.approx(tricycle.layout.height + 0.0393)
    assert layout.contacts == tricycle.layout.contacts and layout.mass == tricycle.layout.mass
    found = as_simulated(tricycle, higher, _limits(tricycle, "grass"))
    assert found["com_height_m"] == pytest.approx(0.4988, abs=1e-4)
    assert found["simulated_com_height_m"] == pytest.approx(0.5381, abs=1e-4)
    # atan(d / h): d = 0.138 m behind the centre of mass to the rear edge, h 0.538 m: 14.37 degrees;
    # rolling, d less grass's 12 mm: 13.17
    d = math.tan(math.radians(15.4533)) * 0.4988
    assert found["with_com"]["predicted_climb_deg"] == pytest.approx(math.degrees(math.atan(d / 0.5381)), abs=0.01)
    assert found["with_com_and_rolling"]["predicted_climb_deg"] == pytest.approx(
        math.degrees(math.atan((d - 0.012) / 0.5381)), abs=0.01
    )
    assert found["with_com_and_rolling"]["rolling_offset_m"] == rolling_offset("grass") == 0.012
    assert found["with_com"]["predicted_limited_by"] == "tipping"
    assert as_simulated(tricycle, SimpleNamespace(centre_of_mass=None), _limits(tricycle, "grass")) == {}


def test_a_tracks_file_keeps_heights_attitudes_and_marks_for_the_side_views(tmp_path):
    poses = tuple(Pose(0.05 * k, 0.1 * k, 0.0, 0.01 * k, 0.0, 0.002 * k, 0.0) for k in range(41))
    drive = SimpleNamespace(label="climb 10 deg", outcome="ok", world={"ground": {"surface": "grass"}}, track=poses,
                            marks={"series": "climb", "value": 10.0, "unit": "deg", "section": "along"})  # fmt: skip
    path = str(tmp_path / "tracks" / "gradeability.json")
    write_tracks(path, [drive])
    with open(path, encoding="utf-8") as f:
        data = json.load(f)
    (read,) = parse_tracks(data).drives
    assert len(read.x) == 21  # a pose every 0.1 s
    assert read.z[-1] == pytest.approx(0.4) and read.pitch[-1] == pytest.approx(0.08) and read.roll[-1] == 0.0
    assert read.marks == drive.marks and read.world == drive.world
    assert os.path.isfile(path)
