"""The keys of a world file: each section's :class:`~thorvald_model.schema.Key` tuple (type,
default, rule, aliases), the rules they share, and what the surface keys mean.

The table of every key with its default and rule is rendered from the element kinds' keys
(:func:`thorvald_sim.world.registry.keys_markdown`); the rules between keys are the elements'
(:mod:`thorvald_sim.world.elements`).
"""

from typing import Mapping, Optional, Tuple

from thorvald_model.schema import NON_NEGATIVE, POSITIVE, Key, in_range, one_of

from .values import MAX_SINKAGE, SURFACE_KINDS, TABLE_DEPTH, Rgba, Surface

WHAT = "world"

# Bounds of every position and length (the package's "Limits")
MAX_REACH = 10_000.0  # [m] |x|, |y| of anything, and an object's |z|: a farm is at most 20 km across
MAX_LENGTH = 10_000.0  # [m] of any length, size, height or spacing
MAX_MESH_SCALE = 1000.0  # [-] a mesh drawn in km, or a scale typed in mm instead of m, is a mistake

GRAVITY_KEY = Key("gravity", float, 9.81, **POSITIVE)
DESCRIPTION_KEY = Key("description", str, "")

# rgba is a list, which the schema's keys do not take: it is checked apart (_take_colours) and stands
# in the entry as an empty string, so that its key is known (for "did you mean") and given once.
RGBA_KEY = Key("rgba", str, "")
RGBA_RULE = "must be a list of 3 or 4 numbers in [0, 1] (red, green, blue, alpha)"


def _frictions(lateral: float) -> Tuple[Key, ...]:
    return (
        Key("lateral_friction", float, lateral, **NON_NEGATIVE),
        Key("rolling_friction", float, 0.0, **NON_NEGATIVE),
        Key("spinning_friction", float, 0.0, **NON_NEGATIVE),
    )


UNIT_RANGE = dict(check=in_range(0.0, 1.0), rule="must be in [0, 1]")

# Every length and position is bounded (MAX_LENGTH, MAX_REACH): the numbers made from them (plants,
# hoops, grid points) are then finite floats, and a count is checked before anything is made.
LENGTH = dict(check=lambda v: 0.0 < v <= MAX_LENGTH, rule=f"must be in (0, {MAX_LENGTH:g}] [m]")
LENGTH_OR_ZERO = dict(check=in_range(0.0, MAX_LENGTH), rule=f"must be in [0, {MAX_LENGTH:g}] [m]")
HEIGHT = dict(check=in_range(-MAX_LENGTH, MAX_LENGTH), rule=f"must be in [-{MAX_LENGTH:g}, {MAX_LENGTH:g}] [m]")
COORDINATE = dict(check=in_range(-MAX_REACH, MAX_REACH), rule=f"must be in [-{MAX_REACH:g}, {MAX_REACH:g}] [m]")
OPTIONAL_LENGTH = dict(default=None, **LENGTH)  # a key a cross-field rule requires or refuses

KINDS_RULE = "must be one of " + ", ".join(SURFACE_KINDS)
SINKAGE_RULE = f"must be in [0, {MAX_SINKAGE}] [m]"

# The ground's and the patches' surface keys default to None: a key not in the file takes its
# surface kind's number (_surface_of), or else the default in SURFACE_DEFAULTS.
SURFACE_KEYS = (
    Key("surface", str, None, check=one_of(*SURFACE_KINDS), rule=KINDS_RULE),
    Key("lateral_friction", float, None, **NON_NEGATIVE),
    Key("rolling_friction", float, None, **NON_NEGATIVE),
    Key("spinning_friction", float, None, **NON_NEGATIVE),
    Key("sinkage", float, None, check=in_range(0.0, MAX_SINKAGE), rule=SINKAGE_RULE),
)
SURFACE_DEFAULTS = {"rolling_friction": 0.0, "spinning_friction": 0.0, "sinkage": 0.0}
ZERO_HINT = "write sinkage: 0 beside a soft surface kind"

GROUND_KEYS = (*SURFACE_KEYS, Key("restitution", float, 0.0, **UNIT_RANGE), RGBA_KEY)
GROUND_DEFAULTS = {**SURFACE_DEFAULTS, "lateral_friction": 0.9}

