"""A kind of world element from outside the simulator: fence posts (``posts:``, entries ``post0``,
...), each a cylinder standing on the ground at ``x``, ``y``, of a ``radius`` and ``height``.

This module is the whole kind, as each module of :mod:`thorvald_sim.world.kinds` is one: its value
type, its keys, its maker (with a rule between two keys), its budget, its footprint and its scene
builder, in one :class:`~thorvald_sim.world.kind.ElementKind`, :data:`POSTS`. The one line that adds it
is ``with registered(POSTS):`` (test_world_element_kinds.py); a kind of the simulator's own is a line
in :data:`thorvald_sim.world.kinds.BUILT_IN` instead. A unique module name, so that no other package's
test module shadows it in one pytest run.
"""

from dataclasses import dataclass
from typing import List, Tuple

from thorvald_model.errors import Problem
from thorvald_model.schema import Key
from thorvald_sim.world.bodies import p
from thorvald_sim.world.kind import Context, ElementKind, Entry
from thorvald_sim.world.limits import bodies_each
from thorvald_sim.world.rules import COORDINATE, LENGTH


@dataclass(frozen=True)
class Post:
    """A fence post: a cylinder standing on the ground."""

    name: str
    index: int
    x: float  # [m] of its axis
    y: float  # [m]
    z: float  # [m] of its foot: the ground under its axis
    radius: float  # [m]
    height: float  # [m]


POST_KEYS = (
    Key("x", float, **COORDINATE),
    Key("y", float, **COORDINATE),
    Key("radius", float, 0.05, **LENGTH),
    Key("height", float, **LENGTH),
)


def make(entry: Entry, context: Context) -> Post:
    v = entry.values
    broken = {pr.path for pr in context.problems}
    if v["height"] < 2 * v["radius"] and f"{entry.path}.radius" not in broken:
        rule = f"must be >= 2 * radius ({2 * v['radius']} m): a post, not a disc"
        context.problems.append(Problem(f"{entry.path}.height", v["height"], rule))
    z = context.ground_at(v["x"], v["y"])
    return Post(entry.name, entry.index, v["x"], v["y"], z, v["radius"], v["height"])


def footprint(post: Post) -> List[Tuple[float, float]]:
    return [(post.x - post.radius, post.y - post.radius), (post.x + post.radius, post.y + post.radius)]


def build(client: int, world, post: Post, name: str, bodies: dict) -> None:
    shape = p.createCollisionShape(p.GEOM_CYLINDER, radius=post.radius, height=post.height, physicsClientId=client)
    centre = (post.x, post.y, post.z + post.height / 2)
    bodies[name] = p.createMultiBody(0, shape, -1, basePosition=centre, physicsClientId=client)


POSTS = ElementKind(
    "posts", "post", POST_KEYS, make, build, budget=bodies_each(looks=True), doc="fence posts", footprint=footprint
)
