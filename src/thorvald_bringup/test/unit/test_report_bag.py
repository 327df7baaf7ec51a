"""The odometry report from a real bag (Debian's rosbag): reading it back, and ``odometry_report --bag``."""

import math
import os
import subprocess

import pytest
import rosbag
import rospy
from geometry_msgs.msg import Twist as TwistMsg
from nav_msgs.msg import Odometry
from report_test_helpers import robot, synthetic

from thorvald_base.kinematics import Twist
from thorvald_bringup.odometry_report import ReportError, check_complete
from thorvald_bringup.report_bag import read_recording
from thorvald_msgs.msg import BaseState

LEGS = [(Twist(1.0, 0.0, 0.0), 4.0), (Twist(0.0, 0.8, 0.0), 3.0), (Twist(0.6, 0.0, 0.4), 6.0)]


def odometry_msg(path, i):
    msg = Odometry()
    msg.header.stamp = rospy.Time.from_sec(path.t[i])
    msg.pose.pose.position.x, msg.pose.pose.position.y = path.x[i], path.y[i]
    msg.pose.pose.orientation.z, msg.pose.pose.orientation.w = math.sin(path.yaw[i] / 2), math.cos(path.yaw[i] / 2)
    msg.twist.twist.linear.x, msg.twist.twist.linear.y, msg.twist.twist.angular.z = path.vx[i], path.vy[i], path.wz[i]
    return msg


def write_bag(path, rec, ns="/thorvald_001", skip=(), lose=()):
    """lose: indices of base_state messages published (numbered, header.seq) and never recorded."""
    with rosbag.Bag(str(path), "w") as bag:
        for t, vx, vy, wz in rec.commands:
            msg = TwistMsg()
            msg.linear.x, msg.linear.y, msg.angular.z = vx, vy, wz
            for topic in ("nav_vel", "twist_mux/cmd_vel"):
                if topic not in skip:
                    bag.write(f"{ns}/{topic}", msg, rospy.Time.from_sec(t + (0.001 if "mux" in topic else 0.0)))
        for topic, series in (("odometry/gazebo", rec.truth), ("odometry/base_raw", rec.odometry)):
            if topic not in skip:
                for i in range(len(series)):
                    bag.write(f"{ns}/{topic}", odometry_msg(series, i), rospy.Time.from_sec(series.t[i] + 0.002))
        if "base_state" not in skip:
            for seq, (t, steering, speed) in enumerate(rec.states):
                if seq in lose:
                    continue
                msg = BaseState()
                msg.header.seq = seq
                msg.header.stamp = rospy.Time.from_sec(t)
                msg.steer_pos, msg.prop_speed = list(steering), list(speed)
                msg.prop_pos, msg.steer_speed = [0.0] * len(speed), [0.0] * len(speed)
                bag.write(f"{ns}/base_state", msg, rospy.Time.from_sec(t + 0.001))


@pytest.fixture(scope="module")
def drive():
    return synthetic(robot(), LEGS, wheel_scale=1.01, truth_origin=(3.0, 1.0, 0.5))


@pytest.mark.slow  # a report of a whole recorded drive
def test_a_bag_reads_back_as_the_drive_that_was_recorded(tmp_path, drive):
    write_bag(tmp_path / "drive.bag", drive)
    rec = read_recording(str(tmp_path / "drive.bag"), robot="asym")
    assert rec.source == str(tmp_path / "drive.bag") and rec.robot == "asym"
    # commands: what base_driver got (twist_mux/cmd_vel), at the bag's receive times
    assert [c[1:] for c in rec.commands] == [c[1:] for c in drive.commands]
    assert rec.commands[0][0] == pytest.approx(drive.commands[0][0] + 0.001, abs=1e-6)
    for got, sent in ((rec.truth, drive.truth), (rec.odometry, drive.odometry)):
        assert got.t == pytest.approx(sent.t, abs=1e-6)  # header stamps, not receive times
        for field in ("x", "y", "vx", "vy", "wz"):
            assert getattr(got, field) == pytest.approx(getattr(sent, field), abs=1e-9), field
        assert [math.remainder(a - b, 2 * math.pi) for a, b in zip(got.yaw, sent.yaw)] == pytest.approx(
            [0.0] * len(got), abs=1e-9
        )
    assert [s[1:] for s in rec.states] == [s[1:] for s in drive.states]


@pytest.mark.slow  # a report of a whole recorded drive
def test_a_bag_without_a_needed_topic_is_refused_naming_it(tmp_path, drive):
    write_bag(tmp_path / "no_truth.bag", drive, skip=("odometry/gazebo",))
    with pytest.raises(
        ReportError, match=r"no topic ending in odometry/gazebo \(the bag has: /thorvald_001/base_state"
    ):
        read_recording(str(tmp_path / "no_truth.bag"))
    write_bag(tmp_path / "sent_only.bag", drive, skip=("twist_mux/cmd_vel",))
    assert len(read_recording(str(tmp_path / "sent_only.bag")).commands) == len(drive.commands)  # nav_vel will do
    (tmp_path / "junk.bag").write_bytes(b"not a bag")
    with pytest.raises(ReportError, match=r"junk\.bag: cannot read the bag"):
        read_recording(str(tmp_path / "junk.bag"))


