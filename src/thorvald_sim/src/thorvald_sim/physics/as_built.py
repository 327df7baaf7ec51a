"""How a built robot differs from its configuration file: the simulator's as-built file.

A robot is built to its configuration only approximately: tyres of slightly different rolling
radii (pressure, wear), steering modules homed a little off, encoders that count in whole counts.
The simulator builds the robot as its as-built file says, while base_driver, as on a real robot,
runs on the configuration file alone and never sees this one. The file has the robot file's own
shape::

    motor_drives:
      drive0: {r_wheel: 0.2015, steering_offset: 0.004}   # true rolling radius [m]; homing error [rad]
      drive2: {r_wheel: 0.1987}
    encoders: true      # report joints in whole encoder counts (prp_enc_ppr, str_enc_ppr, gear ratios)
    delay: 0.02         # [s] measurement delay
    mass_offset: 30.0   # [kg] a load on the frame

Every key is optional: a drive not named is built as configured. ``steering_offset`` is the angle
the wheel really stands at when the controller reads 0 (positive: turned to the left, as the
steering angle); a drive that does not steer has none. Validated as the robot file is: every
problem with the file, its key path, the value and the rule, together in one ConfigError.

A profile draws the imperfections from stated tolerances with a seed (``field:SEED``, see
:data:`PROFILES`): a uniform draw within each tolerance, drive by drive in order, so the same seed
gives the same robot.

Pure: no pybullet, no rospy, no messages.
"""

import dataclasses
import json
import math
import os
import random
import re
from dataclasses import dataclass
from typing import Any, Dict, List, Mapping, Optional, Tuple

from thorvald_base.can.protocol import DriveScaling
from thorvald_model.errors import MISSING, ConfigError, Problem
from thorvald_model.schema import Key, check_top_level, non_negative, parse_entry, parse_scalar, read_yaml_file
from thorvald_model.value_text import value_text
from thorvald_model.values import RobotConfig

WHAT = "as-built file"
MAX_RADIUS_CHANGE = 0.2  # of the configured r_wheel: beyond it the file describes another wheel
MAX_STEERING_OFFSET = 0.2  # [rad], about 11 degrees: beyond it the module is broken, not mis-homed
MAX_DELAY = 1.0  # [s]
# A profile's seed: at most what 64 bits hold (random.Random takes any integer, but reading one of a
# million digits takes seconds, and Python 3.11 refuses past 4300)
MAX_SEED = 2**64 - 1
SEED_TEXT = re.compile(r"[0-9]+")
PROFILE_SPEC = re.compile(r"[A-Za-z_][\w-]*:[^/]*")  # NAME:... without a slash: a profile, unless such a file exists

DRIVE_KEYS = (
    Key("r_wheel", float, None, check=lambda v: v > 0, rule="must be > 0"),
    Key(
        "steering_offset",
        float,
        0.0,
        check=lambda v: abs(v) <= MAX_STEERING_OFFSET,
        rule=f"must be within +-{MAX_STEERING_OFFSET} rad",
    ),
)
ENCODERS_KEY = Key("encoders", bool, False)
DELAY_KEY = Key("delay", float, 0.0, check=lambda v: 0 <= v <= MAX_DELAY, rule=f"must be in [0, {MAX_DELAY}] s")
MASS_OFFSET_KEY = Key("mass_offset", float, 0.0, check=non_negative, rule="must be >= 0 (a load)")
MAX_TYRE_DEFLECTION = 0.1  # [m]
TYRE_KEY = Key(
    "tyre_deflection", float, 0.0, check=lambda v: 0 <= v <= MAX_TYRE_DEFLECTION,
    rule=f"must be in [0, {MAX_TYRE_DEFLECTION}] m (0: rigid tyres)",
)  # fmt: skip
TOP_KEYS = ("motor_drives", "encoders", "delay", "mass_offset", "tyre_deflection")


@dataclass(frozen=True)
class Profile:
    """Tolerances an as-built robot is drawn from."""

    radius: float  # [-] of the configured r_wheel: drawn uniformly from +-radius, per tyre
    steering_offset: float  # [rad]: drawn uniformly from +-steering_offset (steered drives)
    encoders: bool
    # [-] the tyres' loaded rolling radius below the configured one, drawn uniformly from this range
    # once per robot (one load, one pressure for all its tyres)
    loaded: Tuple[float, float] = (0.0, 0.0)
    # [-] of the radius: the tyres' deflection under their share of the weight; None: the loaded draw's
    # TYRE_DEFLECTION_PER_LOADED times
    deflection: Optional[float] = None


