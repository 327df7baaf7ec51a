"""A robot's CAN devices, emulated: every motor controller, KC battery and IO board of a robot file.

It plays the devices' side of the bus that base_driver's CAN base talks to: motor controllers
follow their commands with the configuration's ramps (``prp_sim_a``, the steering's speed limit),
count encoder ticks, report currents, temperatures and flags, send heartbeats; batteries
discharge with the current the motors draw; IO boards switch their relays. Frames go through the
DBC description (``thorvald_base/can/thorvald.dbc``, with cantools) and the emulator's own unit
conversions, never through base_driver's codec: a wrong scaling in either would show in the tests
instead of cancelling out.

Faults: ``silence(device)`` (no frames from it until ``resume``), ``corrupt(n)`` (the next n
frames sent are malformed: a wrong length or an unknown TxPDO4 type), ``drop_bus()`` (the bus
is shut down; ``step`` then does nothing until ``attach`` gives it a new one).

No ROS here; ``can_emulator_node`` wraps it. Times are seconds of the caller's clock.
"""

import logging
import math
import random
from dataclasses import dataclass, field
from typing import Dict, List, Optional

import can
import cantools

from thorvald_model.schema import keys_of
from thorvald_model.values import Battery

TPDO1_PERIOD = 0.02  # [s] speeds and counts
TPDO2_PERIOD = 0.1  # [s] amps and power; TPDO3 status
STATUS_PERIOD = 1.0  # [s] TPDO4 (homing setup, script, PPRs), heartbeat, batteries, IO states
SCRIPT_VERSION = (2, 1, 0)  # major, minor, patch the emulated script reports
BATTERY_KEYS = {k.name: k for k in keys_of(Battery)}  # the robot file's battery keys, their defaults
EMPTY_VOLTS = 44.0 / 48.0  # of a pack's nominal voltage when empty (a 48 V lithium pack: 44 V)
FULL_VOLTS = 54.0 / 48.0  # and when full (54 V)
RX_MESSAGES = {0x200: "Roboteq_RxPDO1", 0x300: "Roboteq_RxPDO2", 0x400: "Roboteq_RxPDO3", 0x500: "Roboteq_RxPDO4"}


class _SameIdentifierVariants(logging.Filter):
    """cantools says when two messages share an identifier; in thorvald.dbc a prop/prop controller's
    TxPDO1 (RoboteqDiff_) shares the prop/steer one's on purpose: messages are looked up by name."""

    def filter(self, record):
        return "RoboteqDiff_" not in record.getMessage()


def load_dbc(path: Optional[str] = None):
    if path is None:
        from thorvald_base.can.protocol import dbc_path  # noqa: PLC0415  (where the file is, not how to read it)

        path = dbc_path()
    log = logging.getLogger("cantools.database.can.database")
    variants = _SameIdentifierVariants()
    log.addFilter(variants)
    try:
        return cantools.database.load_file(path)
    finally:
        log.removeFilter(variants)


@dataclass
class EmulatedDrive:
    """One channel of a controller: the motor behind one drive of the robot file."""

    drive: object  # thorvald_model Drive
    speed: float = 0.0  # wheel rim [m/s]
    target: float = 0.0  # [m/s]
    steering: float = 0.0  # [rad]
    steering_target: float = 0.0  # [rad]
    steering_rate: float = 0.0  # [rad/s]
    steering_limit: float = 0.0  # [rad/s] from the last RxPDO4, 0 until one arrives

    # the emulator's own conversions (from the robot file's fields), kept apart from base_driver's
    def rpm_of(self, speed: float) -> float:
        d = self.drive
        return speed * d.prp_gr_rt * 60.0 / (2.0 * math.pi * d.r_wheel)

    def speed_of_command(self, command: int) -> float:
        d = self.drive
        motor_rpm = command / 1000.0 * d.prp_max_rpm
        return motor_rpm / d.prp_gr_rt / 60.0 * 2.0 * math.pi * d.r_wheel

    def counts(self) -> int:
        d = self.drive
        return round(self.steering / (2.0 * math.pi) * d.str_enc_ppr * 4.0 * d.str_gr_rt)

    def rate_of_counts(self, counts_per_second: int) -> float:
        d = self.drive
        return counts_per_second / (d.str_enc_ppr * 4.0 * d.str_gr_rt) * 2.0 * math.pi


