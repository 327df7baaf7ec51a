"""The robot base's CAN frames: identifiers, scalings and the codec base_driver uses, without ROS.

Every frame is described once, declaratively, in ``thorvald_base/can/thorvald.dbc`` (readable by
cantools and the usual bus tools); this module is the fast hand codec base_driver runs every cycle,
and the tests check it against the DBC. The layouts follow the original's NMBU Roboteq script, KC
battery and IO boards (reference notes, section 8); where the original's format is unknown
(mode values, the prop/prop variant's second channel, encoder PPR and IO board frames) the layout
is ours, and the DBC and the README say so.

All multi-byte fields are little-endian. Device ids:

* Roboteq FBL2360, CANopen node n (``motor_drives/driveN/node``, 1..127): RxPDO1..4 at
  0x200/0x300/0x400/0x500 + n (to the controller), TxPDO1..4 at 0x180/0x280/0x380/0x480 + n,
  heartbeat 0x700 + n, SDO 0x580 / 0x600 + n.
* KC battery id k (``batteries/batN/id``, 1..15): TPDO1..3 at 0x3C0/0x3D0/0x3E0 + k.
* IO board id i (``io/ioN/id``, 0..15): state at 0x6A0 + i, relay command at 0x690 + i (ours).
"""

import math
import os
import struct
from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple

from ..errors import MalformedFrame

_SOURCE = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))


def dbc_path() -> str:
    """thorvald_base/can/thorvald.dbc, where rospack finds the package (or in the source tree)."""
    from thorvald_model.resources import package_folder  # noqa: PLC0415

    return os.path.join(package_folder("thorvald_base", _SOURCE), "can", "thorvald.dbc")


# ---- identifiers ----------------------------------------------------------------------------
RX_PDO1 = 0x200  # [command_seq, prop_cmd]: propulsion command (channel 1)
RX_PDO2 = 0x300  # [setup_id, value]: the setup map
RX_PDO3 = 0x400  # [mode, mode]
RX_PDO4 = 0x500  # [steer_max_speed_counts, steer_cmd]; prop/prop: [command_seq, prop_cmd channel 2] (ours)
TX_PDO1 = 0x180  # speeds and steering counts
TX_PDO2 = 0x280  # motor amps and relative power
TX_PDO3 = 0x380  # status flags, temperature, battery amps and volts
TX_PDO4 = 0x480  # multiplexed by byte 3: 1 homing setup, 2 script type and version, 3 encoder PPRs
HEARTBEAT = 0x700
SDO_TX = 0x580
SDO_RX = 0x600
ROBOTEQ_FUNCTIONS = (RX_PDO1, RX_PDO2, RX_PDO3, RX_PDO4, TX_PDO1, TX_PDO2, TX_PDO3, TX_PDO4, HEARTBEAT, SDO_TX, SDO_RX)

BATTERY_TPDO1 = 0x3C0
BATTERY_TPDO2 = 0x3D0
BATTERY_TPDO3 = 0x3E0
BATTERY_FUNCTIONS = (BATTERY_TPDO1, BATTERY_TPDO2, BATTERY_TPDO3)
MAX_BATTERY_ID = 15

IO_COMMAND = 0x690  # ours
IO_STATE = 0x6A0  # ours
IO_FUNCTIONS = (IO_COMMAND, IO_STATE)
MAX_IO_ID = 15
IO_RELAYS = 2  # rl0, rl1
IO_ANALOG_INPUTS = 3

MAX_NODE = 127
COMMAND_FULL_SCALE = 1000  # a propulsion or steering command of +-1000 is full scale


# ---- script types (TxPDO4 type 2, byte 4; ours) -----------------------------------------------
SCRIPT_PROP_STEER = 1
SCRIPT_PROP_PROP = 2
SCRIPT_NAMES = {SCRIPT_PROP_STEER: "RoboteqFbl2360", SCRIPT_PROP_PROP: "RoboteqFbl2360Diff"}

# The setup map (RxPDO2 setup ids), as the original's ~setup_motor_controller prints it.
SETUP_MAP = (
    "print map",
    "drive direction (permanent)",
    "home count (permanent)",
    "home speed (permanent)",
    "max prop speed",
    "max prop accel",
    "max steer speed",
    "max steer accel",
    "tpdo1 cycle time",
    "tpdo2 cycle time",
    "tpdo3 cycle time",
    "tpdo4 cycle time",
)
SETUP_HOME_COUNT = 2

