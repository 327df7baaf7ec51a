"""The value types of a robot configuration, and the facts derived from them, once.

Each type is one entry of a section of the robot file (``motor_drives/driveN`` is a :class:`Drive`).
A field made with :func:`~thorvald_model.schema.key` is a key of the file: its default, its rule,
its aliases and whether it may change while the robot runs are the field's metadata, and the
schema is read off the types (:mod:`thorvald_model.keys`). A new drive key is one line here.

What other parts derive from a configuration lives here as properties, so base_driver, the CAN
devices, the emulator, the model's xacro and the simulator read one answer: whether a drive steers,
its motors' limits, whether a battery is fitted, which drives share a motor controller, which IO
board is the main one.

SI units (m, rad, s, kg); motor speeds stay in rpm, as the motor controllers use them.
"""

import math
from dataclasses import dataclass, field
from typing import Any, Dict, List, Optional, Tuple

from .constants import BATTERY_KC, DRIVE_STEERED, IO_MAIN_BOARD
from .errors import Problem
from .schema import NON_NEGATIVE, POSITIVE, in_range, key, non_negative, one_of

MAX_STEERING_OFFSET = 0.2  # [rad]: a drive's steering_offset beyond it is a broken module, not a homing error
# A rail wheel's flanges (paper 3.1: the greenhouse robot's double wheels): a disc either side of the
# tread, this much larger in radius than the tread (how far they reach down beside a pipe) and this
# thick. 20 mm reach down a 51 mm pipe's sides to 5.5 mm above its centre, where it is nearly its
# full width (2 sqrt(25.5^2 - 5.5^2) = 49.8 mm): enough to hold the wheel on it.
RAIL_FLANGE_DEPTH = 0.02  # [m]
RAIL_FLANGE_WIDTH = 0.01  # [m]
FRAME_PART_COLORS = ("grey", "dark_grey", "black", "white", "silver", "orange", "red", "green", "blue", "yellow")


@dataclass(frozen=True)
class Suspension:
    """A suspension module between a drive's steering module and the frame (paper 2.1.4)."""

    name: str
    index: int
    drive: str = key()  # name of the drive it carries, e.g. "drive0"
    travel: float = key(0.1, **POSITIVE)  # vertical travel [m]
    stiffness: float = key(30000.0, **POSITIVE)  # spring rate [N/m]
    damping: float = key(3000.0, **NON_NEGATIVE)  # [N s/m]


