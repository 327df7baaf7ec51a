"""Builds a world (:class:`thorvald_sim.world.WorldConfig`) in a pybullet client.

The caller passes in the client id; nothing here connects to pybullet or talks to ROS. Each kind of
world element has its builder here (``build_patch``, ...), which the registry of element kinds
names (:mod:`thorvald_sim.world.registry`); :func:`build_scene` iterates the registry. Every body
but an object with a mass is static (mass 0), so the world costs the solver nothing but its contacts:

- the ground: a plane at z = 0, or the height field's grid in its place; in a world with soft
  patches, flat convex pieces 0.1 m thick with a hole under each patch (bullet's plane has none),
  static bodies of up to 16 pieces, the first drawn as the plane;
- a patch: a box 0.02 m thick whose top is 1 mm above the ground, so a wheel on the patch rests on
  the patch alone (bullet reports the ground 1 mm below too, but a contact that is not closing
  carries no normal force, hence no friction); in a ground with holes, a box filling its hole, 0.3 m
  deep for a soft patch, so a wheel sinking into it meets nothing else;
- a hill: one convex trapezoidal prism (pybullet makes the convex hull of its 8 corners);
- a rail: two cylinders along the rail's direction, their centres ``height`` above the ground;
- an object: a pybullet box, cylinder or sphere, or the mesh file (a static mesh collides as its
  triangles; a moving one as the convex hull of each object in the file, as bullet can collide
  nothing else that moves: the crate of ``worlds/meshes`` is five boxes, so it stays open);
- a wall: a box;
- crop rows and polytunnels: many small parts, merged into a few triangle meshes, each one static
  body (a row of plants; a tunnel's legs, its roof, each table and each table's plants). Thousands
  of bodies of one plant each would cost pybullet a loop over every body each step (a robot among
  2000 plants made so stepped 150 to 300 times a second, against 5000 to 10000 among none); a mesh
  costs the contacts near a robot only (bullet finds them in the mesh's bounding volume tree), and
  nothing while the robot is outside its bounding box. pybullet takes at most 131072 vertices a
  mesh, so a long row is split into bodies of at most MAX_MESH_VERTICES.

Friction: pybullet multiplies the lateral frictions of the two bodies in a contact, and combines
rolling and spinning friction as ``a.rolling * b.lateral + b.rolling * a.lateral`` and restitution
as ``a * b``. The simulator's wheels have lateral friction 1.0 and no rolling or spinning friction,
so the world's values are the effective ones under a wheel. (Restitution therefore matters only
against bodies that have some of their own.) A soft surface gets pybullet's contact stiffness and
damping (:attr:`Surface.contact_stiffness`): bullet turns them into the contact's ERP and CFM, an
implicit spring and damper under each contact point, stable at any step; the wheels have none of
their own (infinitely stiff in series).

Checked (pybullet 3.2.7, 240 Hz; test_world_surfaces.py): a ball of 51 kg on mud (sinkage 15 mm)
sinks 15 mm to 0.1 mm and then moves less than 5 um in 9 s; the standard robot's wheels rolling in
mud sink their load over the stiffness to 0.1 % (11.4 to 14.7 mm for 380 to 490 N) and still roll
0.2000 m a radian; standing there 10 s it stays within 0.1 mm of its height and creeps no more
than its brakes let it on bullet's plane (about 0.5 mm in 10 s there). Every example robot drives
through farm_track's gateway, in and out (the standard one 7 mm off its line and 0.7 mrad turned
after 28 m). On a ground with holes, the rectangular pieces (boxes) are as bullet's plane to a robot
and to a sliding box: the standard robot driving straight turns by less than 0.02 mrad in 12 s on
both, the 2-wheel differential robot veers on its casters by the same 0.12 m in 6 m, and a box
sliding across a seam stops where it does away from one. The pieces beside a turned patch are
convex hulls, which are not: a box sliding across a seam between two hulls is thrown about (0.2 m
boxes sliding at 2 m/s stopped from 23 % short to 56 % beyond where Coulomb friction stops them,
one turned round), and the differential robot veered 0.41 m the other way in 6 m on hulls.
Rolling friction costs bullet three more constraints a contact: a robot on the ``tarmac`` kind
(0.003 m) steps a fifth slower than on this file's default ground (none).

Visual colours (tarmac grey, gravel grey-brown, ice pale blue, a surface kind's own, earth, steel,
leaf green) make snapshots show what is where; pybullet draws its checkered texture on the ground
under the ground's colour (a height field gets checks of 1 m drawn for it, as the plane's).
"""

