"""The simulator's world: a small YAML file of ground, friction patches, hills and heating-pipe rails.

The simulator node's ``~world`` parameter names a shipped world (``flat``, ``tarmac_gravel``,
``slope``, ``greenhouse``: the files in this package's ``worlds`` folder) or gives a path. A world file
has these top-level keys (lengths [m], angles [rad], frictions are pybullet's per-body
coefficients, which pybullet multiplies with the wheel's; the simulator's wheels have friction 1.0):

``gravity``
    [m/s^2], default 9.81.
``ground``
    one mapping: ``lateral_friction``, ``rolling_friction``, ``spinning_friction``, ``restitution``.
``patches``
    ``patch0``, ``patch1``, ...: rectangles of another friction lying on the ground (gravel, ice),
    centred at ``x``, ``y``, ``size_x`` by ``size_y``, turned by ``yaw``.
``slopes``
    ``slope0``, ...: hills along their own x axis: a ramp up at ``angle``, a flat top of
    ``top_length`` at ``height``, a ramp down at ``angle``; ``x``, ``y`` is the centre of the
    footprint, ``width`` its size across.
``rails``
    ``rail0``, ...: pairs of parallel heating pipes as in greenhouses (the paper's Figure 2a robot
    rides them): ``x``, ``y`` is the point between the pipes at the middle of their ``length``,
    ``yaw`` the direction they run in, ``gauge`` the distance between the pipe centres.
``description``
    free text.

Validation is the robot configuration's (:mod:`thorvald_model.schema`): every problem is collected
with its dotted key path, value and rule, and raised together in one :class:`ConfigError`.

Pure: no pybullet, no rospy, no messages (the scene is built by :mod:`thorvald_sim.scene`).
"""

import glob
import math
import os
from dataclasses import dataclass
from typing import Any, List, Mapping, Tuple

from thorvald_model.errors import MISSING, ConfigError, Problem
from thorvald_model.resources import package_folder
from thorvald_model.schema import (
    NON_NEGATIVE,
    POSITIVE,
    Key,
    check_top_level,
    in_range,
    parse_entry,
    parse_section,
    read_yaml_file,
)

WHAT = "world"

# The package folder when this module runs from the source tree (or the devel space, which relays
# to it); in an install space the worlds are under share/thorvald_sim instead.
PACKAGE_DIR = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


# ---------------------------------------------------------------------------------------------
# Value types (SI units: m, rad, m/s^2)
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Surface:
    """pybullet's contact coefficients of one body.

    pybullet multiplies the lateral frictions of the two bodies in a contact, and combines rolling
    and spinning friction as ``a.rolling * b.lateral + b.rolling * a.lateral`` and restitution as
    the product; the simulator's wheels have lateral friction 1.0 and no rolling or spinning
    friction, so these are the effective values under a wheel.
    """

    lateral_friction: float  # [-] Coulomb coefficient
    rolling_friction: float  # [m] pybullet's rolling resistance (torque per normal force)
    spinning_friction: float  # [m] resistance to turning about the contact normal
    restitution: float = 0.0  # [-] 0 (no bounce) .. 1


@dataclass(frozen=True)
class Patch:
    """A rectangle of another friction lying on the ground (its top 1 mm above the ground)."""

    name: str
    index: int
    x: float  # [m] centre
    y: float  # [m]
    size_x: float  # [m] along the patch's own x axis
    size_y: float  # [m]
    yaw: float  # [rad] of the patch's x axis from the world's
    surface: Surface

    def contains(self, px: float, py: float) -> bool:
        """Whether the ground point (px, py) [m] lies on the patch (edges included)."""
        u, v = _to_local(px - self.x, py - self.y, self.yaw)
        return abs(u) <= self.size_x / 2 and abs(v) <= self.size_y / 2


@dataclass(frozen=True)
class Slope:
    """A hill along its own x axis: ramp up at ``angle``, flat top, ramp down at ``angle``."""

    name: str
    index: int
    x: float  # [m] centre of the footprint
    y: float  # [m]
    yaw: float  # [rad] of the hill's x axis
    width: float  # [m] across the hill
    angle: float  # [rad] of both ramps
    height: float  # [m] of the top above the ground
    top_length: float  # [m] of the flat top along the hill
    surface: Surface

    @property
    def footprint_length(self) -> float:
        """[m] along the hill, ramps included."""
        return self.top_length + 2.0 * self.height / math.tan(self.angle)


@dataclass(frozen=True)
class Rail:
    """A pair of parallel pipes lying above the ground (greenhouse heating pipes used as rails)."""

    name: str
    index: int
    x: float  # [m] between the pipes, middle of their length
    y: float  # [m]
    yaw: float  # [rad] direction the pipes run in
    length: float  # [m] of each pipe
    gauge: float  # [m] between the pipe centres
    height: float  # [m] of the pipe centres above the ground
    radius: float  # [m] of each pipe
    surface: Surface