@dataclass
class EmulatedController:
    node: int
    channels: List[EmulatedDrive]
    steered: bool
    mode: int = 3  # online
    home_count: int = 0
    home_speed: int = 100
    drive_direction: int = 1
    last_sequence: Optional[int] = None
    commands: int = 0
    setups: List[tuple] = field(default_factory=list)
    silent: bool = False

    @property
    def name(self) -> str:
        return self.channels[0].drive.name


@dataclass
class EmulatedBattery:
    id: int
    capacity: float  # [Ah] the robot file's (batteries.batN.capacity)
    voltage: float  # [V] nominal, the robot file's
    state_of_charge: float = 95.0  # [%]
    current: float = 0.0  # [A], negative discharging
    alarms: int = 0
    silent: bool = False


@dataclass
class EmulatedIo:
    id: int
    type: int
    relays: List[bool]
    analog: List[float] = field(default_factory=lambda: [12.0, 5.0, 0.0])  # [V]
    silent: bool = False


class CanEmulator:
    """The devices of one robot configuration (a thorvald_model RobotConfig) on a python-can bus."""

    def __init__(self, config, bus: Optional[can.BusABC], dbc=None, seed: int = 0):
        self.config = config
        self.bus = bus
        self.db = dbc or load_dbc()
        self.rng = random.Random(seed)
        # the robot's devices as the configuration says (the loader's facts; the frames stay the DBC's)
        self.controllers = {
            c.node: EmulatedController(c.node, [EmulatedDrive(d) for d in c.drives], c.steered)
            for c in config.motor_controllers
        }
        self.batteries = {b.id: EmulatedBattery(b.id, b.capacity, b.voltage) for b in config.present_batteries}
        # what the motor controllers read as their supply without a battery on the bus: the enclosures' nominal
        self.nominal_volts = config.batteries[0].voltage if config.batteries else BATTERY_KEYS["voltage"].default
        self.ios = {b.id: EmulatedIo(b.id, b.type, [False, False]) for b in config.io_boards_on_bus}
        self.to_corrupt = 0
        self.sent = 0
        self.received = 0
        self.ignored = 0
        self._last: Optional[float] = None
        self._due: Dict[str, float] = {}
        self._messages = {m.name: m for m in self.db.messages}

    # ---- faults ------------------------------------------------------------------------------
    def device(self, name: str):
        """A device by name: a drive's name (its controller), ``node N``, ``battery K``, ``io I``."""
        kind, _, number = name.partition(" ")
        if kind == "node" and number.isdigit() and int(number) in self.controllers:
            return self.controllers[int(number)]
        if kind == "battery" and number.isdigit() and int(number) in self.batteries:
            return self.batteries[int(number)]
        if kind == "io" and number.isdigit() and int(number) in self.ios:
            return self.ios[int(number)]
        for c in self.controllers.values():
            if any(ch.drive.name == name for ch in c.channels):
                return c
        raise KeyError(f"no emulated device {name!r}")

    def silence(self, name: str) -> None:
        self.device(name).silent = True

    def resume(self, name: str) -> None:
        self.device(name).silent = False

    def corrupt(self, frames: int) -> None:
        self.to_corrupt += frames

    def drop_bus(self) -> None:
        if self.bus is not None:
            self.bus.shutdown()
        self.bus = None

    def attach(self, bus) -> None:
        self.bus = bus

    # ---- the loop ----------------------------------------------------------------------------
    def step(self, now: float) -> None:
        """Reads what arrived, moves the motors to now, sends the frames that are due."""
        if self.bus is None:
            return
        self._receive(now)
        dt = 0.0 if self._last is None else max(0.0, now - self._last)
        self._last = now
        self._move(dt)
        if self._is_due("tpdo1", now, TPDO1_PERIOD):
            for c in self.controllers.values():
                self._tpdo1(c)
        if self._is_due("tpdo2", now, TPDO2_PERIOD):
            for c in self.controllers.values():
                self._tpdo2(c)
                self._tpdo3(c)
        if self._is_due("status", now, STATUS_PERIOD):
            for c in self.controllers.values():
                self._tpdo4(c)
                self._send_raw(c, 0x700 + c.node, bytes([0x05]))
            for b in self.batteries.values():
                self._battery(b, dt=STATUS_PERIOD)
            for io in self.ios.values():
                self._io(io)

    def _is_due(self, what: str, now: float, period: float) -> bool:
        due = self._due.get(what)
        if due is None or now >= due - 1e-9:
            self._due[what] = now + period if due is None or now - due > period else due + period
            return True
        return False

    def _move(self, dt: float) -> None:
        for c in self.controllers.values():
            for ch in c.channels:
                target = 0.0 if c.mode == 1 else ch.target  # homing: wheels stopped
                step = ch.drive.prp_sim_a * dt if ch.drive.prp_sim_a > 0 else math.inf
                ch.speed = (
                    target if abs(target - ch.speed) <= step else ch.speed + math.copysign(step, target - ch.speed)
                )
                if c.steered:
                    goal = 0.0 if c.mode == 1 else ch.steering_target
                    limit = ch.steering_limit or ch.drive.str_sim_v
                    move = max(-limit * dt, min(limit * dt, goal - ch.steering))
                    ch.steering += move
                    ch.steering_rate = move / dt if dt > 0 else 0.0

    # ---- frames in ---------------------------------------------------------------------------
    def _receive(self, now: float) -> None:
        while True:
            try:
                msg = self.bus.recv(timeout=0.0)
            except can.CanError:
                return
            if msg is None:
                return
            self.received += 1
            self._handle(msg.arbitration_id, bytes(msg.data))

    def _handle(self, can_id: int, data: bytes) -> None:
        name = RX_MESSAGES.get(can_id & 0x780)  # CANopen: function code + node id (1..127)
        c = self.controllers.get(can_id & 0x7F) if name else None
        if c is not None and len(data) == 8:
            fields = self._messages[name].decode(data, decode_choices=False)
            if name == "Roboteq_RxPDO1":
                c.commands += 1
                c.last_sequence = fields["command_seq"]
                c.channels[0].target = c.channels[0].speed_of_command(fields["prop_cmd"])
            elif name == "Roboteq_RxPDO4":
                if c.steered:
                    ch = c.channels[0]
                    ch.steering_limit = ch.rate_of_counts(fields["steer_max_speed"])
                    ch.steering_target = fields["steer_cmd"] / 1000.0 * ch.drive.str_lim
                elif len(c.channels) > 1:  # prop/prop: channel 2's command where the steering's is
                    c.channels[1].target = c.channels[1].speed_of_command(fields["steer_cmd"])
            elif name == "Roboteq_RxPDO3":
                c.mode = int(fields["mode"])
            else:
                c.setups.append((int(fields["setup_id"]), int(fields["setup_value"])))
                if fields["setup_id"] == 2:
                    c.home_count = int(fields["setup_value"])
            return
        for io in self.ios.values():
            if can_id == 0x690 + io.id and len(data) == 8:
                fields = self._messages["IO_Command"].decode(data)
                for k in range(2):
                    if fields[f"set_rl{k}"]:
                        io.relays[k] = bool(fields[f"rl{k}"])
                return
        self.ignored += 1

    # ---- frames out --------------------------------------------------------------------------
    def _send(self, device, message: str, base_id: int, values: dict) -> None:
        self._send_raw(device, base_id, self._messages[message].encode(values, strict=False))

    def _send_raw(self, device, can_id: int, data: bytes) -> None:
        if device.silent or self.bus is None:
            return
        if self.to_corrupt > 0:
            self.to_corrupt -= 1
            if can_id & 0x780 == 0x480 and len(data) == 8:  # a TxPDO4 of an unknown type
                data = data[:3] + bytes([0x7F]) + data[4:]
            else:
                data = data[: self.rng.randrange(0, len(data))]  # too short
        try:
            self.bus.send(can.Message(arbitration_id=can_id, data=data, is_extended_id=False), timeout=0.01)
            self.sent += 1
        except can.CanError:
            pass

    def _tpdo1(self, c: EmulatedController) -> None:
        ch = c.channels[0]
        if c.steered:
            values = {
                "prop_rpm": round(ch.rpm_of(ch.speed)),
                "steer_rpm": round(self._steer_rpm(ch)),
                "steer_counts": ch.counts(),
            }
            self._send(c, "Roboteq_TxPDO1", 0x180 + c.node, values)
        else:
            second = c.channels[1] if len(c.channels) > 1 else None
            values = {
                "prop_rpm_1": round(ch.rpm_of(ch.speed)),
                "prop_rpm_2": round(second.rpm_of(second.speed)) if second else 0,
            }
            self._send(c, "RoboteqDiff_TxPDO1", 0x180 + c.node, values)

    @staticmethod
    def _steer_rpm(ch: EmulatedDrive) -> float:
        return ch.steering_rate * ch.drive.str_gr_rt * 60.0 / (2.0 * math.pi)

    def _amps(self, ch: EmulatedDrive) -> float:
        return 2.0 + 8.0 * abs(ch.speed)  # a rolling robot's motor current, roughly

    def _tpdo2(self, c: EmulatedController) -> None:
        a = [self._amps(ch) for ch in c.channels]
        if c.steered:
            a.append(1.0 + 5.0 * abs(c.channels[0].steering_rate))
        a += [0.0] * (2 - len(a))
        power = [round(1000 * ch.speed / ch.drive.max_wheel_speed) for ch in c.channels] if c.channels else []
        power += [0] * (2 - len(power))
        self._send(
            c,
            "Roboteq_TxPDO2",
            0x280 + c.node,
            {"motor_amps_1": a[0], "motor_amps_2": a[1], "relative_power_1": power[0], "relative_power_2": power[1]},
        )

    def _tpdo3(self, c: EmulatedController) -> None:
        volts = self._battery_volts()
        values = {s.name: 0 for s in self._messages["Roboteq_TxPDO3"].signals if s.length == 1}  # no fault flag
        values.update(
            controller_ok=1,
            max_temperature=35,
            battery_amps=sum(self._amps(ch) for ch in c.channels),
            battery_volts=volts,
        )
        self._send(c, "Roboteq_TxPDO3", 0x380 + c.node, values)

    def _tpdo4(self, c: EmulatedController) -> None:
        base = 0x480 + c.node
        d = c.channels[0].drive
        major, minor, patch = SCRIPT_VERSION
        self._send(
            c,
            "Roboteq_TxPDO4",
            base,
            {
                "message_type": 1,
                "home_speed": c.home_speed,
                "drive_direction": c.drive_direction,
                "home_count": c.home_count,
            },
        )
        self._send(
            c,
            "Roboteq_TxPDO4",
            base,
            {
                "message_type": 2,
                "script_type": 1 if c.steered else 2,
                "version_patch": patch,
                "version_minor": minor,
                "version_major": major,
            },
        )
        self._send(
            c, "Roboteq_TxPDO4", base, {"message_type": 3, "prop_enc_ppr": d.prp_enc_ppr, "str_enc_ppr": d.str_enc_ppr}
        )

    def _battery_volts(self) -> float:
        if not self.batteries:
            return self.nominal_volts
        weakest = min(self.batteries.values(), key=lambda b: b.state_of_charge)
        # a lithium pack between empty and full, linear in its charge: 44 V to 54 V for a 48 V pack
        share = weakest.state_of_charge / 100.0
        return weakest.voltage * (EMPTY_VOLTS + (FULL_VOLTS - EMPTY_VOLTS) * share)

    def _battery(self, b: EmulatedBattery, dt: float) -> None:
        draw = sum(self._amps(ch) for c in self.controllers.values() for ch in c.channels) / max(1, len(self.batteries))
        b.current = -draw
        b.state_of_charge = max(0.0, b.state_of_charge - draw * dt / 3600.0 / b.capacity * 100.0)
        base = b.id
        volts = self._battery_volts()
        alarms = {s.name: 0 for s in self._messages["Battery_TPDO1"].signals if s.length == 1 and "fet" not in s.name}
        if b.alarms & 2:
            alarms["under_voltage_protection"] = 1
        values = {"charge_fet_on": 0, "discharge_fet_on": 1, "voltage": volts, "temperature_0": 24, "temperature_1": 25}
        values.update(alarms)
        self._send(b, "Battery_TPDO1", 0x3C0 + base, values)
        self._send(
            b,
            "Battery_TPDO2",
            0x3D0 + base,
            {
                "temperature_2": 24,
                "temperature_3": 24,
                "temperature_4": 25,
                "temperature_5": 25,
                "current": b.current,
                "temperature_6": 26,
            },
        )
        self._send(
            b,
            "Battery_TPDO3",
            0x3E0 + base,
            {
                "state_of_charge": int(b.state_of_charge),
                "state_of_health": 97,
                "cycle_count": 42,
                "capacity": b.capacity,
            },
        )

    def _io(self, io: EmulatedIo) -> None:
        self._send(
            io,
            "IO_State",
            0x6A0 + io.id,
            {
                "rl0": int(io.relays[0]),
                "rl1": int(io.relays[1]),
                "board_type": io.type,
                "analog_0": io.analog[0],
                "analog_1": io.analog[1],
                "analog_2": io.analog[2],
            },
        )
