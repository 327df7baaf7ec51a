"""``can``: the real robot's base over a python-can bus (base_driver with ``simple_sim:=false``).

Each cycle base_driver sends the drive commands (RxPDO1 and RxPDO4 per motor controller), then
this handle sends the queued relay frames, reads everything the bus holds and routes it: a frame a
base device owns (batteries first, then motor controllers, then IO boards, as the original) updates
that device; the rest is kept for ``can_frames_device_r``. A motor controller silent for 2 s is in
lost connection: every wheel is then commanded to stop until it is heard again.

Parameters (base_driver's private ones): ``can_interface_type`` (any python-can interface:
``socketcan``, ``slcan``, ``virtual``, ``pcan`` ...), ``can_interface_name`` (its channel, e.g.
``can0`` or ``/dev/ttyACM0``), ``can_bitrate`` (for interfaces that set it, 1000000).
"""

import collections
import math
import time as wall
from dataclasses import dataclass
from typing import Deque, Dict, List, Optional, Sequence, Tuple

import can

from ..can import protocol as pr
from ..can.devices import Battery, IoBoard, MotorController
from ..can.outbox import Outbox, Waiting, write_refused
from ..diagnostics import LOST, NOT_HEARD_YET
from ..errors import ParameterError, ThorvaldBaseError
from ..kinematics import DriveCommand
from ..modes import BATTERY_ALARM, BATTERY_LOST, BATTERY_OK, MODE_DRIVE, MODE_HOME, MODE_LOST_CONNECTION, MODE_ONLINE
from ..params import DEFAULT_BITRATE
from .handle import BaseHandle, BatteryInfo, ControllerInfo, Frame, IoInfo, MeasuredDrive

# The original's enclosure-PCB USB bridges: their serial protocol was never published.
UNPUBLISHED_INTERFACES = ("enc_pcb_v1rev6", "enc_pcb_v2rev1")
RELAY_QUEUE_LIMIT = 100  # frames relayed per cycle; the original dropped its queue past 100
READ_LIMIT = 2000  # frames read per cycle at most (a flooded bus cannot stall the loop)
REOPEN_PERIOD = 1.0  # [s] of wall time between attempts to reopen a failed bus
# [s] of wall time a write may wait for room in a full buffer; what does not fit waits in the outbox
# for the next poll (base_driver polls two or three times a cycle), so a slow reader never holds its loop
WRITE_WAIT = 0.002
CLOSE_WAIT = 0.1  # [s] closing, for the last frames (the wheels' stop) to fit


@dataclass
class BusCounters:
    """What went wrong on the bus, for /diagnostics."""

    send_errors: int = 0  # writes that failed on a broken bus (it is then shut and reopened)
    writes_refused: int = 0  # writes a full buffer or a write timeout refused (the bus kept, retried)
    receive_errors: int = 0
    reopened: int = 0
    relay_dropped: int = 0
    relay_refused: int = 0
    unparsable: int = 0  # frames the interface could not parse
    last_error: str = ""
    last_refused: str = ""  # why the last refused write was refused


def _reason(error: BaseException) -> str:
    """An error and its causes in one line: python-can's message alone hides whether the buffer was full."""
    parts = []
    while error is not None and len(parts) < 4:
        parts.append(f"{type(error).__name__}: {error}")
        error = error.__cause__ or error.__context__
    return " <- ".join(parts)


def open_bus(interface: str, channel: str, bitrate: int = DEFAULT_BITRATE):
    """A python-can bus; ThorvaldBaseError with one clear line when it cannot be opened."""
    if interface in UNPUBLISHED_INTERFACES:
        raise ParameterError(
            f"~can_interface_type: {interface!r}: the original enclosure PCB's protocol was never published; "
            "use a python-can interface instead (socketcan with a USB-CAN adapter, slcan, pcan, ...)"
        )
    if not interface:
        raise ParameterError("~can_interface_type: empty: name a python-can interface (socketcan, slcan, pcan, ...)")
    if interface not in can.interfaces.VALID_INTERFACES:
        raise ParameterError(
            f"~can_interface_type: {interface!r}: not a python-can interface; known: "
            + ", ".join(sorted(can.interfaces.VALID_INTERFACES))
        )
    kwargs = {"interface": interface, "channel": channel or None}
    if interface in ("slcan", "pcan", "kvaser", "ixxat", "vector", "serial", "gs_usb", "nican", "neovi"):
        kwargs["bitrate"] = bitrate
    if interface == "virtual":
        kwargs["receive_own_messages"] = False
    try:
        if interface == "slcan":
            from ..can.slcan import BufferedSlcanBus  # noqa: PLC0415  (python-can 4.1 reads SLCAN bytewise)

            del kwargs["interface"]
            return BufferedSlcanBus(**kwargs)
        return can.Bus(**kwargs)
    except Exception as e:  # python-can raises what the interface's library raises
        raise ThorvaldBaseError(
            f"CAN bus {interface} {channel!r} will not open: {type(e).__name__}: {str(e) or 'no reason given'}"
        ) from None


