"""Patches (``patches:``, entries ``patch0``, ...): rectangles of another surface lying on the ground
(gravel, grass, mud, ice), their tops 1 mm above it.

A patch names a surface kind (:mod:`thorvald_sim.world.surfaces`) or gives its lateral friction. A
soft patch (``sinkage`` above 0) needs a hole in the ground: the ground of a world with soft patches
is flat convex pieces 0.1 m thick with a hole under every patch, each patch filling its own (the
square of 2 km about the origin, :func:`thorvald_sim.world.geometry.ground_pieces`; beyond it there
is no ground), drawn as the plane; so a soft patch lies within 999 m of the origin in x and y, and a
world with a height field, which has no holes, has none. Its rectangular pieces are as the plane to
what drives or slides on them; the pieces beside a turned patch are not quite (see
:mod:`thorvald_sim.physics.scene`). Each takes a body of the world's budget, and with a soft one each is a
hole (:class:`~thorvald_sim.world.limits.Limits`).

In pybullet: a box 0.02 m thick whose top is 1 mm above the ground, so a wheel on the patch rests on
the patch alone (bullet reports the ground 1 mm below too, but a contact that is not closing carries
no normal force, hence no friction); in a ground with holes, a box filling its hole, 0.3 m deep for a
soft patch, so a wheel sinking into it meets nothing else. Drawn in its colour, its surface kind's,
or gravel grey-brown (ice pale blue below a lateral friction of 0.3).
"""

from dataclasses import dataclass
from typing import Any, List, Mapping, Optional, Sequence, Tuple

from thorvald_model.errors import MISSING, Problem
from thorvald_model.schema import Key

from ..bodies import p, set_surface
from ..geometry import GROUND_THICKNESS, SOFT_PATCH_REACH, Point, along, to_local
from ..kind import Context, ElementKind, Entry
from ..limits import Shares, bodies_each
from ..rules import COORDINATE, LENGTH, RGBA_KEY, Rgba
from ..surfaces import (
    RGBA_GRAVEL,
    RGBA_ICE,
    SURFACE_DEFAULTS,
    SURFACE_KEYS,
    SURFACE_NUMBER,
    ZERO_HINT,
    Surface,
    kind_colour,
    rgba_text,
    surface_of,
)

PATCH_TOP = 0.001  # [m] above the ground plane: a patch's top
SOFT_DEPTH = 0.3  # [m] of a soft patch below its top: six times MAX_SINKAGE, so no wheel meets its bottom
PATCH_THICKNESS = 0.02  # [m]: thick enough for a stable box-box or box-cylinder contact
LOW_FRICTION = 0.3  # [-] below this a patch is drawn as ice rather than gravel


@dataclass(frozen=True)
class Patch:
    """A rectangle of another surface lying on the ground (gravel, grass, mud, ice), its top 1 mm
    above the ground. A soft one (``sinkage`` above 0) is let into the ground: the ground has a
    hole under it (and under every other patch then), so a wheel sinks into it; a world with a
    height field, which has no holes, has none."""

    name: str
    index: int
    x: float  # [m] centre
    y: float  # [m]
    size_x: float  # [m] along the patch's own x axis
    size_y: float  # [m]
    yaw: float  # [rad] of the patch's x axis from the world's
    surface: Surface
    rgba: Optional[Rgba] = None  # the file's or its surface kind's; None: the scene's (gravel or ice)

    def contains(self, px: float, py: float) -> bool:
        """Whether the ground point (px, py) [m] lies on the patch (edges included)."""
        u, v = to_local(px - self.x, py - self.y, self.yaw)
        return abs(u) <= self.size_x / 2 and abs(v) <= self.size_y / 2

    def corners(self) -> Tuple[Point, Point, Point, Point]:
        """[m] the four corners in the world, counter-clockwise from the patch's (-x, -y) corner."""
        hx, hy = self.size_x / 2, self.size_y / 2
        return tuple(along(self.x, self.y, self.yaw, u, v) for u, v in ((-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy)))


PATCH_KEYS = (
    Key("x", float, **COORDINATE),
    Key("y", float, **COORDINATE),
    Key("size_x", float, **LENGTH),
    Key("size_y", float, **LENGTH),
    Key("yaw", float, 0.0),
    *SURFACE_KEYS,
    RGBA_KEY,
)


def make(entry: Entry, context: Context) -> Patch:
    v = entry.values
    surface = surface_of(v, SURFACE_DEFAULTS)
    colour = v["rgba"] or kind_colour(surface)
    return Patch(entry.name, entry.index, v["x"], v["y"], v["size_x"], v["size_y"], v["yaw"], surface, colour)