# TxPDO3 byte 0, most significant bit first; the last is sent as "ok" and reported as "not ok".
STATUS_FLAGS = (
    "prop_enc_fail",
    "steer_enc_fail",
    "alignment_fail",
    "power_stage_off",
    "stall_detected",
    "homing_reached_max_count",
    "illegal_command",
    "controller_not_ok",
)

# KC battery alarm bits (TPDO1 [4:5]) -> thorvald_msgs/BatteryAlarms field names.
BATTERY_ALARMS = {
    0: "over_voltage_protection",
    1: "under_voltage_protection",
    2: "over_temperature_protection",
    3: "under_temperature_protection",
    4: "over_charge_current",
    5: "over_discharge_current",
    7: "can_communication_fail",
    9: "cell_voltage_sensing_fault",
    10: "bms_fail",
    11: "short_circuit_discharge",
    12: "temperature_sensing_fault",
    13: "over_voltage_fault",
    14: "under_voltage_fault",
    15: "pack_voltage_sensing_fault",
}

HEARTBEAT_OPERATIONAL = 0x05

_II = struct.Struct("<ii")
_HHI = struct.Struct("<hhi")
_Hxxi = struct.Struct("<hxxi")
_HHHH = struct.Struct("<hhhh")
_BBhhh = struct.Struct("<BBhhh")
_BBhHbb = struct.Struct("<BBhHbb")
_bbbbhbB = struct.Struct("<bbbbhbB")
_BBHHxx = struct.Struct("<BBHHxx")
_BBHHH = struct.Struct("<BBHHH")
_BB = struct.Struct("<BBxxxxxx")


# ---- scalings: physical <-> raw, per drive --------------------------------------------------
@dataclass(frozen=True)
class DriveScaling:
    """A drive's conversions between physical units and the controller's numbers.

    From the configuration: ``r_wheel``, ``prp_gr_rt``, ``prp_max_rpm``, ``str_gr_rt``,
    ``str_enc_ppr``, ``str_lim`` (the reference's section 8), ``prp_enc_ppr``.
    """

    r_wheel: float  # [m]
    prp_gr_rt: float
    prp_max_rpm: float  # motor rpm at a command of 1000
    str_gr_rt: float
    str_enc_ppr: int
    str_lim: float  # [rad] at a steering command of 1000
    prp_enc_ppr: int = 1024  # propulsion encoder pulses per motor revolution

    @classmethod
    def of(cls, drive) -> "DriveScaling":
        """For a thorvald_model.config.Drive."""
        return cls(
            drive.r_wheel,
            drive.prp_gr_rt,
            drive.prp_max_rpm,
            drive.str_gr_rt,
            drive.str_enc_ppr,
            drive.str_lim,
            drive.prp_enc_ppr,
        )

    # propulsion
    def motor_rpm(self, speed: float) -> float:
        """Motor rpm for a wheel rim speed [m/s]."""
        return speed / self.r_wheel * self.prp_gr_rt * 30.0 / math.pi

    def wheel_speed(self, motor_rpm: float) -> float:
        """Wheel rim speed [m/s] for a motor rpm."""
        return motor_rpm / self.prp_gr_rt * math.pi / 30.0 * self.r_wheel

    @property
    def wheel_counts_per_radian(self) -> float:
        """Propulsion encoder counts (quadrature, x4) per radian of the wheel."""
        return self.prp_enc_ppr * 4 * self.prp_gr_rt / (2.0 * math.pi)

    def prop_command(self, speed: float) -> int:
        """RxPDO1's prop_cmd: motor rpm scaled so that +-1000 = +-prp_max_rpm, clamped to +-1000."""
        raw = self.motor_rpm(speed) * COMMAND_FULL_SCALE / self.prp_max_rpm
        return round(max(-COMMAND_FULL_SCALE, min(COMMAND_FULL_SCALE, raw)))

    # steering
    @property
    def counts_per_radian(self) -> float:
        """Steering encoder counts (quadrature, x4) per radian of the steering."""
        return self.str_enc_ppr * 4 * self.str_gr_rt / (2.0 * math.pi)

    def steer_command(self, angle: float) -> int:
        """RxPDO4's steer_cmd: 1000 * angle / str_lim, clamped to +-1000."""
        raw = COMMAND_FULL_SCALE * angle / self.str_lim
        return round(max(-COMMAND_FULL_SCALE, min(COMMAND_FULL_SCALE, raw)))

    def steer_speed_counts(self, rate: float) -> int:
        """RxPDO4's steering speed limit [counts/s] for a rate [rad/s]."""
        return round(abs(rate) * self.counts_per_radian)

    def steering_angle(self, counts: int) -> float:
        """TxPDO1's steering counts -> angle [rad]."""
        return counts / self.counts_per_radian

    def steering_rate(self, motor_rpm: float) -> float:
        """TxPDO1's steering speed (steering motor rpm, ours) -> steering rate [rad/s]."""
        return motor_rpm / self.str_gr_rt * math.pi / 30.0


