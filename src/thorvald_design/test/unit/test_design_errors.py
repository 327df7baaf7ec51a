"""thorvald_design's errors: one tree in errors.py (every exception class of the package there:
tests/test_errors.py), what each part of the package refuses raised as its class with its message as
before, no bare ValueError left to reach a user, and the command ending on the package's error with
one line and exit 2."""

import ast
import os

import pytest

from thorvald_design import design_study, errors
from thorvald_design.energy import parallel
from thorvald_design.metrics import fit_circle
from thorvald_design.optimise import grid, pareto_front
from thorvald_design.optimise_spec import Range
from thorvald_design.quasi_static import Contact, Layout
from thorvald_design.report.tracks import parse_tracks
from thorvald_design.scenarios.turning import turn_centre
from thorvald_design.study import Space
from thorvald_model import load_robot_config
from thorvald_model.description import package_file
from thorvald_model.errors import ConfigError

SOURCES = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "src", "thorvald_design"))
TREE = {
    "DesignError",
    "StudyError",
    "ScenarioError",
    "StaticsError",
    "MetricError",
    "EnergyError",
    "SearchError",
    "ReportError",
}
BARE = {"ValueError", "RuntimeError", "TypeError", "Exception"}


def sources():
    for folder, _, files in os.walk(SOURCES):
        for name in sorted(files):
            if name.endswith(".py"):
                yield os.path.join(folder, name)


def test_one_base_class_each_a_value_error_and_a_study_error_a_config_error():
    for name in TREE:
        cls = getattr(errors, name)
        assert issubclass(cls, errors.DesignError) and issubclass(cls, ValueError), name  # except ValueError: still
    assert issubclass(errors.StudyError, ConfigError)  # a study file's problems, as a robot file's


def test_no_bare_error_is_raised():
    """Every raise names the package's class (or re-raises what it caught)."""
    found = []
    for path in sources():
        with open(path, encoding="utf-8") as f:
            tree = ast.parse(f.read(), path)
        for node in ast.walk(tree):
            if isinstance(node, ast.Raise) and isinstance(node.exc, ast.Call):
                name = getattr(node.exc.func, "id", getattr(node.exc.func, "attr", ""))
                if name in BARE:
                    found.append(f"{os.path.relpath(path, SOURCES)}:{node.lineno}: {name}")
    assert found == []


def test_each_part_raises_its_class_with_its_message():
    with pytest.raises(errors.StaticsError, match=r"^the wheel contacts a, b, c lie on one line: "):
        Layout(10.0, (0.0, 0.0, 0.5), tuple(Contact(n, x, 0.0, True, 1.0) for n, x in zip("abc", (0, 1, 2))))
    with pytest.raises(errors.MetricError, match=r"^fit_circle: 2 points; a circle needs at least 3$"):
        fit_circle([0.0, 1.0], [0.0, 1.0])
    with pytest.raises(errors.EnergyError, match=r"^parallel: no batteries$"):
        parallel([])
    with pytest.raises(errors.SearchError, match=r"^optimise: y is a range: no sweep runs every value of it$"):
        grid([("y", Range(0.5, 1.0))])
    with pytest.raises(errors.SearchError, match=r"^directions must be \+1 or -1, not \[2\]$"):
        pareto_front([(1.0,)], (2,))
    with pytest.raises(errors.ReportError, match=r"^track 0 is not a mapping$"):
        parse_tracks({"tracks": ["a"]})
    std = load_robot_config(package_file("config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml"))
    locked = [type(d)(**{**d.__dict__, "str_lim": 0.0}) for d in std.drives]  # every wheel straight ahead
    with pytest.raises(errors.ScenarioError, match=r"^no centre of rotation within .* suits every drive's steering"):
        turn_centre(locked, std.passive_wheels)
    space = Space("wide", "std.yaml", {"motor_drives": {"drive0": {"y": 0.3}}}, "", None, (("motor_drives.drive9.y",
                  (0.5,)),))  # fmt: skip
    with pytest.raises(errors.StudyError) as refused:  # one line, as before: the combination and why
        space.candidate({"motor_drives.drive9.y": 0.5})
    assert str(refused.value).startswith("wide[y=0.5]: wide.motor_drives.drive9.y: the robot file's motor_drives ")


def test_the_command_ends_on_the_packages_error_with_one_line_and_exit_2(tmp_path, monkeypatch, capsys):
    def refused(path):
        raise errors.ReportError("pareto: 'a.b' is not a column of this study's results:\n  a.c")

    monkeypatch.setattr(design_study, "load_study", refused)
    assert design_study.main([str(tmp_path / "study.yaml"), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err == "design_study: pareto: 'a.b' is not a column of this study's results: a.c\n"


def test_a_study_file_that_breaks_its_rules_is_every_problem_and_exit_2(tmp_path, capsys):
    """A Pareto plane of a word (what limited a climb) has no direction to find a front by: refused with
    the file, before a run, where the report refused it after every run."""
    path = tmp_path / "study.yaml"
    path.write_text(
        "candidates: {a: {robot: thorvald_ii_4wd4ws_std}}\n"
        "pareto: [gradeability.limited_by, turning.turning_diameter_m]\n"
        "scenarios: {gradeability: {}, turning: {}}\n"
    )
    assert design_study.main([str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err == (
        f"{path}: invalid design study (1 problem):\n  {path}: pareto[0]: 'gradeability.limited_by': is a metric of "
        "words, not numbers: it has no better direction to plot a front by\n"
    )
    assert not os.path.exists(tmp_path / "out")