import math
import os
import tempfile
from dataclasses import dataclass
from typing import Any, Callable, Dict, Iterator, List, Optional, Sequence, Tuple

import numpy as np

from .bullet import pybullet as p
from .bullet import quiet_stdout
from .world import (
    GROUND_THICKNESS,
    PATCH_TOP,
    RGBA_GRAVEL,
    RGBA_ICE,
    SOFT_DEPTH,
    TABLE_DEPTH,
    ElementKind,
    HeightField,
    Patch,
    Polytunnel,
    Rail,
    Rgba,
    Rows,
    Slope,
    Surface,
    Wall,
    WorldConfig,
    WorldObject,
    element_kinds,
    ground_pieces,
    plant_positions,
)

PATCH_THICKNESS = 0.02  # [m]: thick enough for a stable box-box or box-cylinder contact

# bullet grows a convex hull made from vertices by this margin [m] on every side (pybullet's URDF
# importer's default, gUrdfDefaultCollisionMargin); the hill's hull is made this much smaller so its
# surface lies where the world file says. Boxes, cylinders and planes keep their margin inside.
CONVEX_MARGIN = 0.001

LOW_FRICTION = 0.3  # [-] below this a patch is drawn as ice rather than gravel

RGBA_HILL = (0.45, 0.50, 0.35, 1.0)
RGBA_PIPE = (0.75, 0.75, 0.78, 1.0)
RGBA_STEEL = (0.78, 0.80, 0.82, 1.0)  # galvanised tunnel hoops
RGBA_TABLE = (0.18, 0.18, 0.20, 1.0)  # black plastic troughs on dark legs
RGBA_SOIL = (0.40, 0.30, 0.20, 1.0)
RGBA_STRAWBERRY_LEAF = (0.20, 0.50, 0.18, 1.0)
RGBA_BERRY = (0.80, 0.08, 0.10, 1.0)

CHECK = 1.0  # [m]: the side of a height field's checks, as the plane's
TEXTURE_PIXELS_PER_CHECK = 4  # so the renderer's sampling keeps the checks' edges
MAX_TEXTURE_PIXELS = 2048  # along a side of a height field's texture; a bigger field has bigger checks

MAX_MESH_VERTICES = 65536  # per body; pybullet refuses a mesh of more than 131072
MAX_SHAPES = 16  # pieces of a ground with holes in one body: pybullet's most shapes in one array
ROOT = 0.1  # [m] plants, posts and legs reach this far into the ground, so a slope leaves no gap under them
PRISM_SIDES = 8  # of a cylindrical plant
STEM_SIDES = 4
BALL_BANDS = (8, 4)  # (around, pole to pole) of a ball
STEM_RADIUS = 0.1  # of the plant's radius
MIN_STEM_RADIUS = 0.005  # [m]
BERRY_RADIUS = 0.025  # [m]
BERRY_DROP = 0.08  # [m] below the table's (or bed's) top


@dataclass
class Scene:
    """The world as built: its configuration and the pybullet body id of each part.

    bodies: ``"ground"`` (the plane or the height field), ``"patches.patch0"``, ``"slopes.slope0"``,
    ``"rails.rail0.left"`` and ``"rails.rail0.right"`` (left: on the left looking along the rail's
    +x), ``"objects.object0"``, ``"rows.row0.1"`` (the entry's second row),
    ``"polytunnels.polytunnel0.legs_left"`` and ``...legs_right`` (the hoops' legs; none when
    ``leg_height`` is 0), ``...roof`` (arches, ridge and leg-row poles), then for each table or bed
    ``...table0``, ``...plants0`` and ``...berries0`` (drawn only, no collision), and
    ``"walls.wall0"``; in that order. A mesh of more than MAX_MESH_VERTICES goes on in bodies named
    ``.part1``, ``.part2``, ... after the first (``"rows.row0.1.part1"``); a row whose every place
    is a gap has no body. A ground with holes of more than MAX_SHAPES pieces goes on in bodies named
    ``"ground.part1"``, ... (the first holds the pieces around the patches).
    """

    world: WorldConfig
    bodies: Dict[str, int]