# ---- Roboteq: frames to the controller ------------------------------------------------------
def encode_pair(a: int, b: int) -> bytes:
    """RxPDO payloads: two little-endian int32."""
    return _II.pack(_int32(a), _int32(b))


def decode_pair(data: bytes) -> Tuple[int, int]:
    _length(data, 8)
    return _II.unpack(bytes(data))


# ---- Roboteq: frames from the controller ----------------------------------------------------
@dataclass(frozen=True)
class TxPdo1:
    """TxPDO1 of a prop/steer controller (a type-0 drive)."""

    prop_rpm: int  # propulsion motor rpm
    steer_rpm: int  # steering motor rpm (ours)
    steer_counts: int  # steering encoder counts


@dataclass(frozen=True)
class TxPdo1Diff:
    """TxPDO1 of a prop/prop controller (a pair of type-1 drives): channel 1's rpm in bytes 0-1,
    channel 2's in bytes 4-7 (reference notes 3.3, RoboteqFbl2360Diff), bytes 2-3 unused."""

    prop_rpm_1: int
    prop_rpm_2: int


@dataclass(frozen=True)
class TxPdo2:
    amps: Tuple[float, float]  # motor amps, channels 1 and 2 [A]
    power: Tuple[int, int]  # relative power, channels 1 and 2 [per mille]


@dataclass(frozen=True)
class TxPdo3:
    flags: Tuple[Tuple[str, bool], ...]  # STATUS_FLAGS, True when set
    max_temperature: int  # [degC]
    battery_amps: float  # [A]
    battery_volts: float  # [V]


@dataclass(frozen=True)
class TxPdo4:
    type: int  # 1 homing setup, 2 script, 3 encoder PPRs
    home_speed: int = 0
    drive_direction: int = 0
    home_count: int = 0
    script_type: int = 0
    version: str = ""
    prop_enc_ppr: int = 0
    str_enc_ppr: int = 0


def encode_tx_pdo1(m: TxPdo1) -> bytes:
    return _HHI.pack(_int16(m.prop_rpm), _int16(m.steer_rpm), _int32(m.steer_counts))


def decode_tx_pdo1(data: bytes) -> TxPdo1:
    _length(data, 8)
    return TxPdo1(*_HHI.unpack(bytes(data)))


def encode_tx_pdo1_diff(m: TxPdo1Diff) -> bytes:
    return _Hxxi.pack(_int16(m.prop_rpm_1), _int32(m.prop_rpm_2))


def decode_tx_pdo1_diff(data: bytes) -> TxPdo1Diff:
    _length(data, 8)
    return TxPdo1Diff(*_Hxxi.unpack(bytes(data)))


def encode_tx_pdo2(m: TxPdo2) -> bytes:
    return _HHHH.pack(
        _int16(round(m.amps[0] * 10)), _int16(round(m.amps[1] * 10)), _int16(m.power[0]), _int16(m.power[1])
    )


def decode_tx_pdo2(data: bytes) -> TxPdo2:
    _length(data, 8)
    a1, a2, p1, p2 = _HHHH.unpack(bytes(data))
    return TxPdo2((a1 / 10.0, a2 / 10.0), (p1, p2))


def encode_tx_pdo3(m: TxPdo3) -> bytes:
    values = dict(m.flags)
    byte = 0
    for bit, name in enumerate(STATUS_FLAGS):
        set_ = bool(values.get(name, False))
        if name == "controller_not_ok":
            set_ = not set_  # the controller sends "ok"
        if set_:
            byte |= 0x80 >> bit
    return _BBhhh.pack(
        byte, 0, _int16(m.max_temperature), _int16(round(m.battery_amps * 10)), _int16(round(m.battery_volts * 10))
    )


def decode_tx_pdo3(data: bytes) -> TxPdo3:
    _length(data, 8)
    byte, _, temperature, amps, volts = _BBhhh.unpack(bytes(data))
    flags = []
    for bit, name in enumerate(STATUS_FLAGS):
        set_ = bool(byte & (0x80 >> bit))
        flags.append((name, not set_ if name == "controller_not_ok" else set_))
    return TxPdo3(tuple(flags), temperature, amps / 10.0, volts / 10.0)


