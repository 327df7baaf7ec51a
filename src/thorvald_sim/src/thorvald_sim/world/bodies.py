"""What the element kinds' scene builders are built on: pybullet (:data:`p`) and numpy (:data:`np`),
each imported when a builder first calls it, so that the kinds' modules, which hold their builders
beside their values, keys, parsers, budgets and footprints, stay pure to whatever only loads worlds
(``check_world``, the design study's plans); a surface set on a body (:func:`set_surface`); bodies
added under an element's name (:func:`add_bodies`); triangle meshes of many parts (:class:`Mesh`).

Many small parts (plants, tubes, tables) are merged into a few triangle meshes, each one static
body: thousands of bodies of one plant each would cost pybullet a loop over every body each step (a
robot among 2000 plants made so stepped 150 to 300 times a second, against 5000 to 10000 among
none); a mesh costs the contacts near a robot only (bullet finds them in the mesh's bounding volume
tree), and nothing while the robot is outside its bounding box. pybullet takes at most 131072
vertices a mesh, so a long row is split into bodies of at most MAX_MESH_VERTICES.

Friction: pybullet multiplies the lateral frictions of the two bodies in a contact, and combines
rolling and spinning friction as ``a.rolling * b.lateral + b.rolling * a.lateral`` and restitution
as ``a * b``. The simulator's wheels have lateral friction 1.0 and no rolling or spinning friction,
so the world's values are the effective ones under a wheel. (Restitution therefore matters only
against bodies that have some of their own.) A soft surface gets pybullet's contact stiffness and
damping (:attr:`~thorvald_sim.world.surfaces.Surface.contact_stiffness`): bullet turns them into the
contact's ERP and CFM, an implicit spring and damper under each contact point, stable at any step;
the wheels have none of their own (infinitely stiff in series).
"""

import functools
import math
from typing import Any, Callable, Dict, Iterator, List, Optional, Sequence, Tuple

from .rules import Rgba
from .surfaces import Surface


class _Imported:
    """A module imported when one of its names is first asked for; each name is then held as an
    attribute (looked up once)."""

    def __init__(self, load: Callable[[], Any]) -> None:
        self._load = load

    def __getattr__(self, name: str) -> Any:
        value = getattr(self._load(), name)
        setattr(self, name, value)
        return value


def _pybullet() -> Any:
    from ..bullet import pybullet  # noqa: PLC0415 (on purpose: see the module's docstring)

    return pybullet


def _numpy() -> Any:
    import numpy  # noqa: PLC0415 (on purpose: importing a world stays cheap)

    return numpy


p = _Imported(_pybullet)  # the kinds' builders call pybullet through this
np = _Imported(_numpy)

MAX_MESH_VERTICES = 65536  # per body; pybullet refuses a mesh of more than 131072
ROOT = 0.1  # [m] plants, posts and legs reach this far into the ground, so a slope leaves no gap under them
PLANT_BALL = (8, 4)  # (around, pole to pole) of a plant's ball (ball_template)

# bullet grows a convex hull made from vertices by this margin [m] on every side (pybullet's URDF
# importer's default, gUrdfDefaultCollisionMargin); a hull is made this much smaller so its surface
# lies where the world file says. Boxes, cylinders and planes keep their margin inside.
CONVEX_MARGIN = 0.001

Template = Tuple[Any, Any, Any]  # numpy arrays: vertices (k, 3), normals (k, 3), triangles (j, 3)


def add_bodies(bodies: Dict[str, int], name: str, ids: Sequence[int]) -> None:
    """The bodies under the name, the first as it is, the others as ``name.part1``, ``name.part2``, ..."""
    for k, body in enumerate(ids):
        bodies[name if k == 0 else f"{name}.part{k}"] = body


@functools.lru_cache(maxsize=None)
def prism_template(sides: int) -> Template:
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


@functools.lru_cache(maxsize=None)
def ball_template(around: int, bands: int) -> Template:
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


@functools.lru_cache(maxsize=None)
def box_template() -> Template:
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


class Mesh:
    """Copies of templates, each moved and shaped by a 3 x 3 matrix (its scaled axes as columns, a
    right-handed frame, so the triangles keep their winding) and an offset [m] in the world."""

    def __init__(self) -> None:
        self._blocks: List[Template] = []

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
        self.add(box_template(), [centre], [m])

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
        self.add(box_template(), (a + b) / 2, matrices)

    def chunks(self) -> Iterator[Template]:
        """(vertices, normals, triangles) of at most MAX_MESH_VERTICES each (more for one copy that big)."""
        group: List[Template] = []
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


def mesh_bodies(client: int, mesh: Mesh, rgba: Rgba, surface: Optional[Surface]) -> List[int]:
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
            set_surface(client, body, surface)
        bodies.append(body)
    return bodies


def diag(x: float, y: float, z: float):
    return np.diag((x, y, z))


def set_surface(client: int, body: int, surface: Surface) -> None:
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