def build_scene(client: int, world: WorldConfig) -> Scene:
    """Sets gravity and adds every body of the world to the pybullet client; returns their ids.

    The ground plane first (unless a height field takes its place), then each element of every
    kind of the registry (:func:`thorvald_sim.world.element_kinds`), in its order, by the kind's
    builder.
    """
    p.setGravity(0, 0, -world.gravity, physicsClientId=client)
    bodies: Dict[str, int] = {}
    if world.height_field is None and world.soft_patches:
        _add(bodies, "ground", _ground_with_holes(client, world))
    elif world.height_field is None:
        bodies["ground"] = _ground(client, world.ground, world.ground_rgba)
    for kind in element_kinds():
        build = builder_of(kind)
        for element in world.elements(kind.section):
            build(client, world, element, kind.body_name(element), bodies)
    return Scene(world, bodies)


def builder_of(kind: ElementKind) -> Callable[[int, WorldConfig, Any, str, Dict[str, int]], None]:
    """The kind's scene builder: its function, or the function of this module it names."""
    if callable(kind.builder):
        return kind.builder
    found = globals().get(kind.builder)
    if not callable(found):
        raise LookupError(f"element kind {kind.section!r}: thorvald_sim.scene has no builder {kind.builder!r}")
    return found


def _add(bodies: Dict[str, int], name: str, ids: Sequence[int]) -> None:
    for k, body in enumerate(ids):
        bodies[name if k == 0 else f"{name}.part{k}"] = body


# ---------------------------------------------------------------------------------------------
# The element kinds' builders: (client, world, element, name, bodies), each adding the element's
# bodies under its name (the registry's entries name them)
# ---------------------------------------------------------------------------------------------
def build_height_field(client: int, world: WorldConfig, field: HeightField, name: str, bodies: Dict[str, int]) -> None:
    bodies[name] = _height_field(client, field, world.ground, world.ground_rgba)


def build_patch(client: int, world: WorldConfig, patch: Patch, name: str, bodies: Dict[str, int]) -> None:
    bodies[name] = _patch(client, patch, holes=bool(world.soft_patches))


def build_slope(client: int, world: WorldConfig, slope: Slope, name: str, bodies: Dict[str, int]) -> None:
    bodies[name] = _slope(client, slope)


def build_rail(client: int, world: WorldConfig, rail: Rail, name: str, bodies: Dict[str, int]) -> None:
    bodies[f"{name}.left"], bodies[f"{name}.right"] = _rail(client, rail)


def build_object(client: int, world: WorldConfig, thing: WorldObject, name: str, bodies: Dict[str, int]) -> None:
    bodies[name] = _object(client, thing)


def build_rows(client: int, world: WorldConfig, rows: Rows, name: str, bodies: Dict[str, int]) -> None:
    for k, parts in enumerate(_rows(world, rows)):
        ids = [body for mesh in parts for body in _mesh_bodies(client, mesh, rows.rgba, rows.surface)]
        _add(bodies, f"{name}.{k}", ids)


def build_polytunnel(client: int, world: WorldConfig, tunnel: Polytunnel, name: str, bodies: Dict[str, int]) -> None:
    _polytunnel(client, tunnel, name, bodies)


def build_wall(client: int, world: WorldConfig, wall: Wall, name: str, bodies: Dict[str, int]) -> None:
    bodies[name] = _wall(client, wall)


def _ground(client: int, surface: Surface, rgba: Rgba) -> int:
    shape = p.createCollisionShape(p.GEOM_PLANE, physicsClientId=client)
    body = p.createMultiBody(0, shape, -1, basePosition=(0, 0, 0), physicsClientId=client)
    # No visual shape of its own (pybullet has none for planes): the renderer draws the collision
    # plane with a checkered texture, tinted by this colour.
    p.changeVisualShape(body, -1, rgbaColor=rgba, physicsClientId=client)
    _set_surface(client, body, surface)
    return body


