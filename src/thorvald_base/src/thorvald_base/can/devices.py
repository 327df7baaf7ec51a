"""The base's CAN devices as base_driver sees them: what they were told, what they last reported.

No bus here: a device ``claim``s a received frame (updating its state from it) and makes the frames
to send. Times are seconds of the caller's clock (base_driver's cycle time). A device silent for
LOST_AFTER seconds is in lost connection until it is heard again; any frame it owns counts.
"""

from typing import Dict, List, Optional, Sequence, Tuple, Union

from ..errors import MalformedFrame
from ..kinematics import DriveCommand
from ..modes import MODE_PRE_INITIATION
from . import protocol as pr

LOST_AFTER = 2.0  # [s] without a frame from a device
# A motor controller's speeds (TxPDO1) older than REPORT_PERIODS of its own report period, and at
# least MIN_REPORT_TIMEOUT, are unheard: odometry leaves them out long before the device is lost.
REPORT_PERIODS = 5
MIN_REPORT_TIMEOUT = 0.2  # [s]: a busy machine delays a 50 Hz report by a cycle or two, not by 10


class Device:
    name = ""

    def __init__(self, ids: Sequence[int]):
        self.ids = frozenset(ids)
        self.last_heard: Optional[float] = None
        self.malformed = 0

    def online(self, time: float) -> bool:
        return self.last_heard is not None and time - self.last_heard <= LOST_AFTER

    def claim(self, can_id: int, data: bytes, time: float) -> bool:
        """Takes the frame if this device owns can_id (a malformed one is counted, not decoded)."""
        if can_id not in self.ids:
            return False
        self.last_heard = time
        try:
            self._decode(can_id, bytes(data))
        except MalformedFrame:
            self.malformed += 1
        return True

    def _decode(self, can_id: int, data: bytes) -> None:
        raise NotImplementedError


