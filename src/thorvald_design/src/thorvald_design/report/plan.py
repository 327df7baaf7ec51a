"""The plan of a world, for the report's maps: each element as the shape a plan draws of it, and the
view a map of some drives shows. Pure: a parsed world in (:class:`thorvald_sim.world.WorldConfig`),
points out; the shapes' corners from :mod:`thorvald_design.geometry` (one rectangle, one hull)."""

from dataclasses import dataclass
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple

from thorvald_sim.world import element_kinds
from thorvald_sim.world.kinds.rows import plant_positions

from ..geometry import Point, convex_hull, rectangle
from .tracks import Drive

MIN_VIEW = 4.0  # [m] the least a map shows across: a robot spinning on the spot is seen at a robot's scale
MIN_SIDE_RATIO = 0.25  # of a map's shorter side to its longer: a 70 m pull is not drawn as a hairline
OK_TRACK = "#0072b2"
OTHER_TRACKS = ("#d55e00", "#e69f00", "#cc79a7", "#009e73", "#56b4e9", "#7f7f7f", "#000000")


@dataclass(frozen=True)
class Shape:
    """One thing of a world's plan. kind: "slope" (its footprint), "slope_top", "solid" (an object,
    a wall), "area" (a patch), "circle" (points: its centre; radius), "outline" (anything else: the
    box around it)."""

    kind: str
    points: Tuple[Point, ...]
    colour: Optional[Tuple[float, ...]] = None
    radius: float = 0.0


@dataclass(frozen=True)
class WorldMap:
    shapes: Tuple[Shape, ...]
    plants: Tuple[Tuple[Tuple[Point, ...], Tuple[float, ...]], ...]  # (each rows entry's plants, its colour)
    description: str = ""


def _slope(slope: Any) -> List[Shape]:
    half = slope.footprint_length / 2
    return [
        Shape("slope", rectangle(slope.x, slope.y, slope.yaw, half, slope.width / 2)),
        Shape("slope_top", rectangle(slope.x, slope.y, slope.yaw, slope.top_length / 2, slope.width / 2)),
    ]


def _patch(patch: Any) -> List[Shape]:
    return [Shape("area", tuple(patch.corners()), patch.rgba)]


def _object(ob: Any) -> List[Shape]:
    if ob.shape == "box":
        return [Shape("solid", rectangle(ob.x, ob.y, ob.yaw, ob.size_x / 2, ob.size_y / 2), ob.rgba)]
    if ob.shape in ("cylinder", "sphere") and (ob.shape == "sphere" or (ob.roll == 0.0 and ob.pitch == 0.0)):
        return [Shape("circle", ((ob.x, ob.y),), ob.rgba, ob.radius)]
    return [Shape("solid", convex_hull(_footprint(_kind("objects"), ob)), ob.rgba)]


def _wall(wall: Any) -> List[Shape]:
    return [Shape("solid", rectangle(wall.x, wall.y, wall.yaw, wall.length / 2, wall.thickness / 2), wall.rgba)]


# The kinds of element a plan draws as themselves, in the order drawn (each kind's elements under the
# next's). Rows are their plants; every other kind, built-in or registered, the hull of its
# footprint (the box around it that the world's checks use), drawn after these.
DRAWN: Tuple[Tuple[str, Callable[[Any], List[Shape]]], ...] = (
    ("slopes", _slope),
    ("patches", _patch),
    ("objects", _object),
    ("walls", _wall),
)
PLANTS = "rows"


def world_map(world: Any) -> WorldMap:
    """The plan of a parsed world (:class:`thorvald_sim.world.WorldConfig`): hills as their footprint
    and top, plants as points, objects and walls as their outline, anything else as the box around it."""
    shapes: List[Shape] = []
    for section, shapes_of in DRAWN:
        for element in world.elements(section):
            shapes += shapes_of(element)
    own = {section for section, _ in DRAWN} | {PLANTS}
    for kind in element_kinds():
        if kind.section in own:
            continue
        for element in world.elements(kind.section):
            shapes.append(Shape("outline", convex_hull(_footprint(kind, element))))
    plants = tuple(
        (tuple(p for line in plant_positions(rows) for p in line), tuple(rows.rgba)) for rows in world.elements(PLANTS)
    )
    return WorldMap(tuple(shapes), plants, world.description)


def _kind(section: str) -> Any:
    return next(k for k in element_kinds() if k.section == section)


def _footprint(kind: Any, element: Any) -> List[Point]:
    return list(kind.footprint(element)) if kind.footprint else []


def outcome_colours(outcomes: Sequence[str]) -> Dict[str, str]:
    """A colour an outcome: "ok" always the same blue, the others in sorted order from a palette."""
    others = sorted(set(outcomes) - {"ok"})
    out = {"ok": OK_TRACK}
    for k, outcome in enumerate(others):
        out[outcome] = OTHER_TRACKS[k % len(OTHER_TRACKS)]
    return out


def view(drives: Sequence[Drive], plan: Optional[WorldMap], reach: float = 15.0) -> Tuple[Point, Point]:
    """The plot's (x, y) limits: the tracks and the map, but no more than ``reach`` [m] beyond the
    tracks (a 100 m field around a 5 m drive would hide it); at least MIN_VIEW across, and the shorter
    side at least MIN_SIDE_RATIO of the longer."""
    xs = [v for d in drives for v in d.x]
    ys = [v for d in drives for v in d.y]
    mx: List[float] = []
    my: List[float] = []
    if plan is not None:
        for shape in plan.shapes:
            for px, py in shape.points:
                mx += [px - shape.radius, px + shape.radius]
                my += [py - shape.radius, py + shape.radius]
        for plants, _ in plan.plants:
            mx += [p[0] for p in plants]
            my += [p[1] for p in plants]
    if xs:
        lo_x, hi_x, lo_y, hi_y = min(xs), max(xs), min(ys), max(ys)
        if mx:
            lo_x = max(min(lo_x, *mx), lo_x - reach)
            hi_x = min(max(hi_x, *mx), hi_x + reach)
            lo_y = max(min(lo_y, *my), lo_y - reach)
            hi_y = min(max(hi_y, *my), hi_y + reach)
    elif mx:
        lo_x, hi_x, lo_y, hi_y = min(mx), max(mx), min(my), max(my)
    else:
        lo_x, hi_x, lo_y, hi_y = -1.0, 1.0, -1.0, 1.0
    margin = max(0.5, 0.05 * max(hi_x - lo_x, hi_y - lo_y))
    (lo_x, hi_x), (lo_y, hi_y) = (lo_x - margin, hi_x + margin), (lo_y - margin, hi_y + margin)
    least = max(MIN_VIEW, MIN_SIDE_RATIO * max(hi_x - lo_x, hi_y - lo_y))
    grow_x, grow_y = max(0.0, least - (hi_x - lo_x)) / 2, max(0.0, least - (hi_y - lo_y)) / 2
    return (lo_x - grow_x, hi_x + grow_x), (lo_y - grow_y, hi_y + grow_y)


__all__ = ["DRAWN", "MIN_SIDE_RATIO", "MIN_VIEW", "Shape", "WorldMap", "outcome_colours", "view", "world_map"]