@dataclass(frozen=True)
class Drive:
    """One drive module, ``motor_drives/driveN``."""

    name: str
    index: int
    node: int = key(check=in_range(1, 127), rule="must be a CANopen node id in 1..127")  # its motor controller
    x: float = key(runtime=True)  # steering axis position in base_link [m]
    y: float = key(runtime=True)  # [m]
    type: int = key(0, one_of(0, 1), "must be 0 (propulsion/steering) or 1 (propulsion/propulsion)")
    leg_mesh: int = key(0, in_range(0, 6), "must be in 0..6")
    r_wheel: float = key(0.2, **POSITIVE, runtime=True)  # wheel radius [m]
    w_wheel: float = key(0.16, **POSITIVE, runtime=True)  # wheel width [m]
    prp_gr_rt: float = key(42.0, **POSITIVE, runtime=True)  # propulsion gear ratio (motor turns per wheel turn)
    prp_enc_ppr: int = key(1024, **POSITIVE, runtime=True)  # propulsion encoder pulses per motor revolution
    prp_max_rpm: float = key(3000.0, **POSITIVE, runtime=True)  # motor speed at full command [rpm]
    prp_sim_a: float = key(1.5, **POSITIVE, aliases=("prp_slm_e",), runtime=True)  # simulated acceleration [m/s^2]
    str_gr_rt: float = key(42.8571429, **POSITIVE, runtime=True)  # steering gear ratio
    str_enc_ppr: int = key(1024, **POSITIVE, runtime=True)  # steering encoder pulses per motor revolution
    # steering angle limit, either side of straight ahead [rad]
    str_lim: float = key(3.078027759, lambda v: 0 < v <= math.pi, "must be in (0, pi] [rad]", runtime=True)
    str_sim_v: float = key(4.0, **POSITIVE, aliases=("str_slm_v",), runtime=True)  # simulated steering speed [rad/s]
    # Ours: the angle the wheel really stands at when its controller reads 0 [rad] (positive to the
    # left, as the steering angle): a homing error, measured by calibration (thorvald_base.calibration).
    # base_driver sends steering - offset and reads reading + offset. Beyond 0.2 rad (about 11 deg)
    # the module is broken, not mis-homed; a drive that does not steer has none (rules.py).
    steering_offset: float = key(
        0.0, lambda v: abs(v) <= MAX_STEERING_OFFSET, f"must be within +-{MAX_STEERING_OFFSET} rad", runtime=True
    )
    # Ours: a flanged rail wheel on the tyre's axle, for greenhouse heating pipes (paper 3.1, the robot
    # of Figure 2a): its radius (0: none), its tread's width between the flanges (0.06 takes a 51 mm
    # pipe with 4.5 mm to spare either side) and its centre's offset from the tyre's centre along the
    # axle (+y of the wheel link, which is base_link's +y with the wheel straight). On the floor the
    # tyre carries the drive, on the pipes the rail wheel does (rules.py: the tyre is the larger);
    # base_driver's r_wheel is the radius in use, which set_drive_params switches between the two.
    rail_r_wheel: float = key(0.0, **NON_NEGATIVE)  # [m]
    rail_w_wheel: float = key(0.06, **POSITIVE)  # [m]
    rail_offset: float = key(0.0)  # [m]
    # Ours: the motors' torque limits, for the simulator. About 500 W at 3000 rpm for propulsion
    # (1.6 N m x 42 = 67 N m at the wheel, 336 N at a 0.2 m rim); 1 N m x 42.9 = 43 N m for steering,
    # enough to turn a loaded wheel on the spot on tarmac.
    prp_motor_torque: float = key(1.6, **POSITIVE)  # [N m]
    str_motor_torque: float = key(1.0, **POSITIVE)  # [N m]
    # Ours: the motors as DC motors behind their gears (thorvald_model.motors), for the simulator's motor
    # currents (drive_currents) and energy (thorvald_design.energy). A 48 V motor of 3000 rpm has a
    # back-EMF constant near 48 V x 0.9 / 314 rad/s = 0.14 V s/rad, which in SI is its torque constant
    # [N m/A]: 1.6 N m takes 11 A. Windings of a quarter ohm, 0.6 A without load, and a two-stage
    # planetary gear's 90 % (steering: 0.4 ohm, 0.4 A, 85 %).
    prp_motor_kt: float = key(0.14, **POSITIVE)  # [N m/A] torque constant (= back-EMF constant [V s/rad])
    prp_motor_r: float = key(0.25, **NON_NEGATIVE)  # [ohm] winding resistance
    prp_motor_i0: float = key(0.6, **NON_NEGATIVE)  # [A] no-load current
    prp_gear_eff: float = key(0.9, lambda v: 0 < v <= 1, "must be in (0, 1]")  # propulsion gear efficiency
    str_motor_kt: float = key(0.14, **POSITIVE)  # [N m/A]
    str_motor_r: float = key(0.4, **NON_NEGATIVE)  # [ohm]
    str_motor_i0: float = key(0.4, **NON_NEGATIVE)  # [A]
    str_gear_eff: float = key(0.85, lambda v: 0 < v <= 1, "must be in (0, 1]")  # steering gear efficiency
    steering_name: str = key("")  # joint name without tf_prefix, default "steeringN"
    wheel_name: str = key("")  # joint name without tf_prefix, default "wheelN"
    tower: bool = key(True)  # a tower module stands above the drive (model only)
    suspension: Optional[Suspension] = None
    channel: int = 1  # propulsion channel on its motor controller: 2 for the second type-1 drive of a node

    @property
    def steerable(self) -> bool:
        """A type-0 drive steers; a type-1 drive rolls along base_link x and its steering joint is fixed."""
        return self.type == DRIVE_STEERED

    @property
    def max_wheel_torque(self) -> float:
        """Torque limit at the wheel [N m]: the propulsion motor's through its gear."""
        return self.prp_motor_torque * self.prp_gr_rt

    @property
    def max_steering_torque(self) -> float:
        """Torque limit about the steering axis [N m]: the steering motor's through its gear."""
        return self.str_motor_torque * self.str_gr_rt

    @property
    def max_steering_speed(self) -> float:
        """The steering speed the drive is allowed [rad/s]: ``str_sim_v``, 0 for a type-1 drive.

        The simulated drive slews at it; on a real base it is the controller's steering speed limit.
        """
        return self.str_sim_v if self.steerable else 0.0

    @property
    def max_wheel_rate(self) -> float:
        """Highest wheel turning rate the motor allows [rad/s]: full motor speed through the gear."""
        return self.prp_max_rpm * 2.0 * math.pi / 60.0 / self.prp_gr_rt

    @property
    def max_wheel_speed(self) -> float:
        """Highest wheel rim speed the motor allows [m/s]."""
        return self.max_wheel_rate * self.r_wheel

    @property
    def has_rail_wheel(self) -> bool:
        """A flanged rail wheel is fitted beside the tyre (``rail_r_wheel`` > 0)."""
        return self.rail_r_wheel > 0

    @property
    def rail_flange_radius(self) -> float:
        """Radius of the rail wheel's flanges [m] (0 without a rail wheel)."""
        # rounded to the nanometre, so that the description reads 0.17 and not 0.16999999999999998
        return round(self.rail_r_wheel + RAIL_FLANGE_DEPTH, 9) if self.has_rail_wheel else 0.0

    @property
    def rail_half_span(self) -> float:
        """Half the rail wheel's width over its flanges [m], from its centre along the axle."""
        return self.rail_w_wheel / 2.0 + RAIL_FLANGE_WIDTH if self.has_rail_wheel else 0.0

    @property
    def rail_clearance_offset(self) -> float:
        """The least ``rail_offset`` [m] that keeps the rail wheel and its flanges beside the tyre, not
        in it: half the tyre's width and the rail wheel's half span over its flanges."""
        return self.w_wheel / 2.0 + self.rail_half_span if self.has_rail_wheel else 0.0


