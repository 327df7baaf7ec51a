"""The simulator's world: a small YAML file of ground, friction patches, hills, heating-pipe rails,
objects, crop rows, polytunnels, walls and uneven ground.

The simulator node's ``~world`` parameter names a shipped world (``flat``, ``tarmac_gravel``,
``farm_track``, ``slope``, ``greenhouse``, ``crop_rows``, ``polytunnel``, ``vineyard``: the files in
this package's ``worlds`` folder) or gives a path. Lengths [m], angles [rad], masses [kg];
frictions are pybullet's per-body coefficients, which pybullet multiplies with the wheel's (the
simulator's wheels have friction 1.0). Every section's entries are numbered from 0 without gaps
(``object0``, ``object1``, ...). A colour, ``rgba``, is a list of 3 or 4 numbers in [0, 1] (red,
green, blue and alpha, 1 if left out). ``rosrun thorvald_sim check_world FILE [FILE ...]``
(:mod:`thorvald_sim.check_world`) checks world files, or shipped worlds by name, as the simulator
loads them, without starting it.

The keys. Every top-level key, each section's entries and each key's default and rule are one table,
rendered from the registry of element kinds by :func:`keys_markdown` (``python -m
thorvald_sim.world`` prints it): ``docs/worlds.md`` holds it between its ``world-keys`` markers, and
a test keeps the two the same. What each kind of element is, and what its keys mean: its value type
(:mod:`thorvald_sim.world.values`). Here: the surface kinds, the rules between keys, and the limits.

The package, by job: :mod:`~thorvald_sim.world.values` (the elements' value types),
:mod:`~thorvald_sim.world.keys`, :mod:`~thorvald_sim.world.budgets`,
:mod:`~thorvald_sim.world.elements` and :mod:`~thorvald_sim.world.loader` (the file's schema and
parser), :mod:`~thorvald_sim.world.geometry` (ground geometry), :mod:`~thorvald_sim.world.terrain`
(height fields). :mod:`~thorvald_sim.world.registry` holds one :class:`ElementKind` a kind of element
(its section, entries' prefix, keys, maker, budget and scene builder); the loader and the scene
iterate it, so a new kind is its module and one registry line (:func:`registered` adds one for a
while, as a test does).

Surface kinds (``surface:`` on the ground and on patches; a key given beside it overrides its
number). Numbers for the simulator's wheels (lateral friction 1.0, radius 0.2 m), from the
published ranges for pneumatic and agricultural tyres:

============  ========  =====  ===============  ========  ==========================================
kind          lateral   C_rr   rolling_friction sinkage   what
============  ========  =====  ===============  ========  ==========================================
tarmac        0.9       0.015  0.003            0         dry asphalt
concrete      0.85      0.012  0.0024           0         a dry concrete floor or yard
gravel        0.6       0.05   0.01             0         loose gravel on a firm base
grass         0.55      0.06   0.012            0.004     dry mown grass on firm soil
wet_grass     0.3       0.08   0.016            0.008     wet grass, a field in the morning
mud           0.35      0.2    0.04             0.015     wet, soft soil: a rutted gateway, a track
sand          0.5       0.25   0.05             0.02      dry loose sand
ice           0.1       0.01   0.002            0         ice, or wet plastic sheeting
soil          0.6       0.08   0.016            0.006     bare field soil, tilled and settled
============  ========  =====  ===============  ========  ==========================================

- ``lateral_friction`` is the tyre's peak grip, the friction coefficient of pybullet's Coulomb
  cone in every direction, from the middle of the published ranges: dry asphalt and concrete 0.7
  to 1.0 (tarmac 0.9 as this file's default ground, concrete a little smoother), loose gravel 0.5
  to 0.7, dry grass 0.45 to 0.65, dry field soil 0.5 to 0.7, wet grass 0.2 to 0.4, wet clay and
  mud 0.2 to 0.5, dry sand 0.4 to 0.6, ice 0.05 to 0.15.
- ``rolling_friction`` [m] is pybullet's rolling resistance: a torque against the wheel's turning of
  this times the normal force, so it is the coefficient of rolling resistance C_rr times the wheel's
  radius. C_rr (the middle of the published ranges: tyres on asphalt 0.01 to 0.02, on concrete
  0.01 to 0.015, on gravel 0.02 to 0.08, on grass and firm field soil 0.05 to 0.1 (bare tilled soil 0.08), on wet grass
  about 0.08, in soft wet soil 0.1 to 0.3, in loose sand 0.15 to 0.3, on ice about 0.01) times the
  Thorvald wheel's 0.2 m. A wheel of another radius r feels C_rr * 0.2 / r: a caster of 0.1 m
  rolls twice as hard. It costs the drive motors torque (the motors hold their speed, so it shows
  as odometry error only where it takes a motor to its torque limit); a coasting wheel slows. It
  costs the simulator too: a robot on rolling friction steps about a fifth slower.
- ``sinkage`` [m] is how far a rolling wheel carrying the reference load of 500 N (a 200 kg robot
  on four wheels) sinks in: turf and topsoil give a few millimetres, wet grass twice that, mud and
  sand 1 to 2 cm (the depth of the ruts a loaded wheel leaves); tarmac, concrete, ice, and gravel
  on its firm base, none. The ground (or the patch) is a spring under each contact point that
  bullet keeps: ``500 / sinkage`` [N/m], critically damped for the 51 kg that the reference load
  weighs (damping ``2 * sqrt(stiffness * 51)`` [N s/m]: it settles within 0.2 s and does not
  bounce at 240 Hz). So a wheel sinks in proportion to its load (the standard robot's wheels carry
  380 to 490 N: 0.76 to 0.98 of ``sinkage``). A body resting on it shares its weight among its
  points: a ball has one, a box four, and a wheel, a thin disc, one while it rolls; at rest bullet
  often keeps a second point at the disc's other rim, and the wheel stands up to half its sinkage
  higher until it rolls again. At most 0.05 m. What it does not do: pybullet applies friction at
  the wheel's own rim, so a sunk wheel still rolls r * omega (measured: the standard robot's 0.2 m
  wheels sunk 11 to 15 mm in mud travel 0.2000 m a radian): the ground truth and the sensors see
  the robot lower and tilted, odometry sees no shorter rolling radius. Neither does any kind's
  spinning friction: it is 0 for every kind (a steering motor turning a wheel on the spot is the
  motor's business).

The ground's own sinkage makes the whole ground plane soft (not a height field: bullet touches a
wheel at one to four points of its triangles, rolling or not, so the sinkage would wander). A soft
patch needs a hole in the ground: the ground of a world with soft patches is flat convex pieces
0.1 m thick with a hole under every patch, each patch filling its own (the square of 2 km about the
origin, :func:`ground_pieces`; beyond it there is no ground), drawn as the plane. Its rectangular
pieces are as the plane to what drives or slides on them; the pieces beside a turned patch are not
quite (see :mod:`thorvald_sim.scene`).

Validation is the robot configuration's (:mod:`thorvald_model.schema`): every problem is collected
with its dotted key path, value and rule, and raised together in one :class:`ConfigError`. Beyond
each key's own rule: a patch names a surface kind or gives its lateral friction; a rail's radius
below its height and its gauge above two radii; an object has its shape's dimensions and no other
shape's, and its mesh file exists and is a mesh pybullet can load (:mod:`thorvald_sim.mesh_check`:
no junk, no STL without triangles or ASCII STL, no OBJ without faces or with faces naming missing
vertices); a sphere plant's height is at least its radius; a tunnel's height is above its leg
height, its end gaps leave the tables a length, its tables leave aisles between them (``tables *
table_width < width``) and its plants stay under its roof; a height field with an image takes no
``resolution``, one without takes no ``min_height`` or ``max_height``, its ``max_height`` is above
its ``min_height`` and its ``rut_width`` at most its ``rut_spacing``; a soft patch lies within 999 m
of the origin in x and y; neither the ground nor a patch is soft in a world with a height field.

Limits. A world is checked against these budgets at load, from its numbers, before anything they
count is made (an image's size is read from its header, a mesh file's from the file system), so a
typing mistake or a hostile file is refused at once with the key to change, not by exhausting the
memory or hanging the loader. A budget over several entries names the entry that takes the most.
Figures measured with pybullet 3.2.7, one core:

- positions: ``x``, ``y`` (and an object's ``z``) in [-10 000, 10 000] m: a farm is at most 20 km
  across, and pybullet draws and its cameras see in single precision, 1 mm steps out there;
- lengths: every length, size, width, height, radius, spacing, thickness, gap, depth, jitter,
  amplitude and resolution at most 10 000 m (``min_height`` and ``max_height`` in [-10 000,
  10 000]); a mesh's ``scale`` at most 1000. So every count made from them is a finite number;
- plants: 50 000 over every rows entry (places, gaps included: each draws its random numbers) and
  every polytunnel (strawberries): a plant is a part of a triangle mesh of 32 to 42 vertices,
  50 000 sphere plants take pybullet 2.6 GB and 14 s to build, cylinders 1.5 GB and 6 s (a
  hectare of lettuce, rows 0.75 m apart and a plant every 0.35 m, is 38 000);
- hoops: 2000 over every polytunnel (432 mesh vertices a hoop: 0.7 GB, 2.8 s; 4 km of tunnel);
- pairs of table legs: 10 000 over every polytunnel (48 mesh vertices a pair);
- pybullet bodies: 2000 (one a patch, hill, object, wall and row, two a rail, three a polytunnel
  and three each of its tables, and the ground): pybullet loops over its bodies every step
  (10 000 static boxes took 6.5 s to build and 17 ms a step, slower than real time);
- holes: 50 patches in a world with a soft patch (each patch is a hole in the ground; overlapping
  holes cut it into pieces that grow as the cube of their number: 50 into 7000 pieces, 2.6 s to
  build; 100 into 21 000, 10 s);
- ground look-ups: 2 000 000; every plant of a row, every point along a wall (every 0.5 m),
  every object and every polytunnel looks for the ground under it among the height field (or the
  plane), every hill and every patch: points times (1 + hills + patches); at the limit 1.6 s of
  loading on the plane, 5.5 s on a height field (99 walls of 10 km);
- a height field's grid points, or its image's pixels: 1 000 000 (2 GB and 5 s in pybullet), its
  image file 32 MB (a 1000 x 1000 16-bit grey PNG is at most 2 MB); its noise lattice
  (``size / feature_length`` along each side, with an ``amplitude``): 1 000 000 points;
- mesh files: 32 MB over every object (each object counts its file: pybullet loads it for each);
  checking them takes up to 3 s, loading them 3 to 6 s and 0.6 to 1.4 GB.

A world at every limit at once would need them together, about 7 GB and a minute to build; each
limit alone leaves room for the largest fields and greenhouses a robot drives in. The shipped
worlds use 5 % of a budget at most (crop_rows' 2471 plants), but for farm_track's 6 holes of 50.
A kind's entries take their shares of these budgets through its ``budget`` function
(:mod:`thorvald_sim.world.budgets`).

Pure: no pybullet, no rospy, no messages (the scene is built by :mod:`thorvald_sim.scene`); the
plants' positions, the tunnels' geometry and the heights of the ground are computed here, so tests
check them without a physics engine.
"""

