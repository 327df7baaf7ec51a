"""What a kind of world element is: :class:`ElementKind`, one entry of the registry
(:mod:`thorvald_sim.world.kinds`), and what its functions are given (:class:`Entry`,
:class:`Context`).

A kind is a section of the world file (``walls:``, entries ``wall0``, ``wall1``, ...; or one
mapping, as ``height_field:``) with its keys, the function that makes an element's value from an
entry's checked values (and reports the rules between its keys), what its entries take of the
world's budgets, where an element lies on the ground, and the function that builds it in pybullet.
All of them live in the kind's own module (:mod:`thorvald_sim.world.kinds.walls`, ...); the loader,
the scene and ``check_world`` iterate the registry: a new kind is its module and one registry line.
"""

from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Mapping, NamedTuple, Optional, Sequence, Tuple

from thorvald_model.errors import Problem
from thorvald_model.schema import Key

from .geometry import Point
from .limits import LIMITS, Budget, Limits


class Entry(NamedTuple):
    """One entry of a section, its keys checked (:func:`thorvald_model.schema.parse_entry`)."""

    name: str  # "wall0" (a single mapping's: its section, "height_field")
    index: int  # 0 for wall0 (and for a single mapping)
    values: dict  # every key's value, defaults filled in (a key that broke its rule: its default)
    raw: Mapping  # the entry as the file holds it (what it gives, not its defaults)
    path: str  # key path of the entry: "walls.wall0" (a single mapping's: "height_field")


@dataclass
class Context:
    """What the functions of every kind share while one world is loaded."""

    data: Mapping  # the whole file (its top-level mapping)
    base_dir: str  # the folder relative paths (meshes, images) are taken from
    problems: List[Problem]  # every problem found so far; a kind's functions add theirs here
    ground: Any  # the ground's Surface
    limits: Limits = LIMITS  # the budgets the world is held to (a maker checks those it counts itself)
    made: Dict[str, Tuple[Any, ...]] = field(default_factory=dict)  # values made so far, by section
    # Whether a budget is broken: the world is refused anyway, and nothing searches for the ground
    over_budget: bool = False
    # [m] the ground's height under (x, y): the kinds that shape it once they are made (0 before, and
    # in a world over its budgets)
    ground_at: Callable[[float, float], float] = lambda x, y: 0.0
    # (key path, value, absolute path) of the mesh files the objects name, read by the objects' check
    meshes: List[Tuple[str, Any, str]] = field(default_factory=list)

    def single(self, section: str) -> Any:
        """The value of a kind of one mapping (``height_field``), None if the world has none (yet)."""
        made = self.made.get(section, ())
        return made[0] if made else None


Builder = Callable[[int, Any, Any, str, Dict[str, int]], None]


@dataclass(frozen=True)
class ElementKind:
    """A kind of world element: one entry of the registry.

    make(entry, context): the element's value (a frozen dataclass with ``name`` and ``index`` for
    a section's entry), reporting the rules between its keys to ``context.problems``; None leaves
    it out (its problem reported).
    builder(client, world, element, name, bodies): adds the element's pybullet bodies to ``bodies``
    under ``name`` (:meth:`body_name`), or ``name.<part>`` for several. It calls pybullet through
    :data:`thorvald_sim.world.bodies.p`, which imports it when a scene is first built, so that the
    kind's module stays pure to whatever only loads worlds.
    budget(section, entries, searched): what the entries take of the world's budgets, by budget name
    (:data:`thorvald_sim.world.limits.BUDGETS`): (key path, value, amount) shares; ``searched`` is
    what one ground look-up searches (the ground, and every entry of the kinds that shape it).
    check(elements, context): the rules between the section's elements, and with the rest of the
    world (what ``context.made`` holds), once all are made.
    footprint(element): the points [m] of a box around it on the ground (the world's extent, in
    ``check_world``). counted: how ``check_world`` counts the section's entries, one and many
    ("hill", "hills").
    ground(element, x, y): for a kind that shapes the ground others stand on (a hill, a patch, a
    height field), the height [m] the element gives it at (x, y), None where it gives none: the
    ground is the highest there (:func:`thorvald_sim.world.geometry.ground_height`). Such a kind is
    made before the budgets (``on_ground`` False).
    replaces_ground: the kind's element takes the ground plane's place (a height field): the scene
    builds no plane then, and a ground look-up searches it as the ground.
    holes(elements): the polygons [m] (corners counter-clockwise) the section's elements need cut out
    of the ground (soft patches sink into theirs): the scene builds the ground in pieces around them.
    """

    section: str  # the top-level key: "walls"
    prefix: Optional[str]  # its entries' name: "wall" for wall0, wall1, ...; None: one mapping
    keys: Tuple[Key, ...]
    make: Callable[[Entry, Context], Any]
    builder: Builder
    budget: Optional[Budget] = None
    check: Optional[Callable[[Tuple[Any, ...], Context], None]] = None
    # False: part of what others stand on (or beside it): made while the file is read, before the
    # budgets; True: made after them, each on the ground under it (context.ground_at)
    on_ground: bool = True
    doc: str = ""  # what an entry is, in a few words (the keys' table)
    # the defaults a key's own cannot say (a colour, a surface kind's number), by key, for the table
    defaults: Mapping[str, str] = field(default_factory=dict)
    body: Optional[str] = None  # the body's name of a single mapping (default: its section)
    footprint: Optional[Callable[[Any], Sequence[Point]]] = None
    counted: Tuple[str, str] = ()  # ("wall", "walls"); default: the prefix and the section
    ground: Optional[Callable[[Any, float, float], Optional[float]]] = None
    replaces_ground: bool = False
    holes: Optional[Callable[[Tuple[Any, ...]], Sequence[Sequence[Point]]]] = None

    @property
    def single(self) -> bool:
        """Whether the section is one mapping rather than numbered entries."""
        return self.prefix is None

    @property
    def count_names(self) -> Tuple[str, str]:
        """(one, many): how an entry and several are counted ("wall", "walls")."""
        return self.counted or (self.prefix or self.section, self.section)

    def body_name(self, element: Any) -> str:
        """The scene's name of the element's body: ``walls.wall0`` (a single mapping's: ``body``)."""
        if self.single:
            return self.body or self.section
        return f"{self.section}.{element.name}"