# A loaded pneumatic tyre's deflection is about three times the drop of its rolling radius (above): a
# profile's loaded tyres give this times its draw of the radius under their share of the weight, so a
# frame of more than three wheels stands on all of them, as tyres do (rigid ones of radii a millimetre
# apart left a six-wheeled frame on two wheels, the others turning in the air)
TYRE_DEFLECTION_PER_LOADED = 3.0

PROFILES: Dict[str, Profile] = {
    # A field robot: tyre pressure and wear +-1 % of the rolling radius per tyre, steering homed within
    # +-0.5 deg, the encoders counting as configured; and its tyres loaded: a pneumatic tyre under a
    # wheel's share of the robot rolls on a radius about a third of its deflection below the free
    # radius a configuration states (10 to 20 mm of deflection at field pressures on 0.2 m tyres: 1 to
    # 2 %), so odometry on the configured radius reads long, as the paper's (+1.0 %)
    "field": Profile(radius=0.01, steering_offset=math.radians(0.5), encoders=True, loaded=(0.01, 0.02)),
    # A robot as the workshop leaves it, before the field: only its tyres' radii (+-0.85 % each, up to
    # 1.7 % apart: pressure and wear) and its steering's homing (+-0.3 deg) off, exact encoders. Its
    # tyres are pneumatic as a field robot's (deflecting 4.5 % of their radius under their share of the
    # weight, the field draw's middle), so its frame stands on every wheel; the drawn radii are the
    # rolling ones.
    "workshop": Profile(radius=0.0085, steering_offset=math.radians(0.3), encoders=False, deflection=0.045),
    # The workshop's draw (the same radii and homing for a seed) on rigid tyres: a frame of more than
    # three wheels stands on the three its radii favour, the others turning almost free, and the
    # differential robot, lifting its lighter drive wheel in a U turn, spins on the spot for the rest of
    # a field route. For studying what a statically indeterminate frame does to odometry.
    "rigid": Profile(radius=0.0085, steering_offset=math.radians(0.3), encoders=False),
}


@dataclass(frozen=True)
class DriveAsBuilt:
    name: str  # driveN, as in the configuration
    r_wheel: float  # [m] the true rolling radius
    steering_offset: float  # [rad] the wheel's true angle when the controller reads 0


@dataclass(frozen=True)
class AsBuilt:
    source: str  # the file, or the profile and seed ("field:7"), or "" for the robot as configured
    drives: Tuple[DriveAsBuilt, ...]  # one per configured drive, in order
    encoders: bool
    delay: float  # [s]
    mass_offset: float  # [kg]
    configured: Tuple[float, ...]  # [m] each drive's r_wheel in the configuration
    loaded: float = 0.0  # [-] a profile's draw: every tyre's radius this much below its own draw (included in r_wheel)
    tyre_deflection: float = 0.0  # [m] each tyre's under its share of the weight (soft tyres); 0: rigid

    def drive(self, name: str) -> DriveAsBuilt:
        for d in self.drives:
            if d.name == name:
                return d
        raise KeyError(name)

    @property
    def ideal(self) -> bool:
        """Built exactly to the configuration."""
        return (
            not self.encoders
            and self.delay == 0
            and self.mass_offset == 0
            and self.tyre_deflection == 0
            and not self.differences()
        )

    def differences(self) -> Dict[str, Dict[str, float]]:
        """The drives that differ from the configuration: {driveN: {key: value}} (for reports)."""
        found = {}
        for d, radius in zip(self.drives, self.configured):
            values = {}
            if d.r_wheel != radius:
                values["r_wheel"] = d.r_wheel
            if d.steering_offset != 0:
                values["steering_offset"] = d.steering_offset
            if values:
                found[d.name] = values
        return found


def as_configured(config: RobotConfig) -> AsBuilt:
    """The robot built exactly to its configuration."""
    drives = tuple(DriveAsBuilt(_name(i), d.r_wheel, 0.0) for i, d in enumerate(config.drives))
    return AsBuilt("", drives, False, 0.0, 0.0, _radii(config))