PATCH_KEYS = (
    Key("x", float, **COORDINATE),
    Key("y", float, **COORDINATE),
    Key("size_x", float, **LENGTH),
    Key("size_y", float, **LENGTH),
    Key("yaw", float, 0.0),
    *SURFACE_KEYS,
    RGBA_KEY,
)

MAX_SLOPE_ANGLE = 1.2  # [rad], about 69 degrees: steeper is a wall, and tan() grows without bound

SLOPE_KEYS = (
    Key("x", float, **COORDINATE),
    Key("y", float, **COORDINATE),
    Key("yaw", float, 0.0),
    Key("width", float, **LENGTH),
    Key("angle", float, check=lambda v: 0.0 < v <= MAX_SLOPE_ANGLE, rule=f"must be in (0, {MAX_SLOPE_ANGLE}] [rad]"),
    Key("height", float, **LENGTH),
    Key("top_length", float, 0.0, **LENGTH_OR_ZERO),
    *SURFACE_KEYS,
)
SLOPE_DEFAULTS = {**SURFACE_DEFAULTS, "lateral_friction": 0.9}

RAIL_KEYS = (
    Key("x", float, **COORDINATE),
    Key("y", float, **COORDINATE),
    Key("yaw", float, 0.0),
    Key("length", float, **LENGTH),
    Key("gauge", float, 0.55, **LENGTH),
    Key("height", float, 0.1, **LENGTH),
    Key("radius", float, 0.0255, **LENGTH),  # 51 mm pipes, the common greenhouse size
    *_frictions(0.8),
)

SHAPES = ("box", "cylinder", "sphere", "mesh")
# the keys of each shape's dimensions: required for it, refused for the others
SHAPE_KEYS = {
    "box": ("size_x", "size_y", "size_z"),
    "cylinder": ("radius", "length"),
    "sphere": ("radius",),
    "mesh": ("file", "scale"),
}
MESH_EXTENSIONS = (".obj", ".stl")

OBJECT_KEYS = (
    Key("shape", str, check=one_of(*SHAPES), rule="must be one of " + ", ".join(SHAPES)),
    Key("x", float, **COORDINATE),
    Key("y", float, **COORDINATE),
    Key("z", float, None, **COORDINATE),
    Key("roll", float, 0.0),
    Key("pitch", float, 0.0),
    Key("yaw", float, 0.0),
    Key("size_x", float, **OPTIONAL_LENGTH),
    Key("size_y", float, **OPTIONAL_LENGTH),
    Key("size_z", float, **OPTIONAL_LENGTH),
    Key("radius", float, **OPTIONAL_LENGTH),
    Key("length", float, **OPTIONAL_LENGTH),
    Key("file", str, None, check=bool, rule="must not be empty"),
    Key("scale", float, None, check=lambda v: 0.0 < v <= MAX_MESH_SCALE, rule=f"must be in (0, {MAX_MESH_SCALE:g}]"),
    Key("mass", float, 0.0, **NON_NEGATIVE),
    RGBA_KEY,
    *_frictions(0.8),
    Key("restitution", float, 0.0, **UNIT_RANGE),
)

PLANTS = ("cylinder", "sphere")

ROWS_KEYS = (
    Key("x", float, **COORDINATE),
    Key("y", float, **COORDINATE),
    Key("yaw", float, 0.0),
    Key("count", int, 1, **POSITIVE),
    Key("spacing", float, 0.75, **LENGTH),
    Key("length", float, **LENGTH),
    Key("plant", str, "cylinder", one_of(*PLANTS), "must be one of " + ", ".join(PLANTS)),
    Key("plant_spacing", float, 0.3, **LENGTH),
    Key("plant_radius", float, 0.1, **LENGTH),
    Key("plant_height", float, 0.4, **LENGTH),
    Key("gap_probability", float, 0.0, aliases=("gaps",), **UNIT_RANGE),
    Key("jitter", float, 0.0, **LENGTH_OR_ZERO),
    Key("seed", int, 0),
    RGBA_KEY,
    *_frictions(0.5),
)

