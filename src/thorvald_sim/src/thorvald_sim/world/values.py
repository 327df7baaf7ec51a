"""The value types of a world's elements (SI units: m, rad, kg, m/s^2): frozen dataclasses, each
made by :mod:`thorvald_sim.world.elements` from a validated entry of the world file.

The geometry an element has of its own is computed here (a row's plants, a tunnel's hoops, tables
and plants, a hill's or a height field's surface), so tests check it without a physics engine. No
pybullet.
"""

import functools
import math
import random
from dataclasses import dataclass, field
from typing import Any, Dict, Optional, Tuple

from .geometry import Point, _along, _ground_height, _stations, _to_local
from .terrain import _field_heights, _image_levels, _points

Rgba = Tuple[float, float, float, float]

RGBA_TARMAC = (0.35, 0.35, 0.37, 1.0)
RGBA_WOOD = (0.60, 0.45, 0.28, 1.0)
RGBA_LEAF = (0.25, 0.55, 0.20, 1.0)
RGBA_CONCRETE = (0.75, 0.74, 0.70, 1.0)
RGBA_GRAVEL = (0.55, 0.48, 0.38, 1.0)
RGBA_ICE = (0.70, 0.85, 1.00, 1.0)

TABLE_DEPTH = 0.2  # [m] of a table-top's trough, below table_height
STRAWBERRY_RADIUS = 0.3  # of table_width: the foliage balls on a table or bed
ARCH_SEGMENTS = 16  # straight tubes of a hoop's arch (even: the ridge is a joint)

SINKAGE_LOAD = 500.0  # [N] on a wheel: the load a surface's sinkage is given for (a 200 kg robot on 4 wheels)
SINKAGE_MASS = SINKAGE_LOAD / 9.81  # [kg] the reference load's mass, critically damped
MAX_SINKAGE = 0.05  # [m]: deeper, a wheel is stuck, not sinking "a little"


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
    """A named kind of ground (``surface: mud``): its numbers and colour (the package's table)."""

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
    "soil": SurfaceKind(0.6, 0.08, 0.016, 0.006, (0.45, 0.34, 0.24, 1.0), "bare field soil, tilled and settled"),
}