def _ground_with_holes(client: int, world: WorldConfig) -> List[int]:
    """The ground with a hole under each patch: flat convex pieces (:func:`ground_pieces`, the four
    around the patches first) in static bodies of at most MAX_SHAPES each, the first drawn as the
    plane (its visual shape is a plane: pybullet draws it as its ground plane, checks and all), the
    others not at all.

    Rigid patches too fill holes of their own, so that nothing lies 1 mm under a patch for a box
    sliding on it to catch its front edge on. A rectangular piece is a box (as the plane to what
    moves on it, see the module's docstring), another a convex hull, from a file (pybullet makes
    the vertices of one shape of an array into one hull only from a file). A hull grows by
    CONVEX_MARGIN all round: its top is made that much lower, so that it ends at z = 0, and its
    sides overlap its neighbours'.
    """
    pieces = ground_pieces([patch.corners() for patch in world.patches])
    bodies = []
    with tempfile.TemporaryDirectory() as folder:
        for start in range(0, len(pieces), MAX_SHAPES):
            types, halves, files, centres = [], [], [], []
            for k, piece in enumerate(pieces[start : start + MAX_SHAPES], start):
                xs, ys = [x for x, _ in piece], [y for _, y in piece]
                if len(piece) == 4 and piece[0][1] == piece[1][1] and piece[2][1] == piece[3][1]:
                    types.append(p.GEOM_BOX)
                    halves.append(((max(xs) - min(xs)) / 2, (max(ys) - min(ys)) / 2, GROUND_THICKNESS / 2))
                    files.append("")
                    centres.append(((max(xs) + min(xs)) / 2, (max(ys) + min(ys)) / 2, -GROUND_THICKNESS / 2))
                else:
                    cx, cy = sum(xs) / len(xs), sum(ys) / len(ys)
                    files.append(os.path.join(folder, f"piece{k}.obj"))
                    outline = [(x - cx, y - cy) for x, y in piece]
                    _write_prism(files[-1], outline, -CONVEX_MARGIN, CONVEX_MARGIN - GROUND_THICKNESS)
                    types.append(p.GEOM_MESH)
                    halves.append((0.0, 0.0, 0.0))
                    centres.append((cx, cy, 0.0))
            shape = p.createCollisionShapeArray(
                types,
                halfExtents=halves,
                fileNames=files,
                meshScales=[(1.0, 1.0, 1.0)] * len(types),
                collisionFramePositions=centres,
                physicsClientId=client,
            )
            if not bodies:
                visual = p.createVisualShape(p.GEOM_PLANE, planeNormal=(0, 0, 1), physicsClientId=client)
            else:  # a speck a metre underground: a body without a visual shape is drawn as its collision shapes
                visual = p.createVisualShape(
                    p.GEOM_SPHERE, radius=1e-4, visualFramePosition=(0, 0, -1), physicsClientId=client
                )
            with quiet_stdout():  # pybullet's URDF importer warns that a plane has no default visual; it draws it
                body = p.createMultiBody(0, shape, visual, physicsClientId=client)
            if not bodies:
                p.changeVisualShape(body, -1, rgbaColor=world.ground_rgba, physicsClientId=client)
            _set_surface(client, body, world.ground)
            bodies.append(body)
    return bodies


def _write_prism(path: str, corners: Sequence[Tuple[float, float]], top: float, bottom: float) -> None:
    """An OBJ file of a prism over the polygon (counter-clockwise) from bottom to top [m]."""
    n = len(corners)
    lines = [f"v {x!r} {y!r} {bottom!r}" for x, y in corners] + [f"v {x!r} {y!r} {top!r}" for x, y in corners]
    lines.append("f " + " ".join(str(n - i) for i in range(n)))  # the bottom, seen from below
    lines.append("f " + " ".join(str(n + 1 + i) for i in range(n)))
    lines += [f"f {i + 1} {(i + 1) % n + 1} {n + (i + 1) % n + 1} {n + i + 1}" for i in range(n)]
    with open(path, "w") as f:
        f.write("\n".join(lines) + "\n")


def _height_field(client: int, field: HeightField, surface: Surface, rgba: Rgba) -> int:
    heights = field.heights()
    nx, ny = field.grid_shape()
    dx, dy = field.grid_step()
    # pybullet's "rows" run along x: numHeightfieldRows is the number of points along x, and the
    # data goes row of constant y after row, from -y. bullet centres the grid on the body and its
    # heights between their lowest and highest, so the body sits at the middle of that range.
    shape = p.createCollisionShape(
        p.GEOM_HEIGHTFIELD,
        meshScale=(dx, dy, 1.0),
        heightfieldData=heights.ravel().tolist(),
        numHeightfieldRows=nx,
        numHeightfieldColumns=ny,
        physicsClientId=client,
    )
    middle = (float(heights.min()) + float(heights.max())) / 2
    body = p.createMultiBody(0, shape, -1, basePosition=(field.x, field.y, middle), physicsClientId=client)
    texture = _checker_texture(client, field.size_x, field.size_y)
    p.changeVisualShape(body, -1, rgbaColor=rgba, textureUniqueId=texture, physicsClientId=client)
    _set_surface(client, body, surface)
    return body


