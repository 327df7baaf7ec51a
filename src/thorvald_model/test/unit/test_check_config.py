"""The check_config command-line tool."""

import json
import subprocess

import pytest
import yaml
from model_test_helpers import EXAMPLE_ROBOTS, FIGURE5, four_drives

from thorvald_model.check_config import main


@pytest.fixture
def bad_file(tmp_path):
    drives = four_drives()
    drives["drive1"]["str_lim"] = 5.0
    drives["drive2"]["r_wheel"] = 0
    path = tmp_path / "bad_robot.yaml"
    path.write_text(yaml.safe_dump({"motor_drives": drives}))
    return str(path)


def test_valid_file_prints_a_summary(capsys):
    assert main([FIGURE5]) == 0
    out = capsys.readouterr().out
    assert "valid robot configuration" in out
    assert "4 (4 steered, 4 driven" in out
    assert "track       0.600 m, wheelbase 1.094 m" in out


def test_invalid_file_lists_every_problem_and_exits_2(bad_file, capsys):
    assert main([bad_file]) == 2
    err = capsys.readouterr().err
    assert bad_file + ": motor_drives.drive1.str_lim: 5.0: must be in (0, pi]" in err
    assert bad_file + ": motor_drives.drive2.r_wheel: 0: must be > 0" in err


def test_the_calculators_own_layout_rules_are_checked_too(tmp_path, capsys):
    """Which layouts a calculator serves is the calculator's rule (its plugin declares it): a
    differential calculator on four steered drives is refused as base_driver would refuse it."""
    path = tmp_path / "diff_on_four.yaml"
    path.write_text(
        yaml.safe_dump({"base_calculator": "pltf_clc_2wdiff::PltfClc2WDiff", "motor_drives": four_drives()})
    )
    assert main([str(path)]) == 2
    err = capsys.readouterr().err
    assert f"{path}: base_calculator: 'pltf_clc_2wdiff::PltfClc2WDiff': the differential calculator serves" in err
    path.write_text(yaml.safe_dump({"base_calculator": "nowhere::Nothing", "motor_drives": four_drives()}))
    assert main([str(path)]) == 2
    assert (
        f"{path}: base_calculator: 'nowhere::Nothing': must name a calculator plugin: known calculators are"
        in capsys.readouterr().err
    )


def test_several_files_print_a_table(capsys):
    assert main([FIGURE5, *EXAMPLE_ROBOTS]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].split()[:5] == ["robot", "drives", "steered", "driven", "passive"]
    assert len(lines) == 1 + 1 + len(EXAMPLE_ROBOTS)
    assert lines[1].split()[:5] == ["paper_figure5", "4", "4", "4", "0"]


def test_batteries_count_the_modules_that_hold_one(capsys):
    """The standard robot has two battery modules, the second with with_battery: 0 (an empty
    enclosure): one battery."""
    std = next(p for p in EXAMPLE_ROBOTS if p.endswith("thorvald_ii_4wd4ws_std.yaml"))
    assert main([std]) == 0
    assert "  batteries   1 (in 2 battery modules)" in capsys.readouterr().out.splitlines()
    assert main(["--json", std]) == 0
    (row,) = json.loads(capsys.readouterr().out)
    assert (row["batteries"], row["battery_modules"]) == (1, 2)


def test_json_summary(capsys):
    assert main(["--json", FIGURE5]) == 0
    (row,) = json.loads(capsys.readouterr().out)
    assert row["calculator"] == "pltf_clc_std::PltfClcStd"
    assert (row["drives"], row["steered"], row["passive"]) == (4, 4, 0)


@pytest.mark.slow  # a process per case: the command as a user types it
def test_rosrun_entry_point_exits_2_without_traceback(bad_file):
    proc = subprocess.run(
        ["rosrun", "thorvald_model", "check_config", bad_file], capture_output=True, text=True, timeout=60
    )
    assert proc.returncode == 2
    assert "motor_drives.drive1.str_lim" in proc.stderr
    assert "Traceback" not in proc.stderr
