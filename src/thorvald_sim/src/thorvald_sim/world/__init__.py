"""The simulator's world: a small YAML file of ground, friction patches, hills, heating-pipe rails,
objects, crop rows, polytunnels, walls and uneven ground.

The simulator node's ``~world`` parameter names a shipped world (``flat``, ``tarmac_gravel``,
``farm_track``, ``slope``, ``greenhouse``, ``crop_rows``, ``polytunnel``, ``vineyard``: the files in
this package's ``worlds`` folder) or gives a path. Lengths [m], angles [rad], masses [kg];
frictions are pybullet's per-body coefficients, which pybullet multiplies with the wheel's (the
simulator's wheels have friction 1.0). Every section's entries are numbered from 0 without gaps
(``object0``, ``object1``, ...). A colour, ``rgba``, is a list of 3 or 4 numbers in [0, 1] (red,
green, blue and alpha, 1 if left out). ``rosrun thorvald_sim check_world FILE [FILE ...]``
(:mod:`thorvald_sim.tools.check_world`) checks world files, or shipped worlds by name, as the simulator
loads them, without starting it.

Validation is the robot configuration's (:mod:`thorvald_model.schema`): every problem is collected
with its dotted key path, value and rule, and raised together in one :class:`ConfigError`; beyond
each key's own rule, each kind's module says the rules between its keys and with the rest of the
world. A world is held to budgets (:class:`~thorvald_sim.world.limits.Limits`, a value the loader
takes: ``load_world(path, limits=...)``) before anything they count is made.

The package, by kind: :mod:`~thorvald_sim.world.kinds` is the registry, one module a kind of
element (``height_field``, ``patches``, ``slopes``, ``rails``, ``objects``, ``rows``, ``polytunnels``,
``walls``) holding its value type, keys, maker and rules, budget, footprint and scene builder, and
one line a kind in the registry. A new kind, built-in or a program's own, is a module and one line
(:func:`registered` adds one for a while, as a test does). What the kinds share:
:mod:`~thorvald_sim.world.kind` (what a kind is), :mod:`~thorvald_sim.world.loader` (the file read,
every kind made), :mod:`~thorvald_sim.world.config` (the loaded world), :mod:`~thorvald_sim.world.limits`
(the budgets), :mod:`~thorvald_sim.world.rules` (the bounds of lengths and positions, colours),
:mod:`~thorvald_sim.world.surfaces` (surfaces and their kinds), :mod:`~thorvald_sim.world.ground`
(the ground's keys), :mod:`~thorvald_sim.world.geometry` (frames, the ground's height, the ground with
holes), :mod:`~thorvald_sim.world.terrain` (the height field's maths), :mod:`~thorvald_sim.world.bodies`
(what the scene builders are built on) and :mod:`~thorvald_sim.world.keys_table` (the keys' table
of ``docs/worlds.md``, ``python -m thorvald_sim.world`` prints it).

Pure: no pybullet, no rospy, no messages. Each kind's scene builder calls pybullet through
:mod:`thorvald_sim.world.bodies`, which imports it when :func:`thorvald_sim.physics.scene.build_scene` first
builds something; the plants' positions, the tunnels' geometry and the heights of the ground are
computed from the values, so tests check them without a physics engine.
"""

from typing import Any

from thorvald_model.errors import ConfigError

from .config import WorldConfig
from .kinds import BUILT_IN, element_kinds, registered, top_level_keys
from .limits import LIMITS, Limits
from .loader import load_world, parse_world, resolve_world, shipped_worlds, worlds_dir


def __getattr__(name: str) -> Any:
    # WORLDS_DIR is looked up when first asked for, not at import: importing this package must not
    # crawl the ROS package path (a module-level __getattr__, PEP 562).
    if name == "WORLDS_DIR":
        return worlds_dir()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


__all__ = [
    "BUILT_IN",
    "LIMITS",
    "ConfigError",
    "Limits",
    "WorldConfig",
    "element_kinds",
    "load_world",
    "parse_world",
    "registered",
    "resolve_world",
    "shipped_worlds",
    "top_level_keys",
    "worlds_dir",
]