def encode_tx_pdo4(m: TxPdo4) -> bytes:
    out = bytearray(8)
    out[3] = m.type
    if m.type == 1:
        struct.pack_into("<h", out, 0, _int16(m.home_speed))
        out[2] = m.drive_direction & 0xFF
        struct.pack_into("<i", out, 4, _int32(m.home_count))
    elif m.type == 2:
        major, minor, patch = (int(x) for x in m.version.split("."))
        out[4] = m.script_type & 0xFF
        out[5], out[6], out[7] = patch & 0xFF, minor & 0xFF, major & 0xFF
    elif m.type == 3:
        struct.pack_into("<HH", out, 4, m.prop_enc_ppr & 0xFFFF, m.str_enc_ppr & 0xFFFF)
    else:
        raise ValueError(f"TxPDO4 type {m.type}: must be 1, 2 or 3")
    return bytes(out)


def decode_tx_pdo4(data: bytes) -> TxPdo4:
    _length(data, 8)
    data = bytes(data)
    kind = data[3]
    if kind == 1:
        (speed,) = struct.unpack_from("<h", data, 0)
        (count,) = struct.unpack_from("<i", data, 4)
        direction = data[2] - 256 if data[2] > 127 else data[2]
        return TxPdo4(1, home_speed=speed, drive_direction=direction, home_count=count)
    if kind == 2:
        return TxPdo4(2, script_type=data[4], version=f"{data[7]}.{data[6]}.{data[5]}")
    if kind == 3:
        prop, steer = struct.unpack_from("<HH", data, 4)
        return TxPdo4(3, prop_enc_ppr=prop, str_enc_ppr=steer)
    raise MalformedFrame(f"TxPDO4 message type {kind}: unknown (1, 2 or 3)")


# ---- KC battery -----------------------------------------------------------------------------
@dataclass(frozen=True)
class BatteryTpdo1:
    charge_fet_on: bool
    discharge_fet_on: bool
    voltage: float  # [V]
    alarms: int  # bit field, BATTERY_ALARMS
    temperatures: Tuple[int, int]  # temperatures 0 and 1 [degC]


@dataclass(frozen=True)
class BatteryTpdo2:
    temperatures: Tuple[int, int, int, int, int]  # temperatures 2..6 [degC]
    current: float  # [A], positive charging


@dataclass(frozen=True)
class BatteryTpdo3:
    state_of_charge: int  # [%]
    state_of_health: int  # [%]
    cycle_count: int
    capacity: float  # [Ah] (ours: [4:5] in 0.1 Ah; the original read it from the cycle count's bytes)


def encode_battery_tpdo1(m: BatteryTpdo1) -> bytes:
    fets = (1 if m.charge_fet_on else 0) | (2 if m.discharge_fet_on else 0)
    return _BBhHbb.pack(
        0, fets, _int16(round(m.voltage * 100)), m.alarms & 0xFFFF, _int8(m.temperatures[0]), _int8(m.temperatures[1])
    )


def decode_battery_tpdo1(data: bytes) -> BatteryTpdo1:
    _length(data, 8)
    _, fets, volts, alarms, t0, t1 = _BBhHbb.unpack(bytes(data))
    return BatteryTpdo1(bool(fets & 1), bool(fets & 2), volts / 100.0, alarms, (t0, t1))


def encode_battery_tpdo2(m: BatteryTpdo2) -> bytes:
    t = [_int8(x) for x in m.temperatures]
    return _bbbbhbB.pack(t[0], t[1], t[2], t[3], _int16(round(m.current * 100)), t[4], 0)


def decode_battery_tpdo2(data: bytes) -> BatteryTpdo2:
    _length(data, 8)
    t2, t3, t4, t5, current, t6, _ = _bbbbhbB.unpack(bytes(data))
    return BatteryTpdo2((t2, t3, t4, t5, t6), current / 100.0)


def encode_battery_tpdo3(m: BatteryTpdo3) -> bytes:
    return _BBHHxx.pack(
        _uint8(m.state_of_charge), _uint8(m.state_of_health), m.cycle_count & 0xFFFF, round(m.capacity * 10) & 0xFFFF
    )


def decode_battery_tpdo3(data: bytes) -> BatteryTpdo3:
    _length(data, 8)
    soc, soh, cycles, capacity = _BBHHxx.unpack(bytes(data))
    return BatteryTpdo3(soc, soh, cycles, capacity / 10.0)


