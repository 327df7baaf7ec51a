"""The registry of world element kinds: one :class:`~thorvald_sim.world.kind.ElementKind` a kind,
in the order the loader makes them and the scene builds them.

The loader (:func:`thorvald_sim.world.parse_world`), the scene
(:func:`thorvald_sim.scene.build_scene`) and ``check_world`` iterate :func:`element_kinds`; the
schema's documentation is rendered from it (:func:`keys_markdown`). A new kind is a module of its
own (value type, keys, maker, budget, scene builder, footprint) and one line in ``BUILT_IN``; a kind of a test or
of a user's program is added for a while with :func:`registered`.
"""

import re
from contextlib import contextmanager
from dataclasses import fields
from typing import Iterator, List, Optional, Sequence, Tuple

from thorvald_model.schema import KIND_NAMES, REQUIRED, Key

from ..doc_tables import markers, with_table
from . import footprints
from .budgets import bodies_each, patches_budget, polytunnels_budget, rows_budget, walls_budget
from .elements import (
    _height_field,
    _height_field_check,
    _object,
    _objects_check,
    _patch,
    _patches_check,
    _polytunnel,
    _rail,
    _rails_check,
    _rows,
    _slope,
    _wall,
)
from .keys import (
    DESCRIPTION_KEY,
    GRAVITY_KEY,
    GROUND_KEYS,
    HEIGHT_FIELD_KEYS,
    OBJECT_KEYS,
    PATCH_KEYS,
    POLYTUNNEL_KEYS,
    RAIL_KEYS,
    RGBA_RULE,
    ROWS_KEYS,
    SLOPE_KEYS,
    WALL_KEYS,
)
from .kind import ElementKind
from .values import RGBA_CONCRETE, RGBA_GRAVEL, RGBA_ICE, RGBA_LEAF, RGBA_TARMAC, RGBA_WOOD, Rgba, WorldConfig


def _rgba(name: str, rgba: Rgba) -> str:
    return f"{name} [{', '.join(f'{c:g}' for c in rgba)}]"


SURFACE_NUMBER = "the surface kind's, else 0"

