"""The base handle contract (stop before close, homing), the handle factory, and the pose covariance."""

import dataclasses
import math

import pytest
from base_test_helpers import diff, four_ws

from thorvald_base.bases import BaseHandle, MeasuredDrive, create_base_handle
from thorvald_base.bases.handle import DriveTopics, Ports
from thorvald_base.bases.simulated import SimulatedBase
from thorvald_base.core import DEFAULT_TWIST_COVARIANCE, BaseDriverCore, PoseCovariance
from thorvald_base.errors import ParameterError, ThorvaldBaseError
from thorvald_base.kinematics import DriveCommand, OdometryResult, PltfClcStd, Pose, Twist
from thorvald_base.params import DriverParams
from thorvald_model import with_drive_param


class RecordingBase(BaseHandle):
    """A handle that records what reaches its drives, in order, and when it was closed."""

    def __init__(self, config):
        super().__init__(config)
        self.log = []

    def _send_drive_commands(self, commands, time):
        self.log.append(("send", time, commands))

    def _read_drive_states(self, time):
        return [MeasuredDrive(0.0, 0.0, 0.0, 0.0) for _ in self.config.drives]

    def _home_steering(self):
        self.log.append(("home",))
        return "homing"

    def _end_homing(self):
        self.log.append(("end homing",))

    def _set_params(self, config):
        pass

    def _close(self):
        self.log.append(("close",))


def core_with(handle):
    calc = PltfClcStd.from_config(handle.config)
    return BaseDriverCore(handle.config, calc, handle)


def test_shutdown_sends_zero_speeds_with_the_steering_kept_before_closing():
    handle = RecordingBase(four_ws())
    core = core_with(handle)
    core.set_command(0.0, 0.4, 0.0, 0.0)  # sideways: every wheel at +90 degrees, 0.4 m/s
    core.step(0.0)
    assert all(c.speed == pytest.approx(0.4) for c in handle.log[-1][2])
    core.shutdown(0.02)
    assert [entry[0] for entry in handle.log[-2:]] == ["send", "close"]
    _, when, stop = handle.log[-2]
    assert when == 0.02
    assert all(c.speed == 0.0 and c.steering == pytest.approx(math.pi / 2) for c in stop)
    assert core.closed and handle.closed


def test_a_closed_handle_sends_nothing_and_closing_twice_is_harmless():
    handle = RecordingBase(four_ws())
    handle.close()
    # never commanded: the stop points the wheels straight ahead
    assert handle.log == [("send", 0.0, tuple(DriveCommand(0.0, 0.0) for _ in range(4))), ("close",)]
    handle.close()
    assert len(handle.log) == 2
    with pytest.raises(ThorvaldBaseError, match="closed"):
        handle.send_drive_commands([DriveCommand(0.0, 0.0)] * 4, 1.0)


def test_homing_belongs_to_the_handle_and_a_new_command_ends_it():
    handle = RecordingBase(four_ws())
    core = core_with(handle)
    assert core.home_steering() == "homing" and handle.homing
    assert core.step(0.0).stopped_by == "homing"
    assert core.set_command(0.2, 0.0, 0.0, 0.02) is None
    assert not handle.homing and ("end homing",) in handle.log
    assert core.step(0.04).stopped_by is None


def test_the_simulated_base_stops_its_drives_on_close():
    base = SimulatedBase(four_ws())
    for k in range(50):  # 1 s at 50 Hz: up to speed (1.5 m/s^2 ramp)
        base.send_drive_commands([DriveCommand(0.0, 0.5)] * 4, 0.02 * k)
    base.close(1.0)
    # the stop command reached the simulated drives: they ramp down from 0.5 m/s at 1.5 m/s^2
    assert [d.speed for d in base.read_drive_states(1.0)] == pytest.approx([0.5 - 1.5 * 0.02] * 4)
    assert all(d.drive.str_lim for d in base.drives)


