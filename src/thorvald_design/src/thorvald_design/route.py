"""Paths a robot follows through a field, and the pure-pursuit rule that follows them.

A :class:`Path` is a polyline sampled every few centimetres, with its arc length. The pieces: straight
lines and circular arcs; the turns a headland sees: a U turn (a half circle, when the robot turns that
tight) and an omega turn (a bulb: out to the far side, round, and back in, when it does not); a field
route (:func:`field_route`) runs rows of a length, each the row spacing from the last, joined by turns.

Pure pursuit (Coulter 1992): the robot steers for the point of the path a look-ahead distance L
ahead of the path's point nearest it; the arc through base_link tangent to its heading and through
that point has curvature k = 2 y / L^2 (y: the point's offset to the left in base_link), so the turn
rate is k v.

Pure: numbers in, numbers out.
"""

import math
from dataclasses import dataclass
from typing import List, Sequence, Tuple

import numpy as np

SPACING = 0.02  # [m] between a path's samples


@dataclass(frozen=True)
class Path:
    x: np.ndarray  # [m]
    y: np.ndarray
    s: np.ndarray  # [m] arc length from the start

    @property
    def length(self) -> float:
        return float(self.s[-1])

    def heading_at(self, k: int) -> float:
        """[rad] of the path at its k-th sample."""
        j = min(k + 1, len(self.x) - 1)
        i = j - 1
        return math.atan2(self.y[j] - self.y[i], self.x[j] - self.x[i])


def path_of(points: Sequence[Tuple[float, float]]) -> Path:
    xy = np.asarray(points, dtype=float)
    keep = np.ones(len(xy), dtype=bool)
    keep[1:] = np.hypot(np.diff(xy[:, 0]), np.diff(xy[:, 1])) > 1e-9  # no repeated points
    xy = xy[keep]
    s = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(xy[:, 0]), np.diff(xy[:, 1])))])
    return Path(xy[:, 0], xy[:, 1], s)


def line(a: Tuple[float, float], b: Tuple[float, float]) -> List[Tuple[float, float]]:
    n = max(1, math.ceil(math.hypot(b[0] - a[0], b[1] - a[1]) / SPACING))
    return [(a[0] + (b[0] - a[0]) * k / n, a[1] + (b[1] - a[1]) * k / n) for k in range(n + 1)]


def arc(centre: Tuple[float, float], radius: float, start: float, sweep: float) -> List[Tuple[float, float]]:
    """Points of the circle about centre from the angle start [rad] through sweep [rad] (positive:
    anticlockwise)."""
    n = max(1, math.ceil(abs(sweep) * radius / SPACING))
    return [
        (centre[0] + radius * math.cos(start + sweep * k / n), centre[1] + radius * math.sin(start + sweep * k / n))
        for k in range(n + 1)
    ]


def turn(end: Tuple[float, float], heading: float, offset: float, radius: float) -> List[Tuple[float, float]]:
    """The headland turn from a row's end (heading along +x or -x: ``heading`` 0 or pi) to the next
    row, ``offset`` [m] away in world y, entered the other way: a U turn (a half circle of radius
    |offset| / 2) when radius <= |offset| / 2, else an omega turn with circles of ``radius``.

    In the turn's own frame (x along the heading, y towards the next row, d = |offset|) the omega
    turn takes the robot from the origin to (0, d) by three arcs of radius R: turning away about
    C1 = (0, -R), round about C2 = (xc, d/2) past its far side, and away again about C3 = (0, d + R).
    Neighbouring circles touch, at the midpoint of their centres, so the centres are 2R apart:
    xc^2 + (d/2 + R)^2 = (2R)^2, which needs R >= d/2."""
    d = abs(offset)
    towards = 1.0 if offset > 0 else -1.0
    c, s = math.cos(heading), math.sin(heading)

    def world(px: float, py: float) -> Tuple[float, float]:
        return (end[0] + px * c, end[1] + px * s + py * towards)

    if radius <= d / 2.0 + 1e-9:
        local = arc((0.0, d / 2.0), d / 2.0, -math.pi / 2.0, math.pi)
    else:
        r = radius
        xc = math.sqrt(4.0 * r * r - (d / 2.0 + r) ** 2)
        c1, c2, c3 = (0.0, -r), (xc, d / 2.0), (0.0, d + r)
        t1 = ((c1[0] + c2[0]) / 2.0, (c1[1] + c2[1]) / 2.0)
        t2 = ((c2[0] + c3[0]) / 2.0, (c2[1] + c3[1]) / 2.0)
        a1 = math.atan2(t1[1] - c1[1], t1[0] - c1[0])
        first = arc(c1, r, math.pi / 2.0, a1 - math.pi / 2.0)  # clockwise, turning away
        b1 = math.atan2(t1[1] - c2[1], t1[0] - c2[0])
        b2 = math.atan2(t2[1] - c2[1], t2[0] - c2[0])
        second = arc(c2, r, b1, (b2 - b1) % (2.0 * math.pi))  # anticlockwise, round the far side
        e3 = math.atan2(t2[1] - c3[1], t2[0] - c3[0])
        third = arc(c3, r, e3, -math.pi / 2.0 - e3)  # clockwise, into the row
        local = first + second[1:] + third[1:]
    return [world(px, py) for px, py in local]


def field_route(rows: int, row_length: float, spacing: float, radius: float) -> Path:
    """Rows along +x from x = 0 to row_length [m], the k-th at y = k spacing, driven up and down in
    turn, joined at each end by the headland turn (:func:`turn`) to the next row."""
    points: List[Tuple[float, float]] = []
    for k in range(rows):
        y = k * spacing
        a, b = ((0.0, y), (row_length, y)) if k % 2 == 0 else ((row_length, y), (0.0, y))
        points += line(a, b)[1 if points else 0 :]
        if k < rows - 1:
            points += turn(b, 0.0 if k % 2 == 0 else math.pi, spacing, radius)[1:]
    return path_of(points)


@dataclass
class PurePursuit:
    """Follows a path: :meth:`command` gives the speed and turn rate for base_link's pose."""

    path: Path
    lookahead: float  # [m]
    speed: float  # [m/s]
    max_rate: float = 1.5  # [rad/s] the turn rate it asks for at most
    nearest: int = 0  # the path's sample nearest the robot last time (the search goes forward from it)

    def command(self, x: float, y: float, yaw: float) -> Tuple[float, float]:
        """(vx [m/s], wz [rad/s]); (0, 0) at the path's end. The nearest point is searched a look-ahead
        forward of the last one only: where the path loops back near itself (an omega turn) the
        robot keeps to the part it is on."""
        reach = math.ceil(self.lookahead / SPACING) + 1
        window = slice(self.nearest, min(len(self.path.x), self.nearest + reach))
        d = np.hypot(self.path.x[window] - x, self.path.y[window] - y)
        self.nearest += int(np.argmin(d))
        if self.nearest >= len(self.path.x) - 1 and float(np.min(d)) < 0.1:
            return (0.0, 0.0)
        target_s = self.path.s[self.nearest] + self.lookahead
        k = min(int(np.searchsorted(self.path.s, target_s)), len(self.path.x) - 1)
        dx, dy = self.path.x[k] - x, self.path.y[k] - y
        lateral = -math.sin(yaw) * dx + math.cos(yaw) * dy  # to the left in base_link
        distance2 = max(dx * dx + dy * dy, (self.lookahead / 2.0) ** 2)
        rate = 2.0 * lateral / distance2 * self.speed
        return (self.speed, max(-self.max_rate, min(self.max_rate, rate)))

    def done(self) -> bool:
        return self.nearest >= len(self.path.x) - 2