def _checker_texture(client: int, size_x: float, size_y: float) -> int:
    """A texture of checks CHECK apart (more on a field over 512 m) over size_x by size_y [m], as the plane's.

    pybullet stretches a height field's texture over the whole field once (its own checker texture
    would be four squares of half the field each), so the checks are drawn into it at the field's
    size. pybullet loads textures from files only: this one goes through a temporary file.
    """
    from PIL import Image  # noqa: PLC0415  (only for height fields)

    check = max(CHECK, max(size_x, size_y) * TEXTURE_PIXELS_PER_CHECK / MAX_TEXTURE_PIXELS)
    ix = (np.arange(max(1, round(size_x / check)) * TEXTURE_PIXELS_PER_CHECK) // TEXTURE_PIXELS_PER_CHECK)[None, :]
    iy = (np.arange(max(1, round(size_y / check)) * TEXTURE_PIXELS_PER_CHECK) // TEXTURE_PIXELS_PER_CHECK)[:, None]
    levels = np.where((ix + iy) % 2 == 0, 255, 205).astype(np.uint8)
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "checks.png")
        Image.fromarray(levels).convert("RGB").save(path)
        return p.loadTexture(path, physicsClientId=client)


def _patch(client: int, patch: Patch, holes: bool) -> int:
    # in a ground with holes a patch fills its own, a soft one deep enough that no wheel sinks through it
    thickness = PATCH_THICKNESS
    if patch.surface.soft:
        thickness = PATCH_TOP + SOFT_DEPTH
    elif holes:
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


def _object(client: int, thing: WorldObject) -> int:
    c = client
    if thing.shape == "box":
        half = (thing.size_x / 2, thing.size_y / 2, thing.size_z / 2)
        shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=c)
        visual = p.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=thing.rgba, physicsClientId=c)
    elif thing.shape == "cylinder":
        shape = p.createCollisionShape(p.GEOM_CYLINDER, radius=thing.radius, height=thing.length, physicsClientId=c)
        visual = p.createVisualShape(
            p.GEOM_CYLINDER, radius=thing.radius, length=thing.length, rgbaColor=thing.rgba, physicsClientId=c
        )
    elif thing.shape == "sphere":
        shape = p.createCollisionShape(p.GEOM_SPHERE, radius=thing.radius, physicsClientId=c)
        visual = p.createVisualShape(p.GEOM_SPHERE, radius=thing.radius, rgbaColor=thing.rgba, physicsClientId=c)
    else:
        scale = (thing.scale,) * 3
        # bullet collides a moving body with a convex shape only: its hull; a static one keeps its triangles
        flags = p.GEOM_FORCE_CONCAVE_TRIMESH if thing.mass == 0 else 0
        shape = p.createCollisionShape(
            p.GEOM_MESH, fileName=thing.file, meshScale=scale, flags=flags, physicsClientId=c
        )
        visual = p.createVisualShape(
            p.GEOM_MESH, fileName=thing.file, meshScale=scale, rgbaColor=thing.rgba, physicsClientId=c
        )
    body = p.createMultiBody(
        thing.mass,
        shape,
        visual,
        basePosition=(thing.x, thing.y, thing.z),
        baseOrientation=p.getQuaternionFromEuler((thing.roll, thing.pitch, thing.yaw)),
        physicsClientId=c,
    )
    _set_surface(client, body, thing.surface)
    if thing.mass > 0:
        # No drag, as the robots (pybullet gives every new body a velocity damping of 0.04 / s). An
        # object at rest sleeps, as bullet lets it: awake, a resting 2 kg crate cost a sixth of the step
        # with one robot; a contact wakes it.
        p.changeDynamics(
            body,
            -1,
            linearDamping=0.0,
            angularDamping=0.0,
            activationState=p.ACTIVATION_STATE_ENABLE_SLEEPING,
            physicsClientId=c,
        )
    return body


def _wall(client: int, wall: Wall) -> int:
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
    _set_surface(client, body, wall.surface)
    return body


# ---------------------------------------------------------------------------------------------
# Triangle meshes of many parts (plants, tubes, tables)
# ---------------------------------------------------------------------------------------------
Template = Tuple[np.ndarray, np.ndarray, np.ndarray]  # vertices (k, 3), normals (k, 3), triangles (j, 3)


