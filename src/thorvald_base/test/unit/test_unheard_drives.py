"""Odometry with drives unheard (issue 45): a drive whose reports stopped contributes no held speed.

The estimate comes from the drives heard where they determine the motion (degraded), else it is blind:
the base stops at once, and the heard drives' speed along the last commanded motion (or nothing) is
all odometry integrates. Every expected number is derived in a comment.
"""

import math

import pytest
from base_test_helpers import EXAMPLE_ROBOTS, diff, four_wd_two_ws, four_ws

from thorvald_base.bases import BaseHandle, MeasuredDrive
from thorvald_base.bases.simulated_joints import SimulatedJointsBase
from thorvald_base.core import BLIND, BLIND_VARIANCE, DEFAULT_TWIST_COVARIANCE, BaseDriverCore, PoseCovariance
from thorvald_base.diagnostics import ERROR, OK, WARN, OdometryWatch, base_statuses
from thorvald_base.kinematics import DriveCommand, DriveState, OdometryResult, PltfClc2WDiff, PltfClcStd, Pose, Twist
from thorvald_base.modes import MODE_LOST_CONNECTION, MODE_ONLINE
from thorvald_base.plugins import load_calculator
from thorvald_model import load_robot_config


def states_for(calc, twist, unheard=(), held=None):
    """The drive states of a rigid body moving with twist, drives in unheard reporting held instead."""
    out = []
    for k, (x, y) in enumerate(zip(calc.layout.x, calc.layout.y)):
        vx, vy = twist.vx - twist.wz * y, twist.vy + twist.wz * x
        if not calc.layout.steerable[k]:
            out.append(DriveState(0.0, vx))
        else:
            out.append(DriveState(math.atan2(vy, vx), math.hypot(vx, vy)))
        if k in unheard:
            out[-1] = held if held is not None else DriveState(0.0, 0.3, 0.0, heard=False)
    return out


ARC = Twist(0.4, 0.1, 0.3)


@pytest.mark.parametrize("k", range(4))
def test_three_drives_of_four_give_the_motion_exactly(k):
    """Two steered drives determine a rigid body's twist; three fit it exactly (no residual), whatever
    the unheard one last said (0.3 m/s straight ahead here, which would pull the mean)."""
    calc = PltfClcStd.from_config(four_ws())
    calc.calculate_odometry(states_for(calc, ARC), 0.0)
    result = calc.calculate_odometry(states_for(calc, ARC, unheard=(k,)), 0.1)
    assert result.unheard == (k,) and not result.blind and result.degraded
    assert result.twist.is_close(ARC, 1e-12) and result.residual < 1e-12
    assert calc.determines_motion((k,)) and calc.determines_motion((k, (k + 1) % 4))
    assert not calc.determines_motion((0, 1, 2))  # one steered drive cannot tell the turn's centre


def test_the_fixed_axle_still_holds_when_its_drive_is_unheard():
    """The 4WD2WS robot: its type-1 drives (2, 3) cannot slide sideways whether they are heard or not,
    so the two steered front drives give the twist, its lateral speed at the rear axle zero."""
    config = four_wd_two_ws()
    calc = PltfClcStd.from_config(config)
    turn = Twist(0.5, 0.5 * 0.3, 0.3)  # no speed across the axle x = -0.5: vy + wz * -0.5 = 0
    result = calc.calculate_odometry(states_for(calc, turn, unheard=(2, 3)), 0.0)
    assert result.twist.is_close(turn, 1e-12) and not result.blind
    # one front drive and one rear drive: the front wheel's two components and the axle's rule
    assert calc.determines_motion((1, 3))
    # the rear drives alone: speeds along x at two y give vx and wz, the axle gives vy
    assert calc.determines_motion((0, 1))


def test_one_wheel_of_a_differential_robot_is_blind_and_scaled_along_the_command():
    """v_left = vx - wz y_left alone cannot give vx and wz apart: blind. Commanded (0.3, 0, 0.2) and
    stopping at half speed, the right wheel (y = 0.3) reads 0.15 - 0.1 * 0.3 = 0.12 m/s: the motion
    along the command that gives it is half the command, (0.15, 0, 0.1)."""
    calc = PltfClc2WDiff.from_config(diff())
    calc.calculate_command(Twist(0.3, 0.0, 0.2))
    half = Twist(0.15, 0.0, 0.1)
    result = calc.calculate_odometry(states_for(calc, half, unheard=(0,)), 0.0)
    assert result.blind and result.unheard == (0,)
    assert result.twist.is_close(half, 1e-12)
    assert not calc.determines_motion((0,)) and not calc.determines_motion((1,))
    # nothing heard: no motion is integrated, whatever was commanded
    none = calc.calculate_odometry(states_for(calc, half, unheard=(0, 1)), 0.1)
    assert none.blind and none.twist == Twist() and none.pose == result.pose


