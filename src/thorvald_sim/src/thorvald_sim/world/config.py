"""The loaded world: :class:`WorldConfig`, a frozen value of the file's top-level keys and every
element kind's values, by section (SI units: m, rad, kg, m/s^2). Pure: no pybullet."""

import dataclasses
from dataclasses import dataclass, field
from typing import Any, Callable, Optional, Tuple

from .geometry import ground_height
from .rules import Rgba
from .surfaces import RGBA_TARMAC, Surface


@dataclass(frozen=True)
class WorldConfig:
    """A validated world file.

    Each element kind's values are read as an attribute named by its section (``world.walls``: a
    tuple; a single mapping's value or None: ``world.height_field``), whichever module the kind
    comes from (:mod:`thorvald_sim.world.kinds`); :meth:`elements` gives any section's as a tuple.
    """

    source: str  # file name, or what the data came from
    gravity: float  # [m/s^2], pointing down
    ground: Surface
    description: str = ""
    ground_rgba: Rgba = RGBA_TARMAC
    # (section, its values) of every kind of the registry the world was loaded with, in its order
    sections: Tuple[Tuple[str, Any], ...] = ()
    # (section, its kind's ground function) of the kinds that shape the ground (ElementKind.ground)
    shapers: Tuple[Tuple[str, Callable[[Any, float, float], Optional[float]]], ...] = field(default=(), repr=False)
    # a Gazebo world file's (thorvald_sim.world.gazebo_world): its models (WorldModel: built as models of
    # the Gazebo API, as Gazebo loads them), its actors, its GNSS datum, and what was read and left out
    models: Tuple[Any, ...] = ()
    actors: Tuple[Any, ...] = ()
    datum: Any = None
    notes: Tuple[str, ...] = ()
    real_time_factor: Optional[float] = None  # a Gazebo world's pace (its physics' steps a second x step); 0: flat out

    def __getattr__(self, name: str) -> Any:
        # called for a name that is no field or method only: a kind's section; read from __dict__, as
        # a copy or an unpickled world asks before its fields are there
        for section, values in self.__dict__.get("sections", ()):
            if section == name:
                return values
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def elements(self, section: str) -> Tuple[Any, ...]:
        """The values of a section, in order: a single mapping's as one value or none."""
        values = getattr(self, section)
        if values is None:
            return ()
        return values if isinstance(values, tuple) else (values,)

    def with_section(self, section: str, values: Any) -> "WorldConfig":
        """The world with the section's values replaced (a tuple; a single mapping's value or None)."""
        if all(name != section for name, _ in self.sections):
            raise ValueError(f"the world has no section {section!r}")
        sections = tuple((name, values if name == section else old) for name, old in self.sections)
        return dataclasses.replace(self, sections=sections)

    def ground_height(self, px: float, py: float) -> float:
        """[m] of the ground's surface at (px, py): the highest of what the elements that shape it give
        there (the height field, 0 off it or without one; the hills; the patches' tops), not rails,
        objects, plants or tunnels. A soft surface's top, before anything sinks into it."""
        return ground_height(tuple((height, self.elements(section)) for section, height in self.shapers), px, py)
