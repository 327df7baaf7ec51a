"""Plan geometry, one of each for the package: a body's points in the world, a rectangle, and the
convex hull (the support polygon of the quasi-static limits, a turn's outline, the report's plan of
a world all use these).

Plan view, SI units: (x, y) [m] in a frame, a frame placed in the world at (x, y) turned by yaw
[rad] anticlockwise seen from above. thorvald_sim's world footprints have a rectangle of their own
(its corners as a set of points, for a world's extent) and no hull; these give polygons, corners
anticlockwise.

Pure: stdlib only.
"""

import math
from typing import Sequence, Tuple

Point = Tuple[float, float]


def in_world(x: float, y: float, yaw: float, points: Sequence[Point]) -> Tuple[Point, ...]:
    """The points (px, py) of a frame at (x, y) turned by yaw, in the world: (x + px cos(yaw) - py
    sin(yaw), y + px sin(yaw) + py cos(yaw))."""
    c, s = math.cos(yaw), math.sin(yaw)
    return tuple((x + c * px - s * py, y + s * px + c * py) for px, py in points)


def rectangle(x: float, y: float, yaw: float, half_u: float, half_v: float) -> Tuple[Point, ...]:
    """The corners of a rectangle centred at (x, y), turned by yaw, half_u [m] long either side along
    its own u axis and half_v across it: anticlockwise, from (-half_u, -half_v)."""
    return in_world(x, y, yaw, ((-half_u, -half_v), (half_u, -half_v), (half_u, half_v), (-half_u, half_v)))


def _cross(o: Point, a: Point, b: Point) -> float:
    """The z of (a - o) x (b - o): > 0 when o, a, b turn anticlockwise."""
    return (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0])


def hull_corners(points: Sequence[Point]) -> Tuple[int, ...]:
    """The indices of the points that are the corners of their convex hull, anticlockwise from the
    lowest x (then y) (Andrew's monotone chain): a point on an edge is no corner, and of points at one
    place one only. Points of equal (x, y) keep their order in the sort, so the same points give the
    same corners."""
    order = sorted(range(len(points)), key=lambda i: (points[i][0], points[i][1]))

    def half(chain: Sequence[int]) -> list:
        out: list = []
        for i in chain:
            while len(out) >= 2 and _cross(points[out[-2]], points[out[-1]], points[i]) <= 0.0:
                out.pop()
            out.append(i)
        return out

    lower, upper = half(order), half(order[::-1])
    return tuple(lower[:-1] + upper[:-1])


def convex_hull(points: Sequence[Point]) -> Tuple[Point, ...]:
    """The convex hull of plan points, anticlockwise (:func:`hull_corners`); a box of two points for a
    diagonal's ends (an element whose footprint is a line); fewer points as they are."""
    pts = sorted(set((float(x), float(y)) for x, y in points))
    if len(pts) == 2:
        (x0, y0), (x1, y1) = pts
        pts = sorted({(x0, y0), (x1, y0), (x1, y1), (x0, y1)})
    if len(pts) < 3:
        return tuple(pts)
    return tuple(pts[i] for i in hull_corners(pts))


__all__ = ["Point", "convex_hull", "hull_corners", "in_world", "rectangle"]
