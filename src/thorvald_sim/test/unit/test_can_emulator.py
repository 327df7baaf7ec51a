"""base_driver's CAN base against the emulated devices, on python-can's in-process virtual bus.

The handle encodes with thorvald_base.can.protocol; the emulator decodes through the DBC file
with cantools and its own conversions. Both run on one simulated clock stepped here.
"""

import itertools
import math
import os

import can
import pytest
import yaml
from hypothesis import given, settings
from hypothesis import strategies as st

from thorvald_base.bases.can_base import CanBase
from thorvald_base.bases.handle import Frame
from thorvald_base.core import BaseDriverCore
from thorvald_base.errors import ParameterError, ThorvaldBaseError
from thorvald_base.kinematics import DriveCommand
from thorvald_base.params import DriverParams
from thorvald_base.plugins import load_calculator
from thorvald_model import load_robot_config, parse_robot_config
from thorvald_sim.can.emulator import CanEmulator

HERE = os.path.dirname(os.path.abspath(__file__))
CONFIGS = os.path.abspath(os.path.join(HERE, "..", "..", "..", "thorvald_model", "config"))
STD = os.path.join(CONFIGS, "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
DIFF = os.path.join(CONFIGS, "thorvald_ii_2wd_diff", "thorvald_ii_2wd_diff.yaml")
CYCLE = 0.02  # [s] base_driver at 50 Hz
_channels = itertools.count()


def pair(config):
    """A CAN base and an emulator of the same robot on a fresh virtual bus."""
    channel = f"thorvald-test-{os.getpid()}-{next(_channels)}"
    handle_bus = can.Bus(interface="virtual", channel=channel, receive_own_messages=False)
    emulator = CanEmulator(config, can.Bus(interface="virtual", channel=channel, receive_own_messages=False))
    emulator.channel = channel  # for a third participant (an implement)
    return CanBase(config, handle_bus), emulator


def run(handle, emulator, commands, start, seconds):
    """base_driver's cycle (commands out, states in) and the emulator, stepped together."""
    t = start
    states = None
    for _ in range(round(seconds / CYCLE)):
        handle.send_drive_commands(commands, t)
        for k in range(4):  # the devices run faster than the base's cycle
            emulator.step(t + k * CYCLE / 4)
        t += CYCLE
        states = handle.read_drive_states(t)
    return t, states


@pytest.fixture
def std():
    config = load_robot_config(STD)
    handle, emulator = pair(config)
    yield config, handle, emulator
    handle.close()
    emulator.drop_bus()


def test_the_drives_follow_commands_through_the_bus(std):
    config, handle, emulator = std
    steering = math.radians(30)
    t, states = run(handle, emulator, [DriveCommand(steering, 0.5)] * 4, 0.0, 3.0)
    for s in states:
        assert s.steering == pytest.approx(steering, abs=0.002)  # quantised by the command's 1000 steps
        assert s.speed == pytest.approx(0.5, rel=0.01)  # prop_cmd 334 of 1000: 0.4990 m/s
    # the emulator saw the commands its own way (DBC + its conversions)
    for c in emulator.controllers.values():
        assert c.channels[0].target == pytest.approx(0.5, rel=0.005)
        assert c.channels[0].steering_limit == pytest.approx(config.drives[0].str_sim_v, rel=1e-3)
        assert c.commands == round(3.0 / CYCLE)
    # the wheel angle is integrated from the reported speed
    assert states[0].wheel_angle != 0.0
    # controllers report online, script type and version; the battery its voltage and charge
    reports = handle.controllers(t)
    assert {r.mode for r in reports} == {3}
    assert {r.type for r in reports} == {"RoboteqFbl2360"} and {r.version for r in reports} == {"2.1.0"}
    assert reports[0].battery_volts > 40
    # relative power in [-1, 1] (motor_controller_data's unit); TxPDO2 carries it in per mille, and the
    # emulator reports the rim speed over the drive's top speed: 0.5 / 1.5 m/s
    propulsion = reports[0].motor_vars[0]
    assert propulsion[0] == "propulsion" and propulsion[4] == pytest.approx(
        0.5 / config.drives[0].max_wheel_speed, abs=0.01
    )
    (battery,) = handle.batteries(t)
    assert battery.state == 0 and 40 < battery.voltage < 60 and battery.state_of_charge > 90


def test_the_battery_is_the_robot_files():
    """A 24 V pack of 50 Ah (the robot file's batteries.bat0 capacity and voltage) reports its capacity
    and a voltage in its own range (22 to 27 V for 24 V: 44 to 54 V for 48 V scaled)."""
    with open(STD, encoding="utf-8") as f:
        data = yaml.safe_load(f)
    data["batteries"]["bat0"].update(capacity=50.0, voltage=24.0)
    handle, emulator = pair(parse_robot_config(data, "24 V robot"))
    try:
        t, _ = run(handle, emulator, [DriveCommand(0.0, 0.0)] * 4, 0.0, 1.5)
        (battery,) = handle.batteries(t)
        assert battery.capacity == pytest.approx(50.0) and 22.0 < battery.voltage < 27.0
    finally:
        handle.close()
        emulator.drop_bus()


def test_ramps_come_from_the_configuration(std):
    _, handle, emulator = std
    _, states = run(handle, emulator, [DriveCommand(0.0, 1.0)] * 4, 0.0, 0.2)
    # prp_sim_a 1.5 m/s^2: about 0.3 m/s after 0.2 s (one 50 Hz report behind)
    assert 0.2 < states[0].speed < 0.33


def test_a_silent_controller_stops_every_wheel_and_control_resumes(std):
    _, handle, emulator = std
    t, _ = run(handle, emulator, [DriveCommand(0.0, 0.5)] * 4, 0.0, 1.0)
    emulator.silence("drive1")
    t, _ = run(handle, emulator, [DriveCommand(0.0, 0.5)] * 4, t, 1.9)
    assert handle.stopped_for_lost == []  # within 2 s: still trusted
    t, _ = run(handle, emulator, [DriveCommand(0.0, 0.5)] * 4, t, 0.2 + CYCLE)
    assert handle.stopped_for_lost == ["drive1"]
    assert [r.mode for r in handle.controllers(t)] == [3, 4, 3, 3]
    # every controller was told zero speed within one cycle of the loss
    assert all(c.channels[0].target == 0.0 for c in emulator.controllers.values())
    emulator.resume("drive1")
    t, states = run(handle, emulator, [DriveCommand(0.0, 0.5)] * 4, t, 1.0)
    assert handle.stopped_for_lost == []
    assert all(s.speed == pytest.approx(0.5, rel=0.01) for s in states)


def test_malformed_frames_are_counted_and_dropped(std):
    _, handle, emulator = std
    t, _ = run(handle, emulator, [DriveCommand(0.0, 0.3)] * 4, 0.0, 0.5)
    emulator.corrupt(40)
    t, states = run(handle, emulator, [DriveCommand(0.0, 0.3)] * 4, t, 1.5)
    assert handle.malformed_frames >= 30
    assert all(s.speed == pytest.approx(0.3, rel=0.02) for s in states)


def test_homing_sends_the_home_mode_and_stops_the_wheels(std):
    _, handle, emulator = std
    t, _ = run(handle, emulator, [DriveCommand(0.5, 0.3)] * 4, 0.0, 1.0)
    handle.home_steering()
    t, states = run(handle, emulator, [DriveCommand(0.5, 0.3)] * 4, t, 1.0)
    assert {c.mode for c in emulator.controllers.values()} == {1}
    assert all(abs(s.speed) < 1e-6 and abs(s.steering) < 0.01 for s in states)
    handle.end_homing()
    t, states = run(handle, emulator, [DriveCommand(0.5, 0.3)] * 4, t, 1.0)
    assert {c.mode for c in emulator.controllers.values()} == {0}
    assert all(s.speed == pytest.approx(0.3, rel=0.02) for s in states)


def test_setup_services(std):
    _, handle, emulator = std
    t, _ = run(handle, emulator, [DriveCommand(0.2, 0.0)] * 4, 0.0, 1.5)
    status, text = handle.setup_motor_controller(2, 0, 0)
    assert status == 0 and "1: drive direction (permanent)" in text
    assert handle.setup_motor_controller(2, 12, 0)[0] == -2
    assert handle.setup_motor_controller(9, 4, 100)[0] == -1
    assert handle.setup_motor_controller(2, 4, 2500)[0] == 0
    status, _ = handle.set_home_count_current_pos_zero(-1)
    run(handle, emulator, [DriveCommand(0.2, 0.0)] * 4, t, 0.1)
    assert status == 0
    assert (4, 2500) in emulator.controllers[2].setups
    counts = emulator.controllers[1].channels[0].counts()
    assert emulator.controllers[1].home_count == -counts != 0


def test_relay_guard_and_routing(std):
    _, handle, emulator = std
    assert "refused" in handle.relay(Frame(0x201, bytes(8)))  # drive0's RxPDO1
    assert handle.relay(Frame(0x123, bytes([1, 2, 3]))) is None
    implement = can.Bus(interface="virtual", channel=emulator.channel, receive_own_messages=False)
    try:
        run(handle, emulator, [DriveCommand(0.0, 0.0)] * 4, 0.0, CYCLE)
        got = implement.recv(0.5)
        while got is not None and got.arbitration_id != 0x123:
            got = implement.recv(0.5)
        assert got is not None and bytes(got.data) == bytes([1, 2, 3])
        implement.send(can.Message(arbitration_id=0x285, data=[7], is_extended_id=False))  # node 5: not the base's
        run(handle, emulator, [DriveCommand(0.0, 0.0)] * 4, 1.0, CYCLE)
        base, device = handle.take_received()
        assert [f.id for f in device] == [0x285]
        assert base and all(f.id in handle.owned for f in base)
    finally:
        implement.shutdown()
    for _ in range(150):
        handle.relay(Frame(0x124, bytes(8)))
    assert handle.counters.relay_dropped == 50


def test_differential_robot_on_one_prop_prop_controller():
    config = load_robot_config(DIFF)
    handle, emulator = pair(config)
    try:
        assert len(handle.controllers_) == 1 and not handle.controllers_[0].steered
        t, states = run(handle, emulator, [DriveCommand(0.0, 0.4), DriveCommand(0.0, -0.2)], 0.0, 2.0)
        assert [s.speed for s in states] == pytest.approx([0.4, -0.2], rel=0.01)
        (report,) = handle.controllers(t)
        assert report.type == "RoboteqFbl2360Diff" and [m[0] for m in report.motor_vars] == ["propulsion"] * 2
    finally:
        handle.close()
        emulator.drop_bus()


def test_the_core_drives_the_can_base_to_a_twist(std):
    config, handle, emulator = std
    core = BaseDriverCore(config, load_calculator(config), handle)
    core.set_command(0.4, 0.0, 0.2, 0.0)
    t = 0.0
    for _ in range(150):
        core.set_command(0.4, 0.0, 0.2, t)
        result = core.step(t)
        for k in range(4):
            emulator.step(t + k * CYCLE / 4)
        t += CYCLE
    assert result.odometry.twist.vx == pytest.approx(0.4, abs=0.01)
    assert result.odometry.twist.wz == pytest.approx(0.2, abs=0.01)


def test_io_boards_get_their_initial_relay_states():
    with open(STD) as f:
        data = yaml.safe_load(f)
    data["io"] = {"io0": {"id": 3, "type": 0, "rl0_init_state": True, "rl1_init_state": False}}
    config = parse_robot_config(data, "std with an IO board")
    handle, emulator = pair(config)
    try:
        t, _ = run(handle, emulator, [DriveCommand(0.0, 0.0)] * 4, 0.0, 0.1)
        assert emulator.ios[3].relays == [True, False]
        handle.set_relay(3, 1, True)
        run(handle, emulator, [DriveCommand(0.0, 0.0)] * 4, t, 1.1)
        assert emulator.ios[3].relays == [True, True]
        assert handle.ios[0].state.relays == (True, True)
        with pytest.raises(ThorvaldBaseError, match="no IO board 4"):
            handle.set_relay(4, 0, True)
    finally:
        handle.close()
        emulator.drop_bus()


@pytest.mark.parametrize(
    ("interface", "channel", "message"),
    [
        ("enc_pcb_v1rev6", "/dev/ttyUSB0", r"never published; use a python-can interface instead"),
        ("warpcan", "x", r"'warpcan': not a python-can interface; known: .*socketcan"),
        ("", "", r"empty: name a python-can interface"),
        ("slcan", "/nonexistent/tty", r"CAN bus slcan '/nonexistent/tty' will not open: "),
    ],
)
def test_buses_that_cannot_open_give_one_line(interface, channel, message):
    with pytest.raises((ParameterError, ThorvaldBaseError), match=message) as info:
        CanBase.from_params(
            load_robot_config(STD),
            DriverParams.from_dict({"can_interface_type": interface, "can_interface_name": channel}),
        )
    assert "\n" not in str(info.value)


@settings(max_examples=400, deadline=None)
@given(st.integers(0, 0x7FF), st.binary(min_size=0, max_size=8), st.booleans())
@pytest.mark.slow  # hypothesis: many frames
def test_any_frame_is_routed_without_raising(can_id, data, extended):
    handle = CanBase(load_robot_config(STD), bus=None)
    handle._route(Frame(can_id, data, extended), 1.0)
    base, device = handle.take_received()
    assert len(base) + len(device) == 1
    assert bool(base) == (not extended and can_id in handle.by_id)