def parse_as_built(data: Any, config: RobotConfig, source: str = "<as-built>") -> AsBuilt:
    """The as-built robot a parsed file describes, for the robot of config; ConfigError naming every
    problem."""
    problems: List[Problem] = []
    data = check_top_level(data, TOP_KEYS, problems, source=source, what=WHAT)
    encoders = parse_scalar(data, ENCODERS_KEY, problems)
    delay = parse_scalar(data, DELAY_KEY, problems)
    mass_offset = parse_scalar(data, MASS_OFFSET_KEY, problems)
    deflection = parse_scalar(data, TYRE_KEY, problems)
    given = _drive_entries(data.get("motor_drives"), config, problems)
    drives = []
    for i, d in enumerate(config.drives):
        name = _name(i)
        values = given.get(name, {})
        path = f"motor_drives.{name}"
        radius = values.get("r_wheel")
        if radius is None:
            radius = d.r_wheel
        elif abs(radius / d.r_wheel - 1.0) > MAX_RADIUS_CHANGE:
            rule = f"must be within {MAX_RADIUS_CHANGE:.0%} of the configured r_wheel ({d.r_wheel} m)"
            problems.append(Problem(f"{path}.r_wheel", radius, rule))
            radius = d.r_wheel
        offset = values.get("steering_offset", 0.0)
        if offset != 0 and not d.steerable:
            problems.append(Problem(f"{path}.steering_offset", offset, "must be 0: this drive does not steer"))
            offset = 0.0
        drives.append(DriveAsBuilt(name, radius, offset))
    if problems:
        raise ConfigError(source, problems, WHAT)
    return AsBuilt(source, tuple(drives), encoders, delay, mass_offset, _radii(config), tyre_deflection=deflection)


def load_as_built(path: str, config: RobotConfig) -> AsBuilt:
    """The as-built robot of a file (see the module's notes)."""
    return parse_as_built(read_yaml_file(path, WHAT), config, path)


def profile_and_seed(spec: str) -> Tuple[Profile, int]:
    """The profile and the seed a ``PROFILE:SEED`` spec names; ConfigError (the spec, the rule)."""
    name, _, seed_text = spec.partition(":")
    seed_text = seed_text.strip()
    if name not in PROFILES:
        known = ", ".join(sorted(PROFILES))
        rule = f"no as-built profile {value_text(name, 40)} (the profiles: {known}) and no file of that name"
    # ASCII digits only ("²" is a digit to str.isdigit, not to int), no sign, and the length first:
    # a seed of a million digits is refused before it is converted
    elif not SEED_TEXT.fullmatch(seed_text) or len(seed_text) > len(str(MAX_SEED)) or int(seed_text) > MAX_SEED:
        rule = f"{name}:SEED: SEED must be a whole number from 0 to {MAX_SEED} (an integer seed), e.g. {name}:7"
    else:
        return PROFILES[name], int(seed_text)
    raise ConfigError(_shown(spec), [Problem("", MISSING, rule)], "as-built profile")


def is_profile_spec(spec: str) -> bool:
    """Whether ``-as_built`` / ``as_built:=`` names a profile and seed rather than a file: a known
    profile's name before a colon, or any NAME:... without a slash where no such file exists (a
    misspelt profile, said so, rather than a missing file)."""
    return spec.partition(":")[0] in PROFILES or (PROFILE_SPEC.fullmatch(spec) is not None and not os.path.exists(spec))


def draw_as_built(spec: str, config: RobotConfig) -> AsBuilt:
    """A robot drawn from a profile's tolerances with a seed: ``field:7``."""
    profile, seed = profile_and_seed(spec)
    rng = random.Random(seed)
    draws = []
    for d in config.drives:
        # two draws a drive, steered or not, so one drive's type does not move the others' draws
        scale = 1.0 + rng.uniform(-profile.radius, profile.radius)
        offset = rng.uniform(-profile.steering_offset, profile.steering_offset)
        draws.append((scale, offset if d.steerable else 0.0))
    loaded = rng.uniform(*profile.loaded)  # after the drives' draws: theirs stay as they were without it
    drives = tuple(
        DriveAsBuilt(_name(i), d.r_wheel * scale * (1.0 - loaded), offset)
        for i, (d, (scale, offset)) in enumerate(zip(config.drives, draws))
    )
    per_radius = TYRE_DEFLECTION_PER_LOADED * loaded if profile.deflection is None else profile.deflection
    deflection = per_radius * sum(d.r_wheel for d in config.drives) / len(config.drives)
    return AsBuilt(spec, drives, profile.encoders, 0.0, 0.0, _radii(config), loaded, deflection)


