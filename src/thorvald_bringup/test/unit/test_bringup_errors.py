"""thorvald_bringup's errors: one hierarchy in errors.py, the old name importable where it was, and
odometry_report printing each of them as one line with exit status 2."""

import os

import pytest

from thorvald_bringup import errors
from thorvald_bringup.odometry_report import manoeuvre_start
from thorvald_bringup.odometry_report_cli import main
from thorvald_testing.sources import exception_classes

SOURCES = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "src", "thorvald_bringup"))


def test_every_exception_of_the_package_is_in_errors_py():
    elsewhere = {}
    for name in sorted(os.listdir(SOURCES)):
        if name.endswith(".py") and name != "errors.py":
            classes = exception_classes(os.path.join(SOURCES, name))
            if classes:
                elsewhere[name] = sorted(classes)
    assert elsewhere == {}
    assert exception_classes(os.path.join(SOURCES, "errors.py")) == {
        "ThorvaldBringupError",
        "ReportError",
        "UnknownRobot",
        "DriveError",
    }


def test_one_base_class_and_the_old_name_where_it_was():
    from thorvald_bringup.odometry_report import ReportError  # noqa: PLC0415

    assert ReportError is errors.ReportError
    for cls in (errors.ReportError, errors.UnknownRobot, errors.DriveError):
        assert issubclass(cls, errors.ThorvaldBringupError)
    # the built-in classes they were before, for code that catches those
    assert issubclass(errors.ReportError, ValueError) and issubclass(errors.UnknownRobot, LookupError)
    assert issubclass(errors.DriveError, RuntimeError)
    with pytest.raises(errors.ThorvaldBringupError, match="no non-zero velocity command"):
        manoeuvre_start([(0.0, 0.0, 0.0, 0.0)])


def test_odometry_report_says_each_error_in_one_line_and_exits_2(tmp_path, capsys, monkeypatch):
    assert main(["--robot", "no_such_robot", "--out", str(tmp_path)]) == 2
    (line,) = capsys.readouterr().err.splitlines()
    assert line.startswith("odometry_report: no example robot 'no_such_robot'; the examples are: ")
    monkeypatch.setenv("PATH", str(tmp_path))  # no roslaunch: the drive cannot start
    assert main(["--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err == "odometry_report: roslaunch not found: source the workspace's devel/setup.bash\n"
