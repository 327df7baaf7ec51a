"""What a kind of world element is: :class:`ElementKind`, one entry of the registry
(:mod:`thorvald_sim.world.registry`), and what its functions are given (:class:`Entry`,
:class:`Context`).

A kind is a section of the world file (``walls:``, entries ``wall0``, ``wall1``, ...; or one
mapping, as ``height_field:``) with its keys, the function that makes an element's value from an
entry's checked values (and reports the rules between its keys), what its entries take of the
world's budgets, and the function that builds an element in pybullet (:mod:`thorvald_sim.scene`).
The loader and the scene iterate the registry: a new kind is its module and one registry line.
"""

from dataclasses import dataclass, field
from typing import Any, Callable, Dict, List, Mapping, NamedTuple, Optional, Sequence, Tuple, Union

from thorvald_model.errors import Problem
from thorvald_model.schema import Key


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
    made: Dict[str, Tuple[Any, ...]] = field(default_factory=dict)  # values made so far, by section
    # Whether a budget is broken: the world is refused anyway, and nothing searches for the ground
    over_budget: bool = False
    # [m] the ground's height under (x, y): the height field, hills and patches once they are made
    # (0 before, and in a world over its budgets)
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
    under ``name`` (:meth:`body_name`), or ``name.<part>`` for several; a string names a function of
    :mod:`thorvald_sim.scene`, so that this pure side never imports pybullet.
    budget(section, entries, searched): what the entries take of the world's budgets, by budget name
    (:data:`thorvald_sim.world.budgets.BUDGETS`): (key path, value, amount) shares; ``searched`` is
    what one ground look-up searches (the ground, every hill and patch).
    check(elements, context): the rules between the section's elements, and with the rest of the
    world (what ``context.made`` holds), once all are made.
    footprint(element): the points [m] of a box around it on the ground (the world's extent, in
    ``check_world``; :mod:`thorvald_sim.world.footprints`). counted: how ``check_world`` counts the
    section's entries, one and many ("hill", "hills").
    """

    section: str  # the top-level key: "walls"
    prefix: Optional[str]  # its entries' name: "wall" for wall0, wall1, ...; None: one mapping
    keys: Tuple[Key, ...]
    make: Callable[[Entry, Context], Any]
    builder: Union[str, Builder]
    budget: Optional[Callable[[str, Sequence[Entry], int], Mapping[str, Sequence[Tuple[str, Any, float]]]]] = None
    check: Optional[Callable[[Tuple[Any, ...], Context], None]] = None
    # False: part of what others stand on (or beside it): made while the file is read, before the
    # budgets; True: made after them, each on the ground under it (context.ground_at)
    on_ground: bool = True
    doc: str = ""  # what an entry is, in a few words (the keys' table)
    # the defaults a key's own cannot say (a colour, a surface kind's number), by key, for the table
    defaults: Mapping[str, str] = field(default_factory=dict)
    body: Optional[str] = None  # the body's name of a single mapping (default: its section)
    footprint: Optional[Callable[[Any], Sequence[Tuple[float, float]]]] = None
    counted: Tuple[str, str] = ()  # ("wall", "walls"); default: the prefix and the section

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
