"""Loading a world file: every element kind of the registry read, checked against the budgets and
made, and the shipped worlds found by name.

Every problem is collected with its dotted key path, value and rule, and raised together in one
:class:`~thorvald_model.errors.ConfigError`; nothing is made that a broken budget counts.
"""

import dataclasses
import glob
import os
from typing import Any, Dict, List, Mapping, Optional, Sequence

from thorvald_model.errors import MISSING, ConfigError, Problem
from thorvald_model.resources import package_folder
from thorvald_model.schema import (
    POSITIVE,
    Key,
    check_top_level,
    parse_entry,
    parse_scalar,
    parse_section,
    read_yaml_file,
)

from .config import WorldConfig
from .geometry import ground_height
from .ground import parse_ground
from .kind import Context, ElementKind, Entry
from .kinds import element_kinds, top_level_keys
from .limits import LIMITS, Limits, budget_problems
from .rules import RGBA_KEY, WHAT, take_colour, take_colours

# The package folder when this module runs from the source tree (or the devel space, which relays
# to it); in an install space the worlds are under share/thorvald_sim instead.
PACKAGE_DIR = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))

# The top-level keys that are neither the ground nor an element kind
GRAVITY_KEY = Key("gravity", float, 9.81, **POSITIVE)
DESCRIPTION_KEY = Key("description", str, "")


def load_world(path: str, limits: Limits = LIMITS) -> WorldConfig:
    """Loads and validates a world file, ours (YAML) or Gazebo's (SDF, told by its content:
    :func:`~thorvald_sim.world.gazebo_world.is_gazebo_world`); raises ConfigError naming every problem.

    A file that cannot be read at all (missing, a directory, not text, not YAML) raises a
    ConfigError with one problem at the top level, which formats as one line. Relative paths in
    the file (meshes, images) are from the file's folder. limits: the budgets it is held to.
    """
    from .gazebo_world import is_gazebo_world, read_gazebo_world  # noqa: PLC0415  (SDF worlds: when one comes)

    if is_gazebo_world(path):
        return gazebo_world_config(read_gazebo_world(path, limits=limits), limits)
    return parse_world(read_yaml_file(path, WHAT), path, os.path.dirname(os.path.abspath(path)), limits)


def gazebo_world_config(world, limits: Limits = LIMITS) -> WorldConfig:
    """Our world of a Gazebo world read (:class:`~thorvald_sim.world.gazebo_world.GazeboWorld`): its
    gravity, its heightmap as the height field, its ground plane as our ground (a static model of
    planes facing up at z = 0: ``ground_plane``, which the Gazebo API lists as ever; our ground's
    surface, since ODE's mu is not bullet's friction), every other model and actor as it was read."""
    gx, gy, gz = world.gravity
    if abs(gx) > 1e-9 or abs(gy) > 1e-9 or not gz < 0:
        raise ConfigError(
            world.source,
            [Problem("gravity", f"{gx:g} {gy:g} {gz:g}", "points straight down here (x and y 0, z below 0)")],
            WHAT,
        )
    described = f"Gazebo world {world.name!r} ({os.path.basename(world.source)})"
    folder = os.path.dirname(world.source)
    data = {"gravity": -gz, "description": described}
    if world.height_field is not None:  # its heightmap as our height field's keys: made and checked as ours
        data["height_field"] = world.height_field
    config = parse_world(data, world.source, folder, limits)
    models, notes = [], list(world.notes)
    # Gazebo paces its steps at real_time_update_rate a wall second (0: flat out), so the world runs at
    # that times max_step_size x real time (<real_time_factor> is only what it aims at)
    pace = max(world.real_time_update_rate, 0.0) * world.max_step_size
    said = "as fast as it can" if pace == 0 else f"{pace:g} x real time"
    notes.append(
        f"physics: Gazebo's steps of {world.max_step_size:g} s, {world.real_time_update_rate:g} a second: the "
        f"simulator runs {said} as they would (unless ~real_time_factor is set) in steps of its ~physics_rate"
    )
    for model in world.models:
        if _is_ground_plane(model):
            notes.append(f"model {model.name!r}: a plane facing up at z = 0, taken as the ground (our ground's)")
        else:
            models.append(model)
    return dataclasses.replace(
        config, models=tuple(models), actors=world.actors, datum=world.datum, notes=tuple(notes), real_time_factor=pace
    )


def _is_ground_plane(model) -> bool:
    from ..models.spec import Plane  # noqa: PLC0415

    def level(pose) -> bool:  # at z = 0, not tilted
        return abs(pose[0][2]) < 1e-9 and abs(pose[1][0]) < 1e-9 and abs(pose[1][1]) < 1e-9

    collisions = [c for link in model.spec.links for c in link.collisions]
    return (
        model.static
        and bool(collisions)
        and level(model.pose)
        and all(level(link.pose) for link in model.spec.links)
        and all(isinstance(c.geometry, Plane) and tuple(c.geometry.normal) == (0.0, 0.0, 1.0) for c in collisions)
        and all(level(c.pose) for c in collisions)
    )


