"""The registry of world element kinds: one :class:`~thorvald_sim.world.kind.ElementKind` a kind, in
the order the loader makes them and the scene builds them.

Every part of the simulator that does something per kind of element looks the kinds up here: the
loader (:func:`thorvald_sim.world.parse_world`: the sections it reads, what each makes and takes of
the budgets), the scene (:func:`thorvald_sim.physics.scene.build_scene`: each element's bodies, the ground's
holes), ``check_world`` (the counts and the extent) and the keys' table (:mod:`thorvald_sim.world.keys_table`).

A kind is a module of its own (its value type, keys, maker and rules, budget, footprint and scene
builder, in one :class:`~thorvald_sim.world.kind.ElementKind`: :mod:`~thorvald_sim.world.kinds.walls`
is a small one) and one line: in ``BUILT_IN`` for a kind of the simulator, or
``with registered(MY_KIND):`` for a kind of a test or of a user's program, which adds it for a while.
"""

import re
from contextlib import contextmanager
from dataclasses import fields
from typing import Iterator, List, Tuple

from ..config import WorldConfig
from ..kind import ElementKind
from . import height_field, objects, patches, polytunnels, rails, rows, slopes, walls

# The kinds, in the order they are made and built (the height field first: it is the ground then)
BUILT_IN: Tuple[ElementKind, ...] = (
    height_field.HEIGHT_FIELD,
    patches.PATCHES,
    slopes.SLOPES,
    rails.RAILS,
    objects.OBJECTS,
    rows.ROWS,
    polytunnels.POLYTUNNELS,
    walls.WALLS,
)

_kinds: List[ElementKind] = list(BUILT_IN)  # BUILT_IN, then the kinds registered() added


def element_kinds() -> Tuple[ElementKind, ...]:
    """The kinds of world element, in the order they are made and built."""
    return tuple(_kinds)


def top_level_keys() -> Tuple[str, ...]:
    """Every key a world file may have at its top level."""
    return ("gravity", "ground", *(kind.section for kind in _kinds), "description")


_NAME = re.compile(r"^[a-z][a-z0-9_]*$")
_PREFIX = re.compile(r"^[a-z_]+$")  # the schema reads an entry's name as letters then its number


@contextmanager
def registered(kind: ElementKind) -> Iterator[ElementKind]:
    """Adds a kind of world element after the others while the ``with`` block runs, then takes it
    out again (even when the block raises), so the registry is left as it was::

        with registered(POSTS):
            world = load_world("posts.yaml")  # reads the posts: section
            scene = build_scene(client, world)  # builds world.posts

    ValueError if the kind cannot be one: its section is taken (a top-level key, or a name of
    :class:`~thorvald_sim.world.config.WorldConfig`), its names are not lowercase words, its keys
    repeat a name, or its maker or builder is no function.
    """
    _check_new(kind)
    _kinds.append(kind)
    try:
        yield kind
    finally:
        _kinds.remove(kind)


def _check_new(kind: ElementKind) -> None:
    def refuse(why: str) -> None:
        raise ValueError(f"element kind {kind.section!r} cannot be registered: {why}")

    if not isinstance(kind.section, str) or not _NAME.match(kind.section):
        refuse("its section must be a lowercase name (letters, digits, _)")
    if kind.section in top_level_keys():
        refuse("the world file has that top-level key already")
    if kind.section in {f.name for f in fields(WorldConfig)} or hasattr(WorldConfig, kind.section):
        refuse("WorldConfig has an attribute of that name, which would hide the section's values")
    if kind.prefix is not None and not _PREFIX.match(kind.prefix):
        refuse(f"its entries' prefix {kind.prefix!r} must be lowercase letters and _ (entries are prefix0, ...)")
    names = [n for key in kind.keys for n in (key.name, *key.aliases)]
    twice = sorted({n for n in names if names.count(n) > 1})
    if twice:
        refuse(f"its keys name {', '.join(twice)} more than once")
    if not callable(kind.make) or not callable(kind.builder):
        refuse("make and builder must be functions")
    if kind.ground is not None and kind.on_ground:
        refuse("a kind that shapes the ground (ground) is made before the others stand on it (on_ground=False)")


__all__ = ["BUILT_IN", "element_kinds", "registered", "top_level_keys"]