@dataclass(frozen=True)
class WorldConfig:
    """A validated world file."""

    source: str  # file name, or what the data came from
    gravity: float  # [m/s^2], pointing down
    ground: Surface
    patches: Tuple[Patch, ...]
    slopes: Tuple[Slope, ...]
    rails: Tuple[Rail, ...]
    description: str = ""


def _to_local(dx: float, dy: float, yaw: float) -> Tuple[float, float]:
    c, s = math.cos(yaw), math.sin(yaw)
    return c * dx + s * dy, -s * dx + c * dy


# ---------------------------------------------------------------------------------------------
# Schema
# ---------------------------------------------------------------------------------------------
GRAVITY_KEY = Key("gravity", float, 9.81, **POSITIVE)
DESCRIPTION_KEY = Key("description", str, "")

GROUND_KEYS = (
    Key("lateral_friction", float, 0.9, **NON_NEGATIVE),
    Key("rolling_friction", float, 0.0, **NON_NEGATIVE),
    Key("spinning_friction", float, 0.0, **NON_NEGATIVE),
    Key("restitution", float, 0.0, in_range(0.0, 1.0), "must be in [0, 1]"),
)

PATCH_KEYS = (
    Key("x", float),
    Key("y", float),
    Key("size_x", float, **POSITIVE),
    Key("size_y", float, **POSITIVE),
    Key("yaw", float, 0.0),
    Key("lateral_friction", float, **NON_NEGATIVE),
    Key("rolling_friction", float, 0.0, **NON_NEGATIVE),
    Key("spinning_friction", float, 0.0, **NON_NEGATIVE),
)

MAX_SLOPE_ANGLE = 1.2  # [rad], about 69 degrees: steeper is a wall, and tan() grows without bound

SLOPE_KEYS = (
    Key("x", float),
    Key("y", float),
    Key("yaw", float, 0.0),
    Key("width", float, **POSITIVE),
    Key("angle", float, check=lambda v: 0.0 < v <= MAX_SLOPE_ANGLE, rule=f"must be in (0, {MAX_SLOPE_ANGLE}] [rad]"),
    Key("height", float, **POSITIVE),
    Key("top_length", float, 0.0, **NON_NEGATIVE),
    Key("lateral_friction", float, 0.9, **NON_NEGATIVE),
    Key("rolling_friction", float, 0.0, **NON_NEGATIVE),
    Key("spinning_friction", float, 0.0, **NON_NEGATIVE),
)

RAIL_KEYS = (
    Key("x", float),
    Key("y", float),
    Key("yaw", float, 0.0),
    Key("length", float, **POSITIVE),
    Key("gauge", float, 0.55, **POSITIVE),
    Key("height", float, 0.1, **POSITIVE),
    Key("radius", float, 0.0255, **POSITIVE),  # 51 mm pipes, the common greenhouse size
    Key("lateral_friction", float, 0.8, **NON_NEGATIVE),
    Key("rolling_friction", float, 0.0, **NON_NEGATIVE),
    Key("spinning_friction", float, 0.0, **NON_NEGATIVE),
)

SECTIONS = (("patches", "patch", PATCH_KEYS), ("slopes", "slope", SLOPE_KEYS), ("rails", "rail", RAIL_KEYS))
TOP_LEVEL_KEYS = ("gravity", "ground", *(key for key, _, _ in SECTIONS), "description")


# ---------------------------------------------------------------------------------------------
# Loading
# ---------------------------------------------------------------------------------------------
def load_world(path: str) -> WorldConfig:
    """Loads and validates a world file; raises ConfigError naming every problem.

    A file that cannot be read at all (missing, a directory, not text, not YAML) raises a
    ConfigError with one problem at the top level, which formats as one line.
    """
    return parse_world(read_yaml_file(path, WHAT), path)


def parse_world(data: Any, source: str = "<world>") -> WorldConfig:
    """Validates an already parsed world (a YAML document or a ROS parameter tree)."""
    problems: List[Problem] = []
    try:
        data = check_top_level(data, TOP_LEVEL_KEYS, problems)
    except ConfigError as e:
        raise ConfigError(source, e.problems, WHAT) from None

    # The two scalar keys go through parse_entry as a one-key entry each, so they get the same
    # coercion and rules as every other key; their paths are the bare key names.
    gravity = _scalar(data, GRAVITY_KEY, problems)
    description = _scalar(data, DESCRIPTION_KEY, problems)

    # A missing ground, or an empty ``ground:`` (YAML null), means every default, as for sections.
    raw_ground = data.get("ground")
    ground_values = parse_entry({} if raw_ground is None else raw_ground, "ground", GROUND_KEYS, problems)
    ground = Surface(**(ground_values or {k.name: k.default for k in GROUND_KEYS}))

    built = {}
    for key, prefix, keys in SECTIONS:
        entries = parse_section(data.get(key), key, prefix, keys, problems)
        built[key] = tuple(_BUILDERS[key](name, index, values) for name, index, values in entries)

    problems.extend(_rail_problems(built["rails"], problems))
    if problems:
        raise ConfigError(source, problems, WHAT)
    return WorldConfig(
        source=source,
        gravity=gravity,
        ground=ground,
        patches=built["patches"],
        slopes=built["slopes"],
        rails=built["rails"],
        description=description,
    )


