"""The simulator's world: a small YAML file of ground, friction patches, hills, heating-pipe rails,
objects, crop rows, polytunnels, walls and uneven ground.

The simulator node's ``~world`` parameter names a shipped world (``flat``, ``tarmac_gravel``,
``farm_track``, ``slope``, ``greenhouse``, ``crop_rows``, ``polytunnel``, ``vineyard``: the files in
this package's ``worlds`` folder) or gives a path. A world file has these top-level keys (lengths
[m], angles [rad], masses [kg]; frictions are pybullet's per-body coefficients, which pybullet
multiplies with the wheel's; the simulator's wheels have friction 1.0). Defaults in brackets; a key
without one is required. Every section's entries are numbered from 0 without gaps (``object0``, ``object1``, ...).
A colour, ``rgba``, is a list of 3 or 4 numbers in [0, 1] (red, green, blue and alpha, 1 if left out).
``rosrun thorvald_sim check_world FILE [FILE ...]`` (:mod:`thorvald_sim.check_world`) checks world
files, or shipped worlds by name, as the simulator loads them, without starting it.

``gravity``
    [m/s^2] (9.81).
``ground``
    one mapping: ``surface`` (none: a kind of ground, below, whose numbers and colour are the
    defaults of the keys that follow), ``lateral_friction`` (0.9), ``rolling_friction`` (0),
    ``spinning_friction`` (0), ``sinkage`` (0: soft ground, below), ``restitution`` (0), ``rgba``
    (tarmac grey ``[0.35, 0.35, 0.37, 1]``: the colour it is drawn in).
``patches``
    ``patch0``, ...: rectangles of another surface lying on the ground (gravel, grass, mud, ice),
    centred at ``x``, ``y``, ``size_x`` by ``size_y``, turned by ``yaw`` (0); ``surface`` (none),
    ``lateral_friction`` (required without a surface), ``rolling_friction`` (0),
    ``spinning_friction`` (0), ``sinkage`` (0), ``rgba`` (the surface's; gravel brown, or ice blue
    below a lateral friction of 0.3, without one). A soft patch (``sinkage`` above 0) is let into
    the ground: its top lies 1 mm above the ground as every patch's, and the ground has a hole under
    it (and under every other patch then), so a wheel sinks into it (not with a ``height_field``,
    which has no holes).
``slopes``
    ``slope0``, ...: hills along their own x axis: a ramp up at ``angle`` (at most 1.2), a flat top
    of ``top_length`` (0) at ``height``, a ramp down at ``angle``; ``x``, ``y`` is the centre of the
    footprint, ``yaw`` (0) the direction uphill, ``width`` its size across; frictions (0.9, 0, 0).
``rails``
    ``rail0``, ...: pairs of parallel heating pipes as in greenhouses (the paper's Figure 2a robot
    rides them): ``x``, ``y`` is the point between the pipes at the middle of their ``length``,
    ``yaw`` (0) the direction they run in, ``gauge`` (0.55) the distance between the pipe centres,
    ``height`` (0.1) of the centres, ``radius`` (0.0255); frictions (0.8, 0, 0).
``objects``
    ``object0``, ...: single bodies. ``shape``: ``box`` (``size_x``, ``size_y``, ``size_z``),
    ``cylinder`` (``radius``, ``length`` along its own z), ``sphere`` (``radius``) or ``mesh``
    (``file``: an OBJ or binary STL file, a relative path from the world file's folder, read at
    load to check it is a mesh (:mod:`thorvald_sim.mesh_check`); ``scale`` (1)).
    ``x``, ``y``; ``z``: of the centre (a mesh's origin) above the ground under it (default: resting
    upright on it, half its height up; a mesh's origin on it); ``roll``, ``pitch``, ``yaw`` (0).
    ``mass`` (0: static; above 0 it falls, slides and can be pushed, without drag as the robots);
    ``rgba`` (wood brown); frictions (0.8, 0, 0), ``restitution`` (0).
``rows``
    ``row0``, ...: crop rows made from a few numbers. The first row starts at ``x``, ``y`` and runs
    ``length`` along ``yaw`` (0); ``count`` (1) rows, each ``spacing`` (0.75) left of the previous
    one (+y for yaw 0). Plants every ``plant_spacing`` (0.3) from the start to the end of each row:
    ``plant``: ``cylinder`` (default: a column of ``plant_radius`` (0.1) and ``plant_height`` (0.4))
    or ``sphere`` (a ball of ``plant_radius`` whose top is at ``plant_height``, on a stem a tenth of
    its radius thick: a lettuce, a cabbage, a vine's canopy); each plant is missing with
    ``gap_probability`` (alias ``gaps``; 0), and moved by up to ``jitter`` (0) along and across its
    row, from a random generator seeded by ``seed`` (0): the same numbers give the same plants.
    Plants stand on the ground under them (hills and height fields too). ``rgba`` (leaf green);
    frictions (0.5, 0, 0). The plants of every entry count against the world's budget (Limits).
``polytunnels``
    ``polytunnel0``, ...: a Haygrove-type tunnel on level ground (its floor is the ground height at
    its centre): ``x``, ``y`` the centre of the floor, ``yaw`` (0) the direction it runs in,
    ``length``, ``width`` (8) between the leg rows, ``height`` (4) of the ridge, ``leg_height``
    (2): straight legs up to there, then an arch (a half ellipse; a half circle when
    ``height - leg_height`` is ``width / 2``); a hoop every ``hoop_spacing`` (2) from end to end
    (the spacing is shrunk to fit a whole number), joined by a ridge pole and a pole along each leg
    row; every tube ``tube`` (0.05) thick. ``crop``: ``table_tops`` (default), ``ground_beds`` or
    ``none``; ``tables`` (4) rows of tables (or beds) across the tunnel, evenly spread (centres
    ``width / tables`` apart, the outer ones half that from the legs), ``table_width`` (0.4),
    ending ``end_gap`` (1.5) inside each end. A table-top: a trough 0.2 deep whose top is at
    ``table_height`` (1.1), on pairs of legs every ``leg_spacing`` (1.8); a ground bed: a bed of
    soil ``bed_height`` (0.2) high. Strawberry plants every ``plant_spacing`` (0.25) on both: balls
    of 0.3 ``table_width`` radius with their centres half a radius above the top, red berries
    hanging over the sides (drawn only). Frictions (0.5, 0, 0).
``walls``
    ``wall0``, ...: boxes standing on the ground: ``x``, ``y`` the centre, ``yaw`` (0) the
    direction the wall runs in, ``length``, ``height`` (2), ``thickness`` (0.2); ``rgba`` (concrete);
    frictions (0.8, 0, 0). The foot is at the lowest ground along the wall.
``height_field``
    one mapping: uneven ground replacing the ground plane (beyond its edges there is no ground);
    friction and colour are the ground's. ``x``, ``y`` (0) its centre, ``size_x``, ``size_y``.
    Either a grey-scale image, ``image`` (a PNG, 8 or 16 bits; colours are taken by luminance;
    relative paths from the world file's folder; its first row is the +y edge, as a map, and its
    pixels are the grid's points), black at ``min_height`` (0) and white at ``max_height`` (1); or a
    grid every ``resolution`` (0.2). Either way, added: random bumps up to ``amplitude`` (0) high
    and deep, ``feature_length`` (1) apart (value noise from ``seed`` (0)), and ruts along the
    field's x axis ``rut_depth`` (0) deep, ``rut_width`` (0.3) wide, every ``rut_spacing`` (1.5)
    across (the field's centre line is half-way between two ruts). Within ``flat_radius`` (2) of the
    origin, where robots spawn at z = 0 by default, the field is 0 (its grid points out to one
    cell's diagonal more), rising to full height over the next metre. Its grid points (an image's
    pixels) and noise lattice count against budgets (Limits). Patches, hills and rails stay at z = 0.
``description``
    free text.

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
============  ========  =====  ===============  ========  ==========================================

- ``lateral_friction`` is the tyre's peak grip, the friction coefficient of pybullet's Coulomb
  cone in every direction, from the middle of the published ranges: dry asphalt and concrete 0.7
  to 1.0 (tarmac 0.9 as this file's default ground, concrete a little smoother), loose gravel 0.5
  to 0.7, dry grass 0.45 to 0.65, wet grass 0.2 to 0.4, wet clay and mud 0.2 to 0.5, dry sand 0.4
  to 0.6, ice 0.05 to 0.15.
- ``rolling_friction`` [m] is pybullet's rolling resistance: a torque against the wheel's turning of
  this times the normal force, so it is the coefficient of rolling resistance C_rr times the wheel's
  radius. C_rr (the middle of the published ranges: tyres on asphalt 0.01 to 0.02, on concrete
  0.01 to 0.015, on gravel 0.02 to 0.08, on grass and firm field soil 0.05 to 0.1, on wet grass
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
each key's own rule: a rail's radius below its height and its gauge above two radii; an object has
its shape's dimensions and no other shape's, and its mesh file exists and is a mesh pybullet can
load (:mod:`thorvald_sim.mesh_check`: no junk, no STL without triangles or ASCII STL, no OBJ
without faces or with faces naming missing vertices); a sphere plant's height is
at least its radius; a tunnel's height is above its leg height, its end gaps leave the tables a
length, its tables leave aisles between them (``tables * table_width < width``) and its plants
stay under its roof; a height field with an image takes no ``resolution``, one without takes no
``min_height`` or ``max_height``, its ``max_height`` is above its ``min_height`` and its
``rut_width`` at most its ``rut_spacing``; a soft patch lies within 999 m of the origin in x and y;
neither the ground nor a patch is soft in a world with a height field.

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

Pure: no pybullet, no rospy, no messages (the scene is built by :mod:`thorvald_sim.scene`); the
plants' positions, the tunnels' geometry and the heights of the ground are computed here, so tests
check them without a physics engine.
"""

import functools
import glob
import math
import os
import random
import warnings
from dataclasses import dataclass, field, replace
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

from thorvald_model.errors import MISSING, ConfigError, Problem
from thorvald_model.resources import package_folder
from thorvald_model.schema import (
    NON_NEGATIVE,
    POSITIVE,
    Key,
    check_top_level,
    in_range,
    one_of,
    parse_entry,
    parse_scalar,
    parse_section,
    read_yaml_file,
)

from .mesh_check import mesh_problem

WHAT = "world"

# The package folder when this module runs from the source tree (or the devel space, which relays
# to it); in an install space the worlds are under share/thorvald_sim instead.
PACKAGE_DIR = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))

Rgba = Tuple[float, float, float, float]
Point = Tuple[float, float]