CROPS = ("table_tops", "ground_beds", "none")

POLYTUNNEL_KEYS = (
    Key("x", float, **COORDINATE),
    Key("y", float, **COORDINATE),
    Key("yaw", float, 0.0),
    Key("length", float, **LENGTH),
    Key("width", float, 8.0, **LENGTH),
    Key("height", float, 4.0, **LENGTH),
    Key("leg_height", float, 2.0, **LENGTH_OR_ZERO),
    Key("hoop_spacing", float, 2.0, **LENGTH),
    Key("tube", float, 0.05, **LENGTH),
    Key("crop", str, "table_tops", one_of(*CROPS), "must be one of " + ", ".join(CROPS)),
    Key("tables", int, 4, **POSITIVE),
    Key(
        "table_height",
        float,
        1.1,
        check=lambda v: TABLE_DEPTH < v <= MAX_LENGTH,
        rule=f"must be in ({TABLE_DEPTH}, {MAX_LENGTH:g}] [m] (above the trough's depth)",
    ),
    Key("table_width", float, 0.4, **LENGTH),
    Key("leg_spacing", float, 1.8, **LENGTH),
    Key("bed_height", float, 0.2, **LENGTH),
    Key("end_gap", float, 1.5, **LENGTH_OR_ZERO),
    Key("plant_spacing", float, 0.25, **LENGTH),
    *_frictions(0.5),
)

WALL_KEYS = (
    Key("x", float, **COORDINATE),
    Key("y", float, **COORDINATE),
    Key("yaw", float, 0.0),
    Key("length", float, **LENGTH),
    Key("height", float, 2.0, **LENGTH),
    Key("thickness", float, 0.2, **LENGTH),
    RGBA_KEY,
    *_frictions(0.8),
)

HEIGHT_FIELD_KEYS = (
    Key("x", float, 0.0, **COORDINATE),
    Key("y", float, 0.0, **COORDINATE),
    Key("size_x", float, **LENGTH),
    Key("size_y", float, **LENGTH),
    Key("resolution", float, **OPTIONAL_LENGTH),
    Key("image", str, None, check=bool, rule="must not be empty"),
    Key("min_height", float, None, **HEIGHT),
    Key("max_height", float, None, **HEIGHT),
    Key("amplitude", float, 0.0, **LENGTH_OR_ZERO),
    Key("feature_length", float, 1.0, **LENGTH),
    Key("seed", int, 0),
    Key("rut_depth", float, 0.0, **LENGTH_OR_ZERO),
    Key("rut_width", float, 0.3, **LENGTH),
    Key("rut_spacing", float, 1.5, **LENGTH),
    Key("flat_radius", float, 2.0, **LENGTH_OR_ZERO),
)


# ---------------------------------------------------------------------------------------------
# What the surface keys mean
# ---------------------------------------------------------------------------------------------
def _surface(values: Mapping) -> Surface:
    return Surface(
        values["lateral_friction"],
        values["rolling_friction"],
        values["spinning_friction"],
        values.get("restitution", 0.0),
    )


def _surface_of(v: Mapping, defaults: Mapping) -> Surface:
    """The surface of an entry with SURFACE_KEYS: each number the file's, else its kind's, else the
    default (0 for a key missing from defaults: :func:`_missing_lateral_friction` reports it)."""
    kind = SURFACE_KINDS.get(v["surface"])
    base = kind.surface(v["surface"]) if kind else None
    numbers = {}
    for name in ("lateral_friction", "rolling_friction", "spinning_friction", "sinkage"):
        if v[name] is not None:
            numbers[name] = v[name]
        elif base is not None:
            numbers[name] = getattr(base, name)
        else:
            numbers[name] = defaults.get(name, 0.0)
    return Surface(
        numbers["lateral_friction"],
        numbers["rolling_friction"],
        numbers["spinning_friction"],
        v.get("restitution", 0.0),
        numbers["sinkage"],
        v["surface"] or "",
    )


def _kind_colour(surface: Surface) -> Optional[Rgba]:
    kind = SURFACE_KINDS.get(surface.kind)
    return kind.rgba if kind else None
