"""Crop rows (``rows:``, entries ``row0``, ...): parallel rows of plants from a few numbers, each
plant on the ground under it (hills and height fields too). The same seed gives the same plants
(:func:`plant_positions`, pure, so tests check rows without pybullet). A sphere plant's height is at
least its radius. Every place of a plant (gaps included: each draws its random numbers) takes a
share of the world's plants and of its ground look-ups; each row is a body.

In pybullet: each row one static triangle mesh of its plants (a column, or a ball on a stem),
reaching ROOT into the ground, bodies ``rows.row0.0``, ``rows.row0.1``, ... (the entry's first row,
its second, ...); a row of more than MAX_MESH_VERTICES goes on in bodies named ``.part1``, ``.part2``,
... after the first (``rows.row0.1.part1``); a row whose every place is a gap has no body.
"""

import math
import random
from dataclasses import dataclass
from typing import List, Mapping, Sequence, Tuple

from thorvald_model.errors import Problem
from thorvald_model.schema import POSITIVE, Key, one_of

from ..bodies import (
    MAX_MESH_VERTICES,
    PLANT_BALL,
    ROOT,
    Mesh,
    add_bodies,
    ball_template,
    diag,
    mesh_bodies,
    np,
    prism_template,
)
from ..geometry import Point, along, rectangle
from ..kind import Context, ElementKind, Entry
from ..limits import Shares, at, floored
from ..rules import COORDINATE, LENGTH, LENGTH_OR_ZERO, RGBA_KEY, UNIT_RANGE, Rgba, broken
from ..surfaces import Surface, frictions, rgba_text, surface

RGBA_LEAF = (0.25, 0.55, 0.20, 1.0)
PLANTS = ("cylinder", "sphere")

PRISM_SIDES = 8  # of a cylindrical plant
STEM_SIDES = 4
STEM_RADIUS = 0.1  # of the plant's radius
MIN_STEM_RADIUS = 0.005  # [m]


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
        return along(self.x, self.y, self.yaw, 0.0, k * self.spacing)


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
                line.append(along(rows.x, rows.y, rows.yaw, i * rows.plant_spacing + du, k * rows.spacing + dv))
        lines.append(tuple(line))
    return tuple(lines)


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
    *frictions(0.5),
)


def make(entry: Entry, context: Context) -> Rows:
    name, index, v, problems = entry.name, entry.index, entry.values, context.problems
    path = f"rows.{name}"
    rows = Rows(
        name, index, v["x"], v["y"], v["yaw"], v["count"], v["spacing"], v["length"], v["plant"], v["plant_spacing"],
        v["plant_radius"], v["plant_height"], v["gap_probability"], v["jitter"], v["seed"], v["rgba"] or RGBA_LEAF,
        surface(v),
    )  # fmt: skip
    if rows.plant == "sphere" and rows.plant_height < rows.plant_radius and not broken(problems, path, "plant_height"):
        rule = f"must be >= plant_radius ({rows.plant_radius} m) for a sphere: its centre would be below the ground"
        problems.append(Problem(f"{path}.plant_height", rows.plant_height, rule))
    return rows


def budget(section: str, entries: Sequence[Entry], searched: int) -> Shares:
    """Every place of a plant (gaps included: each draws its random numbers), one body a row, and a
    ground look-up a place."""
    plants = [(path, value, _row_plants(v)) for path, value, v in at(entries, "plant_spacing")]
    return {
        "plants": plants,
        "bodies": [(path, value, float(v["count"])) for path, value, v in at(entries, "count")],
        "ground_lookups": [(path, value, n * searched) for path, value, n in plants],
    }


def _row_plants(v: Mapping) -> float:
    """Places for plants (gaps included: each draws its random numbers) of a rows entry's values."""
    return v["count"] * (floored(v["length"] / v["plant_spacing"]) + 1)


def footprint(ro: Rows) -> List[Point]:
    """The plants' rectangle, widened by their jitter and radius."""
    margin = ro.jitter + ro.plant_radius
    across = (ro.count - 1) * ro.spacing
    return rectangle(ro.x, ro.y, ro.yaw, (-margin, ro.length + margin), (-margin, across + margin))


# ---------------------------------------------------------------------------------------------
# In pybullet
# ---------------------------------------------------------------------------------------------
def build(client: int, world, rows: Rows, name: str, bodies: dict) -> None:
    for k, parts in enumerate(_meshes(world, rows)):
        ids = [body for mesh in parts for body in mesh_bodies(client, mesh, rows.rgba, rows.surface)]
        add_bodies(bodies, f"{name}.{k}", ids)


def _meshes(world, rows: Rows) -> List[List[Mesh]]:
    """Meshes of each row: each plant stands on the ground under it, reaching ROOT into it. A row
    of more than MAX_MESH_VERTICES is split into meshes of whole plants, each of a stretch of it."""
    prism, stem_prism, ball = prism_template(PRISM_SIDES), prism_template(STEM_SIDES), ball_template(*PLANT_BALL)
    r, h = rows.plant_radius, rows.plant_height
    centre = h - r
    stem = max(MIN_STEM_RADIUS, STEM_RADIUS * r)
    if rows.plant == "cylinder":
        per_plant = len(prism[0])
    else:
        per_plant = len(ball[0]) + (len(stem_prism[0]) if centre > 0 else 0)
    batch = max(1, MAX_MESH_VERTICES // per_plant)
    meshes = []
    for line in plant_positions(rows):
        parts = []
        for start in range(0, max(1, len(line)), batch):
            mesh = Mesh()
            xy = np.asarray(line[start : start + batch], dtype=float).reshape(-1, 2)
            ground = np.array([world.ground_height(x, y) for x, y in xy])
            feet = np.column_stack([xy, ground - ROOT])
            if rows.plant == "cylinder":
                mesh.add(prism, feet, diag(r, r, h + ROOT))
            else:
                if centre > 0:
                    mesh.add(stem_prism, feet, diag(stem, stem, centre + ROOT))
                mesh.add(ball, np.column_stack([xy, ground + centre]), diag(r, r, r))
            parts.append(mesh)
        meshes.append(parts)
    return meshes


ROWS = ElementKind(
    "rows", "row", ROWS_KEYS, make=make, builder=build, budget=budget, footprint=footprint,
    counted=("rows entry", "rows entries"),
    doc="crop rows: parallel rows of plants from a few numbers", defaults={"rgba": rgba_text("leaf green", RGBA_LEAF)},
)  # fmt: skip
