"""Ground geometry of a world: frames along an element, the ground's height under a point from what
shapes it (:func:`ground_height`), and the ground with holes (:func:`ground_pieces`).

Pure maths on numbers and on the world's value types (read through their attributes): no pybullet.
"""

import math
from typing import Any, Callable, List, Optional, Sequence, Tuple

Point = Tuple[float, float]

GROUND_THICKNESS = 0.1  # [m] of the pieces of a ground with holes
GROUND_EXTENT = 1000.0  # [m] from the origin in x and y: a ground with holes ends there
SOFT_PATCH_REACH = GROUND_EXTENT - 1.0  # [m]: a soft patch's corners within this of the origin in x and y

# An element kind's ground function (ElementKind.ground: the height [m] it gives the ground at a point,
# None where it gives none) and the kind's elements
Shaper = Tuple[Callable[[Any, float, float], Optional[float]], Sequence[Any]]


def ground_height(shapers: Sequence[Shaper], px: float, py: float) -> float:
    """[m] of the ground at (px, py): the highest of the heights the elements that shape it give
    there (a height field its own, 0 off it; a hill its own, 0 off it; a patch its top, on it only),
    0 where none gives any."""
    z: Optional[float] = None
    for height, elements in shapers:
        for element in elements:
            h = height(element, px, py)
            if h is not None and (z is None or h > z):
                z = h
    return 0.0 if z is None else z


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


def to_local(dx: float, dy: float, yaw: float) -> Tuple[float, float]:
    c, s = math.cos(yaw), math.sin(yaw)
    return c * dx + s * dy, -s * dx + c * dy


def along(x: float, y: float, yaw: float, u: float, v: float) -> Point:
    """The world point of (u, v) in a frame at (x, y) turned by yaw."""
    c, s = math.cos(yaw), math.sin(yaw)
    return x + c * u - s * v, y + s * u + c * v


def rectangle(x: float, y: float, yaw: float, us: Sequence[float], vs: Sequence[float]) -> List[Point]:
    """The corners [m] of the rectangle us[0]..us[1] by vs[0]..vs[1] in a frame at (x, y) turned by yaw
    (an element's footprint)."""
    return [along(x, y, yaw, u, v) for u in us for v in vs]


def stations(start: float, end: float, spacing: float) -> Tuple[float, ...]:
    """Evenly spread points from start to end (both included), as near ``spacing`` apart as fits."""
    n = max(1, round((end - start) / spacing))
    return tuple(start + (end - start) * k / n for k in range(n + 1))