def check(patches: Tuple[Patch, ...], context: Context) -> None:
    context.problems.extend(_missing_lateral_friction(context.data.get("patches")))
    context.problems.extend(_soft_patch_problems(patches, context.single("height_field") is not None))


def _missing_lateral_friction(section: Any) -> List[Problem]:
    """A patch's lateral friction is required unless it names a surface kind (reported as parse_entry
    reports a required key: beside the entry's other problems, even when they drop the entry)."""
    if not isinstance(section, Mapping):
        return []
    return [
        Problem(f"patches.{name}.lateral_friction", MISSING, "is required")
        for name, entry in section.items()
        if isinstance(entry, Mapping) and "lateral_friction" not in entry and "surface" not in entry
    ]


def _soft_patch_problems(patches: Sequence[Patch], height_field: bool) -> List[Problem]:
    problems = []
    for patch in patches:
        if not patch.surface.soft:
            continue
        path = f"patches.{patch.name}.sinkage"
        if height_field:
            rule = f"must be 0 with a height_field ({ZERO_HINT}): a soft patch needs a hole in the ground"
            problems.append(Problem(path, patch.surface.sinkage, rule))
        elif max(max(abs(x), abs(y)) for x, y in patch.corners()) > SOFT_PATCH_REACH:
            rule = f"needs the patch within {SOFT_PATCH_REACH:g} m of the origin in x and y (the ground ends there)"
            problems.append(Problem(path, patch.surface.sinkage, rule))
    return problems


def budget(section: str, entries: Sequence[Entry], searched: int) -> Shares:
    """One body a patch; with a soft one, a hole in the ground under every patch."""
    shares = bodies_each()(section, entries, searched)
    if any(surface_of(e.values, SURFACE_DEFAULTS).soft for e in entries):
        shares["holes"] = [(section, len(entries), float(len(entries)))]
    return shares


def ground(patch: Patch, px: float, py: float) -> Optional[float]:
    """The patch's top on it; nothing off it."""
    return PATCH_TOP if patch.contains(px, py) else None


def soft_patches(patches: Sequence[Patch]) -> Tuple[Patch, ...]:
    """The soft patches; with any, the ground has a hole under every patch."""
    return tuple(pa for pa in patches if pa.surface.soft)


def holes(patches: Sequence[Patch]) -> List[Tuple[Point, ...]]:
    """A hole under every patch when one is soft (rigid patches too fill holes of their own, so that
    nothing lies 1 mm under a patch for a box sliding on it to catch its front edge on)."""
    return [patch.corners() for patch in patches] if soft_patches(patches) else []


def footprint(pa: Patch) -> List[Point]:
    return list(pa.corners())


def build(client: int, world, patch: Patch, name: str, bodies: dict) -> None:
    # in a ground with holes a patch fills its own, a soft one deep enough that no wheel sinks through it
    thickness = PATCH_THICKNESS
    if patch.surface.soft:
        thickness = PATCH_TOP + SOFT_DEPTH
    elif soft_patches(world.patches):
        thickness = PATCH_TOP + GROUND_THICKNESS
    half = (patch.size_x / 2, patch.size_y / 2, thickness / 2)
    color = patch.rgba or (RGBA_ICE if patch.surface.lateral_friction < LOW_FRICTION else RGBA_GRAVEL)
    shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=client)
    visual = p.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=color, physicsClientId=client)
    body = p.createMultiBody(
        0,
        shape,
        visual,
        basePosition=(patch.x, patch.y, PATCH_TOP - thickness / 2),
        baseOrientation=p.getQuaternionFromEuler((0, 0, patch.yaw)),
        physicsClientId=client,
    )
    set_surface(client, body, patch.surface)
    bodies[name] = body


PATCHES = ElementKind(
    "patches", "patch", PATCH_KEYS, make=make, builder=build, budget=budget, footprint=footprint,
    counted=("patch", "patches"), check=check, on_ground=False, ground=ground, holes=holes,
    doc="rectangles of another surface lying on the ground (a soft one let into it)",
    defaults={
        "surface": "none", "lateral_friction": "the surface kind's; required without a surface",
        "rolling_friction": SURFACE_NUMBER, "spinning_friction": SURFACE_NUMBER, "sinkage": SURFACE_NUMBER,
        "rgba": f"the surface kind's, else {rgba_text('gravel', RGBA_GRAVEL)} ({rgba_text('ice', RGBA_ICE)} below a "
        "lateral friction of 0.3)",
    },
)  # fmt: skip
