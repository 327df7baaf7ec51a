"""The ground (``ground:``): the plane's surface and colour, a key of the world file that is no
element kind's (the ground is built by :mod:`thorvald_sim.physics.scene`, around what the kinds make of it).

The ground's own sinkage makes the whole ground plane soft (not a height field: bullet touches a
wheel at one to four points of its triangles, rolling or not, so the sinkage would wander). A kind
may cut holes in it (a soft patch needs one: :mod:`thorvald_sim.world.kinds.patches`), take its
place (a height field) or shape it (hills, patches): :class:`~thorvald_sim.world.kind.ElementKind`'s
``holes``, ``replaces_ground`` and ``ground``.
"""

from typing import List, Mapping, Tuple

from thorvald_model.errors import Problem
from thorvald_model.schema import Key, parse_entry

from .rules import RGBA_KEY, UNIT_RANGE, Rgba, take_colour
from .surfaces import (
    RGBA_TARMAC,
    SURFACE_DEFAULTS,
    SURFACE_KEYS,
    SURFACE_NUMBER,
    Surface,
    kind_colour,
    rgba_text,
    surface_of,
)

GROUND_KEYS = (*SURFACE_KEYS, Key("restitution", float, 0.0, **UNIT_RANGE), RGBA_KEY)
GROUND_DEFAULTS = {**SURFACE_DEFAULTS, "lateral_friction": 0.9}
GROUND_DEFAULTS_TEXT = {  # the keys' table's defaults that the keys' own cannot say
    "surface": "none",
    "lateral_friction": "the surface kind's, else 0.9",
    "rolling_friction": SURFACE_NUMBER,
    "spinning_friction": SURFACE_NUMBER,
    "sinkage": SURFACE_NUMBER,
    "rgba": f"the surface kind's, else {rgba_text('tarmac grey', RGBA_TARMAC)}",
}


def parse_ground(data: Mapping, problems: List[Problem]) -> Tuple[Surface, Rgba]:
    """The ground's surface and colour. A missing ground, or an empty ``ground:`` (YAML null),
    means every default, as for sections."""
    raw_ground = data.get("ground")
    raw_ground = {} if raw_ground is None else raw_ground
    raw_ground, ground_colour = take_colour(raw_ground, "ground", None, problems)
    ground_values = parse_entry(raw_ground, "ground", GROUND_KEYS, problems)
    if ground_values is None:
        ground_values = {k.name: k.default for k in GROUND_KEYS}
    ground = surface_of(ground_values, GROUND_DEFAULTS)
    return ground, ground_colour or kind_colour(ground) or RGBA_TARMAC
