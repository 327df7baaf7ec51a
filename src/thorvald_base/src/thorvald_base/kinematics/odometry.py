"""Odometry: robot velocity from measured drive states (paper section 3.3), and the pose on the arc.

Two estimators share one interface, ``estimate(steering, speed) -> (vx, vy, wz, residual, translating)``:

* :class:`LeastSquaresEstimator` (default): the rigid-body twist whose wheel velocities fit the
  measured wheel velocity vectors best, subject to the wheels that cannot steer. Exact for wheels
  that agree, no special case for translation, and its residual measures slip and disagreement.
* :class:`PaperEstimator`: the paper's method (notes 3.4): random pairs of wheels, the intersection
  of the lines normal to each wheel, the averaged centre of rotation, and the translation test.

Both take lists of floats (steering [rad], rim speed [m/s] per drive, in drive order).
"""

import math
import random
from typing import List, Optional, Sequence, Tuple

from .geometry import Layout
from .types import Pose, Twist

Estimate = Tuple[float, float, float, float, Optional[bool]]

ESTIMATORS = ("lsq", "paper")
DEFAULT_ESTIMATOR = "lsq"

# Normals closer to parallel than this (sine of the angle between them) do not intersect: the
# original's exact tan(a_i) == tan(a_j) test, made robust to rounding. A larger value would make
# the estimator inexact for arcs of radius above about wheelbase / tolerance.
PARALLEL_TOLERANCE = 1e-6
# [m]: a wheel this close to the centre of rotation says nothing about wz: its rate d x v / d^2 divides
# two tiny numbers, so rounding in the averaged centre (1e-9 m and less) would swamp it (the centre
# drive of the 9WD9WS robot when spinning in place).
AT_ICR = 1e-3


def residual(layout: Layout, twist: Tuple[float, float, float], wvx: Sequence[float], wvy: Sequence[float]) -> float:
    """RMS over the drives of |measured wheel velocity - velocity the twist gives that wheel| [m/s]."""
    vx, vy, wz = twist
    total = 0.0
    for x, y, mx, my in zip(layout.x, layout.y, wvx, wvy):
        ex = vx - wz * y - mx
        ey = vy + wz * x - my
        total += ex * ex + ey * ey
    return math.sqrt(total / len(layout.x))


def wheel_velocities(steering: Sequence[float], speed: Sequence[float]) -> Tuple[List[float], List[float]]:
    wvx = [s * math.cos(a) for a, s in zip(steering, speed)]
    wvy = [s * math.sin(a) for a, s in zip(steering, speed)]
    return wvx, wvy


class LeastSquaresEstimator:
    """Least-squares rigid-body fit over all wheel velocity vectors (closed form, precomputed)."""

    name = "lsq"

    def __init__(self, layout: Layout):
        self.layout = layout

    def estimate(self, steering: Sequence[float], speed: Sequence[float]) -> Estimate:
        wvx, wvy = wheel_velocities(steering, speed)
        # b = sum J_i^T v_i; the constrained normal equations were solved once in Layout (t = P b).
        b0 = sum(wvx)
        b1 = sum(wvy)
        b2 = sum(x * my - y * mx for x, y, mx, my in zip(self.layout.x, self.layout.y, wvx, wvy))
        p = self.layout.lsq
        vx = p[0][0] * b0 + p[0][1] * b1 + p[0][2] * b2
        vy = p[1][0] * b0 + p[1][1] * b1 + p[1][2] * b2
        wz = p[2][0] * b0 + p[2][1] * b1 + p[2][2] * b2
        return vx, vy, wz, residual(self.layout, (vx, vy, wz), wvx, wvy), None