RGBA_TARMAC = (0.35, 0.35, 0.37, 1.0)
RGBA_WOOD = (0.60, 0.45, 0.28, 1.0)
RGBA_LEAF = (0.25, 0.55, 0.20, 1.0)
RGBA_CONCRETE = (0.75, 0.74, 0.70, 1.0)

PATCH_TOP = 0.001  # [m] above the ground plane: a patch's top
TABLE_DEPTH = 0.2  # [m] of a table-top's trough, below table_height
STRAWBERRY_RADIUS = 0.3  # of table_width: the foliage balls on a table or bed
ARCH_SEGMENTS = 16  # straight tubes of a hoop's arch (even: the ridge is a joint)
FLAT_BLEND = 1.0  # [m] over which a height field rises from its flat disc to full height

# Budgets of a world, checked at load before anything is made (the module's "Limits"): a typing
# mistake or a hostile file must be refused at once, not exhaust the memory or hang the loader. The
# figures in brackets were measured with pybullet 3.2.7 on one core.
MAX_REACH = 10_000.0  # [m] |x|, |y| of anything, and an object's |z|: a farm is at most 20 km across
MAX_LENGTH = 10_000.0  # [m] of any length, size, height or spacing
MAX_MESH_SCALE = 1000.0  # [-] a mesh drawn in km, or a scale typed in mm instead of m, is a mistake
MAX_PLANTS = 50_000  # over every rows and polytunnels entry (sphere plants: 2.6 GB, 14 s to build)
MAX_HOOPS = 2_000  # over every polytunnel (432 mesh vertices a hoop: 0.7 GB, 2.8 s)
MAX_TABLE_LEGS = 10_000  # pairs of table legs over every polytunnel (48 mesh vertices a pair)
MAX_BODIES = 2_000  # pybullet bodies (10 000 static boxes: 6.5 s to build, 17 ms a step)
MAX_HOLES = 50  # patches in a world with a soft one (50 overlapping: 7000 ground pieces, 2.6 s)
MAX_GROUND_LOOKUPS = 2_000_000  # points looking for the ground times what they search (1.6 to 5.5 s)
MAX_FIELD_POINTS = 1_000_000  # of a height field's grid, or pixels of its image (2 GB, 5 s)
MAX_NOISE_POINTS = 1_000_000  # of a height field's noise lattice (80 MB, 0.2 s)
MAX_IMAGE_BYTES = 32_000_000  # of a height field's image file (a 1000 x 1000 16-bit PNG is at most 2 MB)
MAX_MESH_BYTES = 32_000_000  # of the mesh files over every object (3 s to check; 0.6 to 1.4 GB in pybullet)
WALL_STEP = 0.5  # [m] between the points where a wall looks for the ground under it

SINKAGE_LOAD = 500.0  # [N] on a wheel: the load a surface's sinkage is given for (a 200 kg robot on 4 wheels)
SINKAGE_MASS = SINKAGE_LOAD / 9.81  # [kg] the reference load's mass, critically damped
MAX_SINKAGE = 0.05  # [m]: deeper, a wheel is stuck, not sinking "a little"
SOFT_DEPTH = 0.3  # [m] of a soft patch below its top: six times MAX_SINKAGE, so no wheel meets its bottom
GROUND_THICKNESS = 0.1  # [m] of the pieces of a ground with holes
GROUND_EXTENT = 1000.0  # [m] from the origin in x and y: a ground with holes ends there
SOFT_PATCH_REACH = GROUND_EXTENT - 1.0  # [m]: a soft patch's corners within this of the origin in x and y

RGBA_GRAVEL = (0.55, 0.48, 0.38, 1.0)
RGBA_ICE = (0.70, 0.85, 1.00, 1.0)


# ---------------------------------------------------------------------------------------------
# Value types (SI units: m, rad, kg, m/s^2)
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Surface:
    """pybullet's contact coefficients of one body.

    pybullet multiplies the lateral frictions of the two bodies in a contact, and combines rolling
    and spinning friction as ``a.rolling * b.lateral + b.rolling * a.lateral`` and restitution as
    the product; the simulator's wheels have lateral friction 1.0 and no rolling or spinning
    friction, so these are the effective values under a wheel. A soft surface (``sinkage`` above 0)
    is a spring and damper under each contact point (pybullet's contact stiffness and damping,
    which it puts in series with the other body's: the wheels have none, so rigid).
    """

    lateral_friction: float  # [-] Coulomb coefficient
    rolling_friction: float  # [m] pybullet's rolling resistance (torque per normal force)
    spinning_friction: float  # [m] resistance to turning about the contact normal
    restitution: float = 0.0  # [-] 0 (no bounce) .. 1
    sinkage: float = 0.0  # [m] of a contact point carrying SINKAGE_LOAD; 0 rigid
    kind: str = field(default="", compare=False)  # the surface kind it was made from ("" for none)

    @property
    def soft(self) -> bool:
        return self.sinkage > 0.0

    @property
    def contact_stiffness(self) -> float:
        """[N/m] of each contact point: SINKAGE_LOAD sinks it by ``sinkage`` (infinite when rigid)."""
        return SINKAGE_LOAD / self.sinkage if self.soft else math.inf

    @property
    def contact_damping(self) -> float:
        """[N s/m] of each contact point: critical for SINKAGE_MASS on the spring (0 when rigid)."""
        return 2.0 * math.sqrt(self.contact_stiffness * SINKAGE_MASS) if self.soft else 0.0


@dataclass(frozen=True)
class SurfaceKind:
    """A named kind of ground (``surface: mud``): its numbers and colour (see the module's table)."""

    lateral_friction: float  # [-]
    rolling_resistance: float  # [-] C_rr, the rolling resistance coefficient
    rolling_friction: float  # [m] C_rr times REFERENCE_WHEEL_RADIUS
    sinkage: float  # [m] under SINKAGE_LOAD
    rgba: Rgba
    what: str

    def surface(self, name: str) -> Surface:
        return Surface(self.lateral_friction, self.rolling_friction, 0.0, 0.0, self.sinkage, name)


REFERENCE_WHEEL_RADIUS = 0.2  # [m], Thorvald II's: rolling_friction = C_rr * this

# The module's table; rolling_friction is written out (C_rr * 0.2, checked by a test) so that the
# numbers are the table's to the last digit.
SURFACE_KINDS: Dict[str, SurfaceKind] = {
    "tarmac": SurfaceKind(0.9, 0.015, 0.003, 0.0, RGBA_TARMAC, "dry asphalt"),
    "concrete": SurfaceKind(0.85, 0.012, 0.0024, 0.0, RGBA_CONCRETE, "a dry concrete floor or yard"),
    "gravel": SurfaceKind(0.6, 0.05, 0.01, 0.0, RGBA_GRAVEL, "loose gravel on a firm base"),
    "grass": SurfaceKind(0.55, 0.06, 0.012, 0.004, (0.33, 0.55, 0.22, 1.0), "dry mown grass on firm soil"),
    "wet_grass": SurfaceKind(0.3, 0.08, 0.016, 0.008, (0.22, 0.45, 0.20, 1.0), "wet grass"),
    "mud": SurfaceKind(0.35, 0.2, 0.04, 0.015, (0.38, 0.28, 0.18, 1.0), "wet, soft soil"),
    "sand": SurfaceKind(0.5, 0.25, 0.05, 0.02, (0.82, 0.73, 0.52, 1.0), "dry loose sand"),
    "ice": SurfaceKind(0.1, 0.01, 0.002, 0.0, RGBA_ICE, "ice, or wet plastic sheeting"),
}


@dataclass(frozen=True)
class Patch:
    """A rectangle of another surface lying on the ground (its top 1 mm above the ground); a soft
    one is let into the ground (the ground has a hole under it)."""

    name: str
    index: int
    x: float  # [m] centre
    y: float  # [m]
    size_x: float  # [m] along the patch's own x axis
    size_y: float  # [m]
    yaw: float  # [rad] of the patch's x axis from the world's
    surface: Surface
    rgba: Optional[Rgba] = None  # the file's or its surface kind's; None: the scene's (gravel or ice)

    def contains(self, px: float, py: float) -> bool:
        """Whether the ground point (px, py) [m] lies on the patch (edges included)."""
        u, v = _to_local(px - self.x, py - self.y, self.yaw)
        return abs(u) <= self.size_x / 2 and abs(v) <= self.size_y / 2

    def corners(self) -> Tuple[Point, Point, Point, Point]:
        """[m] the four corners in the world, counter-clockwise from the patch's (-x, -y) corner."""
        hx, hy = self.size_x / 2, self.size_y / 2
        return tuple(_along(self.x, self.y, self.yaw, u, v) for u, v in ((-hx, -hy), (hx, -hy), (hx, hy), (-hx, hy)))


@dataclass(frozen=True)
class Slope:
    """A hill along its own x axis: ramp up at ``angle``, flat top, ramp down at ``angle``."""

    name: str
    index: int
    x: float  # [m] centre of the footprint
    y: float  # [m]
    yaw: float  # [rad] of the hill's x axis
    width: float  # [m] across the hill
    angle: float  # [rad] of both ramps
    height: float  # [m] of the top above the ground
    top_length: float  # [m] of the flat top along the hill
    surface: Surface

    @property
    def footprint_length(self) -> float:
        """[m] along the hill, ramps included."""
        return self.top_length + 2.0 * self.height / math.tan(self.angle)

    def height_at(self, px: float, py: float) -> Optional[float]:
        """[m] of the hill's surface over the ground point (px, py); None off its footprint."""
        u, v = _to_local(px - self.x, py - self.y, self.yaw)
        half = self.footprint_length / 2
        if abs(u) > half or abs(v) > self.width / 2:
            return None
        return min(self.height, (half - abs(u)) * math.tan(self.angle))


@dataclass(frozen=True)
class Rail:
    """A pair of parallel pipes lying above the ground (greenhouse heating pipes used as rails)."""

    name: str
    index: int
    x: float  # [m] between the pipes, middle of their length
    y: float  # [m]
    yaw: float  # [rad] direction the pipes run in
    length: float  # [m] of each pipe
    gauge: float  # [m] between the pipe centres
    height: float  # [m] of the pipe centres above the ground
    radius: float  # [m] of each pipe
    surface: Surface