def test_the_factory_picks_the_handle_from_the_parameters():
    config = four_ws()
    params = DriverParams.from_dict
    assert params({"simple_sim": True}).handle == "simple_sim"
    assert params({"simple_sim": False}).handle == "can"
    assert params({"simple_sim": False, "base_handle": "simple_sim"}).handle == "simple_sim"
    assert isinstance(create_base_handle(config, params({"simple_sim": True})), SimulatedBase)
    with pytest.raises(
        ParameterError,
        match=r"~base_handle: 'warp': no such base handle; available: can, simple_sim, simulated_joints$",
    ):
        create_base_handle(config, params({"base_handle": "warp"}))
    # simple_sim false is the CAN base, which needs a python-can interface
    with pytest.raises(ParameterError, match=r"~can_interface_type: empty: name a python-can interface"):
        create_base_handle(config, params({"simple_sim": False}))


class LoopbackTopics(DriveTopics):
    """The node's side of simulated_joints, played in the test: what was sent, and the listener."""

    def __init__(self):
        self.sent, self.listener, self.current_listener, self.closed = [], None, None, False

    def send(self, commands, time, drives):
        self.sent.append((time, tuple(commands), [d.max_steering_speed for d in drives]))

    def listen(self, on_states):
        self.listener = on_states

    def listen_currents(self, on_currents):
        self.current_listener = on_currents

    def close(self):
        self.closed = True


class LoopbackPorts(Ports):
    def __init__(self):
        self.topics = {}

    def drive_topics(self, command_topic, state_topic, current_topic="drive_currents"):
        self.topics[(command_topic, state_topic, current_topic)] = LoopbackTopics()
        return self.topics[(command_topic, state_topic, current_topic)]


def test_simulated_joints_trades_on_the_nodes_drive_topics():
    """The factory wires the handle to the ports the node offers: no ROS import in the handle."""
    ports = LoopbackPorts()
    params = DriverParams.from_dict({"base_handle": "simulated_joints", "measured_timeout": 0.25})
    base = create_base_handle(four_ws(), params, ports)
    (topics,) = ports.topics.values()
    assert list(ports.topics) == [("drive_commands", "drive_states", "drive_currents")]
    assert base.stale_after == 0.25
    topics.listener([MeasuredDrive(0.2, 0.3, 1.0, 0.0)] * 4, 5.0)
    base.send_drive_commands([DriveCommand(0.2, 0.4)] * 4, 5.1)
    assert topics.sent[-1] == (5.1, tuple([DriveCommand(0.2, 0.4)] * 4), [4.0] * 4)
    assert base.read_drive_states(5.1)[0].speed == 0.3
    base.close(5.2)
    assert topics.closed
    with pytest.raises(ParameterError, match="needs base_driver's topics"):
        create_base_handle(four_ws(), params)


def test_simulated_joints_reports_the_simulators_motor_currents():
    """motor_controller_data of measured drives: per controller the propulsion and steering channels
    with the measured speeds and angles, the motor currents as they came, and the torque they carry
    over the drive's limit as relative power (the thorvald_model.motors model)."""
    ports = LoopbackPorts()
    base = create_base_handle(four_ws(), DriverParams.from_dict({"base_handle": "simulated_joints"}), ports)
    (topics,) = ports.topics.values()
    states = [MeasuredDrive(0.1, 0.5, 2.0, 0.3)] * 4  # steering [rad], rim speed [m/s], wheel angle [rad], [rad/s]
    topics.listener(states, 1.0)
    before = base.controllers(1.0)
    assert [c.name for c in before] == ["drive0", "drive1", "drive2", "drive3"]
    assert before[0].motor_vars == (("propulsion", 0.5, 2.0, 0.0, 0.0), ("steering", 0.3, 0.1, 0.0, 0.0))
    topics.current_listener([2.0, -0.84, 0.6, 30.0], [0.5, 0.0, -0.4, 0.0], 1.0)
    topics.current_listener([9.0] * 4, [9.0] * 4, 1.0125)  # the next instant's: not yet at 1.0
    prop = [c.motor_vars[0] for c in base.controllers(1.0)]
    # k_t 0.14 N m/A, i_0 0.6 A, G 42, eta 0.9, limit 1.6 x 42 = 67.2 N m; the wheel turns forward:
    # 2.0 A: tau_m = 0.14 (2.0 - 0.6) = 0.196 N m motoring, 0.196 x 42 x 0.9 = 7.4088 N m
    # -0.84 A: tau_m = 0.14 (-1.44) = -0.2016 N m braking, -0.2016 x 42 / 0.9 = -9.408 N m
    # 0.6 A: the friction alone, 0 N m; 30 A: 155.6 N m, beyond the limit
    assert [v[3] for v in prop] == [2.0, -0.84, 0.6, 30.0]
    assert [v[4] for v in prop] == pytest.approx([7.4088 / 67.2, -9.408 / 67.2, 0.0, 1.0])
    assert all(v[:3] == ("propulsion", 0.5, 2.0) for v in prop)
    steer = base.controllers(1.0)[0].motor_vars[1]
    # 0.5 A turning left at 0.3 rad/s: tau_m = 0.14 (0.5 - 0.4) = 0.014 N m, x 42.857 x 0.85 over 1.0 x 42.857
    assert steer[:4] == ("steering", 0.3, 0.1, 0.5) and steer[4] == pytest.approx(0.014 * 0.85)
    assert base.controllers(1.0125)[0].motor_vars[0][3] == 9.0
    # a wheel's radius changed by set_drive_params scales its rim speed, not its current
    base.set_params(with_drive_param(base.config, 0, "r_wheel", 0.2 * 1.002))
    assert base.controllers(1.0125)[0].motor_vars[0][1:4] == (pytest.approx(0.5 * 1.002), 2.0, 9.0)
    with pytest.raises(ValueError, match="3 propulsion and 4 steering currents for 4 drives"):
        base.update_currents([1.0] * 3, [0.0] * 4, 1.05)