def as_built_for(spec: str, config: RobotConfig) -> AsBuilt:
    """What ``-as_built`` / ``as_built:=`` names: "" (as configured), a profile and seed
    (``field:7``) or a file; ConfigError naming the spec or the file and the rule."""
    if not spec:
        return as_configured(config)
    if is_profile_spec(spec):
        return draw_as_built(spec, config)
    return load_as_built(spec, config)


def quantise(angle: float, counts_per_radian: float) -> float:
    """An angle [rad] as an encoder counts it: whole counts (rounded toward zero, as a counter
    that has not reached the next edge)."""
    return math.trunc(angle * counts_per_radian) / counts_per_radian


# ---- what the simulator builds --------------------------------------------------------------
@dataclass(frozen=True)
class BuiltDrive:
    """One drive as the simulator builds and measures it."""

    r_wheel: float  # [m] the wheel's true rolling radius (its collision cylinder)
    steering_offset: float  # [rad] the wheel's true angle when the controller reads 0
    steering_count: float = 0.0  # [rad] one steering encoder count; 0: angles reported exactly
    wheel_count: float = 0.0  # [rad] one propulsion encoder count at the wheel; 0: exactly
    speed_step: float = 0.0  # [m/s] rim speed of one motor rpm, as the controller reports speed; 0: exactly
    steering_rate_step: float = 0.0  # [rad/s] steering rate of one steering motor rpm; 0: exactly

    def measured(self, steering: float, speed: float, wheel_angle: float, steering_rate: float):
        """What the drive's controller reports for the joints' true values: the homing error taken
        off the steering, then whole encoder counts and whole motor rpm where it counts them."""
        steering -= self.steering_offset
        if self.steering_count:
            steering = quantise(steering, 1.0 / self.steering_count)
        if self.wheel_count:
            wheel_angle = quantise(wheel_angle, 1.0 / self.wheel_count)
        if self.speed_step:
            speed = round(speed / self.speed_step) * self.speed_step
        if self.steering_rate_step:
            steering_rate = round(steering_rate / self.steering_rate_step) * self.steering_rate_step
        return steering, speed, wheel_angle, steering_rate


@dataclass(frozen=True)
class SimAsBuilt:
    """An as-built robot resolved for the simulator: per drive in drive order, the true radius, the
    homing error and the encoders' resolution; the measurement delay and the load. It travels from
    spawn_robot (which reads the files) to the simulator (which may run on another computer) as
    JSON in the spawn request."""

    source: str
    drives: Tuple[BuiltDrive, ...]
    delay: float = 0.0  # [s]
    mass_offset: float = 0.0  # [kg]
    # [m] how far each tyre gives under its share of the robot's weight (pneumatic tyres: a soft contact
    # whose stiffness is that share over this); 0: rigid tyres, as configured
    tyre_deflection: float = 0.0

    def to_json(self) -> str:
        return json.dumps(
            {
                "source": self.source,
                "drives": [dataclasses.asdict(d) for d in self.drives],
                "delay": self.delay,
                "mass_offset": self.mass_offset,
                "tyre_deflection": self.tyre_deflection,
            }
        )

    @classmethod
    def from_json(cls, text: str, drives: Optional[int] = None) -> "SimAsBuilt":
        """The spawn request's as_built field (for a robot of that many drives, if given); ValueError
        saying why it cannot be used."""
        try:
            data = json.loads(text)
            built = cls(
                str(data["source"]),
                tuple(BuiltDrive(**{k: float(v) for k, v in d.items()}) for d in data["drives"]),
                float(data["delay"]),
                float(data["mass_offset"]),
                float(data.get("tyre_deflection", 0.0)),
            )
        except (ValueError, TypeError, KeyError) as e:
            raise ValueError(f"the as-built robot is not readable ({type(e).__name__}: {e})") from None
        values = [built.delay, built.mass_offset, built.tyre_deflection] + [
            v for d in built.drives for v in dataclasses.astuple(d)
        ]
        if drives is not None and len(built.drives) != drives:
            raise ValueError(f"the as-built robot has {len(built.drives)} drives, the description {drives}")
        if not all(math.isfinite(v) for v in values) or any(d.r_wheel <= 0 for d in built.drives):
            raise ValueError("the as-built robot's values must be finite, its radii > 0")
        if built.tyre_deflection < 0:
            raise ValueError("the as-built robot's tyre deflection must be >= 0")
        return built