@dataclass(frozen=True)
class Battery:
    """A battery enclosure, ``batteries/batN``; type 0 is an empty enclosure, 1 a KC battery."""

    name: str
    index: int
    id: int = key(None)  # battery CAN id (the original's deprecated node = id + 344); -1 for none
    type: int = key(BATTERY_KC, one_of(0, 1), "must be 0 (empty enclosure) or 1 (KC battery)")
    x: float = key(0.0)
    y: float = key(0.0)
    z: float = key(0.72)
    yaw: float = key(0.0)
    bat_mesh: int = key(0, **NON_NEGATIVE)
    with_battery: bool = key(True)
    # Ours: the battery a KC enclosure holds, for energy and the CAN emulator: a 48 V lithium pack of
    # 100 Ah (4.8 kWh) with 50 milliohm inside
    capacity: float = key(100.0, **POSITIVE)  # [Ah]
    voltage: float = key(48.0, **POSITIVE)  # [V] nominal (open circuit)
    internal_resistance: float = key(0.05, **NON_NEGATIVE)  # [ohm]

    @property
    def present(self) -> bool:
        """A KC battery is fitted: it is on the CAN bus, reports, and weighs what a battery weighs."""
        return self.type == BATTERY_KC and self.with_battery


@dataclass(frozen=True)
class Pipe:
    """Two parallel frame tubes from (x1, y1) to (x2, y2), ``pipes/pipeN`` (model only)."""

    name: str
    index: int
    x1: float = key()
    y1: float = key()
    x2: float = key()
    y2: float = key()
    height: float = key(0.65, **POSITIVE)  # height of the middle between the two tubes [m]
    space: float = key(0.15, **NON_NEGATIVE)  # vertical distance between the tubes [m]

    @property
    def length(self) -> float:
        return math.hypot(self.x2 - self.x1, self.y2 - self.y1)