# The kinds, in the order they are made and built (the height field first: it is the ground then)
BUILT_IN: Tuple[ElementKind, ...] = (
    ElementKind(
        "height_field", None, HEIGHT_FIELD_KEYS, make=_height_field, builder="build_height_field",
        footprint=footprints.height_field,
        check=_height_field_check, on_ground=False, body="ground",
        doc="uneven ground in place of the ground plane (beyond its edges there is no ground), of the ground's "
        "friction and colour",
        defaults={
            "resolution": "0.2; none with an image", "image": "none: a grid", "min_height": "0, with an image only",
            "max_height": "1, with an image only",
        },
    ),
    ElementKind(
        "patches", "patch", PATCH_KEYS, make=_patch, builder="build_patch", budget=patches_budget,
        footprint=footprints.patch, counted=("patch", "patches"),
        check=_patches_check, on_ground=False,
        doc="rectangles of another surface lying on the ground (a soft one let into it)",
        defaults={
            "surface": "none", "lateral_friction": "the surface kind's; required without a surface",
            "rolling_friction": SURFACE_NUMBER, "spinning_friction": SURFACE_NUMBER, "sinkage": SURFACE_NUMBER,
            "rgba": f"the surface kind's, else {_rgba('gravel', RGBA_GRAVEL)} ({_rgba('ice', RGBA_ICE)} below a "
            "lateral friction of 0.3)",
        },
    ),
    ElementKind(
        "slopes", "slope", SLOPE_KEYS, make=_slope, builder="build_slope", budget=bodies_each(), on_ground=False,
        footprint=footprints.slope, counted=("hill", "hills"),
        doc="hills along their own x axis: a ramp up, a flat top, a ramp down (a soft one sinks under a wheel)",
        defaults={
            "surface": "none", "lateral_friction": "the surface kind's, else 0.9",
            "rolling_friction": SURFACE_NUMBER, "spinning_friction": SURFACE_NUMBER, "sinkage": SURFACE_NUMBER,
        },
    ),
    ElementKind(
        "rails", "rail", RAIL_KEYS, make=_rail, builder="build_rail", budget=bodies_each(2.0), check=_rails_check,
        footprint=footprints.rail, counted=("rail pair", "rail pairs"),
        on_ground=False, doc="pairs of parallel heating pipes, as in greenhouses",
    ),
    ElementKind(
        "objects", "object", OBJECT_KEYS, make=_object, builder="build_object", budget=bodies_each(looks=True),
        footprint=footprints.world_object, counted=("object", "objects"),
        check=_objects_check, doc="single bodies: a box, cylinder, sphere or mesh file, static or moving",
        defaults={
            "z": "resting upright on the ground; a mesh's origin on it", "size_x": "required for a box",
            "size_y": "required for a box", "size_z": "required for a box",
            "radius": "required for a cylinder or a sphere", "length": "required for a cylinder",
            "file": "required for a mesh", "scale": "1, a mesh's", "rgba": _rgba("wood brown", RGBA_WOOD),
        },
    ),
    ElementKind(
        "rows", "row", ROWS_KEYS, make=_rows, builder="build_rows", budget=rows_budget,
        footprint=footprints.rows, counted=("rows entry", "rows entries"),
        doc="crop rows: parallel rows of plants from a few numbers", defaults={"rgba": _rgba("leaf green", RGBA_LEAF)},
    ),
    ElementKind(
        "polytunnels", "polytunnel", POLYTUNNEL_KEYS, make=_polytunnel, builder="build_polytunnel",
        footprint=footprints.polytunnel, counted=("polytunnel", "polytunnels"),
        budget=polytunnels_budget, doc="Haygrove-type tunnels of hoops, with table-tops or ground beds of strawberries",
    ),
    ElementKind(
        "walls", "wall", WALL_KEYS, make=_wall, builder="build_wall", budget=walls_budget,
        footprint=footprints.wall, counted=("wall", "walls"),
        doc="boxes standing on the ground", defaults={"rgba": _rgba("concrete", RGBA_CONCRETE)},
    ),
)  # fmt: skip

_kinds: List[ElementKind] = list(BUILT_IN)


def element_kinds() -> Tuple[ElementKind, ...]:
    """The kinds of world element, in the order they are made and built."""
    return tuple(_kinds)


def top_level_keys() -> Tuple[str, ...]:
    """Every key a world file may have at its top level."""
    return ("gravity", "ground", *(kind.section for kind in _kinds), "description")


_NAME = re.compile(r"^[a-z][a-z0-9_]*$")
_PREFIX = re.compile(r"^[a-z_]+$")  # the schema reads an entry's name as letters then its number


@contextmanager
def registered(kind: ElementKind) -> Iterator[ElementKind]:
    """Adds a kind of world element after the others while the ``with`` block runs, then takes it
    out again (even when the block raises), so the registry is left as it was::

        with registered(POSTS):
            world = load_world("posts.yaml")  # reads the posts: section
            scene = build_scene(client, world)  # builds world.posts

    ValueError if the kind cannot be one: its section is taken (a top-level key, or a name of
    :class:`~thorvald_sim.world.values.WorldConfig`), its names are not lowercase words, or its
    keys repeat a name.
    """
    _check_new(kind)
    _kinds.append(kind)
    try:
        yield kind
    finally:
        _kinds.remove(kind)