def _scalar(data: Mapping, key: Key, problems: List[Problem]) -> Any:
    if key.name not in data:
        return key.default
    found: List[Problem] = []
    values = parse_entry({key.name: data[key.name]}, "", (key,), found)
    # parse_entry names a key of the entry at "" as ".gravity"; a top-level key has no dot
    problems.extend(Problem(p.path.lstrip("."), p.value, p.rule) for p in found)
    return values[key.name] if values else key.default


def _surface(values: Mapping) -> Surface:
    return Surface(values["lateral_friction"], values["rolling_friction"], values["spinning_friction"])


def _patch(name: str, index: int, v: Mapping) -> Patch:
    return Patch(name, index, v["x"], v["y"], v["size_x"], v["size_y"], v["yaw"], _surface(v))


def _slope(name: str, index: int, v: Mapping) -> Slope:
    return Slope(
        name, index, v["x"], v["y"], v["yaw"], v["width"], v["angle"], v["height"], v["top_length"], _surface(v)
    )


def _rail(name: str, index: int, v: Mapping) -> Rail:
    return Rail(name, index, v["x"], v["y"], v["yaw"], v["length"], v["gauge"], v["height"], v["radius"], _surface(v))


_BUILDERS = {"patches": _patch, "slopes": _slope, "rails": _rail}


def _rail_problems(rails: Tuple[Rail, ...], found: List[Problem]) -> List[Problem]:
    problems = []
    for rail in rails:
        path = f"rails.{rail.name}"
        # A key that already broke its own rule was replaced by its default; comparing that default
        # would report a value the file does not hold.
        if any(p.path in (f"{path}.radius", f"{path}.height", f"{path}.gauge") for p in found):
            continue
        if rail.radius >= rail.height:
            problems.append(
                Problem(
                    f"{path}.radius",
                    rail.radius,
                    f"must be < height ({rail.height} m): a pipe cannot sink into the ground",
                )
            )
        if rail.gauge <= 2.0 * rail.radius:
            problems.append(
                Problem(
                    f"{path}.gauge",
                    rail.gauge,
                    f"must be > 2 * radius ({2.0 * rail.radius} m): the two pipes would overlap",
                )
            )
    return problems


# ---------------------------------------------------------------------------------------------
# Shipped worlds
# ---------------------------------------------------------------------------------------------
def worlds_dir() -> str:
    """The shipped worlds' folder, in the devel or install space (or the source tree)."""
    return os.path.join(package_folder("thorvald_sim", PACKAGE_DIR), "worlds")


def __getattr__(name: str) -> Any:
    # WORLDS_DIR is looked up when first asked for, not at import: importing this module must not
    # crawl the ROS package path (a module-level __getattr__, PEP 562).
    if name == "WORLDS_DIR":
        return worlds_dir()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def shipped_worlds() -> List[str]:
    """Names of the shipped worlds (``flat``, ...), sorted."""
    return sorted(os.path.splitext(os.path.basename(f))[0] for f in glob.glob(os.path.join(worlds_dir(), "*.yaml")))


def resolve_world(name_or_path: str) -> str:
    """The file of a world given by name (a shipped world) or by path.

    A shipped world's name wins over a file of that name in the current folder. Anything that looks
    like a path (has a folder separator or a YAML extension) or names an existing file is returned
    as it is, so that a missing file is reported by :func:`load_world` with the reason; a bare name
    that is neither raises a ConfigError of one line listing the shipped worlds.
    """
    names = shipped_worlds()
    if name_or_path in names:
        return os.path.join(worlds_dir(), name_or_path + ".yaml")
    looks_like_path = os.sep in name_or_path or name_or_path.endswith((".yaml", ".yml"))
    if looks_like_path or os.path.exists(name_or_path):
        return name_or_path
    rule = "no such world: give a file or one of " + ", ".join(names)
    raise ConfigError(name_or_path, [Problem("", MISSING, rule)], WHAT)


__all__ = [
    "ConfigError",
    "Patch",
    "Rail",
    "Slope",
    "Surface",
    "WorldConfig",
    "load_world",
    "parse_world",
    "resolve_world",
    "shipped_worlds",
    "worlds_dir",
]