def test_blind_before_any_motion_was_commanded_is_zero():
    calc = PltfClc2WDiff.from_config(diff())
    result = calc.calculate_odometry(states_for(calc, Twist(0.2, 0.0, 0.0), unheard=(1,)), 0.0)
    assert result.blind and result.twist == Twist()


def test_a_state_without_a_number_is_unheard():
    calc = PltfClcStd.from_config(four_ws())
    nan = DriveState(math.nan, math.nan)
    result = calc.calculate_odometry(states_for(calc, ARC, unheard=(2,), held=nan), 0.0)
    assert result.valid and result.unheard == (2,) and result.twist.is_close(ARC, 1e-12)


@pytest.mark.parametrize("path", EXAMPLE_ROBOTS, ids=lambda p: p.rsplit("/", 1)[-1])
def test_every_example_robot_says_which_single_drive_it_can_lose(path):
    """A robot with two or more steered drives keeps its odometry without any one of them; one with a
    single steered drive (the tricycles) or two type-1 drives (the differential robot) does not."""
    config = load_robot_config(path)
    calc = load_calculator(config)
    steered = sum(1 for d in config.drives if d.steerable)
    for k in range(len(config.drives)):
        if steered >= 3 or (steered == 2 and not config.drives[k].steerable):
            assert calc.determines_motion((k,)), f"{config.drives[k].name} of {path}"
        if len(config.drives) <= 2:
            assert not calc.determines_motion((k,))


class Scripted(BaseHandle):
    """Drives that report what the test says: every drive follows its command at once, the unheard
    ones report their last heard state, marked."""

    def __init__(self, config):
        super().__init__(config)
        self.unheard = set()
        self.sent = []
        self.states = [MeasuredDrive(0.0, 0.0, 0.0, 0.0)] * len(config.drives)

    def _send_drive_commands(self, commands, time):
        self.sent.append(commands)
        fresh = [MeasuredDrive(c.steering, c.speed, 0.0, 0.0) for c in commands]
        self.states = [
            MeasuredDrive(old.steering, old.speed, 0.0, 0.0, heard=False) if k in self.unheard else new
            for k, (old, new) in enumerate(zip(self.states, fresh))
        ]

    def _read_drive_states(self, time):
        return list(self.states)

    def _home_steering(self):
        return ""

    def _set_params(self, config):
        pass


def test_the_base_stops_at_once_when_blind_and_drives_on_when_degraded():
    handle = Scripted(diff())
    core = BaseDriverCore(handle.config, PltfClc2WDiff.from_config(handle.config), handle)
    core.set_command(0.3, 0.0, 0.0, 0.0)
    assert core.step(0.0).stopped_by is None and handle.sent[-1][0].speed == pytest.approx(0.3)
    handle.unheard = {1}
    core.set_command(0.3, 0.0, 0.0, 0.02)
    core.step(0.02)  # the cycle that finds drive1 unheard after sending: odometry blind
    result = core.step(0.04)
    assert result.stopped_by == BLIND and all(c.speed == 0.0 for c in handle.sent[-1])
    handle.unheard = set()
    core.set_command(0.3, 0.0, 0.0, 0.06)
    core.step(0.06)  # the stop's states, heard again
    core.set_command(0.3, 0.0, 0.0, 0.08)
    assert core.step(0.08).stopped_by is None and handle.sent[-1][1].speed == pytest.approx(0.3)

    handle = Scripted(four_ws())
    core = BaseDriverCore(handle.config, PltfClcStd.from_config(handle.config), handle)
    handle.unheard = {2}
    for t in (0.0, 0.02, 0.04):
        core.set_command(0.3, 0.0, 0.0, t)
        result = core.step(t)
    assert result.stopped_by is None and result.odometry.degraded and not result.odometry.blind
    assert all(c.speed == pytest.approx(0.3) for c in handle.sent[-1])


def test_the_covariance_says_how_much_the_estimate_rests_on():
    cov = PoseCovariance(DEFAULT_TWIST_COVARIANCE, drives=4)
    still = Twist()
    whole = OdometryResult(still, Pose(), 0.0, 0.02)
    cov.update(whole)
    assert cov.current_twist == DEFAULT_TWIST_COVARIANCE and cov.pose == DEFAULT_TWIST_COVARIANCE  # standing
    three = OdometryResult(still, Pose(), 0.0, 0.02, unheard=(1,))
    cov.update(three)
    # a mean over three wheels instead of four: 4/3 of each variance
    assert cov.current_twist[0] == pytest.approx(0.001 * 4 / 3) and cov.current_twist[35] == pytest.approx(0.04)
    blind = OdometryResult(still, Pose(), 0.0, 0.5, unheard=(0, 1, 2, 3), blind=True)
    cov.update(blind)
    assert [cov.current_twist[k] for k in (0, 7, 35)] == [BLIND_VARIANCE] * 3
    # blind, the pose is unknown even when the estimate stands: it grows by BLIND_VARIANCE per second
    assert cov.pose[0] == pytest.approx(0.001 + BLIND_VARIANCE * 0.5)


