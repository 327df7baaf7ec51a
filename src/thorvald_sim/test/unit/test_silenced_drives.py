"""Odometry over a drive's silence (issue 45), against a ground truth: the CAN base against the CAN
emulator's motors, and measured drives against the simulator's physics.

Each drive of a steered and of a differential robot is silenced in turn while the robot drives: its
reports stop, its motors still follow commands. Odometry must not integrate the speed it last
reported: it rests on the drives heard, the base stops when the silence reaches the lost timeout (or
at once where the drives heard cannot tell the motion), and odometry's pose stays with ground truth's
over the stop and after the drive is heard again.
"""

import itertools
import math
import os

import can
import pytest

from thorvald_base.bases.can_base import CanBase
from thorvald_base.core import BLIND, BaseDriverCore
from thorvald_base.plugins import load_calculator
from thorvald_model import load_robot_config
from thorvald_sim.can.emulator import CanEmulator
from thorvald_sim.tools.runner import RobotSession, RunOptions

HERE = os.path.dirname(os.path.abspath(__file__))
CONFIGS = os.path.abspath(os.path.join(HERE, "..", "..", "..", "thorvald_model", "config"))
STD = os.path.join(CONFIGS, "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
DIFF = os.path.join(CONFIGS, "thorvald_ii_2wd_diff", "thorvald_ii_2wd_diff.yaml")
CYCLE = 0.02  # [s] base_driver at 50 Hz
SPEED = 0.3  # [m/s], the speed of the report that found the fault
TARGET = 0.01  # [m] odometry's pose against ground truth's over the stop
_channels = itertools.count()


class CanRobot:
    """base_driver's core on the CAN base and the emulated devices on one virtual bus, stepped together
    on one simulated clock. Ground truth: the emulated motors' own speeds (the robot drives straight
    ahead, every wheel along x, so it moves at their mean)."""

    def __init__(self, path):
        self.config = config = load_robot_config(path)
        channel = f"thorvald-unheard-{os.getpid()}-{next(_channels)}"
        bus = can.Bus(interface="virtual", channel=channel, receive_own_messages=False)
        self.emulator = CanEmulator(config, can.Bus(interface="virtual", channel=channel, receive_own_messages=False))
        self.core = BaseDriverCore(config, load_calculator(config), CanBase(config, bus))
        self.channels = [ch for c in self.emulator.controllers.values() for ch in c.channels]
        self.t = self.x = 0.0
        self.result = None

    def drive(self, seconds, speed):
        for _ in range(round(seconds / CYCLE)):
            self.core.set_command(speed, 0.0, 0.0, self.t)
            self.result = self.core.step(self.t)
            for k in range(4):  # the devices run faster than the base's cycle
                self.emulator.step(self.t + k * CYCLE / 4)
                self.x += sum(ch.speed * math.cos(ch.steering) for ch in self.channels) / len(self.channels) * CYCLE / 4
            self.t += CYCLE
        return self.result

    @property
    def error(self):
        return abs(self.result.odometry.pose.x - self.x)

    def close(self):
        self.core.shutdown(self.t)
        self.emulator.drop_bus()


@pytest.mark.parametrize("drive", ["drive0", "drive1", "drive2", "drive3"])
def test_can_a_silent_controller_of_the_standard_robot(drive):
    robot = CanRobot(STD)
    try:
        robot.drive(2.0, SPEED)
        robot.emulator.silence(drive)
        moving = robot.drive(1.0, SPEED)  # within the 2 s lost timeout: the other three drive on
        assert moving.odometry.unheard == (int(drive[-1]),) and moving.stopped_by is None
        assert moving.odometry.twist.vx == pytest.approx(SPEED, abs=0.005)
        stopped = robot.drive(2.0, SPEED)  # lost: every wheel stopped
        assert stopped.odometry.twist.vx == 0.0  # not drive1's 0.3 m/s held, over four: 0.075
        assert robot.error < TARGET
        robot.emulator.resume(drive)
        back = robot.drive(2.0, SPEED)
        assert back.odometry.unheard == () and back.odometry.twist.vx == pytest.approx(SPEED, abs=0.005)
        robot.drive(1.0, 0.0)
        assert robot.error < TARGET
    finally:
        robot.close()


@pytest.mark.parametrize("speed", [0.1, SPEED])
def test_can_the_differential_robots_one_controller(speed):
    """Both wheels are on one controller: silent, nothing measures the motion. The base stops at once
    (at the report timeout, 0.2 s, not at the lost timeout, 2 s), odometry integrates nothing from
    then on, and its error is what nobody could see: the wheels' stop from speed at prp_sim_a (1.5
    m/s^2), v^2 / 2a (3.3 mm from 0.1 m/s, 30 mm from 0.3 m/s), plus the reports' lag of a cycle or
    two at speed. Within TARGET from 0.1 m/s; driving on for 2 s, as before, was 0.6 m from 0.3 m/s."""
    robot = CanRobot(DIFF)
    try:
        robot.drive(2.0, speed)
        robot.emulator.silence("drive0")
        blind = robot.drive(0.3, speed)
        assert blind.stopped_by == BLIND and blind.odometry.blind and blind.odometry.unheard == (0, 1)
        robot.drive(1.0, speed)
        accel = robot.config.drives[0].prp_sim_a
        unseen = speed**2 / (2 * accel) + 2 * CYCLE * speed
        assert robot.error < unseen
        if speed <= 0.1:
            assert robot.error < TARGET
        robot.emulator.resume("drive0")
        back = robot.drive(2.0, speed)
        assert back.stopped_by is None and back.odometry.twist.vx == pytest.approx(speed, abs=0.005)
    finally:
        robot.close()


def session_error(session):
    truth, odometry = session.truth[-1], session.odometry[-1]
    return math.hypot(truth.x - odometry.x, truth.y - odometry.y)


def drive_through_silence(path, twist, drive=None):
    """(odometry's error [m] at rest with the drive silent, at the end) of 3 s on twist, 1.5 s more with
    drive silenced (None: without a fault), 1.5 s with it heard again, and 1.5 s at rest."""
    with RobotSession(path, RunOptions()) as session:
        session.run(3.0, lambda t: twist)
        if drive is not None:
            session.robot.silence(drive)
        session.run(4.5, lambda t: twist)
        if drive is not None:
            heard = [s.heard for s in session.core.handle.read_drive_states(session.time)]
            assert heard == [k != drive for k in range(len(heard))]
            a, b = session.odometry[-10], session.odometry[-1]  # the last quarter second: standing
            assert math.hypot(b.x - a.x, b.y - a.y) < 1e-4
        silent = session_error(session)
        session.robot.silence(drive or 0, False)
        session.run(6.0, lambda t: twist)
        assert session.odometry[-1].x != session.odometry[-40].x  # driving again
        session.run(7.5, lambda t: (0.0, 0.0, 0.0))
        return silent, session_error(session)


@pytest.mark.slow  # seven drives of 7.5 simulated seconds each in pybullet
@pytest.mark.parametrize("path, drives", [(STD, range(4)), (DIFF, range(2))], ids=["std", "diff"])
def test_measured_drives_a_silenced_drive_in_the_simulator(path, drives):
    """The simulator's drive silenced (its encoders report NaN, its motors follow commands) on an arc
    of 1.5 m radius: the standard robot drives on three drives until the silence is 0.5 s old (the
    measured drives' lost timeout), the differential robot stops at once and its one wheel heard gives
    the speed along the commanded arc. Odometry's pose stays within 1 cm of the simulator's over the
    stop, and, heard again, it ends within 1 cm of where the same drive without the fault ends (the
    arc's own slip: about 1.3 cm over its 2.5 m)."""
    arc = (SPEED, 0.0, 0.2)
    _, baseline = drive_through_silence(path, arc)
    for drive in drives:
        silent, end = drive_through_silence(path, arc, drive)
        assert silent < TARGET, f"drive{drive}"
        assert abs(end - baseline) < TARGET, f"drive{drive}"
