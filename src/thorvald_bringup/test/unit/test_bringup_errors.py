"""thorvald_bringup's errors: one hierarchy in errors.py (every exception class of the package there:
tests/test_errors.py), the old name importable where it was, and odometry_report printing each of
them as one line with exit status 2."""

import pytest

from thorvald_bringup import errors
from thorvald_bringup.odometry_report import manoeuvre_start
from thorvald_bringup.odometry_report_cli import main


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
    assert line.startswith("odometry_report: --robot 'no_such_robot': no example robot of that name; the examples: ")
    assert main(["--robot", "thorvald_ii_4wd4ws_sdt", "--out", str(tmp_path)]) == 2
    assert "(did you mean 'thorvald_ii_4wd4ws_std'?)" in capsys.readouterr().err
    monkeypatch.setenv("PATH", str(tmp_path))  # no roslaunch: the drive cannot start
    assert main(["--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err == "odometry_report: roslaunch not found: source the workspace's devel/setup.bash\n"


def test_a_broken_lockstep_is_found_in_the_launch_log_and_said(capsys):
    """The warnings of the simulator and base_driver when they stop waiting in lockstep (rosconsole's
    colours and all) are what the report lists; base_driver's ordinary end of the stamped stream, when
    the drive leaves, is not a break."""
    from thorvald_base.stamped_commands import LOCKSTEP_BROKEN  # noqa: PLC0415
    from thorvald_bringup.odometry_report_cli import lockstep_breaks, warn_lockstep_breaks  # noqa: PLC0415

    log = "\n".join(
        [
            "[INFO] [1795754010.243808, 0.000000]: verification_drive: /simulator/unpause called: the drive runs",
            f"\x1b[33m[ WARN] [1795754012.264766, 0.050000]: simulator: thorvald_001 did not answer its drive states "
            f"for 2.0 s: going on without it ({LOCKSTEP_BROKEN}; it joins lockstep again with its next command)\x1b[0m",
            f"[WARN] [1795754012.269263, 0.062500]: base_driver: cmd_vel_stamped: no command stamped after 0.050 s "
            f"came (waited 2 s; {LOCKSTEP_BROKEN}): following cmd_vel",
            "[WARN] [1795754069.634023, 96.300000]: base_driver: cmd_vel_stamped: no command stamped after 96.300 s "
            "came (its source left): following cmd_vel",
        ]
    )
    breaks = lockstep_breaks(log)
    assert len(breaks) == 2
    assert breaks[0].startswith("[ WARN] [1795754012.264766, 0.050000]: simulator: thorvald_001 did not answer")
    assert breaks[1].endswith(f"(waited 2 s; {LOCKSTEP_BROKEN}): following cmd_vel")
    warn_lockstep_breaks(breaks, "/tmp/x_launch.log")
    err = capsys.readouterr().err
    assert err.startswith("WARNING: the lockstep was broken, so this run may not repeat (see /tmp/x_launch.log):")
    assert err.count("\n  | ") == 2
    assert lockstep_breaks(log.splitlines()[0] + "\n" + log.splitlines()[-1]) == []
    warn_lockstep_breaks([], "/tmp/x_launch.log")
    assert capsys.readouterr().err == ""
