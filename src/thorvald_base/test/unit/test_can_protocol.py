"""The CAN frames: the reference's numbers, the hand codec against the DBC file, decoders fuzzed."""

import math
import os

import cantools
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from thorvald_base.can import protocol as pr
from thorvald_base.can.dbc import main, robot_dbc
from thorvald_base.errors import MalformedFrame
from thorvald_model import load_robot_config
from thorvald_sim.can.emulator import load_dbc

HERE = os.path.dirname(os.path.abspath(__file__))
SRC = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
STD = os.path.join(SRC, "thorvald_model", "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
DB = load_dbc(os.path.join(SRC, "thorvald_base", "can", "thorvald.dbc"))


def message(name):
    return DB.get_message_by_name(name)


@pytest.fixture(scope="module")
def std():
    return pr.DriveScaling.of(load_robot_config(STD).drives[0])


# ---- the reference's numbers (notes section 8) ------------------------------------------------
def test_propulsion_command_is_motor_rpm_scaled_to_1000_at_prp_max_rpm(std):
    # the standard module: r 0.2 m (check the file), gear 42, 3000 rpm at full command
    assert (std.r_wheel, std.prp_gr_rt, std.prp_max_rpm) == (0.2, 42.0, 3000.0)
    full = 3000.0 / 42.0 * math.pi / 30.0 * 0.2  # [m/s] at 3000 motor rpm: 1.496 m/s
    assert std.prop_command(full) == 1000
    assert std.prop_command(-full) == -1000
    assert std.prop_command(full / 2) == 500
    assert std.prop_command(0.5) == round(0.5 / 0.2 * 42 * 30 / math.pi * 1000 / 3000)  # 334
    assert std.prop_command(10.0) == 1000  # clamped
    assert std.wheel_speed(3000) == pytest.approx(full)


def test_steering_command_is_1000_angle_over_str_lim(std):
    assert std.str_lim == pytest.approx(3.078027759)
    assert std.steer_command(std.str_lim) == 1000
    assert std.steer_command(-std.str_lim / 2) == -500
    assert std.steer_command(math.radians(30)) == round(1000 * math.radians(30) / 3.078027759)  # 170
    assert std.steer_command(4.0) == 1000


def test_steering_counts_are_quadrature_ticks_through_the_gear(std):
    per_turn = 1024 * 4 * 42.8571429  # ticks per steering turn
    assert std.steering_angle(round(per_turn)) == pytest.approx(2 * math.pi, rel=1e-6)
    assert std.steering_angle(round(per_turn / 8)) == pytest.approx(math.pi / 4, rel=1e-5)
    assert std.steer_speed_counts(1.0) == round(per_turn / (2 * math.pi))  # 27937 counts/s
    assert std.steering_rate(60.0 * 42.8571429) == pytest.approx(2 * math.pi)  # one steering turn per second


def test_battery_scalings():
    data = pr.encode_battery_tpdo1(pr.BatteryTpdo1(True, False, 48.57, 0b1000_0000_0000_0010, (21, -5)))
    assert data[1] == 0b01 and int.from_bytes(data[2:4], "little") == 4857
    decoded = pr.decode_battery_tpdo1(data)
    assert decoded.voltage == pytest.approx(48.57) and decoded.temperatures == (21, -5)
    assert pr.battery_alarm_names(decoded.alarms) == ("under_voltage_protection", "pack_voltage_sensing_fault")
    assert pr.decode_battery_tpdo2(pr.encode_battery_tpdo2(pr.BatteryTpdo2((1, 2, 3, 4, 5), -12.34))).current == -12.34
    t3 = pr.decode_battery_tpdo3(bytes([87, 96, 0x2C, 0x01, 0xE8, 0x03, 0, 0]))
    assert (t3.state_of_charge, t3.state_of_health, t3.cycle_count, t3.capacity) == (87, 96, 300, 100.0)


def test_status_flags_msb_first_and_ok_inverted():
    # prop enc fail (MSB) set, controller ok (LSB) set: "not ok" is false
    flags = dict(pr.decode_tx_pdo3(bytes([0b1000_0001, 0, 40, 0, 0x7B, 0, 0xE5, 0x01])).flags)
    assert flags["prop_enc_fail"] and not flags["controller_not_ok"] and not flags["stall_detected"]
    m = pr.decode_tx_pdo3(bytes([0b0000_1000, 0, 40, 0, 0x7B, 0, 0xE5, 0x01]))
    assert dict(m.flags)["stall_detected"] and dict(m.flags)["controller_not_ok"]
    assert (m.max_temperature, m.battery_amps, m.battery_volts) == (40, 12.3, 48.5)


def test_device_ids_and_clashes():
    owned = pr.device_ids([1, 2], [1], [0])
    assert owned[0x181] == "motor controller node 1" and owned[0x702] == "motor controller node 2"
    assert owned[0x3C1] == owned[0x3E1] == "battery 1" and owned[0x690] == "IO board 0"
    with pytest.raises(ValueError, match=r"0x3C1 belongs to both motor controller node 65 and battery 1"):
        pr.device_ids([65], [1], [])


# ---- the hand codec against the DBC ----------------------------------------------------------
int32 = st.integers(-(2**31), 2**31 - 1)
int16 = st.integers(-(2**15), 2**15 - 1)


@given(int32, int32)
def test_rx_pdos_match_the_dbc(a, b):
    data = pr.encode_pair(a, b)
    assert message("Roboteq_RxPDO1").decode(data) == {"command_seq": a, "prop_cmd": b}
    assert message("Roboteq_RxPDO4").decode(data) == {"steer_max_speed": a, "steer_cmd": b}
    assert message("Roboteq_RxPDO2").decode(data) == {"setup_id": a, "setup_value": b}
    assert pr.decode_pair(message("Roboteq_RxPDO3").encode({"mode": a, "mode_repeated": b}, strict=False)) == (a, b)


@given(int16, int16, int32)
def test_tx_pdo1_matches_the_dbc(rpm, steer, counts):
    data = pr.encode_tx_pdo1(pr.TxPdo1(rpm, steer, counts))
    assert message("Roboteq_TxPDO1").decode(data) == {"prop_rpm": rpm, "steer_rpm": steer, "steer_counts": counts}
    back = message("Roboteq_TxPDO1").encode({"prop_rpm": rpm, "steer_rpm": steer, "steer_counts": counts})
    assert pr.decode_tx_pdo1(back) == pr.TxPdo1(rpm, steer, counts)


@given(int16, int32)
def test_tx_pdo1_of_a_prop_prop_controller_matches_the_dbc(rpm_1, rpm_2):
    """Channel 1's rpm in bytes 0-1, channel 2's in bytes 4-7 (reference notes 3.3), bytes 2-3 unused."""
    data = pr.encode_tx_pdo1_diff(pr.TxPdo1Diff(rpm_1, rpm_2))
    assert data[2:4] == b"\0\0"
    assert int.from_bytes(data[0:2], "little", signed=True) == rpm_1
    assert int.from_bytes(data[4:8], "little", signed=True) == rpm_2
    assert message("RoboteqDiff_TxPDO1").decode(data) == {"prop_rpm_1": rpm_1, "prop_rpm_2": rpm_2}
    back = message("RoboteqDiff_TxPDO1").encode({"prop_rpm_1": rpm_1, "prop_rpm_2": rpm_2})
    assert pr.decode_tx_pdo1_diff(back) == pr.TxPdo1Diff(rpm_1, rpm_2)


def test_a_prop_prop_robots_dbc_has_each_nodes_variant():
    diff = os.path.join(SRC, "thorvald_model", "config", "thorvald_ii_2wd_diff", "thorvald_ii_2wd_diff.yaml")
    with open(pr.dbc_path()) as f:
        db = cantools.database.load_string(robot_dbc(f.read(), load_robot_config(diff)))
    node = {d.node for d in load_robot_config(diff).drives}.pop()  # one prop/prop controller
    m = db.get_message_by_frame_id(pr.TX_PDO1 + node)
    assert m.name == f"RoboteqDiff_TxPDO1_node{node}"
    assert m.decode(pr.encode_tx_pdo1_diff(pr.TxPdo1Diff(-1500, 2900))) == {"prop_rpm_1": -1500, "prop_rpm_2": 2900}
    assert f"Roboteq_TxPDO1_node{node}" not in [x.name for x in db.messages]
    assert db.get_message_by_frame_id(pr.TX_PDO3 + node).name == f"Roboteq_TxPDO3_node{node}"


@given(int16, int16, int16, int16)
def test_tx_pdo2_matches_the_dbc(a1, a2, p1, p2):
    m = pr.decode_tx_pdo2(pr.encode_tx_pdo2(pr.TxPdo2((a1 / 10, a2 / 10), (p1, p2))))
    d = message("Roboteq_TxPDO2").decode(pr.encode_tx_pdo2(m))
    assert d["motor_amps_1"] == pytest.approx(m.amps[0]) and d["motor_amps_2"] == pytest.approx(m.amps[1])
    assert (d["relative_power_1"], d["relative_power_2"]) == m.power == (p1, p2)


@given(st.integers(0, 255), int16, int16, int16)
def test_tx_pdo3_matches_the_dbc(byte, temperature, amps, volts):
    data = bytes([byte, 0]) + b"".join(v.to_bytes(2, "little", signed=True) for v in (temperature, amps, volts))
    m = pr.decode_tx_pdo3(data)
    d = message("Roboteq_TxPDO3").decode(data)
    flags = dict(m.flags)
    for name in pr.STATUS_FLAGS[:-1]:
        assert flags[name] == bool(d[name])
    assert flags["controller_not_ok"] == (not d["controller_ok"])
    assert (m.max_temperature, m.battery_amps, m.battery_volts) == pytest.approx(
        (d["max_temperature"], d["battery_amps"], d["battery_volts"])
    )
    assert pr.encode_tx_pdo3(m) == data


@given(int16, st.sampled_from([-1, 1]), int32, st.integers(1, 2), st.tuples(st.integers(0, 255), st.integers(0, 255)))
def test_tx_pdo4_matches_the_dbc(speed, direction, count, script, version):
    minor, patch = version
    db = message("Roboteq_TxPDO4")
    one = pr.encode_tx_pdo4(pr.TxPdo4(1, home_speed=speed, drive_direction=direction, home_count=count))
    assert db.decode(one, decode_choices=False) == {
        "message_type": 1,
        "home_speed": speed,
        "drive_direction": direction,
        "home_count": count,
    }
    two = db.encode(
        {"message_type": 2, "script_type": script, "version_patch": patch, "version_minor": minor, "version_major": 3}
    )
    assert pr.decode_tx_pdo4(two) == pr.TxPdo4(2, script_type=script, version=f"3.{minor}.{patch}")
    three = pr.encode_tx_pdo4(pr.TxPdo4(3, prop_enc_ppr=1024, str_enc_ppr=4096))
    assert db.decode(three, decode_choices=False) == {"message_type": 3, "prop_enc_ppr": 1024, "str_enc_ppr": 4096}


@given(st.booleans(), st.booleans(), st.integers(-32768, 32767), st.integers(0, 0xFFFF), st.integers(-128, 127))
def test_battery_frames_match_the_dbc(charge, discharge, volts, alarms, temperature):
    data = pr.encode_battery_tpdo1(pr.BatteryTpdo1(charge, discharge, volts / 100, alarms, (temperature, 20)))
    d = message("Battery_TPDO1").decode(data)
    assert (bool(d["charge_fet_on"]), bool(d["discharge_fet_on"])) == (charge, discharge)
    assert d["voltage"] == pytest.approx(volts / 100) and d["temperature_0"] == temperature
    assert {name for name in pr.BATTERY_ALARMS.values() if d[name]} == set(pr.battery_alarm_names(alarms))
    d2 = message("Battery_TPDO2").decode(
        pr.encode_battery_tpdo2(pr.BatteryTpdo2((1, 2, 3, 4, temperature), volts / 100))
    )
    assert d2["current"] == pytest.approx(volts / 100) and d2["temperature_6"] == temperature
    d3 = message("Battery_TPDO3").decode(pr.encode_battery_tpdo3(pr.BatteryTpdo3(55, 90, alarms, alarms / 10)))
    assert (d3["state_of_charge"], d3["state_of_health"], d3["cycle_count"]) == (55, 90, alarms)
    assert d3["capacity"] == pytest.approx(alarms / 10)


@given(st.dictionaries(st.integers(0, 1), st.booleans()), st.lists(st.integers(0, 65535), min_size=3, max_size=3))
def test_io_frames_match_the_dbc(relays, millivolts):
    d = message("IO_Command").decode(pr.encode_io_command(relays))
    assert {k: bool(d[f"rl{k}"]) for k in range(2) if d[f"set_rl{k}"]} == relays
    state = pr.IoState((True, False), 2, tuple(v / 1000 for v in millivolts))
    s = message("IO_State").decode(pr.encode_io_state(state), decode_choices=False)
    assert (s["rl0"], s["rl1"], s["board_type"]) == (1, 0, 2)
    assert [s[f"analog_{k}"] for k in range(3)] == pytest.approx(list(state.analog))
    assert pr.decode_io_state(pr.encode_io_state(state)) == state


def test_every_frame_of_the_dbc_has_its_identifier_in_the_protocol():
    ids = {
        pr.RX_PDO1, pr.RX_PDO2, pr.RX_PDO3, pr.RX_PDO4, pr.TX_PDO1, pr.TX_PDO2, pr.TX_PDO3, pr.TX_PDO4,
        pr.HEARTBEAT, pr.BATTERY_TPDO1, pr.BATTERY_TPDO2, pr.BATTERY_TPDO3, pr.IO_COMMAND, pr.IO_STATE,
    }  # fmt: skip
    assert {m.frame_id for m in DB.messages} == ids
    assert pr.dbc_path().endswith(os.path.join("thorvald_base", "can", "thorvald.dbc"))


# ---- decoders never raise past MalformedFrame ------------------------------------------------
DECODERS = [
    pr.decode_pair,
    pr.decode_tx_pdo1,
    pr.decode_tx_pdo1_diff,
    pr.decode_tx_pdo2,
    pr.decode_tx_pdo3,
    pr.decode_tx_pdo4,
    pr.decode_battery_tpdo1,
    pr.decode_battery_tpdo2,
    pr.decode_battery_tpdo3,
    pr.decode_io_command,
    pr.decode_io_state,
]


@settings(max_examples=300)
@given(st.binary(min_size=0, max_size=8))
def test_decoders_take_any_payload(data):
    for decode in DECODERS:
        try:
            decode(data)
        except MalformedFrame:
            assert len(data) != 8 or decode is pr.decode_tx_pdo4


# ---- one robot's DBC file --------------------------------------------------------------------
def test_a_robots_dbc_has_every_device_at_its_own_id(tmp_path):
    config = load_robot_config(STD)
    with open(pr.dbc_path()) as f:
        text = robot_dbc(f.read(), config)
    db = cantools.database.load_string(text)
    nodes = sorted({d.node for d in config.drives})
    batteries = [b.id for b in config.batteries if b.type == 1 and b.with_battery]
    # the file has no io section: the main IO board (id 0) is on the bus all the same, 2 messages
    assert len(db.messages) == 9 * len(nodes) + 3 * len(batteries) + 2
    assert db.get_message_by_frame_id(pr.IO_STATE + 0).name.endswith("io0")
    for n in nodes:
        m = db.get_message_by_frame_id(pr.TX_PDO1 + n)
        assert m.name == f"Roboteq_TxPDO1_node{n}"
        assert m.decode(pr.encode_tx_pdo1(pr.TxPdo1(123, -4, 5678))) == {
            "prop_rpm": 123,
            "steer_rpm": -4,
            "steer_counts": 5678,
        }
        assert db.get_message_by_frame_id(pr.RX_PDO3 + n).decode(pr.encode_pair(1, 1))["mode"] == "home"
    for k in batteries:
        assert db.get_message_by_frame_id(pr.BATTERY_TPDO3 + k).name == f"Battery_TPDO3_bat{k}"
    out = tmp_path / "robot.dbc"
    assert main([STD, "-o", str(out)]) == 0
    assert out.read_text() == text
    assert main([str(tmp_path / "missing.yaml")]) == 2
