"""Builds a world (:class:`thorvald_sim.world.WorldConfig`) in a pybullet client.

The caller passes in the client id; nothing here connects to pybullet or talks to ROS. The ground is
built here; every element by its kind's builder (:attr:`~thorvald_sim.world.kind.ElementKind.builder`,
in the kind's module of :mod:`thorvald_sim.world.kinds`, which says what bodies it makes):
:func:`build_scene` iterates the registry. Every body but an object with a mass is static (mass 0),
so the world costs the solver nothing but its contacts.

The ground: a plane at z = 0, unless a kind takes its place (a height field's grid); where kinds need
holes in it (soft patches), flat convex pieces 0.1 m thick around the holes (bullet's plane has
none), static bodies of up to 16 pieces, the first drawn as the plane. A soft surface gets
pybullet's contact stiffness and damping (:func:`thorvald_sim.world.bodies.set_surface`).

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
(0.003 m) steps a fifth slower than on the world file's default ground (none).

Visual colours (tarmac grey, gravel grey-brown, ice pale blue, a surface kind's own, earth, steel,
leaf green) make snapshots show what is where; pybullet draws its checkered texture on the ground
under the ground's colour (a height field gets checks of 1 m drawn for it, as the plane's).
"""

import os
import tempfile
from dataclasses import dataclass
from typing import Dict, List, Sequence, Tuple

from ..bullet import pybullet as p
from ..bullet import quiet_stdout
from ..world import WorldConfig, element_kinds
from ..world.bodies import CONVEX_MARGIN, add_bodies, set_surface
from ..world.geometry import GROUND_THICKNESS, Point, ground_pieces
from ..world.rules import Rgba
from ..world.surfaces import Surface

MAX_SHAPES = 16  # pieces of a ground with holes in one body: pybullet's most shapes in one array


@dataclass
class Scene:
    """The world as built: its configuration and the pybullet body id of each part.

    bodies: ``"ground"`` (the plane, or the kind's that takes its place), then each element's in the
    registry's order, under its kind's name for it (``"patches.patch0"``; ``"rails.rail0.left"``,
    ``"rows.row0.1"``, ...: each kind's module says which); a part of more than one body goes on in
    bodies named ``.part1``, ``.part2``, ... after the first (``"rows.row0.1.part1"``). A ground with
    holes of more than MAX_SHAPES pieces goes on in bodies named ``"ground.part1"``, ... (the first
    holds the pieces around the holes).
    """

    world: WorldConfig
    bodies: Dict[str, int]


def build_scene(client: int, world: WorldConfig) -> Scene:
    """Sets gravity and adds every body of the world to the pybullet client; returns their ids.

    The ground first (unless a kind takes its place), then each element of every kind of the
    registry (:func:`thorvald_sim.world.element_kinds`), in its order, by the kind's builder.
    """
    p.setGravity(0, 0, -world.gravity, physicsClientId=client)
    kinds = element_kinds()
    bodies: Dict[str, int] = {}
    if not any(kind.replaces_ground and world.elements(kind.section) for kind in kinds):
        holes = [hole for kind in kinds if kind.holes for hole in kind.holes(world.elements(kind.section))]
        if holes:
            add_bodies(bodies, "ground", _ground_with_holes(client, world, holes))
        else:
            bodies["ground"] = _ground(client, world.ground, world.ground_rgba)
    for kind in kinds:
        for element in world.elements(kind.section):
            kind.builder(client, world, element, kind.body_name(element), bodies)
    return Scene(world, bodies)


def _ground(client: int, surface: Surface, rgba: Rgba) -> int:
    shape = p.createCollisionShape(p.GEOM_PLANE, physicsClientId=client)
    body = p.createMultiBody(0, shape, -1, basePosition=(0, 0, 0), physicsClientId=client)
    # No visual shape of its own (pybullet has none for planes): the renderer draws the collision
    # plane with a checkered texture, tinted by this colour.
    p.changeVisualShape(body, -1, rgbaColor=rgba, physicsClientId=client)
    set_surface(client, body, surface)
    return body


def _ground_with_holes(client: int, world: WorldConfig, holes: Sequence[Sequence[Point]]) -> List[int]:
    """The ground with the holes: flat convex pieces (:func:`ground_pieces`, the four around the
    holes first) in static bodies of at most MAX_SHAPES each, the first drawn as the
    plane (its visual shape is a plane: pybullet draws it as its ground plane, checks and all), the
    others not at all.

    Rigid patches too fill holes of their own, so that nothing lies 1 mm under a patch for a box
    sliding on it to catch its front edge on. A rectangular piece is a box (as the plane to what
    moves on it, see the module's docstring), another a convex hull, from a file (pybullet makes
    the vertices of one shape of an array into one hull only from a file). A hull grows by
    CONVEX_MARGIN all round: its top is made that much lower, so that it ends at z = 0, and its
    sides overlap its neighbours'.
    """
    pieces = ground_pieces(holes)
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
            set_surface(client, body, world.ground)
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