class MotorController(Device):
    """One Roboteq FBL2360: a type-0 drive (prop/steer) or a pair of type-1 drives (prop/prop)."""

    def __init__(self, controller):
        """controller: the configuration's (thorvald_model MotorController): node, drives, indices."""
        super().__init__(pr.roboteq_ids(controller.node))
        self.node = controller.node
        self.drives = list(controller.drives)  # thorvald_model Drive, channel order
        self.indices = list(controller.indices)  # their places in the robot's drive order
        self.steered = controller.steered
        self.scalings = [pr.DriveScaling.of(d) for d in self.drives]
        self.name = self.drives[0].name
        self.sequence = 0
        self.tx1: Optional[Union[pr.TxPdo1, pr.TxPdo1Diff]] = None
        self.tx2: Optional[pr.TxPdo2] = None
        self.tx3: Optional[pr.TxPdo3] = None
        self.homing_setup: Optional[pr.TxPdo4] = None
        self.script: Optional[pr.TxPdo4] = None
        self.encoders: Optional[pr.TxPdo4] = None
        self.mode = MODE_PRE_INITIATION  # RxPDO3 takes the BaseState modes
        self.tx1_time: Optional[float] = None  # [s] when its speeds last came
        self.report_period: Optional[float] = None  # [s] between its speeds, a running mean

    def set_drives(self, drives: Sequence) -> None:
        self.drives = list(drives)
        self.scalings = [pr.DriveScaling.of(d) for d in self.drives]

    # ---- to the controller ---------------------------------------------------------------------
    def command_frames(self, commands: Sequence[DriveCommand]) -> List[Tuple[int, bytes]]:
        """RxPDO1 and RxPDO4 for this controller's drives' commands (channel order)."""
        self.sequence = (self.sequence + 1) & 0x7FFFFFFF
        first = self.scalings[0]
        frames = [(pr.RX_PDO1 + self.node, pr.encode_pair(self.sequence, first.prop_command(commands[0].speed)))]
        if self.steered:
            limit = first.steer_speed_counts(self.drives[0].max_steering_speed)
            frames.append((pr.RX_PDO4 + self.node, pr.encode_pair(limit, first.steer_command(commands[0].steering))))
        else:
            second = self.scalings[-1].prop_command(commands[-1].speed) if len(commands) > 1 else 0
            frames.append((pr.RX_PDO4 + self.node, pr.encode_pair(self.sequence, second)))
        return frames

    def mode_frame(self, mode: int) -> Tuple[int, bytes]:
        return pr.RX_PDO3 + self.node, pr.encode_pair(mode, mode)

    def setup_frame(self, setup_id: int, value: int) -> Tuple[int, bytes]:
        return pr.RX_PDO2 + self.node, pr.encode_pair(setup_id, value)

    # ---- from the controller -------------------------------------------------------------------
    def _decode(self, can_id: int, data: bytes) -> None:
        function = can_id - self.node
        if function == pr.TX_PDO1:
            self.tx1 = pr.decode_tx_pdo1(data) if self.steered else pr.decode_tx_pdo1_diff(data)
            self._speeds_came(self.last_heard)
        elif function == pr.TX_PDO2:
            self.tx2 = pr.decode_tx_pdo2(data)
        elif function == pr.TX_PDO3:
            self.tx3 = pr.decode_tx_pdo3(data)
        elif function == pr.TX_PDO4:
            m = pr.decode_tx_pdo4(data)
            if m.type == 1:
                self.homing_setup = m
            elif m.type == 2:
                self.script = m
            else:
                self.encoders = m
        # heartbeat, SDO and the frames to the controller (seen on a shared bus) only refresh it

    def _speeds_came(self, time: float) -> None:
        if self.tx1_time is not None and 0.0 < time - self.tx1_time <= LOST_AFTER:
            # frames read in one cycle share its time: only the cycles' gaps count
            interval = time - self.tx1_time
            self.report_period = interval if self.report_period is None else 0.9 * self.report_period + 0.1 * interval
        self.tx1_time = time

    def speeds_heard(self, time: float) -> bool:
        """Whether its speeds and steering (TxPDO1) are recent enough to measure the motion at time [s]."""
        if self.tx1_time is None:
            return False
        timeout = max(MIN_REPORT_TIMEOUT, REPORT_PERIODS * (self.report_period or 0.0))
        return time - self.tx1_time <= timeout

    def measured(self) -> List[Tuple[float, float, float]]:
        """(steering [rad], steering rate [rad/s], wheel rim speed [m/s]) per drive, channel order."""
        if self.tx1 is None:
            return [(0.0, 0.0, 0.0) for _ in self.drives]
        s = self.scalings
        if self.steered:
            return [
                (
                    s[0].steering_angle(self.tx1.steer_counts),
                    s[0].steering_rate(self.tx1.steer_rpm),
                    s[0].wheel_speed(self.tx1.prop_rpm),
                )
            ]
        rpms = (self.tx1.prop_rpm_1, self.tx1.prop_rpm_2)
        return [(0.0, 0.0, scaling.wheel_speed(rpm)) for scaling, rpm in zip(s, rpms)]

    @property
    def type_name(self) -> str:
        expected = pr.SCRIPT_PROP_STEER if self.steered else pr.SCRIPT_PROP_PROP
        return pr.SCRIPT_NAMES[expected]

    @property
    def script_mismatch(self) -> Optional[str]:
        """Why the controller's script does not fit the drive it serves, if it does not."""
        if self.script is None:
            return None
        expected = pr.SCRIPT_PROP_STEER if self.steered else pr.SCRIPT_PROP_PROP
        if self.script.script_type != expected:
            got = pr.SCRIPT_NAMES.get(self.script.script_type, f"type {self.script.script_type}")
            return f"node {self.node} runs the {got} script; {self.name} needs {pr.SCRIPT_NAMES[expected]}"
        return None


class Battery(Device):
    def __init__(self, config_battery):
        super().__init__(pr.battery_ids(config_battery.id))
        self.id = config_battery.id
        self.name = config_battery.name
        self.tpdo1: Optional[pr.BatteryTpdo1] = None
        self.tpdo2: Optional[pr.BatteryTpdo2] = None
        self.tpdo3: Optional[pr.BatteryTpdo3] = None

    def _decode(self, can_id: int, data: bytes) -> None:
        function = can_id - self.id
        if function == pr.BATTERY_TPDO1:
            self.tpdo1 = pr.decode_battery_tpdo1(data)
        elif function == pr.BATTERY_TPDO2:
            self.tpdo2 = pr.decode_battery_tpdo2(data)
        else:
            self.tpdo3 = pr.decode_battery_tpdo3(data)


class IoBoard(Device):
    def __init__(self, config_board):
        super().__init__([pr.IO_STATE + config_board.id])  # its command id is ours to send, not to claim
        self.id = config_board.id
        self.type = config_board.type
        self.name = config_board.name
        self.initial = {0: config_board.rl0_init_state, 1: config_board.rl1_init_state}
        self.state: Optional[pr.IoState] = None

    def _decode(self, can_id: int, data: bytes) -> None:
        self.state = pr.decode_io_state(data)

    def command_frame(self, relays: Dict[int, bool]) -> Tuple[int, bytes]:
        return pr.IO_COMMAND + self.id, pr.encode_io_command(relays)