def for_simulator(as_built: AsBuilt, config: RobotConfig) -> SimAsBuilt:
    """What the simulator needs of an as-built robot of config. The encoders count as the CAN
    codec's scalings say (thorvald_base.can.protocol.DriveScaling): steering in quadrature counts of
    str_enc_ppr through str_gr_rt, the wheel in counts of prp_enc_ppr through prp_gr_rt, speeds in
    whole motor rpm, with the configured radius, as the controllers and base_driver convert them."""
    drives = []
    for built, drive in zip(as_built.drives, config.drives):
        counts = {}
        if as_built.encoders:
            scaling = DriveScaling.of(drive)
            counts = {
                "steering_count": 1.0 / scaling.counts_per_radian if drive.steerable else 0.0,
                "wheel_count": 1.0 / scaling.wheel_counts_per_radian,
                "speed_step": scaling.wheel_speed(1.0),
                "steering_rate_step": scaling.steering_rate(1.0) if drive.steerable else 0.0,
            }
        drives.append(BuiltDrive(built.r_wheel, built.steering_offset, **counts))
    return SimAsBuilt(as_built.source, tuple(drives), as_built.delay, as_built.mass_offset, as_built.tyre_deflection)


def describe_as_built(built: AsBuilt) -> str:
    """One line for reports: each drive's radius against the configured one [%] and its steering
    offset [deg], the encoders, the delay and the load."""
    drives = [f"tyres loaded {-built.loaded * 100:+.2f} % (in every r below)"] if built.loaded else []
    for d, radius in zip(built.drives, built.configured):
        text = f"{d.name} r {(d.r_wheel / radius - 1.0) * 100:+.2f} %"
        if d.steering_offset:
            text += f" steering {math.degrees(d.steering_offset):+.2f} deg"
        drives.append(text)
    extras = ["encoders counting" if built.encoders else "exact encoders"]
    if built.delay:
        extras.append(f"delay {built.delay * 1000:g} ms")
    if built.mass_offset:
        extras.append(f"load {built.mass_offset:g} kg")
    if built.tyre_deflection:
        extras.append(f"soft tyres ({built.tyre_deflection * 1000:.1f} mm under their share of the weight)")
    return ", ".join(drives + extras)


def _shown(spec: str) -> str:
    """A spec as a message's source: itself, or its repr cut, when it is long or not printable."""
    return spec if len(spec) <= 60 and spec.isprintable() else value_text(spec, 60)


def _name(index: int) -> str:
    return f"drive{index}"


def _radii(config: RobotConfig) -> Tuple[float, ...]:
    return tuple(d.r_wheel for d in config.drives)


def _drive_entries(raw: Any, config: RobotConfig, problems: List[Problem]) -> Dict[str, Dict[str, Any]]:
    """The drives the file names, checked: only drives of the configuration, each a mapping of
    DRIVE_KEYS."""
    if raw is None:
        return {}
    if not isinstance(raw, Mapping):
        problems.append(Problem("motor_drives", raw, "must be a mapping of the configuration's drives (drive0, ...)"))
        return {}
    known = [_name(i) for i in range(len(config.drives))]
    entries = {}
    for name, entry in raw.items():
        path = f"motor_drives.{name}"
        if str(name) not in known:
            rule = f"is not a drive of the robot (it has {', '.join(known)})"
            problems.append(Problem(path, MISSING, rule))
            continue
        values: Optional[dict] = parse_entry(entry, path, DRIVE_KEYS, problems)
        if values is not None:
            entries[str(name)] = values
    return entries


__all__ = [
    "PROFILES",
    "AsBuilt",
    "BuiltDrive",
    "DriveAsBuilt",
    "Profile",
    "SimAsBuilt",
    "as_built_for",
    "as_configured",
    "describe_as_built",
    "draw_as_built",
    "for_simulator",
    "is_profile_spec",
    "load_as_built",
    "parse_as_built",
    "profile_and_seed",
    "quantise",
]