@dataclass(frozen=True)
class WorldObject:
    """One body: a box, cylinder, sphere or mesh; static when its mass is 0.

    Only the shape's own dimensions are set; the others are 0 (``file`` empty).
    """

    name: str
    index: int
    shape: str  # box, cylinder, sphere or mesh
    x: float  # [m] of the centre (a mesh's origin) in the world
    y: float  # [m]
    z: float  # [m] in the world (the file's z is above the ground; this is resolved)
    roll: float  # [rad], pybullet's Euler angles: roll about x, then pitch about y, then yaw about z
    pitch: float  # [rad]
    yaw: float  # [rad]
    size_x: float  # [m] box
    size_y: float  # [m]
    size_z: float  # [m]
    radius: float  # [m] cylinder, sphere
    length: float  # [m] cylinder, along its own z
    file: str  # mesh: the absolute path of an OBJ or STL file
    scale: float  # [-] mesh
    mass: float  # [kg], 0 static
    rgba: Rgba
    surface: Surface

    @property
    def half_height(self) -> float:
        """[m] from the centre to the bottom, upright (a mesh's origin: 0)."""
        return {"box": self.size_z / 2, "cylinder": self.length / 2, "sphere": self.radius}.get(self.shape, 0.0)


@dataclass(frozen=True)
class Rows:
    """``count`` parallel crop rows of plants, from a few numbers (:func:`plant_positions`)."""

    name: str
    index: int
    x: float  # [m] start of the first row
    y: float  # [m]
    yaw: float  # [rad] direction the rows run in
    count: int  # rows
    spacing: float  # [m] between neighbouring rows, each to the left of the one before
    length: float  # [m] of each row
    plant: str  # cylinder or sphere
    plant_spacing: float  # [m] along a row
    plant_radius: float  # [m]
    plant_height: float  # [m] of the plant's top above the ground
    gap_probability: float  # [-] of each plant to be missing
    jitter: float  # [m] largest move of a plant along and across its row
    seed: int
    rgba: Rgba
    surface: Surface

    @property
    def plants_per_row(self) -> int:
        """Places for plants along a row, from its start to its end (both included)."""
        # a row of exactly k spacings ends with a plant, though floating point makes it 2.9999...
        return math.floor(self.length / self.plant_spacing + 1e-9) + 1

    def row_start(self, k: int) -> Point:
        """[m] the start of row k (0 the first)."""
        return _along(self.x, self.y, self.yaw, 0.0, k * self.spacing)


def plant_positions(rows: Rows) -> Tuple[Tuple[Point, ...], ...]:
    """The plants of each row, (x, y) [m] in the world, in order along the row; gaps left out.

    Row k's plant i sits at ``i * plant_spacing`` along the row and ``k * spacing`` to the left of
    the first row, moved by ``du``, ``dv`` drawn uniformly from [-jitter, jitter]. One generator,
    seeded by ``seed``, gives three numbers a place, row after row and place after place: whether the
    plant is missing, du, dv. They are drawn for missing plants too, so another gap probability takes
    plants away or puts them back without moving the others.
    """
    rng = random.Random(rows.seed)
    j = rows.jitter
    lines = []
    for k in range(rows.count):
        line = []
        for i in range(rows.plants_per_row):
            missing = rng.random() < rows.gap_probability
            du = rng.uniform(-j, j)
            dv = rng.uniform(-j, j)
            if not missing:
                line.append(_along(rows.x, rows.y, rows.yaw, i * rows.plant_spacing + du, k * rows.spacing + dv))
        lines.append(tuple(line))
    return tuple(lines)


@dataclass(frozen=True)
class Polytunnel:
    """A tunnel of hoops on legs, with table-tops (or ground beds) of strawberries inside.

    Its own frame: u along the tunnel from its centre, v across it (to the left), z up from its floor.
    """

    name: str
    index: int
    x: float  # [m] centre of the floor
    y: float  # [m]
    z: float  # [m] of the floor in the world: the ground height at the centre
    yaw: float  # [rad] direction the tunnel runs in
    length: float  # [m]
    width: float  # [m] between the leg rows (the centres of the legs)
    height: float  # [m] of the ridge (the centre of its pole) above the floor
    leg_height: float  # [m] where the straight legs end and the arch begins
    hoop_spacing: float  # [m] asked for; the hoops are length / round(length / hoop_spacing) apart
    tube: float  # [m] side of the square tubes
    crop: str  # table_tops, ground_beds or none
    tables: int  # rows of tables (or beds) across the tunnel
    table_height: float  # [m] of a table-top's top
    table_width: float  # [m]
    leg_spacing: float  # [m] asked for between a table's leg pairs (shrunk to fit, as the hoops)
    bed_height: float  # [m] of a ground bed
    end_gap: float  # [m] from each end of the tunnel to the ends of the tables
    plant_spacing: float  # [m] between strawberry plants along a table
    surface: Surface

    def to_world(self, u: float, v: float) -> Point:
        """The world point [m] of the tunnel point (u, v)."""
        return _along(self.x, self.y, self.yaw, u, v)

    def hoop_stations(self) -> Tuple[float, ...]:
        """u [m] of every hoop, from end to end."""
        return _stations(-self.length / 2, self.length / 2, self.hoop_spacing)

    def arch(self) -> Tuple[Point, ...]:
        """(v, z) [m] of the arch's joints from the left leg's top to the right one's, ridge included."""
        rise = self.height - self.leg_height
        points = []
        for i in range(ARCH_SEGMENTS + 1):
            a = math.pi * i / ARCH_SEGMENTS
            points.append((self.width / 2 * math.cos(a), self.leg_height + rise * math.sin(a)))
        return tuple(points)

    def roof_height(self, v: float) -> float:
        """[m] of the hoops' centre line above the floor at v (|v| <= width / 2), the arch as an ellipse."""
        s = min(1.0, abs(v) / (self.width / 2))
        return self.leg_height + (self.height - self.leg_height) * math.sqrt(1.0 - s * s)

    def table_offsets(self) -> Tuple[float, ...]:
        """v [m] of each table's (or bed's) centre line."""
        if self.crop == "none":
            return ()
        return tuple(self.table_offset(i) for i in range(self.tables))

    def table_offset(self, i: int) -> float:
        """v [m] of table i's centre line (0 the rightmost, at -v)."""
        return -self.width / 2 + self.width / self.tables * (i + 0.5)

    def table_span(self) -> Tuple[float, float]:
        """u [m] of the tables' ends."""
        return -self.length / 2 + self.end_gap, self.length / 2 - self.end_gap

    def table_leg_stations(self) -> Tuple[float, ...]:
        """u [m] of each pair of a table's legs (table-tops only)."""
        if self.crop != "table_tops":
            return ()
        return _stations(*self.table_span(), self.leg_spacing)

    def plant_stations(self) -> Tuple[float, ...]:
        """u [m] of the strawberry plants along each table or bed, half a spacing in from its ends."""
        if self.crop == "none":
            return ()
        start, end = self.table_span()
        n = math.floor((end - start) / self.plant_spacing + 1e-9)
        return tuple(start + self.plant_spacing * (i + 0.5) for i in range(n))

    @property
    def crop_top(self) -> float:
        """[m] above the floor of a table's top or a bed's."""
        return self.table_height if self.crop == "table_tops" else self.bed_height

    @property
    def plant_radius(self) -> float:
        """[m] of a strawberry plant's foliage ball."""
        return STRAWBERRY_RADIUS * self.table_width

    @property
    def plant_top(self) -> float:
        """[m] above the floor of a strawberry plant's top: its centre is half a radius above the table."""
        return self.crop_top + 1.5 * self.plant_radius


@dataclass(frozen=True)
class Wall:
    """A box standing on the ground."""

    name: str
    index: int
    x: float  # [m] centre
    y: float  # [m]
    z: float  # [m] of its foot in the world: the lowest ground along it
    yaw: float  # [rad] direction the wall runs in
    length: float  # [m]
    height: float  # [m]
    thickness: float  # [m]
    rgba: Rgba
    surface: Surface


@dataclass(frozen=True)
class HeightField:
    """Uneven ground on a regular grid: an image's grey levels, bumps and ruts (:meth:`heights`)."""

    x: float  # [m] centre
    y: float  # [m]
    size_x: float  # [m]
    size_y: float  # [m]
    resolution: float  # [m] asked for between grid points (0 with an image: its pixels are the grid)
    image: str  # absolute path, or ""
    min_height: float  # [m] of black
    max_height: float  # [m] of white
    amplitude: float  # [m] of the bumps, up and down
    feature_length: float  # [m] between the bumps' random heights
    seed: int
    rut_depth: float  # [m]
    rut_width: float  # [m]
    rut_spacing: float  # [m] between neighbouring ruts' centre lines
    flat_radius: float  # [m] around the world's origin where the field is 0

    def grid_shape(self) -> Tuple[int, int]:
        """(nx, ny): grid points along x and along y."""
        if self.image:
            ny, nx = self._levels.shape
            return nx, ny
        return _points(self.size_x, self.resolution), _points(self.size_y, self.resolution)

    def grid_step(self) -> Tuple[float, float]:
        """[m] between grid points along x and along y (the resolution, shrunk to fit the size)."""
        nx, ny = self.grid_shape()
        return self.size_x / (nx - 1), self.size_y / (ny - 1)

    def heights(self):
        """The grid's heights [m] (a read-only numpy array ny x nx; row 0 is the -y edge, column 0 the -x edge)."""
        return self._heights

    # Made once per field (a frozen dataclass keeps a cached_property in its __dict__, outside its
    # fields): the image is read again by the next load of the world, so an edited image counts.
    @functools.cached_property
    def _levels(self):
        return _image_levels(self.image)

    @functools.cached_property
    def _heights(self):
        return _field_heights(self)

    def height_at(self, px: float, py: float) -> Optional[float]:
        """[m] of the surface at (px, py), as bullet draws it between the grid points; None off the field.

        bullet's height field splits each cell into two triangles along the diagonal from its
        (+x, -y) corner to its (-x, +y) corner, and is flat on each.
        """
        nx, ny = self.grid_shape()
        dx, dy = self.grid_step()
        u = (px - (self.x - self.size_x / 2)) / dx
        v = (py - (self.y - self.size_y / 2)) / dy
        if not (-1e-9 <= u <= nx - 1 + 1e-9 and -1e-9 <= v <= ny - 1 + 1e-9):
            return None
        i, j = min(max(math.floor(u), 0), nx - 2), min(max(math.floor(v), 0), ny - 2)
        fu, fv = u - i, v - j
        h = self.heights()
        h00, h10, h01, h11 = h[j, i], h[j, i + 1], h[j + 1, i], h[j + 1, i + 1]
        if fu + fv <= 1.0:
            return float(h00 + fu * (h10 - h00) + fv * (h01 - h00))
        return float(h11 + (1.0 - fu) * (h01 - h11) + (1.0 - fv) * (h10 - h11))