class PaperEstimator:
    """The paper's random-pair centre-of-rotation method (notes 3.4), reproducible with a seed.

    Pairs are drawn ``iterations_per_wheel`` (10 in the original) times per wheel. Fixed passive
    wheels take part with their known normal line, so a one-wheel drive has pairs to intersect (the
    original left the pose unchanged with one drive); they have no speed, so pairs are drawn with at
    least one drive in them.
    """

    name = "paper"

    def __init__(self, layout: Layout, seed: Optional[int] = None, iterations_per_wheel: int = 10):
        self.layout = layout
        self.rng = random.Random(seed)
        self.iterations_per_wheel = iterations_per_wheel
        self.px = layout.x + [a.x for a in layout.fixed_axles]
        self.py = layout.y + [a.y for a in layout.fixed_axles]

    def seed(self, seed: Optional[int]) -> None:
        self.rng.seed(seed)

    def estimate(self, steering: Sequence[float], speed: Sequence[float]) -> Estimate:
        layout = self.layout
        nd = len(layout.x)
        n = len(self.px)
        wvx, wvy = wheel_velocities(steering, speed)
        # Normal of a wheel rolling along (cos a, sin a): the original's (sin(-a), cos(-a)).
        nx = [-math.sin(a) for a in steering] + [a.dx for a in layout.fixed_axles]
        ny = [math.cos(a) for a in steering] + [a.dy for a in layout.fixed_axles]
        px, py = self.px, self.py
        iterations = self.iterations_per_wheel * n if n > 1 else 0
        inf_count = 0
        samples = 0
        sum_x = sum_y = 0.0
        rnd = self.rng.random
        for _ in range(iterations):
            i = int(rnd() * nd)
            j = int(rnd() * (n - 1))
            if j >= i:
                j += 1
            if speed[i] == 0.0 and (j >= nd or speed[j] == 0.0):
                inf_count += 1
                continue
            dx = px[j] - px[i]
            dy = py[j] - py[i]
            cross = nx[i] * ny[j] - ny[i] * nx[j]
            if abs(cross) > PARALLEL_TOLERANCE:
                # Intersection of the two normal lines; exact for any pair that is not parallel. The
                # original's tan() form is singular at 90 degrees, and its c > 0.9 / c < 0.1
                # shortcuts took a wheel's position (or the baseline) for the centre, which is off
                # by up to 25 degrees' worth; only truly coincident lines need the speeds.
                t = (dx * ny[j] - dy * nx[j]) / cross
                sum_x += px[i] + t * nx[i]
                sum_y += py[i] + t * ny[i]
                samples += 1
                continue
            dist = math.hypot(dx, dy)
            if abs(dx * ny[i] - dy * nx[i]) / dist > PARALLEL_TOLERANCE:
                inf_count += 1  # parallel normal lines apart: translation
                continue
            if j >= nd:
                continue  # on the axle of a fixed wheel, whose speed is unknown
            # Both normals lie on one line, the baseline: the velocity across it is linear along it and zero
            # at the centre (the original's "line through the velocity tips", without slopes).
            ux, uy = -dy / dist, dx / dist
            wi = wvx[i] * ux + wvy[i] * uy
            wj = wvx[j] * ux + wvy[j] * uy
            if wi == wj:
                inf_count += 1
                continue
            s = wi / (wi - wj)
            sum_x += px[i] + s * dx
            sum_y += py[i] + s * dy
            samples += 1
        translating = samples == 0 or (iterations > 0 and inf_count / iterations > 0.5)
        if translating:
            vx = sum(wvx) / nd
            vy = sum(wvy) / nd
            wz = 0.0
        else:
            cx = sum_x / samples
            cy = sum_y / samples
            rates = []
            for k in range(nd):
                dx = layout.x[k] - cx
                dy = layout.y[k] - cy
                d2 = dx * dx + dy * dy
                if d2 > AT_ICR * AT_ICR:
                    rates.append((dx * wvy[k] - dy * wvx[k]) / d2)
            # The original averages the non-zero rates; a wheel at the centre gives none.
            rates = [r for r in rates if r != 0.0]
            wz = sum(rates) / len(rates) if rates else 0.0
            vx = wz * cy
            vy = -wz * cx
        return vx, vy, wz, residual(layout, (vx, vy, wz), wvx, wvy), translating


def make_estimator(name: str, layout: Layout, seed: Optional[int] = None):
    if name == "lsq":
        return LeastSquaresEstimator(layout)
    if name == "paper":
        return PaperEstimator(layout, seed)
    raise ValueError("estimator must be one of {}, not {!r}".format(", ".join(ESTIMATORS), name))


def normalize_angle(a: float) -> float:
    """The angle in (-pi, pi] [rad]."""
    a = math.fmod(a + math.pi, 2.0 * math.pi)
    if a <= 0.0:
        a += 2.0 * math.pi
    return a - math.pi


def integrate_se2(pose: Pose, twist: Twist, dt: float) -> Pose:
    """The pose after moving with a constant body twist for dt [s], exactly on the arc.

    The original stepped x += v cos(yaw) dt; on a circle that drifts outward by about v wz dt^2 / 2
    each step. Here the body-frame displacement over the arc is (sin th, 1 - cos th)-weighted with
    th = wz dt, with a series for small th so that translation is exact too.
    """
    th = twist.wz * dt
    if abs(th) < 1e-6:
        # sin(th)/th and (1 - cos th)/th to well below double precision at this size
        s = dt * (1.0 - th * th / 6.0)
        c = dt * (th / 2.0 - th * th * th / 24.0)
    else:
        s = math.sin(th) / twist.wz
        c = (1.0 - math.cos(th)) / twist.wz
    dx = twist.vx * s - twist.vy * c
    dy = twist.vx * c + twist.vy * s
    cy = math.cos(pose.yaw)
    sy = math.sin(pose.yaw)
    return Pose(pose.x + cy * dx - sy * dy, pose.y + sy * dx + cy * dy, normalize_angle(pose.yaw + th))
