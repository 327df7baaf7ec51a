"""Polytunnels (``polytunnels:``, entries ``polytunnel0``, ...): Haygrove-type tunnels of hoops on
legs, with table-tops (or ground beds) of strawberries inside, on level ground: a tunnel's floor is
the ground's height at its centre.

Rules beyond each key's own: a tunnel's height is above its leg height, its end gaps leave the tables
a length, its tables leave aisles between them (``tables * table_width < width``) and its plants stay
under its roof. Its strawberries take shares of the world's plants, its hoops and pairs of table legs
budgets of their own (:class:`~thorvald_sim.world.limits.Limits`).

In pybullet: many small parts merged into a few static triangle meshes (:class:`thorvald_sim.world.bodies.Mesh`),
bodies ``polytunnels.polytunnel0.legs_left`` and ``...legs_right`` (the hoops' legs; none when
``leg_height`` is 0), ``...roof`` (arches, ridge and leg-row poles), then for each table or bed
``...table0``, ``...plants0`` and ``...berries0`` (drawn only, no collision); a mesh of more than
MAX_MESH_VERTICES goes on in bodies named ``.part1``, ... after the first.
"""

import math
from dataclasses import dataclass
from typing import List, Mapping, Sequence, Tuple

from thorvald_model.errors import Problem
from thorvald_model.schema import POSITIVE, Key, one_of

from ..bodies import PLANT_BALL, ROOT, Mesh, add_bodies, ball_template, diag, mesh_bodies, np
from ..geometry import Point, along, rectangle, stations
from ..kind import Context, ElementKind, Entry
from ..limits import Shares, at, floored, rounded
from ..rules import COORDINATE, LENGTH, LENGTH_OR_ZERO, MAX_LENGTH, broken
from ..surfaces import Surface, frictions, surface

TABLE_DEPTH = 0.2  # [m] of a table-top's trough, below table_height
STRAWBERRY_RADIUS = 0.3  # of table_width: the foliage balls on a table or bed
ARCH_SEGMENTS = 16  # straight tubes of a hoop's arch (even: the ridge is a joint)
CROPS = ("table_tops", "ground_beds", "none")

RGBA_STEEL = (0.78, 0.80, 0.82, 1.0)  # galvanised tunnel hoops
RGBA_TABLE = (0.18, 0.18, 0.20, 1.0)  # black plastic troughs on dark legs
RGBA_SOIL = (0.40, 0.30, 0.20, 1.0)
RGBA_STRAWBERRY_LEAF = (0.20, 0.50, 0.18, 1.0)
RGBA_BERRY = (0.80, 0.08, 0.10, 1.0)
BERRY = (4, 2)  # (around, pole to pole) of a berry's ball: an octahedron, a berry 5 cm across needs no more
BERRY_RADIUS = 0.025  # [m]
BERRY_DROP = 0.08  # [m] below the table's (or bed's) top


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
        return along(self.x, self.y, self.yaw, u, v)

    def hoop_stations(self) -> Tuple[float, ...]:
        """u [m] of every hoop, from end to end."""
        return stations(-self.length / 2, self.length / 2, self.hoop_spacing)

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
        return stations(*self.table_span(), self.leg_spacing)

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
    *frictions(0.5),
)


def make(entry: Entry, context: Context) -> Polytunnel:
    name, index, v, problems = entry.name, entry.index, entry.values, context.problems
    path = f"polytunnels.{name}"
    z = context.ground_at(v["x"], v["y"])
    tunnel = Polytunnel(
        name, index, v["x"], v["y"], z, v["yaw"], v["length"], v["width"], v["height"], v["leg_height"],
        v["hoop_spacing"], v["tube"], v["crop"], v["tables"], v["table_height"], v["table_width"], v["leg_spacing"],
        v["bed_height"], v["end_gap"], v["plant_spacing"], surface(v),
    )  # fmt: skip
    t = tunnel
    if not broken(problems, path, "height", "leg_height") and t.height <= t.leg_height:
        problems.append(Problem(f"{path}.height", t.height, f"must be > leg_height ({t.leg_height} m)"))
        return tunnel
    if not broken(problems, path, "end_gap", "length") and 2 * t.end_gap >= t.length:
        rule = f"must be < length / 2 ({t.length / 2} m): the tables would have no length"
        problems.append(Problem(f"{path}.end_gap", t.end_gap, rule))
    if t.crop == "none" or broken(problems, path, "tables", "table_width", "width", "table_height", "crop"):
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


def budget(section: str, entries: Sequence[Entry], searched: int) -> Shares:
    """Strawberries, hoops, pairs of table legs, three bodies a tunnel and three each of its tables,
    and one ground look-up a tunnel (its floor)."""
    return {
        "plants": [(path, value, _tunnel_counts(v)[2]) for path, value, v in at(entries, "plant_spacing")],
        "hoops": [(path, value, _tunnel_counts(v)[0]) for path, value, v in at(entries, "hoop_spacing")],
        "table_legs": [(path, value, _tunnel_counts(v)[1]) for path, value, v in at(entries, "leg_spacing")],
        "bodies": [(path, value, _tunnel_counts(v)[3]) for path, value, v in at(entries, "tables")],
        "ground_lookups": [(section, len(entries), len(entries) * searched)],
    }