def _check_new(kind: ElementKind) -> None:
    def refuse(why: str) -> None:
        raise ValueError(f"element kind {kind.section!r} cannot be registered: {why}")

    if not isinstance(kind.section, str) or not _NAME.match(kind.section):
        refuse("its section must be a lowercase name (letters, digits, _)")
    if kind.section in top_level_keys():
        refuse("the world file has that top-level key already")
    if kind.section in {f.name for f in fields(WorldConfig)} or hasattr(WorldConfig, kind.section):
        refuse("WorldConfig has an attribute of that name, which would hide the section's values")
    if kind.prefix is not None and not _PREFIX.match(kind.prefix):
        refuse(f"its entries' prefix {kind.prefix!r} must be lowercase letters and _ (entries are prefix0, ...)")
    names = [n for key in kind.keys for n in (key.name, *key.aliases)]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        refuse(f"its keys name {', '.join(twice)} more than once")
    if not callable(kind.make) or not (callable(kind.builder) or isinstance(kind.builder, str)):
        refuse("make must be a function, builder a function or the name of one in thorvald_sim.scene")


# ---------------------------------------------------------------------------------------------
# The keys' table
# ---------------------------------------------------------------------------------------------
GROUND_DEFAULTS_TEXT = {
    "surface": "none",
    "lateral_friction": "the surface kind's, else 0.9",
    "rolling_friction": SURFACE_NUMBER,
    "spinning_friction": SURFACE_NUMBER,
    "sinkage": SURFACE_NUMBER,
    "rgba": f"the surface kind's, else {_rgba('tarmac grey', RGBA_TARMAC)}",
}


def keys_markdown(kinds: Optional[Sequence[ElementKind]] = None) -> str:
    """The world file's keys as a markdown table: one row a top-level key (the element kinds', and
    gravity, ground and description), with its entries and each key's default and rule.

    kinds: default the registry's. The rules between keys and the budgets are the package's
    docstring's (:mod:`thorvald_sim.world`).
    """
    kinds = element_kinds() if kinds is None else kinds
    rows = [
        ("gravity", "a number [m/s^2]", _keys_text((GRAVITY_KEY,), {})),
        ("ground", "one mapping: the ground plane's surface and colour", _keys_text(GROUND_KEYS, GROUND_DEFAULTS_TEXT)),
    ]
    for kind in kinds:
        entries = "one mapping" if kind.single else f"`{kind.prefix}0`, `{kind.prefix}1`, ..."
        if kind.doc:
            entries += f": {kind.doc}"
        rows.append((kind.section, entries, _keys_text(kind.keys, kind.defaults)))
    rows.append(("description", "free text", _keys_text((DESCRIPTION_KEY,), {})))
    lines = ["| section | entries | keys (default): rule |", "| --- | --- | --- |"]
    lines += [f"| `{section}` | {_cell(entries)} | {keys} |" for section, entries, keys in rows]
    return "\n".join(lines) + "\n"


KEYS_TABLE = "world-keys"  # the name of its marker lines in a markdown file (docs/worlds.md)
KEYS_BEGIN, KEYS_END = markers(KEYS_TABLE)


def with_keys_table(text: str, table: str) -> str:
    """The markdown text with the lines between its KEYS_BEGIN and KEYS_END lines replaced by table;
    ValueError if it has not both, in that order, once each."""
    return with_table(text, table, KEYS_TABLE)


def _keys_text(keys: Sequence[Key], defaults) -> str:
    return "<br>".join(_cell(_key_text(key, defaults.get(key.name))) for key in keys)


def _key_text(key: Key, default: Optional[str]) -> str:
    aliases = "".join(f", alias `{alias}`" for alias in key.aliases)
    if default is None:
        default = _default_text(key.default)
    rule = RGBA_RULE if key.name == "rgba" else key.rule or f"must be {KIND_NAMES[key.kind]}"
    return f"`{key.name}` ({default}{aliases}): {rule}"


def _default_text(default) -> str:
    if default is REQUIRED:
        return "required"
    if default is None:
        return "none"
    if isinstance(default, float):
        return f"{default:g}"
    if isinstance(default, str):
        return f"`{default}`" if default else '""'
    return str(default)


def _cell(text: str) -> str:
    """Text as it stands in a table's cell: a | would end the cell."""
    return text.replace("|", "\\|")