@dataclass(frozen=True)
class Corner:
    """A frame corner clamp, ``corners/cornerN`` (model only)."""

    name: str
    index: int
    type: int = key(0, in_range(0, 3), "must be in 0..3")  # orientation 0..3
    corner_mesh: int = key(0, **NON_NEGATIVE)
    x: float = key()
    y: float = key()
    z: float = key(0.65)
    space: float = key(0.15, **NON_NEGATIVE)
    susp_ang: float = key(0.0)  # [rad]


@dataclass(frozen=True)
class Beam:
    """A frame beam between two drive modules, ``beams/beamN`` (model only)."""

    name: str
    index: int
    start: str = key()  # drive name
    end: str = key()  # drive name
    height: float = key(0.65, **POSITIVE)  # [m]


@dataclass(frozen=True)
class IOBoard:
    """An IO board on the CAN bus, ``io/ioN``."""

    name: str
    index: int
    id: int = key(check=non_negative, rule="must be >= 0")
    # 0 main enclosure PCB, 1 sister enclosure PCB, 2 UV lamp board
    type: int = key(IO_MAIN_BOARD, in_range(0, 2), "must be 0 (main PCB), 1 (sister PCB) or 2 (UV lamp board)")
    rl0_init_state: bool = key(False)
    rl1_init_state: bool = key(False)

    @property
    def is_main(self) -> bool:
        """The main enclosure PCB: its relays are the original's ``setRl1`` and ``setRl2``."""
        return self.type == IO_MAIN_BOARD


DEFAULT_MAIN_IO_BOARD = IOBoard("io0", 0, id=0, type=IO_MAIN_BOARD, rl0_init_state=False, rl1_init_state=False)


@dataclass(frozen=True)
class PassiveWheel:
    """An unpowered wheel, ``passive_wheels/passiveN`` (paper 2.1.5).

    A ``caster`` swivels freely and constrains nothing; a ``fixed`` wheel rolls only along its
    ``yaw`` and so cannot slide sideways, which confines the centre of rotation to its axle line.
    """

    name: str
    index: int
    type: str = key(check=one_of("caster", "fixed"), rule="must be 'caster' or 'fixed'")
    x: float = key()  # wheel contact (caster: swivel axis) in base_link [m]
    y: float = key()
    r_wheel: float = key(0.1, **POSITIVE)  # [m]
    w_wheel: float = key(0.05, **POSITIVE)  # [m]
    yaw: float = key(0.0)  # rolling direction of a fixed wheel in base_link [rad]
    caster_offset: float = key(0.05, **NON_NEGATIVE)  # horizontal trail from swivel axis to wheel centre [m]

    @property
    def fixed(self) -> bool:
        return self.type == "fixed"


@dataclass(frozen=True)
class FramePart:
    """A custom frame member, ``frame_parts/partN``: a box, cylinder or sphere (model only)."""

    name: str
    index: int
    shape: str = key(check=one_of("box", "cylinder", "sphere"), rule="must be 'box', 'cylinder' or 'sphere'")
    x: float = key(0.0)  # centre in base_link [m]
    y: float = key(0.0)
    z: float = key(0.0)
    roll: float = key(0.0)  # [rad]
    pitch: float = key(0.0)
    yaw: float = key(0.0)
    size_x: float = key(0.0, **POSITIVE)  # box [m]
    size_y: float = key(0.0, **POSITIVE)
    size_z: float = key(0.0, **POSITIVE)
    radius: float = key(0.0, **POSITIVE)  # cylinder and sphere [m]
    length: float = key(0.0, **POSITIVE)  # cylinder, along its local z [m]
    mass: float = key(**POSITIVE)  # [kg]
    color: str = key("grey", one_of(*FRAME_PART_COLORS), "must be one of " + ", ".join(FRAME_PART_COLORS))