def test_a_type_1_pair_reports_two_propulsion_channels_on_its_controller():
    ports = LoopbackPorts()
    base = create_base_handle(diff(), DriverParams.from_dict({"base_handle": "simulated_joints"}), ports)
    (topics,) = ports.topics.values()
    topics.listener([MeasuredDrive(0.0, 0.4, 1.0, 0.0), MeasuredDrive(0.0, -0.4, -1.0, 0.0)], 2.0)
    topics.current_listener([3.0, -3.0], [0.0, 0.0], 2.0)
    (controller,) = base.controllers(2.0)
    assert [v[:4] for v in controller.motor_vars] == [("propulsion", 0.4, 1.0, 3.0), ("propulsion", -0.4, -1.0, -3.0)]
    # both motoring, each its own way: the same relative power with opposite signs
    assert (
        controller.motor_vars[0][4] == pytest.approx(-controller.motor_vars[1][4]) and controller.motor_vars[0][4] > 0
    )


@pytest.mark.parametrize(
    "raw, message",
    [
        ({"rate": 0}, r"~rate: 0: must be > 0 \[Hz\]"),
        ({"rate": "fast"}, r"~rate: 'fast': must be a number"),
        ({"measured_timeout": -1.0}, r"~measured_timeout: -1.0: must be > 0 \[s\]"),
        ({"enable_odom_tf": "maybe"}, r"~enable_odom_tf: 'maybe': must be true or false"),
        ({"command_timeout": [1]}, r"~command_timeout: \[1\]: must be a number"),
    ],
)
def test_driver_parameters_refuse_bad_values_by_name(raw, message):
    with pytest.raises(ParameterError, match=message):
        DriverParams.from_dict(raw)


def test_driver_parameters_read_once_with_the_originals_defaults():
    p = DriverParams.from_dict({"tf_prefix": "thorvald_001", "enable_odom_tf": "false", "motor_drives": {}})
    assert (p.tf_prefix, p.base_frame, p.enable_odom_tf) == ("thorvald_001/", "thorvald_001/base_link", False)
    default = DriverParams.from_dict({})
    assert (default.rate, default.command_timeout, default.odom_frame_id, default.enable_odom_tf) == (
        50.0,
        0.5,
        "odom",
        True,
    )
    assert default.twist_covariance == DEFAULT_TWIST_COVARIANCE and default.can_bitrate == 1000000
    with pytest.raises(dataclasses.FrozenInstanceError):  # read once, the same value everywhere
        default.rate = 10.0


def odometry(vx, dt):
    return OdometryResult(Twist(vx, 0.0, 0.0), Pose(), 0.0, dt)