@dataclass(frozen=True)
class Patch:
    """A rectangle of another surface lying on the ground (gravel, grass, mud, ice), its top 1 mm
    above the ground. A soft one (``sinkage`` above 0) is let into the ground: the ground has a
    hole under it (and under every other patch then), so a wheel sinks into it; a world with a
    height field, which has no holes, has none."""

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
    """A hill along its own x axis: a ramp up at ``angle``, a flat top of ``top_length`` at
    ``height``, a ramp down at ``angle``; ``x``, ``y`` the centre of its footprint, ``yaw`` the
    direction uphill, ``width`` its size across."""

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
    """A pair of parallel pipes lying above the ground: greenhouse heating pipes used as rails (the
    paper's Figure 2a robot rides them); ``x``, ``y`` the point between the pipes at the middle of
    their length."""

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
    """One body: a box (``size_x``, ``size_y``, ``size_z``), cylinder (``radius``, ``length`` along
    its own z), sphere (``radius``) or mesh (``file``, an OBJ or binary STL file, checked at load to
    be a mesh pybullet can load (:mod:`thorvald_sim.mesh_check`), drawn ``scale`` times).

    Only the shape's own dimensions are set; the others are 0 (``file`` empty). The file's ``z`` is
    the centre's (a mesh's origin's) height above the ground under it, by default resting upright on
    it. Static when its mass is 0; with a mass it falls, slides and can be pushed, without drag as
    the robots.
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
    """``count`` parallel crop rows of plants, from a few numbers (:func:`plant_positions`).

    The first row starts at ``x``, ``y`` and runs ``length`` along ``yaw``; each next row lies
    ``spacing`` to the left of the one before (+y for yaw 0). A plant every ``plant_spacing`` from
    the start to the end of each row: a ``cylinder``, a column of ``plant_radius`` and
    ``plant_height``, or a ``sphere``, a ball of ``plant_radius`` whose top is at ``plant_height``
    on a stem a tenth of its radius thick (a lettuce, a cabbage, a vine's canopy). Each is missing
    with ``gap_probability`` and moved by up to ``jitter`` along and across its row, from a random
    generator seeded by ``seed``: the same numbers give the same plants. Plants stand on the ground
    under them (hills and height fields too).
    """

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
    """A Haygrove-type tunnel of hoops on legs, with table-tops (or ground beds) of strawberries
    inside, on level ground: its floor is the ground's height at its centre.

    Its own frame: u along the tunnel from its centre, v across it (to the left), z up from its floor.
    Straight legs up to ``leg_height``, then an arch up to the ridge at ``height`` (a half ellipse; a
    half circle when ``height - leg_height`` is ``width / 2``); a hoop every ``hoop_spacing`` from end
    to end (shrunk to fit a whole number), joined by a ridge pole and a pole along each leg row; every
    tube ``tube`` thick. ``tables`` rows of tables (or beds) run along the tunnel, evenly spread across
    it (centres ``width / tables`` apart, the outer ones half that from the legs), ending ``end_gap``
    inside each end. A table-top is a trough TABLE_DEPTH deep whose top is at ``table_height``, on
    pairs of legs every ``leg_spacing``; a ground bed, soil ``bed_height`` high. Strawberry plants
    every ``plant_spacing`` on both: balls of STRAWBERRY_RADIUS ``table_width`` with their centres
    half a radius above the top, red berries hanging over the sides (drawn only).
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
    """A box standing on the ground, its foot at the lowest ground along its centre line."""

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
    """Uneven ground on a regular grid in place of the ground plane (beyond its edges there is no
    ground; its friction and colour are the ground's): an image's grey levels, bumps and ruts
    (:meth:`heights`).

    Either a grey-scale ``image`` (a PNG, 8 or 16 bits; colours by luminance; its first row is the
    +y edge, as a map, and its pixels are the grid's points), black at ``min_height`` and white at
    ``max_height``; or a grid every ``resolution``. Either way, added: random bumps up to
    ``amplitude`` high and deep, ``feature_length`` apart (value noise from ``seed``), and ruts along
    the field's x axis ``rut_depth`` deep, ``rut_width`` wide, every ``rut_spacing`` across (the
    field's centre line half-way between two ruts). Within ``flat_radius`` of the origin, where robots
    spawn at z = 0 by default, the field is 0 (its grid points out to one cell's diagonal more),
    rising to full height over the next FLAT_BLEND. Patches, hills and rails stay at z = 0.
    """

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
    """A validated world file.

    Each element kind's values are a field named by its section (``world.walls``; a single mapping's
    value or None: ``world.height_field``). A kind registered beyond these
    (:func:`thorvald_sim.world.registered`) keeps its values in ``extra``, read as an attribute the
    same way (``world.posts``); :meth:`elements` gives any section's as a tuple.
    """

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
    extra: Tuple[Tuple[str, Any], ...] = ()  # (section, its values) of the kinds registered beyond these

    def __getattr__(self, name: str) -> Any:
        # called for a name that is no field or method only: a registered kind's section; read from
        # __dict__, as a copy or an unpickled world asks before its fields are there
        for section, values in self.__dict__.get("extra", ()):
            if section == name:
                return values
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def elements(self, section: str) -> Tuple[Any, ...]:
        """The values of a section, in order: a single mapping's as one value or none."""
        values = getattr(self, section)
        if values is None:
            return ()
        return values if isinstance(values, tuple) else (values,)

    def ground_height(self, px: float, py: float) -> float:
        """[m] of the ground's surface at (px, py): the height field (0 off it, or without one), the
        hills and the patches' tops, whichever is highest (not rails, objects, plants or tunnels).
        A soft surface's top, before anything sinks into it."""
        return _ground_height(self.height_field, self.slopes, self.patches, px, py)

    @property
    def soft_patches(self) -> Tuple[Patch, ...]:
        """The soft patches; with any, the ground has a hole under every patch."""
        return tuple(pa for pa in self.patches if pa.surface.soft)