import random  # noqa: F401  (the generator of plants and bumps, reached through this package by tests)
import sys
import types
from typing import Any

from thorvald_model.errors import ConfigError, Problem

from . import budgets, elements, geometry, keys, kind, loader, registry, terrain, values
from .budgets import (
    BUDGETS,
    MAX_BODIES,
    MAX_FIELD_POINTS,
    MAX_GROUND_LOOKUPS,
    MAX_HOLES,
    MAX_HOOPS,
    MAX_IMAGE_BYTES,
    MAX_MESH_BYTES,
    MAX_NOISE_POINTS,
    MAX_PLANTS,
    MAX_TABLE_LEGS,
    WALL_STEP,
    Share,
    bodies_each,
)
from .elements import mesh_problem
from .geometry import (
    GROUND_EXTENT,
    GROUND_THICKNESS,
    PATCH_TOP,
    SNAP,
    SOFT_DEPTH,
    SOFT_PATCH_REACH,
    Point,
    _ground_height,
    ground_pieces,
)
from .keys import (
    COORDINATE,
    CROPS,
    DESCRIPTION_KEY,
    GRAVITY_KEY,
    GROUND_DEFAULTS,
    GROUND_KEYS,
    HEIGHT,
    HEIGHT_FIELD_KEYS,
    KINDS_RULE,
    LENGTH,
    LENGTH_OR_ZERO,
    MAX_LENGTH,
    MAX_MESH_SCALE,
    MAX_REACH,
    MAX_SLOPE_ANGLE,
    MESH_EXTENSIONS,
    OBJECT_KEYS,
    OPTIONAL_LENGTH,
    PATCH_KEYS,
    PLANTS,
    POLYTUNNEL_KEYS,
    RAIL_KEYS,
    RGBA_KEY,
    RGBA_RULE,
    ROWS_KEYS,
    SHAPE_KEYS,
    SHAPES,
    SINKAGE_RULE,
    SLOPE_KEYS,
    SURFACE_DEFAULTS,
    SURFACE_KEYS,
    UNIT_RANGE,
    WALL_KEYS,
    WHAT,
    ZERO_HINT,
)
from .kind import Context, ElementKind, Entry
from .loader import PACKAGE_DIR, load_world, parse_world, resolve_world, shipped_worlds, worlds_dir
from .registry import BUILT_IN, element_kinds, keys_markdown, registered, top_level_keys
from .terrain import FLAT_BLEND, PNG_SIGNATURE
from .values import (
    ARCH_SEGMENTS,
    MAX_SINKAGE,
    REFERENCE_WHEEL_RADIUS,
    RGBA_CONCRETE,
    RGBA_GRAVEL,
    RGBA_ICE,
    RGBA_LEAF,
    RGBA_TARMAC,
    RGBA_WOOD,
    SINKAGE_LOAD,
    SINKAGE_MASS,
    STRAWBERRY_RADIUS,
    SURFACE_KINDS,
    TABLE_DEPTH,
    HeightField,
    Patch,
    Polytunnel,
    Rail,
    Rgba,
    Rows,
    Slope,
    Surface,
    SurfaceKind,
    Wall,
    WorldConfig,
    WorldObject,
    plant_positions,
)