def test_pose_covariance_grows_per_second_of_motion():
    cov = PoseCovariance()
    assert cov.pose == cov.twist == DEFAULT_TWIST_COVARIANCE
    assert DEFAULT_TWIST_COVARIANCE[0] == 0.001 and DEFAULT_TWIST_COVARIANCE[35] == 0.03
    cov.update(odometry(0.004, 1.0))  # below 5 mm/s: standing still
    assert cov.pose == DEFAULT_TWIST_COVARIANCE
    for _ in range(50):
        cov.update(odometry(0.5, 0.02))  # one second of motion at 50 Hz
    assert cov.pose[0] == pytest.approx(0.002) and cov.pose[35] == pytest.approx(0.06)
    cov.reset()
    assert cov.pose == DEFAULT_TWIST_COVARIANCE


@pytest.mark.parametrize("bad", [[0.1] * 35, "0.1", [0.1] * 35 + [float("nan")], [0.1] * 35 + [True]])
def test_pose_covariance_refuses_a_bad_twist_covariance(bad):
    with pytest.raises(ParameterError, match=r"~twist_covariance: .*36 finite numbers"):
        PoseCovariance(bad)


def test_simulated_joints_send_commands_and_read_the_measured_states():
    from thorvald_base.bases.simulated_joints import SimulatedJointsBase  # noqa: PLC0415

    sent = []
    config = four_ws()
    base = SimulatedJointsBase(config, lambda commands, time: sent.append((time, commands)), stale_after=0.5)
    measured = [MeasuredDrive(0.1 * k, 0.4, 1.0, 0.0) for k in range(4)]
    base.update(measured, 10.0)
    base.send_drive_commands([DriveCommand(0.3, 0.5)] * 4, 10.2)
    assert sent[-1] == (10.2, tuple([DriveCommand(0.3, 0.5)] * 4))
    assert base.read_drive_states(10.2) == measured
    assert [c.mode for c in base.controllers(10.2)] == [3, 3, 3, 3]  # online
    # no measurement for longer than stale_after: the simulator lost the robot; the wheels stop
    base.send_drive_commands([DriveCommand(0.3, 0.5)] * 4, 10.6)
    assert sent[-1] == (10.6, tuple([DriveCommand(0.3, 0.0)] * 4))
    assert {c.mode for c in base.controllers(10.6)} == {4}  # lost connection
    # homing: straight ahead, stopped, until a command ends it
    base.update(measured, 10.7)
    base.home_steering()
    base.send_drive_commands([DriveCommand(0.3, 0.5)] * 4, 10.7)
    assert sent[-1][1] == tuple([DriveCommand(0.0, 0.0)] * 4)
    with pytest.raises(ValueError, match="3 drive states for 4 drives"):
        base.update(measured[:3], 11.0)
    base.close(11.0)
    assert sent[-1] == (11.0, tuple([DriveCommand(0.0, 0.0)] * 4))  # the stop before closing


def test_simulated_joints_give_a_cycle_the_states_of_its_instant_not_newer_ones():
    # in lockstep the simulator steps on once the cycle's commands reach it: the next instant's states
    # may arrive before the cycle reads them again, and must not be read as the cycle's
    from thorvald_base.bases.simulated_joints import SimulatedJointsBase  # noqa: PLC0415

    base = SimulatedJointsBase(four_ws(), lambda commands, time: None, stale_after=0.5)
    at = {t: [MeasuredDrive(0.0, t, t, 0.0)] * 4 for t in (1.0, 1.01, 1.02)}
    base.update(at[1.0], 1.0)
    base.update(at[1.01], 1.01)
    assert base.read_drive_states(1.0) == at[1.0]
    assert base.read_drive_states(1.015) == at[1.01]  # the newest at or before the instant
    base.update(at[1.02], 1.02)
    assert base.read_drive_states(1.05) == at[1.02]
    base.update(at[1.0], 0.5)  # simulated time went back: the newest is all there is
    assert base.read_drive_states(0.5) == at[1.0]


def test_lockstep_is_a_property_of_the_handle_and_those_that_claim_it_can_wait_and_answer():
    from thorvald_base.bases import BASE_HANDLES, BaseHandle, handle_class_named  # noqa: PLC0415

    claims = {name: handle_class_named(name).supports_lockstep for name in BASE_HANDLES}
    assert claims == {"simple_sim": False, "simulated_joints": True, "can": False}
    for name, claimed in claims.items():
        cls = handle_class_named(name)
        if claimed:  # the lockstep loop's two calls, implemented by the handle itself
            assert cls.wait_for_states is not getattr(BaseHandle, "wait_for_states", None)
            assert callable(cls.wait_for_states) and callable(cls.answer)