FRAME_PART_DIMENSIONS = {
    "box": ("size_x", "size_y", "size_z"),
    "cylinder": ("radius", "length"),
    "sphere": ("radius",),
}
ALL_DIMENSIONS = ("size_x", "size_y", "size_z", "radius", "length")


@dataclass(frozen=True)
class MotorController:
    """One motor controller of the robot: a type-0 drive's own, or the one a type-1 pair shares.

    drives: in channel order (a pair's channels 1 and 2, as the file lists them); indices: their
    places in the robot's drive order.
    """

    node: int  # its CANopen node id
    drives: Tuple[Drive, ...]
    indices: Tuple[int, ...]

    @property
    def steered(self) -> bool:
        """Propulsion and steering (a type-0 drive), not two propulsion channels."""
        return len(self.drives) == 1 and self.drives[0].steerable

    @property
    def name(self) -> str:
        """Named after its first drive, as motor_controller_data names it."""
        return self.drives[0].name


@dataclass(frozen=True)
class RobotConfig:
    """A validated robot configuration."""

    source: str
    base_calculator: str
    drives: Tuple[Drive, ...]
    batteries: Tuple[Battery, ...] = ()
    pipes: Tuple[Pipe, ...] = ()
    corners: Tuple[Corner, ...] = ()
    beams: Tuple[Beam, ...] = ()
    io: Tuple[IOBoard, ...] = ()
    passive_wheels: Tuple[PassiveWheel, ...] = ()
    suspensions: Tuple[Suspension, ...] = ()
    frame_parts: Tuple[FramePart, ...] = ()
    # Top-level keys for the user's own files (the sensor keys, and unknown ones kept), and unknown
    # keys kept inside entries: (section, entry, key, value). to_dict() gives them back.
    extras: Tuple[Tuple[str, Any], ...] = field(default=(), compare=False)
    entry_extras: Tuple[Tuple[str, str, str, Any], ...] = field(default=(), compare=False)
    warnings: Tuple[Problem, ...] = field(default=(), compare=False)  # each unknown key kept

    def drive(self, name: str) -> Drive:
        for d in self.drives:
            if d.name == name:
                return d
        raise KeyError(name)

    @property
    def steered_drives(self) -> Tuple[Drive, ...]:
        return tuple(d for d in self.drives if d.steerable)

    @property
    def motor_controllers(self) -> Tuple[MotorController, ...]:
        """The robot's motor controllers, in order of their first drive: one per type-0 drive, one
        per pair of type-1 drives on a node (the loader's rules make sure of those shapes)."""
        by_node: Dict[int, List[int]] = {}
        for k, d in enumerate(self.drives):
            by_node.setdefault(d.node, []).append(k)
        out = []
        for node, indices in by_node.items():
            indices = sorted(indices, key=lambda k: self.drives[k].channel)
            out.append(MotorController(node, tuple(self.drives[k] for k in indices), tuple(indices)))
        return tuple(out)

    @property
    def present_batteries(self) -> Tuple[Battery, ...]:
        """The KC batteries fitted (on the CAN bus); empty enclosures and unfitted ones left out."""
        return tuple(b for b in self.batteries if b.present)

    @property
    def io_boards_on_bus(self) -> Tuple[IOBoard, ...]:
        """The IO boards on the robot's CAN bus: the ``io`` section's, or, without one, the main
        enclosure PCB every Thorvald has (the original's default board, id 0, relays off at start)."""
        return self.io or (DEFAULT_MAIN_IO_BOARD,)

    @property
    def track(self) -> float:
        """Widest lateral distance between two wheel contacts [m]."""
        ys = [w[1] for w in self.wheel_contacts()]
        return max(ys) - min(ys)

    @property
    def wheelbase(self) -> float:
        """Longest longitudinal distance between two wheel contacts [m]."""
        xs = [w[0] for w in self.wheel_contacts()]
        return max(xs) - min(xs)

    def wheel_contacts(self) -> List[Tuple[float, float]]:
        return [(d.x, d.y) for d in self.drives] + [(w.x, w.y) for w in self.passive_wheels]