@dataclass(frozen=True)
class WorldConfig:
    """A validated world file."""

    source: str  # file name, or what the data came from
    gravity: float  # [m/s^2], pointing down
    ground: Surface
    patches: Tuple[Patch, ...]
    slopes: Tuple[Slope, ...]
    rails: Tuple[Rail, ...]
    description: str = ""
    objects: Tuple[WorldObject, ...] = ()
    rows: Tuple[Rows, ...] = ()
    polytunnels: Tuple[Polytunnel, ...] = ()
    walls: Tuple[Wall, ...] = ()
    height_field: Optional[HeightField] = None
    ground_rgba: Rgba = RGBA_TARMAC

    def ground_height(self, px: float, py: float) -> float:
        """[m] of the ground's surface at (px, py): the height field (0 off it, or without one), the
        hills and the patches' tops, whichever is highest (not rails, objects, plants or tunnels).
        A soft surface's top, before anything sinks into it."""
        return _ground_height(self.height_field, self.slopes, self.patches, px, py)

    @property
    def soft_patches(self) -> Tuple[Patch, ...]:
        """The soft patches; with any, the ground has a hole under every patch."""
        return tuple(pa for pa in self.patches if pa.surface.soft)


def _ground_height(
    height_field: Optional[HeightField], slopes: Sequence[Slope], patches: Sequence[Patch], px: float, py: float
) -> float:
    z = 0.0
    if height_field is not None:
        z = height_field.height_at(px, py) or 0.0
    for slope in slopes:
        z = max(z, slope.height_at(px, py) or 0.0)
    if any(patch.contains(px, py) for patch in patches):
        z = max(z, PATCH_TOP)
    return z


def ground_pieces(holes: Sequence[Sequence[Point]], extent: float = GROUND_EXTENT) -> List[Tuple[Point, ...]]:
    """Convex pieces (3 or 4 corners [m], counter-clockwise) that tile the square ``|x|, |y| <=
    extent`` but for the holes (convex polygons, counter-clockwise, inside the square; they may
    overlap).

    Around the holes' bounding box, four pieces turned like a pinwheel (so their seams are four
    rays from its corners); within it, a vertical-slab (trapezoidal) decomposition: the box is cut
    at the x of every corner of a hole and of every crossing of two holes' edges. Within a slab no
    edge ends or crosses another, so each hole is a band between two straight lines there, and the
    ground between the bands (merged where they overlap) a trapezoid each, or a triangle where two
    lines meet at the slab's side. Cuts closer than SNAP are one (a sliver under a tenth of a
    millimetre wide is no ground a wheel can find), and a piece thinner than SNAP all along is left
    out.
    """
    e = extent
    if not holes:
        return [((-e, -e), (e, -e), (e, e), (-e, e))]
    x0, x1 = min(x for hole in holes for x, _ in hole), max(x for hole in holes for x, _ in hole)
    y0, y1 = min(y for hole in holes for _, y in hole), max(y for hole in holes for _, y in hole)
    outside = [
        ((-e, -e), (x0, -e), (x0, y1), (-e, y1)),  # left, below the top
        ((-e, y1), (x1, y1), (x1, e), (-e, e)),  # top, left of the right
        ((x1, y0), (e, y0), (e, e), (x1, e)),  # right, above the bottom
        ((x0, -e), (e, -e), (e, y0), (x0, y0)),  # bottom, right of the left
    ]
    pieces = [q for q in outside if q[1][0] - q[0][0] > SNAP and q[3][1] - q[0][1] > SNAP]
    return pieces + _slab_pieces(holes, x0, x1, y0, y1)


def _slab_pieces(
    holes: Sequence[Sequence[Point]], x0: float, x1: float, y0: float, y1: float
) -> List[Tuple[Point, ...]]:
    """ground_pieces' trapezoids within the box from (x0, y0) to (x1, y1)."""
    xs = {x0, x1}
    edges = [_edges(hole) for hole in holes]
    for hole in holes:
        xs.update(x for x, _ in hole)
    for i in range(len(edges)):
        for j in range(i + 1, len(edges)):
            for a in edges[i]:
                for b in edges[j]:
                    x = _crossing_x(a, b)
                    if x is not None:
                        xs.add(x)
    cuts: List[float] = []
    for x in sorted(xs):
        if not cuts or x - cuts[-1] > SNAP:
            cuts.append(x)
    cuts[-1] = x1
    pieces: List[Tuple[Point, ...]] = []
    bottom, top = ((x0, y0), (x1, y0)), ((x0, y1), (x1, y1))
    for xa, xb in zip(cuts, cuts[1:]):
        xm = (xa + xb) / 2
        bands = []
        for hole_edges in edges:
            crossing = [e for e in hole_edges if min(e[0][0], e[1][0]) < xm < max(e[0][0], e[1][0])]
            if len(crossing) == 2:
                low, high = sorted(crossing, key=lambda e: _line_y(e, xm))
                bands.append([low, high])
        bands.sort(key=lambda band: _line_y(band[0], xm))
        merged: List[List[Tuple[Point, Point]]] = []
        for band in bands:
            if merged and _line_y(band[0], xm) <= _line_y(merged[-1][1], xm):
                if _line_y(band[1], xm) > _line_y(merged[-1][1], xm):
                    merged[-1][1] = band[1]
            else:
                merged.append(band)
        lows = [bottom] + [band[1] for band in merged]
        highs = [band[0] for band in merged] + [top]
        for low, high in zip(lows, highs):
            corners = [(xa, _line_y(low, xa)), (xb, _line_y(low, xb)), (xb, _line_y(high, xb)), (xa, _line_y(high, xa))]
            if corners[2][1] - corners[1][1] <= SNAP and corners[3][1] - corners[0][1] <= SNAP:
                continue
            if corners[2][1] - corners[1][1] <= SNAP:
                del corners[2]
            elif corners[3][1] - corners[0][1] <= SNAP:
                del corners[3]
            pieces.append(tuple(corners))
    return pieces


SNAP = 1e-4  # [m]: ground_pieces' cuts closer than this are one


def _edges(polygon: Sequence[Point]) -> List[Tuple[Point, Point]]:
    return [(polygon[i], polygon[(i + 1) % len(polygon)]) for i in range(len(polygon))]


def _line_y(edge: Tuple[Point, Point], x: float) -> float:
    """y [m] of the edge's line at x (the edge is not vertical)."""
    (x1, y1), (x2, y2) = edge
    return y1 + (y2 - y1) * (x - x1) / (x2 - x1)


def _crossing_x(a: Tuple[Point, Point], b: Tuple[Point, Point]) -> Optional[float]:
    """x [m] where two edges cross each other inside both; None if they do not (or are parallel)."""
    (x1, y1), (x2, y2) = a
    (x3, y3), (x4, y4) = b
    d = (x2 - x1) * (y4 - y3) - (y2 - y1) * (x4 - x3)
    if abs(d) < 1e-12:
        return None
    t = ((x3 - x1) * (y4 - y3) - (y3 - y1) * (x4 - x3)) / d
    u = ((x3 - x1) * (y2 - y1) - (y3 - y1) * (x2 - x1)) / d
    if 0.0 < t < 1.0 and 0.0 < u < 1.0:
        return x1 + t * (x2 - x1)
    return None


def _to_local(dx: float, dy: float, yaw: float) -> Tuple[float, float]:
    c, s = math.cos(yaw), math.sin(yaw)
    return c * dx + s * dy, -s * dx + c * dy


def _along(x: float, y: float, yaw: float, u: float, v: float) -> Point:
    """The world point of (u, v) in a frame at (x, y) turned by yaw."""
    c, s = math.cos(yaw), math.sin(yaw)
    return x + c * u - s * v, y + s * u + c * v


def _stations(start: float, end: float, spacing: float) -> Tuple[float, ...]:
    """Evenly spread points from start to end (both included), as near ``spacing`` apart as fits."""
    n = max(1, round((end - start) / spacing))
    return tuple(start + (end - start) * k / n for k in range(n + 1))


def _points(size: float, resolution: float) -> int:
    return max(2, round(size / resolution) + 1)


# ---------------------------------------------------------------------------------------------
# Height fields (numpy and PIL are imported when a field is made: importing this module stays cheap)
# ---------------------------------------------------------------------------------------------
def _image_levels(path: str):
    """The image's grey levels in [0, 1] (numpy, rows from the -y edge); ValueError if it cannot be read."""
    import numpy as np  # noqa: PLC0415
    from PIL import Image, UnidentifiedImageError  # noqa: PLC0415

    try:
        with Image.open(path) as image:
            image.load()
            if image.mode in ("I;16", "I;16L", "I;16B", "I"):
                levels = np.asarray(image, dtype=np.float64) / 65535.0
            else:
                levels = np.asarray(image.convert("L"), dtype=np.float64) / 255.0
    except (OSError, UnidentifiedImageError) as e:
        raise ValueError(f"cannot read the image: {e}") from None
    if levels.ndim != 2 or min(levels.shape) < 2:
        raise ValueError(f"must be an image of at least 2 x 2 pixels, not {levels.shape[::-1]}")
    levels = np.clip(np.flipud(levels), 0.0, 1.0)  # the image's first row is the +y edge
    levels.setflags(write=False)
    return levels


def _field_heights(hf: HeightField):
    import numpy as np  # noqa: PLC0415

    nx, ny = hf.grid_shape()
    xs = np.linspace(-hf.size_x / 2, hf.size_x / 2, nx)  # from the field's centre
    ys = np.linspace(-hf.size_y / 2, hf.size_y / 2, ny)
    gx, gy = np.meshgrid(xs, ys)
    h = np.zeros((ny, nx))
    if hf.image:
        h += hf.min_height + (hf.max_height - hf.min_height) * hf._levels
    if hf.amplitude > 0:
        h += hf.amplitude * _value_noise(gx / hf.feature_length, gy / hf.feature_length, hf.seed)
    if hf.rut_depth > 0:
        # distance from the nearest rut's centre line; ruts at (k + 1/2) rut_spacing across the field
        d = np.abs((gy / hf.rut_spacing) % 1.0 - 0.5) * hf.rut_spacing
        h -= np.where(d < hf.rut_width / 2, hf.rut_depth * 0.5 * (1 + np.cos(2 * np.pi * d / hf.rut_width)), 0.0)
    if hf.flat_radius > 0:
        # every grid point within a cell's diagonal beyond the radius is 0 too, so that each triangle
        # over the disc is flat at 0, not just its points
        r = np.hypot(gx + hf.x, gy + hf.y) - math.hypot(*hf.grid_step())
        h *= _smoothstep((r - hf.flat_radius) / FLAT_BLEND)
    h.setflags(write=False)
    return h


