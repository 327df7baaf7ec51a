"""check_world: checks world files (paths or shipped names) without the simulator, as a command."""

import json
import os
import shutil
import subprocess
import sys

import pytest
import yaml

from thorvald_sim.tools.check_world import plant_count
from thorvald_sim.world import load_world, resolve_world, shipped_worlds

WORLD = {
    "description": "two patches' worth of test",
    "patches": {"patch0": {"x": 2, "y": 3, "size_x": 2, "size_y": 1, "lateral_friction": 0.5}},
    "rows": {"row0": {"x": 0, "y": 0, "count": 3, "spacing": 1, "length": 4, "plant_spacing": 1}},
    "walls": {"wall0": {"x": 10, "y": 0, "length": 4}},
}


def check_world(*args):
    """(exit status, stdout, stderr) of ``python -m thorvald_sim.tools.check_world args``."""
    run = subprocess.run(
        [sys.executable, "-m", "thorvald_sim.tools.check_world", *args], capture_output=True, text=True, timeout=120
    )
    return run.returncode, run.stdout, run.stderr


def write(tmp_path, name, data):
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data))
    return str(path)


@pytest.mark.slow  # a process per case: the command as a user types it
def test_a_valid_world_is_summarised(tmp_path):
    path = write(tmp_path, "ok.yaml", WORLD)
    status, out, err = check_world(path)
    assert (status, err) == (0, "")
    # plants: 3 rows of 5 (0 .. 4 m every 1 m). Extent: the rows' plants reach their radius (0.1 m)
    # beyond the rows (x -0.1 .. 4.1, y -0.1 .. 2.1), the patch y 2.5 .. 3.5, the wall x 8 .. 12
    assert out.splitlines() == [
        f"{path}: valid world",
        "  two patches' worth of test",
        "  elements  1 patch, 1 rows entry (3 rows), 1 wall",
        "  plants    15",
        "  extent    x -0.10 .. 12.00 m, y -0.10 .. 3.50 m (12.1 x 3.6 m)",
    ]


@pytest.mark.slow  # a process per case: the command as a user types it
def test_an_invalid_world_prints_every_problem_on_stderr_and_exits_2(tmp_path):
    bad = {"patches": {"patch0": {"x": 2e4, "y": 0, "size_x": 0, "size_y": 1, "lateral_friction": 0.5}}}
    bad["walls"] = {"wall0": {"x": 0, "y": 0, "length": 1e9}}
    path = write(tmp_path, "bad.yaml", bad)
    status, out, err = check_world(path)
    assert (status, out) == (2, "")
    assert err.splitlines() == [
        f"{path}: invalid world (3 problems):",
        # in the file's order (safe_dump sorts the keys)
        f"  {path}: patches.patch0.size_x: 0: must be in (0, 10000] [m]",
        f"  {path}: patches.patch0.x: 20000.0: must be in [-10000, 10000] [m]",
        f"  {path}: walls.wall0.length: 1000000000.0: must be in (0, 10000] [m]",
    ]


@pytest.mark.slow  # a process per case: the command as a user types it
def test_a_world_over_a_budget_is_refused_by_the_command_at_once(tmp_path):
    rows = {f"row{i}": {"x": 0, "y": i, "length": 999, "plant_spacing": 1} for i in range(100)}
    path = write(tmp_path, "many.yaml", {"rows": rows})
    status, out, err = check_world(path)
    assert (status, out) == (2, "") and "Traceback" not in err
    assert "rows.row0.plant_spacing: 1: makes 100000 plants over the world's rows and polytunnels" in err


@pytest.mark.slow  # a process per case: the command as a user types it
def test_a_shipped_world_by_name_through_rosrun():
    if shutil.which("rosrun") is None:
        pytest.fail("rosrun is not on the PATH: source the workspace's devel/setup.bash")
    run = subprocess.run(["rosrun", "thorvald_sim", "check_world", "crop_rows"], capture_output=True, text=True)
    assert (run.returncode, run.stderr) == (0, "")
    world = load_world(resolve_world("crop_rows"))
    lines = run.stdout.splitlines()
    assert lines[0] == f"{world.source}: valid world"
    assert os.path.samefile(world.source, os.path.join(os.path.dirname(world.source), "crop_rows.yaml"))
    assert "  elements  3 objects, 2 rows entries (17 rows)" in lines
    assert f"  plants    {plant_count(world)}" in lines
    # 11 lettuce rows (1 to 5 % gaps) of 115 places and 6 maize rows of 201 (8 %)
    assert 2150 < plant_count(world) < 2471


