"""Builds a world (:class:`thorvald_sim.world.WorldConfig`) in a pybullet client.

The caller passes in the client id; nothing here connects to pybullet or talks to ROS. Every body
is static (mass 0), so the world costs the solver nothing but its contacts:

- the ground: a plane at z = 0;
- a patch: a box 0.02 m thick whose top is 1 mm above the ground, so a wheel on the patch rests on
  the patch alone (bullet reports the ground 1 mm below too, but a contact that is not closing
  carries no normal force, hence no friction);
- a hill: one convex trapezoidal prism (pybullet makes the convex hull of its 8 corners);
- a rail: two cylinders along the rail's direction, their centres ``height`` above the ground.

Friction: pybullet multiplies the lateral frictions of the two bodies in a contact, and combines
rolling and spinning friction as ``a.rolling * b.lateral + b.rolling * a.lateral`` and restitution
as ``a * b``. The simulator's wheels have lateral friction 1.0 and no rolling or spinning friction,
so the world's values are the effective ones under a wheel. (Restitution therefore matters only
against bodies that have some of their own.)

Visual colours (tarmac grey, gravel grey-brown, ice pale blue, earth, steel) make snapshots show
what is where; pybullet draws its checkered texture on the plane under the ground's colour.
"""

import math
from dataclasses import dataclass
from typing import Dict, List, Tuple

import pybullet as p

from .world import Patch, Rail, Slope, Surface, WorldConfig

PATCH_TOP = 0.001  # [m] above the ground plane
PATCH_THICKNESS = 0.02  # [m]: thick enough for a stable box-box or box-cylinder contact

# bullet grows a convex hull made from vertices by this margin [m] on every side (pybullet's URDF
# importer's default, gUrdfDefaultCollisionMargin); the hill's hull is made this much smaller so its
# surface lies where the world file says. Boxes, cylinders and planes keep their margin inside.
CONVEX_MARGIN = 0.001

LOW_FRICTION = 0.3  # [-] below this a patch is drawn as ice rather than gravel

RGBA_TARMAC = (0.35, 0.35, 0.37, 1.0)
RGBA_GRAVEL = (0.55, 0.48, 0.38, 1.0)
RGBA_ICE = (0.70, 0.85, 1.00, 1.0)
RGBA_HILL = (0.45, 0.50, 0.35, 1.0)
RGBA_PIPE = (0.75, 0.75, 0.78, 1.0)


@dataclass
class Scene:
    """The world as built: its configuration and the pybullet body id of each part.

    bodies: ``"ground"``, ``"patches.patch0"``, ``"slopes.slope0"``, ``"rails.rail0.left"`` and
    ``"rails.rail0.right"`` (left: on the left looking along the rail's +x).
    """

    world: WorldConfig
    bodies: Dict[str, int]


def build_scene(client: int, world: WorldConfig) -> Scene:
    """Sets gravity and adds every body of the world to the pybullet client; returns their ids."""
    p.setGravity(0, 0, -world.gravity, physicsClientId=client)
    bodies = {"ground": _ground(client, world.ground)}
    for patch in world.patches:
        bodies[f"patches.{patch.name}"] = _patch(client, patch)
    for slope in world.slopes:
        bodies[f"slopes.{slope.name}"] = _slope(client, slope)
    for rail in world.rails:
        left, right = _rail(client, rail)
        bodies[f"rails.{rail.name}.left"] = left
        bodies[f"rails.{rail.name}.right"] = right
    return Scene(world, bodies)


def _ground(client: int, surface: Surface) -> int:
    shape = p.createCollisionShape(p.GEOM_PLANE, physicsClientId=client)
    body = p.createMultiBody(0, shape, -1, basePosition=(0, 0, 0), physicsClientId=client)
    # No visual shape of its own (pybullet has none for planes): the renderer draws the collision
    # plane with a checkered texture, tinted by this colour.
    p.changeVisualShape(body, -1, rgbaColor=RGBA_TARMAC, physicsClientId=client)
    _set_surface(client, body, surface)
    return body


def _patch(client: int, patch: Patch) -> int:
    half = (patch.size_x / 2, patch.size_y / 2, PATCH_THICKNESS / 2)
    color = RGBA_ICE if patch.surface.lateral_friction < LOW_FRICTION else RGBA_GRAVEL
    shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=client)
    visual = p.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=color, physicsClientId=client)
    body = p.createMultiBody(
        0,
        shape,
        visual,
        basePosition=(patch.x, patch.y, PATCH_TOP - PATCH_THICKNESS / 2),
        baseOrientation=p.getQuaternionFromEuler((0, 0, patch.yaw)),
        physicsClientId=client,
    )
    _set_surface(client, body, patch.surface)
    return body


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


def _slope(client: int, slope: Slope) -> int:
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
    _set_surface(client, body, slope.surface)
    return body


def pipe_centres(rail: Rail) -> Tuple[Tuple[float, float, float], Tuple[float, float, float]]:
    """Centres [m] of the rail's (left, right) pipes, left of the rail's +x direction first."""
    # the rail's left is its +y, (-sin yaw, cos yaw) in the world
    ox, oy = -math.sin(rail.yaw) * rail.gauge / 2, math.cos(rail.yaw) * rail.gauge / 2
    return (rail.x + ox, rail.y + oy, rail.height), (rail.x - ox, rail.y - oy, rail.height)


def _rail(client: int, rail: Rail) -> Tuple[int, int]:
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
        _set_surface(client, body, rail.surface)
        pipes.append(body)
    return pipes[0], pipes[1]


def _set_surface(client: int, body: int, surface: Surface) -> None:
    p.changeDynamics(
        body,
        -1,
        lateralFriction=surface.lateral_friction,
        rollingFriction=surface.rolling_friction,
        spinningFriction=surface.spinning_friction,
        restitution=surface.restitution,
        physicsClientId=client,
    )