def battery_alarm_names(bits: int) -> Tuple[str, ...]:
    return tuple(name for bit, name in sorted(BATTERY_ALARMS.items()) if bits & (1 << bit))


# ---- IO boards (ours) -----------------------------------------------------------------------
@dataclass(frozen=True)
class IoState:
    relays: Tuple[bool, ...]  # rl0, rl1
    type: int
    analog: Tuple[float, ...]  # [V], three inputs


def encode_io_command(relays: Dict[int, bool]) -> bytes:
    """Relay command: byte 0 the states, byte 1 the mask of relays to set (others unchanged)."""
    states = mask = 0
    for k, on in relays.items():
        if not 0 <= k < IO_RELAYS:
            raise ValueError(f"relay {k}: an IO board has relays 0..{IO_RELAYS - 1}")
        mask |= 1 << k
        states |= (1 << k) if on else 0
    return _BB.pack(states, mask)


def decode_io_command(data: bytes) -> Dict[int, bool]:
    _length(data, 8)
    states, mask = data[0], data[1]
    return {k: bool(states & (1 << k)) for k in range(IO_RELAYS) if mask & (1 << k)}


def encode_io_state(m: IoState) -> bytes:
    bits = sum(1 << k for k, on in enumerate(m.relays) if on)
    mv = [max(0, min(0xFFFF, round(v * 1000))) for v in m.analog]
    return _BBHHH.pack(bits, m.type & 0xFF, *mv)


def decode_io_state(data: bytes) -> IoState:
    _length(data, 8)
    bits, kind, a0, a1, a2 = _BBHHH.unpack(bytes(data))
    return IoState(tuple(bool(bits & (1 << k)) for k in range(IO_RELAYS)), kind, (a0 / 1000, a1 / 1000, a2 / 1000))


# ---- the ids a robot's devices own ----------------------------------------------------------
def roboteq_ids(node: int) -> List[int]:
    return [f + node for f in ROBOTEQ_FUNCTIONS]


def battery_ids(battery_id: int) -> List[int]:
    return [f + battery_id for f in BATTERY_FUNCTIONS]


def io_ids(io_id: int) -> List[int]:
    return [f + io_id for f in IO_FUNCTIONS]


def device_ids(nodes: Sequence[int], batteries: Sequence[int], ios: Sequence[int]) -> Dict[int, str]:
    """Every CAN id the base's devices own -> the device's name; ValueError naming both on a clash."""
    owners: Dict[int, str] = {}
    groups = (
        [(f"motor controller node {n}", roboteq_ids(n)) for n in nodes]
        + [(f"battery {b}", battery_ids(b)) for b in batteries]
        + [(f"IO board {i}", io_ids(i)) for i in ios]
    )
    for name, ids in groups:
        for can_id in ids:
            other = owners.get(can_id)
            if other is not None and other != name:
                raise ValueError(f"CAN id 0x{can_id:03X} belongs to both {other} and {name}")
            owners[can_id] = name
    return owners


def function_of(can_id: int, owner: str) -> Optional[str]:
    """A readable name of a device frame (``TxPDO1`` ...), for logs."""
    names = {
        RX_PDO1: "RxPDO1",
        RX_PDO2: "RxPDO2",
        RX_PDO3: "RxPDO3",
        RX_PDO4: "RxPDO4",
        TX_PDO1: "TxPDO1",
        TX_PDO2: "TxPDO2",
        TX_PDO3: "TxPDO3",
        TX_PDO4: "TxPDO4",
        HEARTBEAT: "heartbeat",
        SDO_TX: "SDO tx",
        SDO_RX: "SDO rx",
    }
    if owner.startswith("motor controller"):
        node = int(owner.rsplit(" ", 1)[1])
        return names.get(can_id - node)
    return None


# ---- range helpers --------------------------------------------------------------------------
def _length(data: bytes, n: int) -> None:
    if len(data) != n:
        raise MalformedFrame(f"{len(data)} data bytes, the layout has {n}")


def _clamp(value: int, lo: int, hi: int) -> int:
    return lo if value < lo else hi if value > hi else value


def _int32(v) -> int:
    return _clamp(int(v), -(2**31), 2**31 - 1)


def _int16(v) -> int:
    return _clamp(int(v), -(2**15), 2**15 - 1)


def _int8(v) -> int:
    return _clamp(int(v), -128, 127)


def _uint8(v) -> int:
    return _clamp(int(v), 0, 255)