@pytest.mark.slow  # a report of a whole recorded drive
def test_a_recording_that_lost_a_message_the_report_reads_is_refused_naming_it(tmp_path, drive):
    write_bag(tmp_path / "whole.bag", drive)
    check_complete(read_recording(str(tmp_path / "whole.bag")))  # every message, numbered in order
    write_bag(tmp_path / "lost.bag", drive, lose=(40, 41, 97))
    rec = read_recording(str(tmp_path / "lost.bag"))
    with pytest.raises(
        ReportError,
        match=r"lost\.bag: the recording is incomplete \(/thorvald_001/base_state: 3 lost, "
        r"the first seq 40\)",
    ):
        check_complete(rec)
    done = run_report("--bag", str(tmp_path / "lost.bag"), "--out", str(tmp_path / "report"))
    assert done.returncode != 0 and "the recording is incomplete" in done.stderr and "Traceback" not in done.stderr


def run_report(*args):
    return subprocess.run(
        ["rosrun", "thorvald_bringup", "odometry_report", *args], capture_output=True, text=True, timeout=120
    )


@pytest.mark.slow  # a process per case: the command as a user types it
def test_odometry_report_from_a_bag_prints_the_table_and_writes_figures_8_and_9(tmp_path, drive):
    write_bag(tmp_path / "drive.bag", drive)
    out = tmp_path / "report"
    r = run_report("--bag", str(tmp_path / "drive.bag"), "--out", str(out))
    assert r.returncode == 0, r.stderr
    assert "Odometry report: thorvald_ii_6wd6ws_asym" in r.stdout
    error_row = next(line for line in r.stdout.splitlines() if "distance error [%]" in line)
    assert error_row.split()[4:6] == ["+1.00", "+1.00"]  # lsq and paper: the wheels measure 1 % too far
    assert "within 0.0 mm" in r.stdout  # the replayed lsq is base_driver's
    for name in ("figure8_paths.png", "figure9_velocities.png"):
        png = out / name
        assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n" and png.stat().st_size > 20000, name
        assert f"{png}" in r.stdout


@pytest.mark.slow  # a process per case: the command as a user types it
def test_odometry_report_refuses_a_bag_of_another_robot_and_a_bad_robot_with_one_line(tmp_path, drive):
    write_bag(tmp_path / "drive.bag", drive)
    r = run_report("--bag", str(tmp_path / "drive.bag"), "--robot", "thorvald_ii_4wd4ws_std", "--out", str(tmp_path))
    assert r.returncode == 2
    assert len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert r.stderr.strip().endswith(
        "base_state has 6 drives, thorvald_ii_4wd4ws_std has 4: pass the bag's robot with --robot or --robot-model"
    )
    assert "Traceback" not in r.stderr
    r = run_report("--robot", "no_such_robot", "--out", str(tmp_path))
    assert (
        r.returncode == 2
        and "'no_such_robot': no example robot of that name" in r.stderr
        and "Traceback" not in r.stderr
    )
    bad = tmp_path / "bad.yaml"
    bad.write_text("base_calculator: 5\n")
    r = run_report("--robot-model", str(bad), "--bag", str(tmp_path / "drive.bag"), "--out", str(tmp_path))
    assert r.returncode == 2 and str(bad) in r.stderr and "Traceback" not in r.stderr
    assert not os.path.exists(tmp_path / "figure8_paths.png")


@pytest.mark.slow  # a report of a whole recorded drive
def test_odometry_report_refuses_a_calculator_it_cannot_load_as_a_problem_of_the_robot_file(tmp_path, drive, capsys):
    """The bag reads, then the robot's calculator cannot be loaded: the robot file's problem, exit 2."""
    from thorvald_bringup.odometry_report_cli import main  # noqa: PLC0415

    write_bag(tmp_path / "drive.bag", drive)
    with open(robot().source) as f:
        text = f.read()
    assert 'base_calculator: "pltf_clc_std::PltfClcStd"' in text
    bad = tmp_path / "robot.yaml"
    bad.write_text(text.replace('base_calculator: "pltf_clc_std::PltfClcStd"', 'base_calculator: "nowhere::Nothing"'))
    assert main(["--robot-model", str(bad), "--bag", str(tmp_path / "drive.bag"), "--out", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert f"{bad}: base_calculator: 'nowhere::Nothing': must name a calculator plugin: " in err
    assert not os.path.exists(tmp_path / "figure8_paths.png")