def _value_noise(u, v, seed: int):
    """Smooth noise in [-1, 1] at lattice coordinates (u, v) (numpy arrays): random values at the
    integer points, from one generator seeded by seed in row order over the lattice around (u, v),
    blended with the smoothstep (continuous slopes, flat at the lattice points)."""
    import numpy as np  # noqa: PLC0415

    i0, j0 = int(np.floor(u.min())), int(np.floor(v.min()))
    ni, nj = int(np.floor(u.max())) - i0 + 2, int(np.floor(v.max())) - j0 + 2
    rng = random.Random(seed)
    lattice = np.array([[rng.uniform(-1.0, 1.0) for _ in range(ni)] for _ in range(nj)])
    iu, jv = np.floor(u).astype(int) - i0, np.floor(v).astype(int) - j0
    iu, jv = np.minimum(iu, ni - 2), np.minimum(jv, nj - 2)
    su, sv = _smoothstep(u - i0 - iu), _smoothstep(v - j0 - jv)
    a = lattice[jv, iu] + su * (lattice[jv, iu + 1] - lattice[jv, iu])
    b = lattice[jv + 1, iu] + su * (lattice[jv + 1, iu + 1] - lattice[jv + 1, iu])
    return a + sv * (b - a)


def _smoothstep(t):
    import numpy as np  # noqa: PLC0415

    t = np.clip(t, 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


# ---------------------------------------------------------------------------------------------
# Schema
# ---------------------------------------------------------------------------------------------
GRAVITY_KEY = Key("gravity", float, 9.81, **POSITIVE)
DESCRIPTION_KEY = Key("description", str, "")

# rgba is a list, which the schema's keys do not take: it is checked apart (_take_colours) and stands
# in the entry as an empty string, so that its key is known (for "did you mean") and given once.
RGBA_KEY = Key("rgba", str, "")
RGBA_RULE = "must be a list of 3 or 4 numbers in [0, 1] (red, green, blue, alpha)"


def _frictions(lateral: float) -> Tuple[Key, ...]:
    return (
        Key("lateral_friction", float, lateral, **NON_NEGATIVE),
        Key("rolling_friction", float, 0.0, **NON_NEGATIVE),
        Key("spinning_friction", float, 0.0, **NON_NEGATIVE),
    )


UNIT_RANGE = dict(check=in_range(0.0, 1.0), rule="must be in [0, 1]")

# Every length and position is bounded (MAX_LENGTH, MAX_REACH): the numbers made from them (plants,
# hoops, grid points) are then finite floats, and a count is checked before anything is made.
LENGTH = dict(check=lambda v: 0.0 < v <= MAX_LENGTH, rule=f"must be in (0, {MAX_LENGTH:g}] [m]")
LENGTH_OR_ZERO = dict(check=in_range(0.0, MAX_LENGTH), rule=f"must be in [0, {MAX_LENGTH:g}] [m]")
HEIGHT = dict(check=in_range(-MAX_LENGTH, MAX_LENGTH), rule=f"must be in [-{MAX_LENGTH:g}, {MAX_LENGTH:g}] [m]")
COORDINATE = dict(check=in_range(-MAX_REACH, MAX_REACH), rule=f"must be in [-{MAX_REACH:g}, {MAX_REACH:g}] [m]")
OPTIONAL_LENGTH = dict(default=None, **LENGTH)  # a key a cross-field rule requires or refuses

KINDS_RULE = "must be one of " + ", ".join(SURFACE_KINDS)
SINKAGE_RULE = f"must be in [0, {MAX_SINKAGE}] [m]"

# The ground's and the patches' surface keys default to None: a key not in the file takes its
# surface kind's number (_surface_of), or else the default in SURFACE_DEFAULTS.
SURFACE_KEYS = (
    Key("surface", str, None, check=one_of(*SURFACE_KINDS), rule=KINDS_RULE),
    Key("lateral_friction", float, None, **NON_NEGATIVE),
    Key("rolling_friction", float, None, **NON_NEGATIVE),
    Key("spinning_friction", float, None, **NON_NEGATIVE),
    Key("sinkage", float, None, check=in_range(0.0, MAX_SINKAGE), rule=SINKAGE_RULE),
)
SURFACE_DEFAULTS = {"rolling_friction": 0.0, "spinning_friction": 0.0, "sinkage": 0.0}
ZERO_HINT = "write sinkage: 0 beside a soft surface kind"

GROUND_KEYS = (*SURFACE_KEYS, Key("restitution", float, 0.0, **UNIT_RANGE), RGBA_KEY)
GROUND_DEFAULTS = {**SURFACE_DEFAULTS, "lateral_friction": 0.9}

PATCH_KEYS = (
    Key("x", float, **COORDINATE),
    Key("y", float, **COORDINATE),
    Key("size_x", float, **LENGTH),
    Key("size_y", float, **LENGTH),
    Key("yaw", float, 0.0),
    *SURFACE_KEYS,
    RGBA_KEY,
)

MAX_SLOPE_ANGLE = 1.2  # [rad], about 69 degrees: steeper is a wall, and tan() grows without bound

SLOPE_KEYS = (
    Key("x", float, **COORDINATE),
    Key("y", float, **COORDINATE),
    Key("yaw", float, 0.0),
    Key("width", float, **LENGTH),
    Key("angle", float, check=lambda v: 0.0 < v <= MAX_SLOPE_ANGLE, rule=f"must be in (0, {MAX_SLOPE_ANGLE}] [rad]"),
    Key("height", float, **LENGTH),
    Key("top_length", float, 0.0, **LENGTH_OR_ZERO),
    *_frictions(0.9),
)

RAIL_KEYS = (
    Key("x", float, **COORDINATE),
    Key("y", float, **COORDINATE),
    Key("yaw", float, 0.0),
    Key("length", float, **LENGTH),
    Key("gauge", float, 0.55, **LENGTH),
    Key("height", float, 0.1, **LENGTH),
    Key("radius", float, 0.0255, **LENGTH),  # 51 mm pipes, the common greenhouse size
    *_frictions(0.8),
)

SHAPES = ("box", "cylinder", "sphere", "mesh")
# the keys of each shape's dimensions: required for it, refused for the others
SHAPE_KEYS = {
    "box": ("size_x", "size_y", "size_z"),
    "cylinder": ("radius", "length"),
    "sphere": ("radius",),
    "mesh": ("file", "scale"),
}
MESH_EXTENSIONS = (".obj", ".stl")

OBJECT_KEYS = (
    Key("shape", str, check=one_of(*SHAPES), rule="must be one of " + ", ".join(SHAPES)),
    Key("x", float, **COORDINATE),
    Key("y", float, **COORDINATE),
    Key("z", float, None, **COORDINATE),
    Key("roll", float, 0.0),
    Key("pitch", float, 0.0),
    Key("yaw", float, 0.0),
    Key("size_x", float, **OPTIONAL_LENGTH),
    Key("size_y", float, **OPTIONAL_LENGTH),
    Key("size_z", float, **OPTIONAL_LENGTH),
    Key("radius", float, **OPTIONAL_LENGTH),
    Key("length", float, **OPTIONAL_LENGTH),
    Key("file", str, None, check=bool, rule="must not be empty"),
    Key("scale", float, None, check=lambda v: 0.0 < v <= MAX_MESH_SCALE, rule=f"must be in (0, {MAX_MESH_SCALE:g}]"),
    Key("mass", float, 0.0, **NON_NEGATIVE),
    RGBA_KEY,
    *_frictions(0.8),
    Key("restitution", float, 0.0, **UNIT_RANGE),
)

PLANTS = ("cylinder", "sphere")

ROWS_KEYS = (
    Key("x", float, **COORDINATE),
    Key("y", float, **COORDINATE),
    Key("yaw", float, 0.0),
    Key("count", int, 1, **POSITIVE),
    Key("spacing", float, 0.75, **LENGTH),
    Key("length", float, **LENGTH),
    Key("plant", str, "cylinder", one_of(*PLANTS), "must be one of " + ", ".join(PLANTS)),
    Key("plant_spacing", float, 0.3, **LENGTH),
    Key("plant_radius", float, 0.1, **LENGTH),
    Key("plant_height", float, 0.4, **LENGTH),
    Key("gap_probability", float, 0.0, aliases=("gaps",), **UNIT_RANGE),
    Key("jitter", float, 0.0, **LENGTH_OR_ZERO),
    Key("seed", int, 0),
    RGBA_KEY,
    *_frictions(0.5),
)

CROPS = ("table_tops", "ground_beds", "none")

POLYTUNNEL_KEYS = (
    Key("x", float, **COORDINATE),
    Key("y", float, **COORDINATE),
    Key("yaw", float, 0.0),
    Key("length", float, **LENGTH),
    Key("width", float, 8.0, **LENGTH),
    Key("height", float, 4.0, **LENGTH),
    Key("leg_height", float, 2.0, **LENGTH_OR_ZERO),
    Key("hoop_spacing", float, 2.0, **LENGTH),
    Key("tube", float, 0.05, **LENGTH),
    Key("crop", str, "table_tops", one_of(*CROPS), "must be one of " + ", ".join(CROPS)),
    Key("tables", int, 4, **POSITIVE),
    Key(
        "table_height",
        float,
        1.1,
        check=lambda v: TABLE_DEPTH < v <= MAX_LENGTH,
        rule=f"must be in ({TABLE_DEPTH}, {MAX_LENGTH:g}] [m] (above the trough's depth)",
    ),
    Key("table_width", float, 0.4, **LENGTH),
    Key("leg_spacing", float, 1.8, **LENGTH),
    Key("bed_height", float, 0.2, **LENGTH),
    Key("end_gap", float, 1.5, **LENGTH_OR_ZERO),
    Key("plant_spacing", float, 0.25, **LENGTH),
    *_frictions(0.5),
)

WALL_KEYS = (
    Key("x", float, **COORDINATE),
    Key("y", float, **COORDINATE),
    Key("yaw", float, 0.0),
    Key("length", float, **LENGTH),
    Key("height", float, 2.0, **LENGTH),
    Key("thickness", float, 0.2, **LENGTH),
    RGBA_KEY,
    *_frictions(0.8),
)

HEIGHT_FIELD_KEYS = (
    Key("x", float, 0.0, **COORDINATE),
    Key("y", float, 0.0, **COORDINATE),
    Key("size_x", float, **LENGTH),
    Key("size_y", float, **LENGTH),
    Key("resolution", float, **OPTIONAL_LENGTH),
    Key("image", str, None, check=bool, rule="must not be empty"),
    Key("min_height", float, None, **HEIGHT),
    Key("max_height", float, None, **HEIGHT),
    Key("amplitude", float, 0.0, **LENGTH_OR_ZERO),
    Key("feature_length", float, 1.0, **LENGTH),
    Key("seed", int, 0),
    Key("rut_depth", float, 0.0, **LENGTH_OR_ZERO),
    Key("rut_width", float, 0.3, **LENGTH),
    Key("rut_spacing", float, 1.5, **LENGTH),
    Key("flat_radius", float, 2.0, **LENGTH_OR_ZERO),
)

# (top-level key, entry prefix, keys); built in this order, the scene too
SECTIONS = (
    ("patches", "patch", PATCH_KEYS),
    ("slopes", "slope", SLOPE_KEYS),
    ("rails", "rail", RAIL_KEYS),
    ("objects", "object", OBJECT_KEYS),
    ("rows", "row", ROWS_KEYS),
    ("polytunnels", "polytunnel", POLYTUNNEL_KEYS),
    ("walls", "wall", WALL_KEYS),
)
TOP_LEVEL_KEYS = ("gravity", "ground", "height_field", *(key for key, _, _ in SECTIONS), "description")


# ---------------------------------------------------------------------------------------------
# Loading
# ---------------------------------------------------------------------------------------------
def load_world(path: str) -> WorldConfig:
    """Loads and validates a world file; raises ConfigError naming every problem.

    A file that cannot be read at all (missing, a directory, not text, not YAML) raises a
    ConfigError with one problem at the top level, which formats as one line. Relative paths in
    the file (meshes, images) are from the file's folder.
    """
    return parse_world(read_yaml_file(path, WHAT), path, os.path.dirname(os.path.abspath(path)))


def parse_world(data: Any, source: str = "<world>", base_dir: Optional[str] = None) -> WorldConfig:
    """Validates an already parsed world (a YAML document or a ROS parameter tree).

    base_dir: the folder relative paths (meshes, images) are taken from; default the current one.
    """
    base_dir = os.path.abspath(base_dir or os.getcwd())
    problems: List[Problem] = []
    data = check_top_level(data, TOP_LEVEL_KEYS, problems, source=source, what=WHAT)

    # The two scalar keys go through parse_entry as a one-key entry each, so they get the same
    # coercion and rules as every other key; their paths are the bare key names.
    gravity = parse_scalar(data, GRAVITY_KEY, problems)
    description = parse_scalar(data, DESCRIPTION_KEY, problems)

    # A missing ground, or an empty ``ground:`` (YAML null), means every default, as for sections.
    raw_ground = data.get("ground")
    raw_ground = {} if raw_ground is None else raw_ground
    raw_ground, ground_colour = _take_colour(raw_ground, "ground", None, problems)
    ground_values = parse_entry(raw_ground, "ground", GROUND_KEYS, problems)
    if ground_values is None:
        ground_values = {k.name: k.default for k in GROUND_KEYS}
    ground = _surface_of(ground_values, GROUND_DEFAULTS)
    ground_colour = ground_colour or _kind_colour(ground) or RGBA_TARMAC

    height_field = None
    if data.get("height_field") is not None:
        height_field = _height_field(data["height_field"], base_dir, problems)

    entries: Dict[str, List[Tuple[str, int, dict, Mapping]]] = {}
    for key, prefix, keys in SECTIONS:
        raw, colours = data.get(key), {}
        if RGBA_KEY in keys:
            raw, colours = _take_colours(raw, key, problems)
        parsed = parse_section(raw, key, prefix, keys, problems)
        entries[key] = [(name, index, values, _raw_entry(data.get(key), name)) for name, index, values in parsed]
        for name, _, values, _ in entries[key]:
            if RGBA_KEY in keys:
                values["rgba"] = colours.get(name)

    problems.extend(_missing_lateral_friction(data.get("patches")))
    patches = tuple(_patch(name, index, v) for name, index, v, _ in entries["patches"])
    problems.extend(_soft_patch_problems(patches, height_field is not None))
    if height_field is not None and ground.soft:
        rule = f"must be 0 with a height_field ({ZERO_HINT}): bullet touches a wheel at 1 to 4 of its triangles"
        problems.append(Problem("ground.sinkage", ground.sinkage, rule))
    slopes = tuple(_slope(name, index, v) for name, index, v, _ in entries["slopes"])
    rails = tuple(_rail(name, index, v) for name, index, v, _ in entries["rails"])
    problems.extend(_rail_problems(rails, problems))

    # The budgets before anything that grows with them is made. A world over them is refused
    # anyway: its objects, tunnels and walls take the plane's height, without a search.
    over = _budget_problems(entries, problems)

    def ground_at(px: float, py: float) -> float:
        return 0.0 if over else _ground_height(height_field, slopes, patches, px, py)

    meshes: List[Tuple[str, str, str]] = []
    objects = tuple(
        _object(name, index, v, raw, base_dir=base_dir, ground_at=ground_at, problems=problems, meshes=meshes)
        for name, index, v, raw in entries["objects"]
    )
    _mesh_problems(meshes, problems)
    rows = tuple(_rows(name, index, v, problems) for name, index, v, _ in entries["rows"])
    polytunnels = tuple(
        _polytunnel(name, index, v, ground_at, problems) for name, index, v, _ in entries["polytunnels"]
    )
    walls = tuple(_wall(name, index, v, ground_at, sample=not over) for name, index, v, _ in entries["walls"])

    if problems:
        raise ConfigError(source, problems, WHAT)
    return WorldConfig(
        source=source,
        gravity=gravity,
        ground=ground,
        patches=patches,
        slopes=slopes,
        rails=rails,
        description=description,
        objects=objects,
        rows=rows,
        polytunnels=polytunnels,
        walls=walls,
        height_field=height_field,
        ground_rgba=ground_colour,
    )


def _raw_entry(section: Any, name: str) -> Mapping:
    entry = section.get(name) if isinstance(section, Mapping) else None
    return entry if isinstance(entry, Mapping) else {}


def _colour(value: Any) -> Optional[Rgba]:
    """The colour a list of 3 or 4 numbers in [0, 1] gives (alpha 1 if left out); None if it is not one."""
    if not isinstance(value, (list, tuple)) or len(value) not in (3, 4):
        return None
    numbers = []
    for v in value:
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not 0.0 <= v <= 1.0:
            return None
        numbers.append(float(v))
    return (*numbers, 1.0) if len(numbers) == 3 else tuple(numbers)


def _take_colour(entry: Any, path: str, default: Rgba, problems: List[Problem]) -> Tuple[Any, Rgba]:
    """The entry with its rgba, checked here, replaced by "" for parse_entry, and the colour."""
    if not isinstance(entry, Mapping) or "rgba" not in entry:
        return entry, default
    colour = _colour(entry["rgba"])
    if colour is None:
        problems.append(Problem(f"{path}.rgba", entry["rgba"], RGBA_RULE))
    return {**entry, "rgba": ""}, colour or default


def _take_colours(section: Any, key: str, problems: List[Problem]) -> Tuple[Any, Dict[str, Optional[Rgba]]]:
    """The section with each entry's rgba taken out (as :func:`_take_colour`), and the colours by entry."""
    if not isinstance(section, Mapping):
        return section, {}
    clean, colours = {}, {}
    for name, entry in section.items():
        clean[name], colour = _take_colour(entry, f"{key}.{name}", None, problems)
        colours[str(name)] = colour
    return clean, colours


def _surface(values: Mapping) -> Surface:
    return Surface(
        values["lateral_friction"],
        values["rolling_friction"],
        values["spinning_friction"],
        values.get("restitution", 0.0),
    )


def _surface_of(v: Mapping, defaults: Mapping) -> Surface:
    """The surface of an entry with SURFACE_KEYS: each number the file's, else its kind's, else the
    default (0 for a key missing from defaults: :func:`_missing_lateral_friction` reports it)."""
    kind = SURFACE_KINDS.get(v["surface"])
    base = kind.surface(v["surface"]) if kind else None
    numbers = {}
    for name in ("lateral_friction", "rolling_friction", "spinning_friction", "sinkage"):
        if v[name] is not None:
            numbers[name] = v[name]
        elif base is not None:
            numbers[name] = getattr(base, name)
        else:
            numbers[name] = defaults.get(name, 0.0)
    return Surface(
        numbers["lateral_friction"],
        numbers["rolling_friction"],
        numbers["spinning_friction"],
        v.get("restitution", 0.0),
        numbers["sinkage"],
        v["surface"] or "",
    )


def _kind_colour(surface: Surface) -> Optional[Rgba]:
    kind = SURFACE_KINDS.get(surface.kind)
    return kind.rgba if kind else None


def _patch(name: str, index: int, v: Mapping) -> Patch:
    surface = _surface_of(v, SURFACE_DEFAULTS)
    colour = v["rgba"] or _kind_colour(surface)
    return Patch(name, index, v["x"], v["y"], v["size_x"], v["size_y"], v["yaw"], surface, colour)


def _missing_lateral_friction(section: Any) -> List[Problem]:
    """A patch's lateral friction is required unless it names a surface kind (reported as parse_entry
    reports a required key: beside the entry's other problems, even when they drop the entry)."""
    if not isinstance(section, Mapping):
        return []
    return [
        Problem(f"patches.{name}.lateral_friction", MISSING, "is required")
        for name, entry in section.items()
        if isinstance(entry, Mapping) and "lateral_friction" not in entry and "surface" not in entry
    ]


def _soft_patch_problems(patches: Sequence[Patch], height_field: bool) -> List[Problem]:
    problems = []
    for patch in patches:
        if not patch.surface.soft:
            continue
        path = f"patches.{patch.name}.sinkage"
        if height_field:
            rule = f"must be 0 with a height_field ({ZERO_HINT}): a soft patch needs a hole in the ground"
            problems.append(Problem(path, patch.surface.sinkage, rule))
        elif max(max(abs(x), abs(y)) for x, y in patch.corners()) > SOFT_PATCH_REACH:
            rule = f"needs the patch within {SOFT_PATCH_REACH:g} m of the origin in x and y (the ground ends there)"
            problems.append(Problem(path, patch.surface.sinkage, rule))
    return problems


def _slope(name: str, index: int, v: Mapping) -> Slope:
    return Slope(
        name, index, v["x"], v["y"], v["yaw"], v["width"], v["angle"], v["height"], v["top_length"], _surface(v)
    )


def _rail(name: str, index: int, v: Mapping) -> Rail:
    return Rail(name, index, v["x"], v["y"], v["yaw"], v["length"], v["gauge"], v["height"], v["radius"], _surface(v))


def _rail_problems(rails: Tuple[Rail, ...], found: List[Problem]) -> List[Problem]:
    problems = []
    for rail in rails:
        path = f"rails.{rail.name}"
        # A key that already broke its own rule was replaced by its default; comparing that default
        # would report a value the file does not hold.
        if _broken(found, path, "radius", "height", "gauge"):
            continue
        if rail.radius >= rail.height:
            problems.append(
                Problem(
                    f"{path}.radius",
                    rail.radius,
                    f"must be < height ({rail.height} m): a pipe cannot sink into the ground",
                )
            )
        if rail.gauge <= 2.0 * rail.radius:
            problems.append(
                Problem(
                    f"{path}.gauge",
                    rail.gauge,
                    f"must be > 2 * radius ({2.0 * rail.radius} m): the two pipes would overlap",
                )
            )
    return problems


def _broken(problems: Sequence[Problem], path: str, *keys: str) -> bool:
    """Whether one of the entry's keys has a problem already (its value was replaced by the default)."""
    paths = {f"{path}.{k}" for k in keys}
    return any(p.path in paths for p in problems)


def _file(value: str, base_dir: str, path: str, problems: List[Problem], extensions: Sequence[str] = ()) -> str:
    """The absolute path of a file the world names (relative to base_dir); a problem if it is not there."""
    full = os.path.normpath(os.path.join(base_dir, os.path.expanduser(value)))
    if extensions and not full.lower().endswith(tuple(extensions)):
        names = " or ".join(e[1:].upper() for e in extensions)
        problems.append(Problem(path, value, f"must be an {names} file ({', '.join(extensions)})"))
    elif not os.path.isfile(full):
        problems.append(Problem(path, value, f"no such file: {full} (a relative path is from the world file's folder)"))
    return full


def _object(name, index, v, raw, *, base_dir, ground_at, problems, meshes) -> WorldObject:
    """The object; a mesh's (key path, value, absolute file) goes to meshes, read by :func:`_mesh_problems`."""
    path = f"objects.{name}"
    shape = v["shape"]
    others = {k for keys in SHAPE_KEYS.values() for k in keys} - set(SHAPE_KEYS[shape])
    for k in sorted(others & set(raw)):
        wanted = ", ".join(SHAPE_KEYS[shape])
        problems.append(Problem(f"{path}.{k}", raw[k], f"is not a key of a {shape} (it takes {wanted})"))
    for k in SHAPE_KEYS[shape]:
        if v[k] is None and k != "scale" and not _broken(problems, path, k):
            problems.append(Problem(f"{path}.{k}", MISSING, f"is required for a {shape}"))
    dims = {k: v[k] or 0.0 for k in ("size_x", "size_y", "size_z", "radius", "length")}
    file = ""
    if shape == "mesh" and v["file"]:
        found = len(problems)
        file = _file(v["file"], base_dir, f"{path}.file", problems, MESH_EXTENSIONS)
        if len(problems) == found:
            meshes.append((f"{path}.file", v["file"], file))
    colour = v["rgba"] or RGBA_WOOD
    thing = WorldObject(
        name, index, shape, v["x"], v["y"], 0.0, v["roll"], v["pitch"], v["yaw"], **dims, file=file,
        scale=v["scale"] or 1.0, mass=v["mass"], rgba=colour, surface=_surface(v),
    )  # fmt: skip
    above = thing.half_height if v["z"] is None else v["z"]
    return replace(thing, z=ground_at(v["x"], v["y"]) + above)


def _rows(name, index, v, problems) -> Rows:
    path = f"rows.{name}"
    rows = Rows(
        name, index, v["x"], v["y"], v["yaw"], v["count"], v["spacing"], v["length"], v["plant"], v["plant_spacing"],
        v["plant_radius"], v["plant_height"], v["gap_probability"], v["jitter"], v["seed"], v["rgba"] or RGBA_LEAF,
        _surface(v),
    )  # fmt: skip
    if rows.plant == "sphere" and rows.plant_height < rows.plant_radius and not _broken(problems, path, "plant_height"):
        rule = f"must be >= plant_radius ({rows.plant_radius} m) for a sphere: its centre would be below the ground"
        problems.append(Problem(f"{path}.plant_height", rows.plant_height, rule))
    return rows


def _polytunnel(name, index, v, ground_at, problems) -> Polytunnel:
    path = f"polytunnels.{name}"
    z = ground_at(v["x"], v["y"])
    tunnel = Polytunnel(
        name, index, v["x"], v["y"], z, v["yaw"], v["length"], v["width"], v["height"], v["leg_height"],
        v["hoop_spacing"], v["tube"], v["crop"], v["tables"], v["table_height"], v["table_width"], v["leg_spacing"],
        v["bed_height"], v["end_gap"], v["plant_spacing"], _surface(v),
    )  # fmt: skip
    t = tunnel
    if not _broken(problems, path, "height", "leg_height") and t.height <= t.leg_height:
        problems.append(Problem(f"{path}.height", t.height, f"must be > leg_height ({t.leg_height} m)"))
        return tunnel
    if not _broken(problems, path, "end_gap", "length") and 2 * t.end_gap >= t.length:
        rule = f"must be < length / 2 ({t.length / 2} m): the tables would have no length"
        problems.append(Problem(f"{path}.end_gap", t.end_gap, rule))
    if t.crop == "none" or _broken(problems, path, "tables", "table_width", "width", "table_height", "crop"):
        return tunnel
    if t.tables * t.table_width >= t.width:
        rule = f"times tables ({t.tables}) must be < width ({t.width} m): an aisle between the tables"
        problems.append(Problem(f"{path}.table_width", t.table_width, rule))
        return tunnel
    outer = max(abs(t.table_offset(0)), abs(t.table_offset(t.tables - 1))) + t.table_width / 2
    roof = t.roof_height(outer) - t.tube / 2
    if t.crop_top + 1.5 * t.plant_radius >= roof:
        key = "table_height" if t.crop == "table_tops" else "bed_height"
        rule = (
            f"puts the plants ({1.5 * t.plant_radius:.3g} m above it) under the roof ({roof:.3g} m at the outer table)"
        )
        problems.append(Problem(f"{path}.{key}", t.crop_top, "is too high: " + rule))
    return tunnel


def _wall(name, index, v, ground_at, sample: bool = True) -> Wall:
    # the foot follows the lowest ground along the wall's centre line (every WALL_STEP); without
    # sample (a world over its budgets), the ground at its centre
    if sample:
        n = _wall_steps(v["length"])
        along = (_along(v["x"], v["y"], v["yaw"], v["length"] * (k / n - 0.5), 0.0) for k in range(n + 1))
        foot = min(ground_at(*point) for point in along)
    else:
        foot = ground_at(v["x"], v["y"])
    return Wall(
        name, index, v["x"], v["y"], foot, v["yaw"], v["length"], v["height"], v["thickness"],
        v["rgba"] or RGBA_CONCRETE, _surface(v),
    )  # fmt: skip


def _height_field(raw: Any, base_dir: str, problems: List[Problem]) -> Optional[HeightField]:
    v = parse_entry(raw, "height_field", HEIGHT_FIELD_KEYS, problems)
    if v is None:
        return None
    path = "height_field"
    image, levels = "", None
    if v["image"]:
        image = _file(v["image"], base_dir, f"{path}.image", problems)
        if os.path.isfile(image):
            try:
                # its size from its header first: a huge image is refused before it is decoded
                _check_image_budget(image)
                levels = _image_levels(image)
            except ValueError as e:
                problems.append(Problem(f"{path}.image", v["image"], str(e)))
                image = ""
        else:
            image = ""
        if v["resolution"] is not None:
            rule = "must not be given with an image: its pixels are the grid"
            problems.append(Problem(f"{path}.resolution", v["resolution"], rule))
    elif "image" not in raw:
        for k in ("min_height", "max_height"):
            if v[k] is not None:
                problems.append(Problem(f"{path}.{k}", v[k], "is used with an image only"))
    low = 0.0 if v["min_height"] is None else v["min_height"]
    high = 1.0 if v["max_height"] is None else v["max_height"]
    if high <= low:
        problems.append(Problem(f"{path}.max_height", high, f"must be > min_height ({low} m)"))
    if v["rut_width"] > v["rut_spacing"] and not _broken(problems, path, "rut_width", "rut_spacing"):
        problems.append(Problem(f"{path}.rut_width", v["rut_width"], f"must be <= rut_spacing ({v['rut_spacing']} m)"))
    hf = HeightField(
        v["x"], v["y"], v["size_x"], v["size_y"], 0.0 if image else (v["resolution"] or 0.2), image, low, high,
        v["amplitude"], v["feature_length"], v["seed"], v["rut_depth"], v["rut_width"], v["rut_spacing"],
        v["flat_radius"],
    )  # fmt: skip
    if "image" in raw and not image:
        return None  # the problem is reported; there is no grid to make
    if levels is not None:
        hf.__dict__["_levels"] = levels  # the image as read to check it (the cached property's place)
    else:
        # counted as floats: a tiny resolution makes a count beyond any budget, not an OverflowError
        nx, ny = (max(2.0, _rounded(size / hf.resolution) + 1) for size in (hf.size_x, hf.size_y))
        if nx * ny > MAX_FIELD_POINTS:
            rule = f"makes {_n(nx)} x {_n(ny)} grid points; at most {MAX_FIELD_POINTS}"
            problems.append(Problem(f"{path}.resolution", raw.get("resolution", hf.resolution), rule))
            return None
    if hf.amplitude > 0:
        ni, nj = _noise_lattice(hf.size_x, hf.feature_length), _noise_lattice(hf.size_y, hf.feature_length)
        if ni * nj > MAX_NOISE_POINTS:
            rule = f"makes {_n(ni)} x {_n(nj)} noise lattice points (size / feature_length); at most {MAX_NOISE_POINTS}"
            problems.append(Problem(f"{path}.feature_length", hf.feature_length, rule))
            return None
    return hf


def _check_image_budget(path: str) -> None:
    """ValueError (the rule) if the image's file or its pixels (from its header) are over the budgets."""
    size = os.path.getsize(path)
    if size > MAX_IMAGE_BYTES:
        raise ValueError(f"is a file of {size} bytes; at most {MAX_IMAGE_BYTES}")
    width, height = _image_size(path)
    if width * height > MAX_FIELD_POINTS:
        raise ValueError(f"makes {width} x {height} grid points (its pixels); at most {MAX_FIELD_POINTS}")


PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def _image_size(path: str) -> Tuple[int, int]:
    """(width, height) of the image from its header, without decoding it; ValueError if it cannot be read.

    A PNG's are read here (its IHDR chunk: PIL refuses a PNG of more than 179 million pixels with a
    DecompressionBombError that hides the size); another format's through PIL, which reads only the
    header until the image is loaded.
    """
    from PIL import Image, UnidentifiedImageError  # noqa: PLC0415

    with open(path, "rb") as f:
        head = f.read(24)
    if head[:8] == PNG_SIGNATURE:
        if len(head) < 24 or head[12:16] != b"IHDR":
            raise ValueError("cannot read the image: a PNG file without its IHDR header")
        return int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            with Image.open(path) as image:
                return image.size
    except (OSError, UnidentifiedImageError, Image.DecompressionBombError) as e:
        raise ValueError(f"cannot read the image: {e}") from None


def _rounded(ratio: float) -> float:
    """round(ratio), as a float; a ratio too big to be any count (inf for a tiny spacing) is itself."""
    return float(round(ratio)) if ratio < 1e15 else ratio


def _floored(ratio: float) -> float:
    """math.floor(ratio + 1e-9) (a whole number of spacings, though floating point makes it 2.9999...)
    as a float; a ratio too big to be any count is itself."""
    return float(math.floor(ratio + 1e-9)) if ratio < 1e15 else ratio


def _n(count: float) -> str:
    """A count (a float from :func:`_rounded`) as the message says it."""
    if count < 1e15:
        return str(int(count))
    return f"{count:.3g}" if math.isfinite(count) else "more than 1e308"


def _noise_lattice(size: float, feature_length: float) -> float:
    """Lattice points along one side of a field's noise (as :func:`_value_noise` makes them)."""
    half = size / 2 / feature_length
    return half * 2 + 3 if half >= 1e15 else float(math.floor(half) - math.floor(-half) + 2)


def _wall_steps(length: float) -> int:
    """Steps of WALL_STEP (at most) along a wall: its points are one more."""
    return max(1, math.ceil(length / WALL_STEP))


# ---------------------------------------------------------------------------------------------
# Budgets of the whole world (the module's "Limits"), counted from the parsed numbers before
# anything is made
# ---------------------------------------------------------------------------------------------
Share = Tuple[str, Any, float]  # (key path, its value, how much of a budget its entry takes)
Entries = Mapping[str, Sequence[Tuple[str, int, dict, Mapping]]]


def _row_plants(v: Mapping) -> float:
    """Places for plants (gaps included: each draws its random numbers) of a rows entry's values."""
    return v["count"] * (_floored(v["length"] / v["plant_spacing"]) + 1)


def _tunnel_counts(v: Mapping) -> Tuple[float, float, float, float]:
    """(hoops, pairs of table legs, plants, bodies) of a polytunnels entry's values, as
    :class:`Polytunnel` and the scene make them."""
    hoops = max(1.0, _rounded(v["length"] / v["hoop_spacing"])) + 1
    if v["crop"] == "none":
        return hoops, 0.0, 0.0, 3.0
    span = v["length"] - 2 * v["end_gap"]
    tables = v["tables"]
    legs = tables * (max(1.0, _rounded(span / v["leg_spacing"])) + 1) if v["crop"] == "table_tops" else 0.0
    plants = tables * max(0.0, _floored(span / v["plant_spacing"]))
    # the legs of each side and the roof; each table's table, plants and berries
    return hoops, legs, plants, 3.0 + 3.0 * tables


def _budget_problems(entries: Entries, problems: List[Problem]) -> bool:
    """Adds a problem for each budget the world's entries break; whether any is broken."""
    found: List[Problem] = []

    def at(section: str, key: str) -> List[Tuple[str, Any, dict]]:
        """(key path, the file's value or else the default, values) of the key of each entry."""
        return [(f"{section}.{name}.{key}", raw.get(key, v[key]), v) for name, _, v, raw in entries[section]]

    row_plants = [(path, value, _row_plants(v)) for path, value, v in at("rows", "plant_spacing")]
    plants = row_plants + [(path, value, _tunnel_counts(v)[2]) for path, value, v in at("polytunnels", "plant_spacing")]
    found.append(_over(plants, MAX_PLANTS, "plants over the world's rows and polytunnels"))
    hoops = [(path, value, _tunnel_counts(v)[0]) for path, value, v in at("polytunnels", "hoop_spacing")]
    found.append(_over(hoops, MAX_HOOPS, "hoops over the world's polytunnels"))
    legs = [(path, value, _tunnel_counts(v)[1]) for path, value, v in at("polytunnels", "leg_spacing")]
    found.append(_over(legs, MAX_TABLE_LEGS, "pairs of table legs over the world's polytunnels"))

    # one body an entry, two a rail (its pipes), one a row, three a tunnel and three each of its
    # tables; and the ground
    bodies = [(key, len(entries[key]), (2.0 if key == "rails" else 1.0) * len(entries[key])) for key in SINGLES]
    bodies += [(path, value, float(v["count"])) for path, value, v in at("rows", "count")]
    bodies += [(path, value, _tunnel_counts(v)[3]) for path, value, v in at("polytunnels", "tables")]
    found.append(_over(bodies, MAX_BODIES, "pybullet bodies over the world's entries and the ground", extra=1))

    patches = [v for _, _, v, _ in entries["patches"]]
    soft = any(_surface_of(v, SURFACE_DEFAULTS).soft for v in patches)
    if soft and len(patches) > MAX_HOLES:
        rule = f"makes {len(patches)} holes in the ground (one under every patch, as one is soft); at most {MAX_HOLES}"
        found.append(Problem("patches", len(patches), rule))

    # Each plant, point along a wall, object and tunnel looks for the ground under it: the height
    # field (or the plane), every hill and every patch.
    searched = 1 + len(entries["slopes"]) + len(entries["patches"])
    points = [(path, value, n * searched) for path, value, n in row_plants]
    points += [(path, value, (_wall_steps(v["length"]) + 1.0) * searched) for path, value, v in at("walls", "length")]
    points += [(key, len(entries[key]), len(entries[key]) * searched) for key in ("objects", "polytunnels")]
    what = f"ground look-ups (plants, points every {WALL_STEP:g} m along walls, objects and tunnels, each over"
    what += f" the ground, {searched - 1} hills and patches)"
    lookups = _over(points, MAX_GROUND_LOOKUPS, what)
    # said once a key: too many plants (the first budget) are too many look-ups too
    if lookups is not None and all(pr is None or pr.path != lookups.path for pr in found):
        found.append(lookups)

    found = [pr for pr in found if pr is not None]
    problems.extend(found)
    return bool(found)


# the sections whose entries are one pybullet body each (a rail two)
SINGLES = ("patches", "slopes", "rails", "objects", "walls")


def _over(shares: Sequence[Share], limit: int, what: str, extra: float = 0.0) -> Optional[Problem]:
    """The problem of a budget the shares (and extra, at no key) break, at the largest share's key; None within it."""
    total = sum(amount for _, _, amount in shares) + extra
    if total <= limit:
        return None
    path, value, amount = max(shares, key=lambda share: share[2])
    here = f", {_n(amount)} of them here" if amount < total else ""
    return Problem(path, value, f"makes {_n(total)} {what}{here}; at most {limit}")


def _mesh_problems(meshes: Sequence[Tuple[str, str, str]], problems: List[Problem]) -> None:
    """Problems of the mesh files (key path, value, absolute file) the objects name: their sizes over
    the budget first (nothing is read then), else each file that is not a mesh pybullet can load."""
    sized = []
    for path, value, file in meshes:
        try:
            sized.append((path, value, file, float(os.path.getsize(file))))
        except OSError as e:
            problems.append(Problem(path, value, f"cannot be read ({file}): {e.strerror}"))
    shares = [(path, value, size) for path, value, _, size in sized]
    # each object loads its file: pybullet makes a collision shape and a visual shape of each
    over = _over(shares, MAX_MESH_BYTES, "bytes of mesh files over the world's objects (each object's counted)")
    if over is not None:
        problems.append(over)
        return
    reasons: Dict[str, Optional[str]] = {}
    for path, value, file, _ in sized:
        if file not in reasons:
            reasons[file] = mesh_problem(file)
        if reasons[file]:
            problems.append(Problem(path, value, f"is not a mesh pybullet can load ({file}): {reasons[file]}"))


# ---------------------------------------------------------------------------------------------
# Shipped worlds
# ---------------------------------------------------------------------------------------------
def worlds_dir() -> str:
    """The shipped worlds' folder, in the devel or install space (or the source tree)."""
    return os.path.join(package_folder("thorvald_sim", PACKAGE_DIR), "worlds")


def __getattr__(name: str) -> Any:
    # WORLDS_DIR is looked up when first asked for, not at import: importing this module must not
    # crawl the ROS package path (a module-level __getattr__, PEP 562).
    if name == "WORLDS_DIR":
        return worlds_dir()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def shipped_worlds() -> List[str]:
    """Names of the shipped worlds (``flat``, ...), sorted."""
    return sorted(os.path.splitext(os.path.basename(f))[0] for f in glob.glob(os.path.join(worlds_dir(), "*.yaml")))


def resolve_world(name_or_path: str) -> str:
    """The file of a world given by name (a shipped world) or by path.

    A shipped world's name wins over a file of that name in the current folder. Anything that looks
    like a path (has a folder separator or a YAML extension) or names an existing file is returned
    as it is, so that a missing file is reported by :func:`load_world` with the reason; a bare name
    that is neither raises a ConfigError of one line listing the shipped worlds.
    """
    names = shipped_worlds()
    if name_or_path in names:
        return os.path.join(worlds_dir(), name_or_path + ".yaml")
    looks_like_path = os.sep in name_or_path or name_or_path.endswith((".yaml", ".yml"))
    if looks_like_path or os.path.exists(name_or_path):
        return name_or_path
    rule = "no such world: give a file or one of " + ", ".join(names)
    raise ConfigError(name_or_path, [Problem("", MISSING, rule)], WHAT)


__all__ = [
    "ConfigError",
    "HeightField",
    "Patch",
    "Polytunnel",
    "Rail",
    "Rows",
    "Slope",
    "Surface",
    "Wall",
    "WorldConfig",
    "WorldObject",
    "load_world",
    "parse_world",
    "plant_positions",
    "resolve_world",
    "shipped_worlds",
    "worlds_dir",
]