def _prism_template(sides: int) -> Template:
    """A prism around the z axis from z = 0 to 1, its corners on the unit circle; the caps have
    vertices of their own so that they are drawn flat."""
    a = 2 * math.pi * np.arange(sides) / sides
    ring = np.stack([np.cos(a), np.sin(a), np.zeros(sides)], axis=1)
    up = ring + np.array((0.0, 0.0, 1.0))
    vertices = np.concatenate([ring, up, ring, up])  # sides: 0..2n-1; bottom cap, then top cap
    normals = np.concatenate([ring, ring, np.tile((0.0, 0.0, -1.0), (sides, 1)), np.tile((0.0, 0.0, 1.0), (sides, 1))])
    triangles = []
    for i in range(sides):
        j = (i + 1) % sides
        triangles += [(i, j, sides + j), (i, sides + j, sides + i)]
    bottom, top = 2 * sides, 3 * sides
    for i in range(1, sides - 1):
        triangles += [(bottom, bottom + i + 1, bottom + i), (top, top + i, top + i + 1)]
    return vertices, normals, np.array(triangles)


def _ball_template(around: int, bands: int) -> Template:
    """A sphere of radius 1 about the origin with a vertex at each pole (so its top is exactly 1 up)."""
    vertices = [(0.0, 0.0, 1.0)]
    for k in range(1, bands):
        polar = math.pi * k / bands
        for i in range(around):
            a = 2 * math.pi * i / around
            vertices.append((math.sin(polar) * math.cos(a), math.sin(polar) * math.sin(a), math.cos(polar)))
    vertices.append((0.0, 0.0, -1.0))
    bottom = len(vertices) - 1

    def ring(k: int, i: int) -> int:
        return 1 + (k - 1) * around + i % around

    triangles = []
    for i in range(around):
        triangles.append((0, ring(1, i), ring(1, i + 1)))
        for k in range(1, bands - 1):
            triangles += [
                (ring(k, i), ring(k + 1, i), ring(k + 1, i + 1)),
                (ring(k, i), ring(k + 1, i + 1), ring(k, i + 1)),
            ]
        triangles.append((bottom, ring(bands - 1, i + 1), ring(bands - 1, i)))
    v = np.array(vertices)
    return v, v.copy(), np.array(triangles)


def _box_template() -> Template:
    """A cube from -1 to 1, four vertices a face (drawn flat)."""
    vertices, normals, triangles = [], [], []
    for axis in range(3):
        for sign in (-1.0, 1.0):
            n = np.zeros(3)
            n[axis] = sign
            u = np.zeros(3)
            u[(axis + 1) % 3] = 1.0
            v = np.cross(n, u)  # u x v = n: the corners below go counter-clockwise seen from outside
            start = len(vertices)
            for cu, cv in ((-1, -1), (1, -1), (1, 1), (-1, 1)):
                vertices.append(n + cu * u + cv * v)
                normals.append(n)
            triangles += [(start, start + 1, start + 2), (start, start + 2, start + 3)]
    return np.array(vertices), np.array(normals), np.array(triangles)


PRISM = _prism_template(PRISM_SIDES)
STEM = _prism_template(STEM_SIDES)
BALL = _ball_template(*BALL_BANDS)
BERRY = _ball_template(4, 2)  # an octahedron: a berry 5 cm across needs no more
BOX = _box_template()


