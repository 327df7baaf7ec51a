"""Rails (``rails:``, entries ``rail0``, ...): pairs of parallel heating pipes lying above the ground,
as in greenhouses (the paper's Figure 2a robot rides them). A rail's radius is below its height (a
pipe cannot sink into the ground) and its gauge above two radii (the pipes would overlap).

In pybullet: two cylinders along the rail's direction, their centres ``height`` above the ground,
bodies ``rails.rail0.left`` and ``rails.rail0.right`` (left: on the left looking along the rail's +x).
"""

import math
from dataclasses import dataclass
from typing import List, Tuple

from thorvald_model.errors import Problem
from thorvald_model.schema import Key

from ..bodies import p, set_surface
from ..geometry import Point, rectangle
from ..kind import Context, ElementKind, Entry
from ..limits import bodies_each
from ..rules import COORDINATE, LENGTH, broken
from ..surfaces import Surface, frictions, surface

RGBA_PIPE = (0.75, 0.75, 0.78, 1.0)


@dataclass(frozen=True)
class Rail:
    """A pair of parallel pipes lying above the ground: greenhouse heating pipes used as rails (the
    paper's Figure 2a robot rides them); ``x``, ``y`` the point between the pipes at the middle of
    their length."""

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


RAIL_KEYS = (
    Key("x", float, **COORDINATE),
    Key("y", float, **COORDINATE),
    Key("yaw", float, 0.0),
    Key("length", float, **LENGTH),
    Key("gauge", float, 0.55, **LENGTH),
    Key("height", float, 0.1, **LENGTH),
    Key("radius", float, 0.0255, **LENGTH),  # 51 mm pipes, the common greenhouse size
    *frictions(0.8),
)


def make(entry: Entry, context: Context) -> Rail:
    v = entry.values
    return Rail(
        entry.name, entry.index, v["x"], v["y"], v["yaw"], v["length"], v["gauge"], v["height"], v["radius"],
        surface(v),
    )  # fmt: skip


def check(rails: Tuple[Rail, ...], context: Context) -> None:
    context.problems.extend(_rail_problems(rails, context.problems))


def _rail_problems(rails: Tuple[Rail, ...], found: List[Problem]) -> List[Problem]:
    problems = []
    for rail in rails:
        path = f"rails.{rail.name}"
        # A key that already broke its own rule was replaced by its default; comparing that default
        # would report a value the file does not hold.
        if broken(found, path, "radius", "height", "gauge"):
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


def footprint(ra: Rail) -> List[Point]:
    side = ra.gauge / 2 + ra.radius
    return rectangle(ra.x, ra.y, ra.yaw, (-ra.length / 2, ra.length / 2), (-side, side))


def pipe_centres(rail: Rail) -> Tuple[Tuple[float, float, float], Tuple[float, float, float]]:
    """Centres [m] of the rail's (left, right) pipes, left of the rail's +x direction first."""
    # the rail's left is its +y, (-sin yaw, cos yaw) in the world
    ox, oy = -math.sin(rail.yaw) * rail.gauge / 2, math.cos(rail.yaw) * rail.gauge / 2
    return (rail.x + ox, rail.y + oy, rail.height), (rail.x - ox, rail.y - oy, rail.height)


def build(client: int, world, rail: Rail, name: str, bodies: dict) -> None:
    # A pybullet cylinder's axis is its z; pitch by 90 degrees turns it onto x, then yaw onto the
    # rail's direction (cos yaw, sin yaw, 0) (pybullet's Euler angles apply roll, pitch, then yaw).
    orientation = p.getQuaternionFromEuler((0, math.pi / 2, rail.yaw))
    shape = p.createCollisionShape(p.GEOM_CYLINDER, radius=rail.radius, height=rail.length, physicsClientId=client)
    visual = p.createVisualShape(
        p.GEOM_CYLINDER, radius=rail.radius, length=rail.length, rgbaColor=RGBA_PIPE, physicsClientId=client
    )
    pipes = []
    for centre in pipe_centres(rail):
        body = p.createMultiBody(
            0, shape, visual, basePosition=centre, baseOrientation=orientation, physicsClientId=client
        )
        set_surface(client, body, rail.surface)
        pipes.append(body)
    bodies[f"{name}.left"], bodies[f"{name}.right"] = pipes


RAILS = ElementKind(
    "rails", "rail", RAIL_KEYS, make=make, builder=build, budget=bodies_each(2.0), check=check,
    footprint=footprint, counted=("rail pair", "rail pairs"),
    on_ground=False, doc="pairs of parallel heating pipes, as in greenhouses",
)  # fmt: skip