_SUBMODULES = (values, geometry, terrain, keys, budgets, kind, elements, registry, loader)


def __getattr__(name: str) -> Any:
    # WORLDS_DIR is looked up when first asked for, not at import: importing this package must not
    # crawl the ROS package path (a module-level __getattr__, PEP 562).
    if name == "WORLDS_DIR":
        return worlds_dir()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


class _Package(types.ModuleType):
    """This package, a name set on which is set in each of its modules that has it too.

    The limits and helpers are read in the modules that use them (a budget in budgets.py and
    elements.py, the ground's search in loader.py); a test tunes one on ``thorvald_sim.world``
    (``monkeypatch.setattr(world, "MAX_BODIES", 21)``), and this makes it reach them all.
    """

    def __setattr__(self, name: str, value: Any) -> None:
        if not name.startswith("__") and not isinstance(value, types.ModuleType):
            for module in _SUBMODULES:
                if name in vars(module):
                    setattr(module, name, value)
        super().__setattr__(name, value)


sys.modules[__name__].__class__ = _Package

__all__ = [
    "ARCH_SEGMENTS",
    "BUDGETS",
    "BUILT_IN",
    "COORDINATE",
    "CROPS",
    "DESCRIPTION_KEY",
    "FLAT_BLEND",
    "GRAVITY_KEY",
    "GROUND_DEFAULTS",
    "GROUND_EXTENT",
    "GROUND_KEYS",
    "GROUND_THICKNESS",
    "HEIGHT",
    "HEIGHT_FIELD_KEYS",
    "KINDS_RULE",
    "LENGTH",
    "LENGTH_OR_ZERO",
    "MAX_BODIES",
    "MAX_FIELD_POINTS",
    "MAX_GROUND_LOOKUPS",
    "MAX_HOLES",
    "MAX_HOOPS",
    "MAX_IMAGE_BYTES",
    "MAX_LENGTH",
    "MAX_MESH_BYTES",
    "MAX_MESH_SCALE",
    "MAX_NOISE_POINTS",
    "MAX_PLANTS",
    "MAX_REACH",
    "MAX_SINKAGE",
    "MAX_SLOPE_ANGLE",
    "MAX_TABLE_LEGS",
    "MESH_EXTENSIONS",
    "OBJECT_KEYS",
    "OPTIONAL_LENGTH",
    "PACKAGE_DIR",
    "PATCH_KEYS",
    "PATCH_TOP",
    "PLANTS",
    "PNG_SIGNATURE",
    "POLYTUNNEL_KEYS",
    "RAIL_KEYS",
    "REFERENCE_WHEEL_RADIUS",
    "RGBA_CONCRETE",
    "RGBA_GRAVEL",
    "RGBA_ICE",
    "RGBA_KEY",
    "RGBA_LEAF",
    "RGBA_RULE",
    "RGBA_TARMAC",
    "RGBA_WOOD",
    "ROWS_KEYS",
    "SHAPES",
    "SHAPE_KEYS",
    "SINKAGE_LOAD",
    "SINKAGE_MASS",
    "SINKAGE_RULE",
    "SLOPE_KEYS",
    "SNAP",
    "SOFT_DEPTH",
    "SOFT_PATCH_REACH",
    "STRAWBERRY_RADIUS",
    "SURFACE_DEFAULTS",
    "SURFACE_KEYS",
    "SURFACE_KINDS",
    "TABLE_DEPTH",
    "UNIT_RANGE",
    "WALL_KEYS",
    "WALL_STEP",
    "WHAT",
    "ZERO_HINT",
    "ConfigError",
    "Context",
    "ElementKind",
    "Entry",
    "HeightField",
    "Patch",
    "Point",
    "Polytunnel",
    "Problem",
    "Rail",
    "Rgba",
    "Rows",
    "Share",
    "Slope",
    "Surface",
    "SurfaceKind",
    "Wall",
    "WorldConfig",
    "WorldObject",
    "_ground_height",
    "bodies_each",
    "element_kinds",
    "ground_pieces",
    "keys_markdown",
    "load_world",
    "mesh_problem",
    "parse_world",
    "plant_positions",
    "registered",
    "resolve_world",
    "shipped_worlds",
    "top_level_keys",
    "worlds_dir",
]