class CanBase(BaseHandle):
    """The robot's motor controllers, batteries and IO boards on one CAN bus."""

    def __init__(self, config, bus, reopen=None):
        super().__init__(config)
        self.bus = bus
        self._reopen = reopen  # () -> a new bus, after bus errors
        self._next_reopen = 0.0  # [s] monotonic
        self.counters = BusCounters()
        self.controllers_ = [MotorController(c) for c in config.motor_controllers]
        self.batteries_ = [Battery(b) for b in config.present_batteries]
        self.ios = [IoBoard(b) for b in self.io_config]
        try:
            self.owned = pr.device_ids(
                [c.node for c in self.controllers_], [b.id for b in self.batteries_], [b.id for b in self.ios]
            )
        except ValueError as e:
            raise ParameterError(f"the robot's CAN devices: {e}") from None
        self.devices = [*self.batteries_, *self.controllers_, *self.ios]  # the original's routing order
        # ids never clash (device_ids), so one lookup routes a frame as the original's search would
        self.by_id = {can_id: d for d in self.devices for can_id in d.ids}
        self.relay_queue: Deque[Frame] = collections.deque()
        self.received_base: List[Frame] = []
        self.received_device: List[Frame] = []
        self.wheel_angles = [0.0] * len(config.drives)
        self._last_read: Optional[float] = None
        self.stopped_for_lost: List[str] = []
        self.not_heard_yet: List[str] = [c.name for c in self.controllers_]
        self.muted = False
        self.allow_relay_to_base = False
        self._pending: List[Tuple[int, bytes]] = [b.command_frame(b.initial) for b in self.ios]
        self.outbox = Outbox()  # frames a refused write left for the next one
        self._now: Optional[float] = None  # [s] the last cycle's time: when frames are given and written
        # a newer command or mode to a controller makes the waiting one worthless; a setup never is
        self._replaceable = frozenset(
            n + c.node for c in self.controllers_ for n in (pr.RX_PDO1, pr.RX_PDO3, pr.RX_PDO4)
        )

    @property
    def io_config(self):
        # the main enclosure PCB is on every robot's bus, named in the robot file or not
        return self.config.io_boards_on_bus

    @classmethod
    def from_params(cls, config, params, ports=None):
        interface, channel, bitrate = params.can_interface_type, params.can_interface_name, params.can_bitrate
        handle = cls(
            config, open_bus(interface, channel, bitrate), reopen=lambda: open_bus(interface, channel, bitrate)
        )
        handle.allow_relay_to_base = params.allow_relay_to_base_devices
        return handle

    # ---- the cycle -------------------------------------------------------------------------------
    def _send_drive_commands(self, commands, time):
        self._poll(time)
        silent = [c for c in self.controllers_ if not c.online(time)]
        # lost: heard, then silent; a controller never heard since start is not lost, only not there yet
        self.stopped_for_lost = [c.name for c in silent if c.last_heard is not None]
        self.not_heard_yet = [c.name for c in silent if c.last_heard is None]
        if silent or self.homing:
            commands = [DriveCommand(c.steering, 0.0) for c in commands]
        for controller in self.controllers_:
            self._queue(controller.command_frames([commands[k] for k in controller.indices]))
        if self._pending:
            pending, self._pending = self._pending, []
            self._queue(pending)
        self._send_relayed()  # and the cycle's frames with them, in one write

    def _read_drive_states(self, time) -> List[MeasuredDrive]:
        self._poll(time)
        out: List[Optional[MeasuredDrive]] = [None] * len(self.config.drives)
        dt = 0.0 if self._last_read is None else max(0.0, time - self._last_read)
        self._last_read = time
        for controller in self.controllers_:
            heard = controller.speeds_heard(time)
            for k, (steering, rate, speed) in zip(controller.indices, controller.measured()):
                radius = self.config.drives[k].r_wheel
                if heard:  # the wheel's angle, like odometry, does not turn on a speed nobody reports
                    self.wheel_angles[k] = math.remainder(self.wheel_angles[k] + speed / radius * dt, 2 * math.pi)
                out[k] = MeasuredDrive(steering, speed, self.wheel_angles[k], rate, heard)
        return out  # type: ignore[return-value]

    def _home_steering(self):
        self._send_all([c.mode_frame(MODE_HOME) for c in self.controllers_])
        return "homing commands sent"

    def _end_homing(self):
        self._send_all([c.mode_frame(MODE_DRIVE) for c in self.controllers_])

    def _set_params(self, config):
        for controller in self.controllers_:
            controller.set_drives(sorted((config.drives[k] for k in controller.indices), key=lambda d: d.channel))

    def _close(self):
        if self.bus is None:
            return
        self._flush(CLOSE_WAIT)  # the wheels' stop, if the last write left it waiting
        if self.bus is None:
            return
        try:
            self.bus.shutdown()
        except Exception:  # closing a broken bus must not hide why it broke
            pass

    # ---- services ----------------------------------------------------------------------------
    def controller(self, node: int) -> Optional[MotorController]:
        return next((c for c in self.controllers_ if c.node == node), None)

    def setup_motor_controller(self, node: int, setup_id: int, value: int) -> Tuple[int, str]:
        """(status, message) as ~setup_motor_controller answers: 0 ok, -1 unknown node, -2 invalid id."""
        if setup_id == 0:
            return 0, "; ".join(f"{k}: {name}" for k, name in enumerate(pr.SETUP_MAP))
        if not 0 < setup_id < len(pr.SETUP_MAP):
            return -2, f"setup id {setup_id}: invalid; 1..{len(pr.SETUP_MAP) - 1} (0 prints the map)"
        targets = self.controllers_ if node == -1 else [c for c in self.controllers_ if c.node == node]
        if not targets:
            return -1, f"no motor controller on node {node}; nodes: {', '.join(str(c.node) for c in self.controllers_)}"
        self._send_all([c.setup_frame(setup_id, value) for c in targets])
        return 0, f"setup {setup_id} ({pr.SETUP_MAP[setup_id]}) = {value} sent to node(s) " + ", ".join(
            str(c.node) for c in targets
        )

    def set_home_count_current_pos_zero(self, node: int) -> Tuple[int, str]:
        targets = self.controllers_ if node == -1 else [c for c in self.controllers_ if c.node == node]
        targets = [c for c in targets if c.steered]
        if not targets:
            return -1, f"no steering motor controller on node {node}"
        frames, done = [], []
        for c in targets:
            if c.homing_setup is None or c.tx1 is None:
                continue
            frames.append(c.setup_frame(pr.SETUP_HOME_COUNT, c.homing_setup.home_count - c.tx1.steer_counts))
            done.append(str(c.node))
        self._send_all(frames)
        if not done:
            return -1, "no controller has reported its home count and steering counts yet"
        return 0, "home count set to the current position on node(s) " + ", ".join(done)

    def set_relay(self, io_id: int, relay: int, on: bool) -> str:
        board = next((b for b in self.ios if b.id == io_id), None)
        if board is None:
            raise ThorvaldBaseError(f"no IO board {io_id}")
        self._send_all([board.command_frame({relay: on})])
        return f"IO board {io_id} relay {relay} {'on' if on else 'off'}"

    # ---- the relay for implements ----------------------------------------------------------------
    def relay(self, frame: Frame) -> Optional[str]:
        """Queues a frame from can_frames_device_t; the reason when it is refused or dropped."""
        if self.muted:
            return None
        if not frame.is_extended and frame.id in self.owned and not self.allow_relay_to_base:
            self.counters.relay_refused += 1
            return (
                f"a relayed frame to 0x{frame.id:03X} ({self.owned[frame.id]}) refused: it belongs to the base "
                "(set ~allow_relay_to_base_devices to allow)"
            )
        self.relay_queue.append(frame)
        if len(self.relay_queue) > RELAY_QUEUE_LIMIT:
            self.counters.relay_dropped += 1
            self.relay_queue.popleft()
            return f"more than {RELAY_QUEUE_LIMIT} relayed frames waiting: the oldest dropped"
        return None

    def mute(self, muted: bool) -> str:
        self.muted = muted
        if muted:
            self.relay_queue.clear()
            self.outbox.discard(lambda f: f.relayed)  # those a refused write left: muted means none go
        return "extra CAN device commands " + ("muted" if muted else "unmuted")

    def take_received(self) -> Tuple[List[Frame], List[Frame]]:
        """(frames base devices claimed, frames none claimed) since the last call."""
        base, device = self.received_base, self.received_device
        self.received_base, self.received_device = [], []
        return base, device

    def _send_relayed(self):
        for f in self.relay_queue:  # never replaced: an implement's protocol may count every frame
            self.outbox.put(Waiting(f.id, f.data, f.is_extended, f.is_remote, self._now, relayed=True))
        self.relay_queue.clear()
        self._flush()

    # ---- bus I/O -----------------------------------------------------------------------------
    def _send_all(self, frames: Sequence[Tuple[int, bytes]]) -> None:
        self._queue(frames)
        self._flush()

    def _queue(self, frames: Sequence[Tuple[int, bytes]]) -> None:
        for can_id, data in frames:
            key = can_id if can_id in self._replaceable else None
            self.outbox.put(Waiting(can_id, data, since=self._now), key)

    def _flush(self, wait: float = WRITE_WAIT) -> None:
        """Writes the waiting frames: a refused write keeps them for the next one, a broken bus is reopened."""
        if not len(self.outbox):
            return
        waiting = self.outbox.waiting(self._now)  # the frames that waited too long dropped, bus or none
        if not waiting or (self.bus is None and not self._try_reopen()):
            return
        messages = [
            can.Message(arbitration_id=f.can_id, data=f.data, is_extended_id=f.extended, is_remote_frame=f.remote)
            for f in waiting
        ]
        sent, error = self._write(messages, wait)
        self.outbox.sent(sent, self._now)
        if error is not None and not write_refused(error):
            self._bus_error("send", error)
        elif sent < len(messages):
            self.counters.writes_refused += 1
            self.counters.last_refused = "the buffer is full" if error is None else _reason(error)

    def _write(self, messages: List[can.Message], wait: float) -> Tuple[int, Optional[Exception]]:
        """(how many of the messages went, in order; the error that stopped the rest, if any)."""
        batch = getattr(self.bus, "send_batch", None)  # one write for all (BufferedSlcanBus)
        if batch is not None:
            try:
                sent = batch(messages, timeout=wait)
            except Exception as e:  # the interface's own errors, whatever their class
                return 0, e
            return (len(messages) if sent is None else sent), None  # None: a batch that says nothing sent all
        for k, msg in enumerate(messages):
            try:
                self.bus.send(msg, timeout=wait)
            except Exception as e:  # a full buffer, bus-off, a port that went away
                return k, e
        return len(messages), None

    def _poll(self, time: float) -> None:
        self._now = time
        if self.bus is None and not self._try_reopen():
            return
        if len(self.outbox):  # what a refused write left: retried at every poll
            self._flush()
            if self.bus is None:
                return
        for _ in range(READ_LIMIT):
            try:
                msg = self.bus.recv(timeout=0.0)
            except (ValueError, IndexError):  # an interface's parser on a garbled frame (python-can's slcan)
                self.counters.unparsable += 1
                continue
            except Exception as e:  # the interface's own errors, whatever their class
                self._bus_error("receive", e)
                return
            if msg is None:
                return
            if msg.is_error_frame:
                self.counters.receive_errors += 1
                continue
            self._route(Frame(msg.arbitration_id, bytes(msg.data), msg.is_extended_id, msg.is_remote_frame), time)

    def _route(self, frame: Frame, time: float) -> None:
        device = None if frame.is_extended else self.by_id.get(frame.id)
        if device is not None and device.claim(frame.id, frame.data, time):
            self.received_base.append(frame)
        else:
            self.received_device.append(frame)

    def _bus_error(self, what: str, error: Exception) -> None:
        if what == "send":
            self.counters.send_errors += 1
        else:
            self.counters.receive_errors += 1
        self.counters.last_error = f"{what}: {_reason(error)}"
        if self._reopen is not None:
            try:
                self.bus.shutdown()
            except Exception:  # it is being dropped anyway
                pass
            self.bus = None

    def _try_reopen(self) -> bool:
        if self._reopen is None:
            return self.bus is not None
        now = wall.monotonic()
        if now < self._next_reopen:
            return False
        self._next_reopen = now + REOPEN_PERIOD
        try:
            self.bus = self._reopen()
        except ThorvaldBaseError as e:
            self.counters.last_error = str(e)
            return False
        self.counters.reopened += 1
        return True

    # ---- what base_driver reports ------------------------------------------------------------
    @property
    def malformed_frames(self) -> int:
        return sum(d.malformed for d in self.devices)

    def batteries(self, time) -> List[BatteryInfo]:
        out = []
        for b in self.batteries_:
            t1, t2, t3 = b.tpdo1, b.tpdo2, b.tpdo3
            alarms = pr.battery_alarm_names(t1.alarms) if t1 else ()
            state = BATTERY_LOST if not b.online(time) else (BATTERY_ALARM if alarms else BATTERY_OK)
            temps = (t1.temperatures if t1 else ()) + (t2.temperatures if t2 else ())
            out.append(
                BatteryInfo(
                    b.id,
                    state,
                    float(t3.state_of_charge) if t3 else 0.0,
                    float(t3.state_of_health) if t3 else 0.0,
                    t1.voltage if t1 else 0.0,
                    t2.current if t2 else 0.0,
                    charge_fet_on=t1.charge_fet_on if t1 else False,
                    discharge_fet_on=t1.discharge_fet_on if t1 else False,
                    cycle_count=t3.cycle_count if t3 else 0,
                    capacity=t3.capacity if t3 else 0.0,
                    temperatures=tuple(float(t) for t in temps),
                    alarms=alarms,
                )
            )
        return out

    def io_boards(self, time) -> List[IoInfo]:
        return [
            IoInfo(
                b.id,
                b.type,
                b.state.relays if b.state else (),
                b.state.analog if b.state else (),
                b.online(time),
            )
            for b in self.ios
        ]

    def diagnostics(self, time) -> Dict[str, str]:
        c = self.counters
        values = {
            "bus": "open" if self.bus is not None else "closed (reopening)",
            "send errors": str(c.send_errors),
            "writes refused": str(c.writes_refused),
            "frames queued": str(self.outbox.counters.deferred),
            "frames waiting": str(len(self.outbox)),
            "commands superseded": str(self.outbox.counters.superseded),
            "frames dropped": str(self.outbox.counters.dropped),
            "worst write latency": f"{self.outbox.counters.worst_latency:.3f} s",
            "receive errors": str(c.receive_errors),
            "bus reopened": str(c.reopened),
            "malformed frames": str(self.malformed_frames + c.unparsable),
            "relayed frames dropped": str(c.relay_dropped),
            "relayed frames refused": str(c.relay_refused),
            "relay muted": str(self.muted),
        }
        if c.last_error:
            values["last error"] = c.last_error
        if c.last_refused:
            values["last write refused"] = c.last_refused
        if self.stopped_for_lost:
            values[LOST] = ", ".join(self.stopped_for_lost)
        if self.not_heard_yet:
            values[NOT_HEARD_YET] = ", ".join(self.not_heard_yet)
        mismatches = [c.script_mismatch for c in self.controllers_ if c.script_mismatch]
        if mismatches:
            values["wrong script"] = "; ".join(mismatches)
        return values

    def controllers(self, time) -> List[ControllerInfo]:
        out = []
        for c in self.controllers_:
            mode = MODE_LOST_CONNECTION if not c.online(time) else (MODE_HOME if self.homing else MODE_ONLINE)
            measured = c.measured()
            amps = c.tx2.amps if c.tx2 else (0.0, 0.0)
            # TxPDO2 reports it in per mille; motor_controller_data's relative_power is in [-1, 1]
            power = tuple(p / 1000.0 for p in c.tx2.power) if c.tx2 else (0.0, 0.0)
            if c.steered:
                steering, rate, speed = measured[0]
                k = c.indices[0]
                motor_vars = (
                    ("propulsion", speed, self.wheel_angles[k], amps[0], power[0]),
                    ("steering", rate, steering, amps[1], power[1]),
                )
            else:
                motor_vars = tuple(
                    ("propulsion", m[2], self.wheel_angles[k], amps[i], power[i])
                    for i, (k, m) in enumerate(zip(c.indices, measured))
                )
            version = c.script.version if c.script else ""
            out.append(
                ControllerInfo(
                    name=c.name,
                    type=c.type_name,
                    version=version,
                    can_id=c.node,
                    mode=mode,
                    battery_volts=c.tx3.battery_volts if c.tx3 else 0.0,
                    battery_amps=c.tx3.battery_amps if c.tx3 else 0.0,
                    temps=(float(c.tx3.max_temperature),) if c.tx3 else (),
                    status_flags=c.tx3.flags if c.tx3 else (),
                    motor_vars=motor_vars,
                    drive_direction=c.homing_setup.drive_direction if c.homing_setup else 0,
                    home_speed=c.homing_setup.home_speed if c.homing_setup else 0,
                    home_count=c.homing_setup.home_count if c.homing_setup else 0,
                )
            )
        return out
