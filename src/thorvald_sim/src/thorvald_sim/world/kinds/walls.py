"""Walls (``walls:``, entries ``wall0``, ...): boxes standing on the ground, a wall's foot at the
lowest ground along its centre line (looked for every WALL_STEP: each point a ground look-up of the
world's budget).

In pybullet: a box, one body.
"""

import math
from dataclasses import dataclass
from typing import List, Sequence

from thorvald_model.schema import Key

from ..bodies import p, set_surface
from ..geometry import Point, along, rectangle
from ..kind import Context, ElementKind, Entry
from ..limits import WALL_STEP, Shares, at
from ..rules import COORDINATE, LENGTH, RGBA_KEY, Rgba
from ..surfaces import RGBA_CONCRETE, Surface, frictions, rgba_text, surface


@dataclass(frozen=True)
class Wall:
    """A box standing on the ground, its foot at the lowest ground along its centre line."""

    name: str
    index: int
    x: float  # [m] centre
    y: float  # [m]
    z: float  # [m] of its foot in the world: the lowest ground along it
    yaw: float  # [rad] direction the wall runs in
    length: float  # [m]
    height: float  # [m]
    thickness: float  # [m]
    rgba: Rgba
    surface: Surface


WALL_KEYS = (
    Key("x", float, **COORDINATE),
    Key("y", float, **COORDINATE),
    Key("yaw", float, 0.0),
    Key("length", float, **LENGTH),
    Key("height", float, 2.0, **LENGTH),
    Key("thickness", float, 0.2, **LENGTH),
    RGBA_KEY,
    *frictions(0.8),
)


def make(entry: Entry, context: Context) -> Wall:
    name, index, v, ground_at = entry.name, entry.index, entry.values, context.ground_at
    # the foot follows the lowest ground along the wall's centre line (every WALL_STEP); in a world
    # over its budgets, the ground at its centre
    if not context.over_budget:
        n = _wall_steps(v["length"])
        points = (along(v["x"], v["y"], v["yaw"], v["length"] * (k / n - 0.5), 0.0) for k in range(n + 1))
        foot = min(ground_at(*point) for point in points)
    else:
        foot = ground_at(v["x"], v["y"])
    return Wall(
        name, index, v["x"], v["y"], foot, v["yaw"], v["length"], v["height"], v["thickness"],
        v["rgba"] or RGBA_CONCRETE, surface(v),
    )  # fmt: skip


def budget(section: str, entries: Sequence[Entry], searched: int) -> Shares:
    """One body a wall, and a ground look-up every WALL_STEP along it."""
    return {
        "bodies": [(section, len(entries), float(len(entries)))],
        "ground_lookups": [
            (path, value, (_wall_steps(v["length"]) + 1.0) * searched) for path, value, v in at(entries, "length")
        ],
    }


def _wall_steps(length: float) -> int:
    """Steps of WALL_STEP (at most) along a wall: its points are one more."""
    return max(1, math.ceil(length / WALL_STEP))


def footprint(wa: Wall) -> List[Point]:
    return rectangle(wa.x, wa.y, wa.yaw, (-wa.length / 2, wa.length / 2), (-wa.thickness / 2, wa.thickness / 2))


def build(client: int, world, wall: Wall, name: str, bodies: dict) -> None:
    half = (wall.length / 2, wall.thickness / 2, wall.height / 2)
    shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=client)
    visual = p.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=wall.rgba, physicsClientId=client)
    body = p.createMultiBody(
        0,
        shape,
        visual,
        basePosition=(wall.x, wall.y, wall.z + wall.height / 2),
        baseOrientation=p.getQuaternionFromEuler((0, 0, wall.yaw)),
        physicsClientId=client,
    )
    set_surface(client, body, wall.surface)
    bodies[name] = body


WALLS = ElementKind(
    "walls", "wall", WALL_KEYS, make=make, builder=build, budget=budget, footprint=footprint,
    counted=("wall", "walls"),
    doc="boxes standing on the ground", defaults={"rgba": rgba_text("concrete", RGBA_CONCRETE)},
)  # fmt: skip