def test_diagnostics_and_the_log_say_what_odometry_rests_on():
    names = ["drive0", "drive1", "drive2", "drive3"]
    statuses = base_statuses("", [], [], {}, odometry=OdometryResult(Twist(), Pose(), 0.0, 0.0), drive_names=names)
    assert [(s.name, s.level, s.message) for s in statuses] == [("base_driver: odometry", OK, "from every drive")]
    degraded = OdometryResult(Twist(), Pose(), 0.0, 0.0, unheard=(1,))
    (status,) = base_statuses("r1", [], [], {}, odometry=degraded, drive_names=names)
    assert status.level == WARN and status.message == "degraded: from 3 of 4 drives (drive1 unheard)"
    assert dict(status.values)["drives heard"] == "3 of 4"
    blind = OdometryResult(Twist(), Pose(), 0.0, 0.0, unheard=(0, 1, 2, 3), blind=True)
    (status,) = base_statuses("r1", [], [], {}, odometry=blind, drive_names=names)
    assert status.level == ERROR and status.message == (
        "blind (drive0, drive1, drive2, drive3 unheard): the wheels are stopped; "
        "no drive heard: zero twist, the pose held"
    )
    one = OdometryResult(Twist(), Pose(), 0.0, 0.0, unheard=(1,), blind=True)
    (status,) = base_statuses("r1", [], [], {}, odometry=one, drive_names=["drive0", "drive1"])
    assert status.message == (
        "blind (drive1 unheard): the wheels are stopped; the estimate is the 1 heard drive(s)' speed along the last "
        "commanded motion"
    )

    watch = OdometryWatch(names)
    starting = OdometryResult(Twist(), Pose(), 0.0, 0.0, unheard=(0, 1, 2, 3), blind=True)
    assert watch.change(starting) is None  # as it starts, before anything was heard: nothing to say
    assert watch.change(OdometryResult(Twist(), Pose(), 0.0, 0.0)) is None
    level, line = watch.change(degraded)
    assert level == WARN and line == "odometry degraded: from 3 of 4 drives (drive1 unheard)"
    assert watch.change(degraded) is None  # said once
    assert watch.change(OdometryResult(Twist(), Pose(), 0.0, 0.0)) == (OK, "odometry from every drive again")


def test_measured_drives_a_silenced_drive_is_unheard_at_once_and_lost_after_the_timeout():
    """simulated_joints: a drive reported as NaN keeps its last values, unheard; silent for longer than
    stale_after (0.5 s) it is lost: every wheel gets zero speed and its controller reads lost."""
    config = four_ws()
    sent = []
    handle = SimulatedJointsBase(config, lambda commands, time: sent.append(commands), stale_after=0.5)
    moving = [MeasuredDrive(0.0, 0.3, 1.0, 0.0)] * 4
    handle.update(moving, 0.0)
    silent = [*moving[:2], MeasuredDrive(math.nan, math.nan, math.nan, math.nan), moving[3]]
    handle.update(silent, 0.1)
    states = handle.read_drive_states(0.1)
    assert [s.heard for s in states] == [True, True, False, True]
    assert states[2].speed == 0.3  # held, marked
    handle.send_drive_commands([DriveCommand(0.0, 0.3)] * 4, 0.1)
    assert all(c.speed == 0.3 for c in sent[-1])  # not lost yet
    handle.update(silent, 0.6)
    handle.send_drive_commands([DriveCommand(0.0, 0.3)] * 4, 0.6)
    assert all(c.speed == 0.0 for c in sent[-1]) and handle.lost_drives(0.6) == [2]
    modes = [c.mode for c in handle.controllers(0.6)]
    assert modes == [MODE_ONLINE, MODE_ONLINE, MODE_LOST_CONNECTION, MODE_ONLINE]
    handle.update(moving, 0.62)
    assert all(s.heard for s in handle.read_drive_states(0.62)) and handle.lost_drives(0.62) == []
    handle.send_drive_commands([DriveCommand(0.0, 0.3)] * 4, 0.62)
    assert all(c.speed == 0.3 for c in sent[-1])