@pytest.mark.slow  # a process per case: the command as a user types it
def test_several_files_make_a_table_and_count_the_invalid_ones(tmp_path):
    status, out, err = check_world("flat", "polytunnel", write(tmp_path, "ok.yaml", WORLD), "no_such_world")
    assert status == 2
    lines = out.splitlines()
    assert lines[0].split() == ["world", "elements", "plants", "extent"]
    assert [line.split()[1:3] for line in lines[1:]] == [["0", "0"], ["5", "1504"], ["3", "15"]]
    assert err.splitlines() == [
        "no_such_world: no such world: give a file or one of " + ", ".join(shipped_worlds()),
        "1 of 4 file(s) invalid",
    ]


@pytest.mark.slow  # a process per case: the command as a user types it
def test_json_summaries():
    status, out, _ = check_world("--json", "polytunnel", "vineyard")
    assert status == 0
    polytunnel, vineyard = json.loads(out)
    assert polytunnel["elements"]["polytunnels"] == 2 and polytunnel["plants"] == 1504
    # 2 tunnels x 4 tables of 188 strawberries (47 m every 0.25 m)
    assert polytunnel["plants"] == 2 * 4 * 188
    assert vineyard["height_field"] == [71, 37]  # the image's pixels
    assert vineyard["extent"] == [-10.0, -18.0, 60.0, 18.0]  # the field: 70 x 36 m about (25, 0)


@pytest.mark.slow  # a process per case: the command as a user types it
def test_the_command_needs_no_pybullet():
    probe = (
        "import sys; from thorvald_sim.tools.check_world import main; status = main(['vineyard', 'crop_rows']); "
        "print(status, 'pybullet' in sys.modules)"
    )
    run = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=120)
    assert run.stdout.splitlines()[-1] == "0 False"


GAZEBO_WORLD = """<?xml version="1.0"?>
<sdf version="1.6">
  <world name="yard">
    <include><uri>model://sun</uri></include>
    <include><uri>model://ground_plane</uri></include>
    <light type="point" name="lamp"><pose>0 0 3 0 0 0</pose></light>
    <model name="post">
      <static>true</static>
      <pose>2 1 0.5 0 0 0</pose>
      <link name="link"><collision name="c"><geometry><box><size>0.1 0.1 1</size></box></geometry></collision></link>
    </model>
    <model name="crate">
      <pose>-2 0 0.2 0 0 0</pose>
      <link name="link"><collision name="c"><geometry><box><size>0.4 0.4 0.4</size></box></geometry></collision></link>
    </model>
    {extra}
  </world>
</sdf>
"""


@pytest.mark.slow  # a process per case: the command as a user types it
def test_a_gazebo_world_is_checked_as_ours(tmp_path, monkeypatch):
    monkeypatch.setenv("HOME", str(tmp_path))  # no ~/.gazebo/models of this machine's
    monkeypatch.delenv("GAZEBO_MODEL_PATH", raising=False)
    path = tmp_path / "yard.world"
    path.write_text(GAZEBO_WORLD.format(extra=""))
    status, out, err = check_world(str(path))
    assert (status, err) == (0, "")
    lines = out.splitlines()
    assert lines[:2] == [f"{path}: valid world", "  Gazebo world 'yard' (yard.world)"]
    assert "  models    2 (1 static, 1 dynamic), actors 0" in lines
    left_out = [line for line in lines if line.startswith("  left out  ")]
    assert any("light 'lamp'" in line and "not simulated" in line for line in left_out), left_out
    assert any("'ground_plane'" in line and "taken as the ground" in line for line in left_out), left_out
    # every problem at once, each with its line and element path; a missing model names where it looked
    path.write_text(
        GAZEBO_WORLD.format(
            extra="<include><uri>model://crop</uri></include>\n"
            "    <model name='bad'><link name='l'><collision name='c'><geometry><box><size>1 -1 1</size>"
            "</box></geometry></collision></link></model>"
        )
    )
    status, out, err = check_world(str(path))
    assert (status, out) == (2, "")
    problems = err.splitlines()
    assert problems[0] == f"{path}: invalid Gazebo world (2 problems):"
    assert "line 16: world 'yard' > include" in problems[1] and "model://crop not found" in problems[1]
    assert "GAZEBO_MODEL_PATH is not set" in problems[1]
    assert "line 17: world 'yard' > model 'bad'" in problems[2] and "size" in problems[2]