class _Mesh:
    """Copies of templates, each moved and shaped by a 3 x 3 matrix (its scaled axes as columns, a
    right-handed frame, so the triangles keep their winding) and an offset [m] in the world."""

    def __init__(self) -> None:
        self._blocks: List[Tuple[np.ndarray, np.ndarray, np.ndarray]] = []

    def add(self, template: Template, offsets, matrices=None) -> None:
        tv, tn, tt = template
        offsets = np.asarray(offsets, dtype=float).reshape(-1, 3)
        n = len(offsets)
        if n == 0:
            return
        matrices = np.broadcast_to(np.eye(3) if matrices is None else np.asarray(matrices, dtype=float), (n, 3, 3))
        per = max(1, MAX_MESH_VERTICES // len(tv))
        for s in range(0, n, per):
            o, m = offsets[s : s + per], matrices[s : s + per]
            vertices = np.einsum("nij,kj->nki", m, tv) + o[:, None, :]
            normals = np.einsum("nij,kj->nki", m, tn)
            normals /= np.maximum(np.linalg.norm(normals, axis=2, keepdims=True), 1e-12)
            triangles = tt[None, :, :] + (np.arange(len(o)) * len(tv))[:, None, None]
            self._blocks.append((vertices.reshape(-1, 3), normals.reshape(-1, 3), triangles.reshape(-1, 3)))

    def box(self, centre, axes, half) -> None:
        """A box about centre with the given axes (unit vectors, right-handed) and half sizes."""
        m = np.stack([np.asarray(a, dtype=float) * h for a, h in zip(axes, half)], axis=1)
        self.add(BOX, [centre], [m])

    def tubes(self, starts, ends, side, size: float) -> None:
        """Square tubes of side ``size`` from each start to its end [m], one pair of faces facing
        along ``side`` (made perpendicular to the tube)."""
        a, b = np.asarray(starts, dtype=float).reshape(-1, 3), np.asarray(ends, dtype=float).reshape(-1, 3)
        length = np.linalg.norm(b - a, axis=1, keepdims=True)
        axis = (b - a) / length
        side = np.asarray(side, dtype=float) - axis * (axis @ np.asarray(side, dtype=float))[:, None]
        side /= np.linalg.norm(side, axis=1, keepdims=True)
        third = np.cross(axis, side)  # (side, third, axis) is right-handed
        matrices = np.stack([side * size / 2, third * size / 2, axis * length / 2], axis=2)
        self.add(BOX, (a + b) / 2, matrices)

    def chunks(self) -> Iterator[Tuple[np.ndarray, np.ndarray, np.ndarray]]:
        """(vertices, normals, triangles) of at most MAX_MESH_VERTICES each (more for one copy that big)."""
        group: List[Tuple[np.ndarray, np.ndarray, np.ndarray]] = []
        count = 0
        for block in self._blocks:
            if group and count + len(block[0]) > MAX_MESH_VERTICES:
                yield _merge(group)
                group, count = [], 0
            group.append(block)
            count += len(block[0])
        if group:
            yield _merge(group)


def _merge(blocks):
    offsets = np.cumsum([0] + [len(v) for v, _, _ in blocks[:-1]])
    return (
        np.concatenate([v for v, _, _ in blocks]),
        np.concatenate([n for _, n, _ in blocks]),
        np.concatenate([t + o for (_, _, t), o in zip(blocks, offsets)]),
    )


def _mesh_bodies(client: int, mesh: _Mesh, rgba: Rgba, surface: Optional[Surface]) -> List[int]:
    """Static bodies of the mesh (one per chunk): collision as triangles, or drawn only without a surface."""
    bodies = []
    for vertices, normals, triangles in mesh.chunks():
        v, indices = vertices.tolist(), triangles.ravel().tolist()
        shape = -1
        if surface is not None:
            shape = p.createCollisionShape(
                p.GEOM_MESH, vertices=v, indices=indices, flags=p.GEOM_FORCE_CONCAVE_TRIMESH, physicsClientId=client
            )
        visual = p.createVisualShape(
            p.GEOM_MESH, vertices=v, indices=indices, normals=normals.tolist(), rgbaColor=rgba, physicsClientId=client
        )
        body = p.createMultiBody(0, shape, visual, physicsClientId=client)
        if surface is not None:
            _set_surface(client, body, surface)
        bodies.append(body)
    return bodies


def _diag(x: float, y: float, z: float) -> np.ndarray:
    return np.diag((x, y, z))


# ---------------------------------------------------------------------------------------------
# Crop rows
# ---------------------------------------------------------------------------------------------
def _rows(world: WorldConfig, rows: Rows) -> List[List[_Mesh]]:
    """Meshes of each row: each plant stands on the ground under it, reaching ROOT into it. A row
    of more than MAX_MESH_VERTICES is split into meshes of whole plants, each of a stretch of it."""
    r, h = rows.plant_radius, rows.plant_height
    centre = h - r
    stem = max(MIN_STEM_RADIUS, STEM_RADIUS * r)
    if rows.plant == "cylinder":
        per_plant = len(PRISM[0])
    else:
        per_plant = len(BALL[0]) + (len(STEM[0]) if centre > 0 else 0)
    batch = max(1, MAX_MESH_VERTICES // per_plant)
    meshes = []
    for line in plant_positions(rows):
        parts = []
        for start in range(0, max(1, len(line)), batch):
            mesh = _Mesh()
            xy = np.asarray(line[start : start + batch], dtype=float).reshape(-1, 2)
            ground = np.array([world.ground_height(x, y) for x, y in xy])
            feet = np.column_stack([xy, ground - ROOT])
            if rows.plant == "cylinder":
                mesh.add(PRISM, feet, _diag(r, r, h + ROOT))
            else:
                if centre > 0:
                    mesh.add(STEM, feet, _diag(stem, stem, centre + ROOT))
                mesh.add(BALL, np.column_stack([xy, ground + centre]), _diag(r, r, r))
            parts.append(mesh)
        meshes.append(parts)
    return meshes


# ---------------------------------------------------------------------------------------------
# Polytunnels
# ---------------------------------------------------------------------------------------------
def _polytunnel(client: int, t: Polytunnel, name: str, bodies: Dict[str, int]) -> None:
    c, s = math.cos(t.yaw), math.sin(t.yaw)
    along, across, up = np.array((c, s, 0.0)), np.array((-s, c, 0.0)), np.array((0.0, 0.0, 1.0))
    origin = np.array((t.x, t.y, t.z))

    def at(u, v, z) -> np.ndarray:
        """World points [m] of tunnel points (u, v, z): numbers or arrays of one shape."""
        u, v, z = np.broadcast_arrays(*(np.asarray(q, dtype=float) for q in (u, v, z)))
        return origin + u[..., None] * along + v[..., None] * across + z[..., None] * up

    # The legs of each side and the roof (arches and poles, all from leg_height up) are bodies of their
    # own: bullet pairs a robot with a body whose bounding box it enters, and a robot in the tunnel
    # enters none of these three then (one body of the whole frame cost a fifth of the step).
    hoops = np.array(t.hoop_stations())[:, None]
    for side, v in (("left", t.width / 2), ("right", -t.width / 2)):
        if t.leg_height > 0:
            legs = _Mesh()
            legs.tubes(at(hoops, v, -ROOT), at(hoops, v, t.leg_height), along, t.tube)
            _add(bodies, f"{name}.legs_{side}", _mesh_bodies(client, legs, RGBA_STEEL, t.surface))
    roof = _Mesh()
    arch = np.array(t.arch())
    roof.tubes(at(hoops, arch[:-1, 0], arch[:-1, 1]), at(hoops, arch[1:, 0], arch[1:, 1]), along, t.tube)
    poles = np.array(((0.0, t.height), (-t.width / 2, t.leg_height), (t.width / 2, t.leg_height)))
    roof.tubes(at(-t.length / 2, poles[:, 0], poles[:, 1]), at(t.length / 2, poles[:, 0], poles[:, 1]), across, t.tube)
    _add(bodies, f"{name}.roof", _mesh_bodies(client, roof, RGBA_STEEL, t.surface))

    start, end = t.table_span()
    middle, half_length = (start + end) / 2, (end - start) / 2
    r = t.plant_radius
    stations = np.array(t.plant_stations())
    legs = np.array(t.table_leg_stations())
    for k, v in enumerate(t.table_offsets()):
        table = _Mesh()
        if t.crop == "table_tops":
            trough = at(middle, v, t.table_height - TABLE_DEPTH / 2)
            table.box(trough, (along, across, up), (half_length, t.table_width / 2, TABLE_DEPTH / 2))
            for side in (-1, 1):
                leg_v = v + side * (t.table_width / 2 - t.tube / 2)
                table.tubes(at(legs, leg_v, -ROOT), at(legs, leg_v, t.table_height - TABLE_DEPTH), along, t.tube)
            colour = RGBA_TABLE
        else:
            bed = at(middle, v, (t.bed_height - ROOT) / 2)
            table.box(bed, (along, across, up), (half_length, t.table_width / 2, (t.bed_height + ROOT) / 2))
            colour = RGBA_SOIL
        _add(bodies, f"{name}.table{k}", _mesh_bodies(client, table, colour, t.surface))

        plants, berries = _Mesh(), _Mesh()
        plants.add(BALL, at(stations, v, t.crop_top + r / 2), _diag(r, r, r))
        for side in (-1, 1):
            hang = at(stations, v + side * (t.table_width / 2 + BERRY_RADIUS), t.crop_top - BERRY_DROP)
            berries.add(BERRY, hang, _diag(BERRY_RADIUS, BERRY_RADIUS, BERRY_RADIUS))
        _add(bodies, f"{name}.plants{k}", _mesh_bodies(client, plants, RGBA_STRAWBERRY_LEAF, t.surface))
        _add(bodies, f"{name}.berries{k}", _mesh_bodies(client, berries, RGBA_BERRY, None))


def _set_surface(client: int, body: int, surface: Surface) -> None:
    soft = {}
    if surface.soft:
        soft = dict(contactStiffness=surface.contact_stiffness, contactDamping=surface.contact_damping)
    p.changeDynamics(
        body,
        -1,
        lateralFriction=surface.lateral_friction,
        rollingFriction=surface.rolling_friction,
        spinningFriction=surface.spinning_friction,
        restitution=surface.restitution,
        physicsClientId=client,
        **soft,
    )