def _tunnel_counts(v: Mapping) -> Tuple[float, float, float, float]:
    """(hoops, pairs of table legs, plants, bodies) of a polytunnels entry's values, as
    :class:`Polytunnel` and the scene make them."""
    hoops = max(1.0, rounded(v["length"] / v["hoop_spacing"])) + 1
    if v["crop"] == "none":
        return hoops, 0.0, 0.0, 3.0
    span = v["length"] - 2 * v["end_gap"]
    tables = v["tables"]
    legs = tables * (max(1.0, rounded(span / v["leg_spacing"])) + 1) if v["crop"] == "table_tops" else 0.0
    plants = tables * max(0.0, floored(span / v["plant_spacing"]))
    # the legs of each side and the roof; each table's table, plants and berries
    return hoops, legs, plants, 3.0 + 3.0 * tables


def footprint(tu: Polytunnel) -> List[Point]:
    side = (tu.width + tu.tube) / 2
    return rectangle(tu.x, tu.y, tu.yaw, (-tu.length / 2, tu.length / 2), (-side, side))


# ---------------------------------------------------------------------------------------------
# In pybullet
# ---------------------------------------------------------------------------------------------
def build(client: int, world, t: Polytunnel, name: str, bodies: dict) -> None:
    c, s = math.cos(t.yaw), math.sin(t.yaw)
    along, across, up = np.array((c, s, 0.0)), np.array((-s, c, 0.0)), np.array((0.0, 0.0, 1.0))
    origin = np.array((t.x, t.y, t.z))

    def at(u, v, z):
        """World points [m] of tunnel points (u, v, z): numbers or arrays of one shape."""
        u, v, z = np.broadcast_arrays(*(np.asarray(q, dtype=float) for q in (u, v, z)))
        return origin + u[..., None] * along + v[..., None] * across + z[..., None] * up

    # The legs of each side and the roof (arches and poles, all from leg_height up) are bodies of their
    # own: bullet pairs a robot with a body whose bounding box it enters, and a robot in the tunnel
    # enters none of these three then (one body of the whole frame cost a fifth of the step).
    hoops = np.array(t.hoop_stations())[:, None]
    for side, v in (("left", t.width / 2), ("right", -t.width / 2)):
        if t.leg_height > 0:
            legs = Mesh()
            legs.tubes(at(hoops, v, -ROOT), at(hoops, v, t.leg_height), along, t.tube)
            add_bodies(bodies, f"{name}.legs_{side}", mesh_bodies(client, legs, RGBA_STEEL, t.surface))
    roof = Mesh()
    arch = np.array(t.arch())
    roof.tubes(at(hoops, arch[:-1, 0], arch[:-1, 1]), at(hoops, arch[1:, 0], arch[1:, 1]), along, t.tube)
    poles = np.array(((0.0, t.height), (-t.width / 2, t.leg_height), (t.width / 2, t.leg_height)))
    roof.tubes(at(-t.length / 2, poles[:, 0], poles[:, 1]), at(t.length / 2, poles[:, 0], poles[:, 1]), across, t.tube)
    add_bodies(bodies, f"{name}.roof", mesh_bodies(client, roof, RGBA_STEEL, t.surface))

    start, end = t.table_span()
    middle, half_length = (start + end) / 2, (end - start) / 2
    r = t.plant_radius
    stations = np.array(t.plant_stations())
    legs = np.array(t.table_leg_stations())
    for k, v in enumerate(t.table_offsets()):
        table = Mesh()
        if t.crop == "table_tops":
            trough = at(middle, v, t.table_height - TABLE_DEPTH / 2)
            table.box(trough, (along, across, up), (half_length, t.table_width / 2, TABLE_DEPTH / 2))
            for side in (-1, 1):
                leg_v = v + side * (t.table_width / 2 - t.tube / 2)
                table.tubes(at(legs, leg_v, -ROOT), at(legs, leg_v, t.table_height - TABLE_DEPTH), along, t.tube)
            colour = RGBA_TABLE
        else:
            bed = at(middle, v, (t.bed_height - ROOT) / 2)
            table.box(bed, (along, across, up), (half_length, t.table_width / 2, (t.bed_height + ROOT) / 2))
            colour = RGBA_SOIL
        add_bodies(bodies, f"{name}.table{k}", mesh_bodies(client, table, colour, t.surface))

        plants, berries = Mesh(), Mesh()
        plants.add(ball_template(*PLANT_BALL), at(stations, v, t.crop_top + r / 2), diag(r, r, r))
        for side in (-1, 1):
            hang = at(stations, v + side * (t.table_width / 2 + BERRY_RADIUS), t.crop_top - BERRY_DROP)
            berries.add(ball_template(*BERRY), hang, diag(BERRY_RADIUS, BERRY_RADIUS, BERRY_RADIUS))
        add_bodies(bodies, f"{name}.plants{k}", mesh_bodies(client, plants, RGBA_STRAWBERRY_LEAF, t.surface))
        add_bodies(bodies, f"{name}.berries{k}", mesh_bodies(client, berries, RGBA_BERRY, None))


POLYTUNNELS = ElementKind(
    "polytunnels", "polytunnel", POLYTUNNEL_KEYS, make=make, builder=build, budget=budget, footprint=footprint,
    counted=("polytunnel", "polytunnels"),
    doc="Haygrove-type tunnels of hoops, with table-tops or ground beds of strawberries",
)  # fmt: skip