def parse_world(
    data: Any, source: str = "<world>", base_dir: Optional[str] = None, limits: Limits = LIMITS
) -> WorldConfig:
    """Validates an already parsed world (a YAML document or a ROS parameter tree).

    base_dir: the folder relative paths (meshes, images) are taken from; default the current one.
    limits: the budgets the world is held to (:class:`~thorvald_sim.world.limits.Limits`).
    """
    base_dir = os.path.abspath(base_dir or os.getcwd())
    problems: List[Problem] = []
    kinds = element_kinds()
    data = check_top_level(data, top_level_keys(), problems, source=source, what=WHAT)

    # The two scalar keys go through parse_entry as a one-key entry each, so they get the same
    # coercion and rules as every other key; their paths are the bare key names.
    gravity = parse_scalar(data, GRAVITY_KEY, problems)
    description = parse_scalar(data, DESCRIPTION_KEY, problems)
    ground, ground_colour = parse_ground(data, problems)

    # The kinds the others stand on (or beside) are made as they are read; the budgets are checked
    # before anything that grows with them is made. A world over them is refused anyway: its
    # objects, tunnels and walls take the plane's height, without a search.
    context = Context(data, base_dir, problems, ground, limits)
    entries: Dict[str, List[Entry]] = {}
    for kind in kinds:
        entries[kind.section] = _entries(kind, data, problems)
        if not kind.on_ground:
            _make(kind, entries[kind.section], context)
    context.over_budget = budget_problems(kinds, entries, problems, limits)
    if not context.over_budget:
        shapers = tuple((kind.ground, context.made[kind.section]) for kind in kinds if kind.ground is not None)
        context.ground_at = lambda px, py: ground_height(shapers, px, py)
    for kind in kinds:
        if kind.on_ground:
            _make(kind, entries[kind.section], context)

    if problems:
        raise ConfigError(source, problems, WHAT)
    sections = tuple(
        (kind.section, context.single(kind.section) if kind.single else context.made[kind.section]) for kind in kinds
    )
    return WorldConfig(
        source=source,
        gravity=gravity,
        ground=ground,
        description=description,
        ground_rgba=ground_colour,
        sections=sections,
        shapers=tuple((kind.section, kind.ground) for kind in kinds if kind.ground is not None),
    )


def _entries(kind: ElementKind, data: Mapping, problems: List[Problem]) -> List[Entry]:
    """The kind's entries in the file, their keys checked (in index order; those without a required
    key left out, their problems reported)."""
    section = data.get(kind.section)
    coloured = RGBA_KEY in kind.keys
    if kind.single:
        if section is None:
            return []
        raw, colour = take_colour(section, kind.section, None, problems) if coloured else (section, None)
        values = parse_entry(raw, kind.section, kind.keys, problems)
        if values is None:
            return []
        if coloured:
            values["rgba"] = colour
        return [Entry(kind.section, 0, values, section, kind.section)]
    raw, colours = take_colours(section, kind.section, problems) if coloured else (section, {})
    found = []
    for name, index, values in parse_section(raw, kind.section, kind.prefix, kind.keys, problems):
        if coloured:
            values["rgba"] = colours.get(name)
        found.append(Entry(name, index, values, _raw_entry(section, name), f"{kind.section}.{name}"))
    return found


def _make(kind: ElementKind, entries: Sequence[Entry], context: Context) -> None:
    """The kind's elements into context.made (an entry whose maker gives None left out), then its check."""
    made = tuple(element for element in (kind.make(entry, context) for entry in entries) if element is not None)
    context.made[kind.section] = made
    if kind.check is not None:
        kind.check(made, context)


def _raw_entry(section: Any, name: str) -> Mapping:
    entry = section.get(name) if isinstance(section, Mapping) else None
    return entry if isinstance(entry, Mapping) else {}


# ---------------------------------------------------------------------------------------------
# Shipped worlds
# ---------------------------------------------------------------------------------------------
def worlds_dir() -> str:
    """The shipped worlds' folder, in the devel or install space (or the source tree)."""
    return os.path.join(package_folder("thorvald_sim", PACKAGE_DIR), "worlds")


def shipped_worlds() -> List[str]:
    """Names of the shipped worlds (``flat``, ...), sorted."""
    return sorted(os.path.splitext(os.path.basename(f))[0] for f in glob.glob(os.path.join(worlds_dir(), "*.yaml")))


def resolve_world(name_or_path: str) -> str:
    """The file of a world given by name (a shipped world) or by path.

    A shipped world's name wins over a file of that name in the current folder. An existing file is
    returned as it is; a missing ``.world`` or ``.sdf`` is looked for as Gazebo looks for a world name
    (``worlds/farm.world`` under ``GAZEBO_RESOURCE_PATH`` and the packages' ``gazebo_media_path``:
    :meth:`~thorvald_sim.models.gazebo_paths.GazeboPaths.find_world`), a ConfigError naming every folder
    searched when it is nowhere; anything else that looks like a path (a folder separator, a YAML
    extension) is returned as it is, so that a missing file is reported by :func:`load_world` with the
    reason; a bare name that is neither raises a ConfigError of one line listing the shipped worlds.
    """
    names = shipped_worlds()
    if name_or_path in names:
        return os.path.join(worlds_dir(), name_or_path + ".yaml")
    if os.path.exists(name_or_path):
        return name_or_path
    if name_or_path.endswith((".world", ".sdf")):  # a Gazebo world's name: on Gazebo's resource path
        from ..models.gazebo_paths import gazebo_paths  # noqa: PLC0415  (rospkg: only for such a name)

        found, why = gazebo_paths().find_world(name_or_path)
        if found is None:
            raise ConfigError(name_or_path, [Problem("", MISSING, why)], WHAT)
        return found
    looks_like_path = os.sep in name_or_path or name_or_path.endswith((".yaml", ".yml"))
    if looks_like_path:
        return name_or_path
    rule = "no such world: give a file or one of " + ", ".join(names)
    raise ConfigError(name_or_path, [Problem("", MISSING, rule)], WHAT)
