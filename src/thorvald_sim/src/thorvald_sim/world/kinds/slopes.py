"""Hills (``slopes:``, entries ``slope0``, ...): a ramp up, a flat top, a ramp down along the hill's
own x axis; a soft one (a surface kind's or its own ``sinkage``) sinks under a wheel. Made before the
budgets, as part of the ground the others stand on: every ground look-up searches each hill.

In pybullet: one convex trapezoidal prism (pybullet makes the convex hull of its 8 corners), made
CONVEX_MARGIN smaller so that the hull bullet grows lies where the world file says; one body.
"""

import math
from dataclasses import dataclass
from typing import List, Optional, Tuple

from thorvald_model.schema import Key

from ..bodies import CONVEX_MARGIN, p, set_surface
from ..geometry import Point, rectangle, to_local
from ..kind import Context, ElementKind, Entry
from ..limits import bodies_each
from ..rules import COORDINATE, LENGTH, LENGTH_OR_ZERO
from ..surfaces import SURFACE_DEFAULTS, SURFACE_KEYS, SURFACE_NUMBER, Surface, surface_of

MAX_SLOPE_ANGLE = 1.2  # [rad], about 69 degrees: steeper is a wall, and tan() grows without bound
RGBA_HILL = (0.45, 0.50, 0.35, 1.0)


@dataclass(frozen=True)
class Slope:
    """A hill along its own x axis: a ramp up at ``angle``, a flat top of ``top_length`` at
    ``height``, a ramp down at ``angle``; ``x``, ``y`` the centre of its footprint, ``yaw`` the
    direction uphill, ``width`` its size across."""

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

    def height_at(self, px: float, py: float) -> Optional[float]:
        """[m] of the hill's surface over the ground point (px, py); None off its footprint."""
        u, v = to_local(px - self.x, py - self.y, self.yaw)
        half = self.footprint_length / 2
        if abs(u) > half or abs(v) > self.width / 2:
            return None
        return min(self.height, (half - abs(u)) * math.tan(self.angle))


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


def make(entry: Entry, context: Context) -> Slope:
    v = entry.values
    return Slope(
        entry.name, entry.index, v["x"], v["y"], v["yaw"], v["width"], v["angle"], v["height"], v["top_length"],
        surface_of(v, SLOPE_DEFAULTS),
    )  # fmt: skip


def ground(slope: Slope, px: float, py: float) -> float:
    """The hill's height at (px, py), 0 off it."""
    return slope.height_at(px, py) or 0.0


def footprint(sl: Slope) -> List[Point]:
    half = sl.footprint_length / 2
    return rectangle(sl.x, sl.y, sl.yaw, (-half, half), (-sl.width / 2, sl.width / 2))


# ---------------------------------------------------------------------------------------------
# In pybullet
# ---------------------------------------------------------------------------------------------
# Triangles of the prism's six faces over the corners of hill_vertices(), counter-clockwise seen
# from outside (the renderer culls faces seen from behind).
_PRISM_TRIANGLES = (
    (0, 2, 1), (0, 3, 2),  # bottom
    (4, 5, 6), (4, 6, 7),  # top
    (0, 1, 5), (0, 5, 4),  # side y < 0
    (1, 2, 6), (1, 6, 5),  # far ramp (+x)
    (2, 3, 7), (2, 7, 6),  # side y > 0
    (3, 0, 4), (3, 4, 7),  # near ramp (-x)
)  # fmt: skip


def hill_vertices(slope: Slope, margin: float = 0.0) -> List[Tuple[float, float, float]]:
    """The 8 corners [m] of the hill in its own frame (x along the hill, z up, origin at the centre
    of the footprint on the ground): bottom 0-3, then top 4-7, each counter-clockwise from (-x, -y).

    With a margin, every face but the bottom moves inwards by it, so that the hull grown by that
    margin has the nominal shape. The ramps' feet move in by margin / sin(angle); the top corners
    lie where the moved top and ramps meet, or on the ridge where the ramps meet if the top is too
    short for that (the grown ridge is then margin * (1 / cos(angle) - 1) below height: 0.015 mm at 10
    degrees, 1.8 mm at the steepest 1.2 rad).
    """
    a, m = slope.angle, margin
    bottom_x = slope.footprint_length / 2 - m / math.sin(a)
    top_x = max(slope.top_length / 2 - m * math.tan(a / 2), 0.0)
    top_z = min(slope.height - m, (bottom_x - top_x) * math.tan(a))
    y = slope.width / 2 - m
    return [
        (-bottom_x, -y, 0.0),
        (bottom_x, -y, 0.0),
        (bottom_x, y, 0.0),
        (-bottom_x, y, 0.0),
        (-top_x, -y, top_z),
        (top_x, -y, top_z),
        (top_x, y, top_z),
        (-top_x, y, top_z),
    ]


def build(client: int, world, slope: Slope, name: str, bodies: dict) -> None:
    shape = p.createCollisionShape(p.GEOM_MESH, vertices=hill_vertices(slope, CONVEX_MARGIN), physicsClientId=client)
    visual = p.createVisualShape(
        p.GEOM_MESH,
        vertices=hill_vertices(slope),
        indices=[i for triangle in _PRISM_TRIANGLES for i in triangle],
        rgbaColor=RGBA_HILL,
        physicsClientId=client,
    )
    body = p.createMultiBody(
        0,
        shape,
        visual,
        basePosition=(slope.x, slope.y, 0.0),
        baseOrientation=p.getQuaternionFromEuler((0, 0, slope.yaw)),
        physicsClientId=client,
    )
    set_surface(client, body, slope.surface)
    bodies[name] = body


SLOPES = ElementKind(
    "slopes", "slope", SLOPE_KEYS, make=make, builder=build, budget=bodies_each(), on_ground=False,
    footprint=footprint, counted=("hill", "hills"), ground=ground,
    doc="hills along their own x axis: a ramp up, a flat top, a ramp down (a soft one sinks under a wheel)",
    defaults={
        "surface": "none", "lateral_friction": "the surface kind's, else 0.9",
        "rolling_friction": SURFACE_NUMBER, "spinning_friction": SURFACE_NUMBER, "sinkage": SURFACE_NUMBER,
    },
)  # fmt: skip
