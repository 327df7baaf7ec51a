"""What a design study measures on a robot's ground-truth track: turning and clearance diameters,
lateral drift, whether a ramp was climbed, plants touched, distances.

A track is the robot's pose over time as the simulator knows it (ground truth, not odometry):
times ``t`` [s], the body origin's world position ``x``, ``y`` [m], heading ``yaw`` [rad] and,
optionally, height ``z`` [m], ``pitch`` and ``roll`` [rad]. Everything here works in plan view: a
body point (px, py) [m] in the robot's frame (x forward, y to the left) stands in the world at

    X = x + px cos(yaw) - py sin(yaw)
    Y = y + px sin(yaw) + py cos(yaw)

(the rotation by yaw, then the translation; pitch and roll are ignored, so on a slope a body
length shows foreshortened by cos(slope) in the robot, not here: the error is 1.5 % at 10 deg).

Pure: stdlib and numpy only; no rospy, no pybullet, no messages. SI units throughout.
"""

import math
from dataclasses import dataclass
from typing import Optional, Sequence, Tuple

import numpy as np

from .errors import MetricError

# Kasa's algebraic fit is exact for exact points; Gauss-Newton then refines it to the geometric
# least-squares circle, which converges in a few steps from so close a start
GAUSS_NEWTON_STEPS = 10
# points whose spread across their principal direction is below this fraction of their spread
# along it are a straight line: no circle is determined
COLLINEAR = 1e-9
SPIN_TOLERANCE = 0.05  # [m] a body origin that stays within this of its mean position spins on the spot
POSES_PER_CHUNK = 64  # plants_touched: poses tested together against the plants near them


@dataclass(frozen=True, eq=False)
class Track:
    """The robot's ground-truth poses: arrays of one length, times increasing.

    t [s], x, y [m] (the body origin in the world), yaw [rad]; z [m], pitch, roll [rad] optional."""

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    yaw: np.ndarray
    z: Optional[np.ndarray] = None
    pitch: Optional[np.ndarray] = None
    roll: Optional[np.ndarray] = None

    def __post_init__(self):
        n = None
        for name in ("t", "x", "y", "yaw", "z", "pitch", "roll"):
            value = getattr(self, name)
            if value is None:
                continue
            array = np.asarray(value, dtype=float).reshape(-1)
            if n is None:
                n = array.size
            elif array.size != n:
                raise MetricError(f"track: {name} has {array.size} values, t has {n}")
            if not np.all(np.isfinite(array)):
                raise MetricError(f"track: {name} has a value that is not finite")
            object.__setattr__(self, name, array)
        if n == 0:
            raise MetricError("track: no poses")
        if np.any(np.diff(self.t) < 0.0):
            raise MetricError("track: times must not decrease")

    def __len__(self) -> int:
        return int(self.t.size)

    def between(self, t_start: float, t_end: float) -> "Track":
        """The poses with t_start <= t <= t_end (e.g. the steady part of a turn)."""
        keep = (self.t >= t_start) & (self.t <= t_end)
        if not np.any(keep):
            raise MetricError(f"track: no pose between t = {t_start} s and {t_end} s")

        def cut(a):
            return None if a is None else a[keep]

        return Track(
            self.t[keep], self.x[keep], self.y[keep], self.yaw[keep], cut(self.z), cut(self.pitch), cut(self.roll)
        )


def body_point_path(track: Track, px: float, py: float) -> Tuple[np.ndarray, np.ndarray]:
    """The world path (X, Y) [m] of the body point (px, py) [m] over the track (see the module text)."""
    c, s = np.cos(track.yaw), np.sin(track.yaw)
    return track.x + c * px - s * py, track.y + s * px + c * py


def path_length(track: Track) -> float:
    """The distance [m] the body origin travelled: the sum of the straight segments between poses,
    in 3D when the track has z (on a slope the wheels roll the slant distance), else in plan."""
    steps = [np.diff(track.x), np.diff(track.y)]
    if track.z is not None:
        steps.append(np.diff(track.z))
    return float(np.sum(np.sqrt(sum(d * d for d in steps))))


def distance_between(track: Track, i: int = 0, j: int = -1) -> float:
    """The straight-line plan distance [m] between the body origin at poses i and j (default: the
    start and the end), however the robot got there."""
    return math.hypot(track.x[j] - track.x[i], track.y[j] - track.y[i])


# --- circle fit ------------------------------------------------------------------------------


def fit_circle(xs, ys) -> Tuple[float, float, float, float]:
    """The circle through the points (xs, ys) in the least-squares sense: (cx, cy, radius, rms) [m],
    rms the root mean square of the points' distances from the circle. MetricError for fewer than 3
    points or points on a line (or all on one point).

    Kasa's algebraic fit first: a circle is x^2 + y^2 + D x + E y + F = 0, linear in (D, E, F), so
    least squares over the points solves [x y 1] (D E F)^T = -(x^2 + y^2); then the centre is
    (-D/2, -E/2) and radius^2 = cx^2 + cy^2 - F. It minimises the algebraic residual
    d^2 - r^2 = (d - r)(d + r), which weights points by d + r and pulls short noisy arcs towards
    smaller circles; so a few Gauss-Newton steps follow on the geometric residuals
    e_i = |p_i - c| - r, whose Jacobian rows are (-(x_i - cx)/d_i, -(y_i - cy)/d_i, -1).
    The points are centred on their mean (and scaled) first, so the normal equations stay well
    conditioned for a circle far from the origin."""
    x = np.asarray(xs, dtype=float).reshape(-1)
    y = np.asarray(ys, dtype=float).reshape(-1)
    if x.size != y.size:
        raise MetricError(f"fit_circle: {x.size} x values, {y.size} y values")
    if x.size < 3:
        raise MetricError(f"fit_circle: {x.size} points; a circle needs at least 3")
    mx, my = float(np.mean(x)), float(np.mean(y))
    u, v = x - mx, y - my
    # the singular values of the centred points: their spread along and across the principal
    # direction; none across (relative to along) means a line, none at all one point
    spread = np.linalg.svd(np.column_stack([u, v]), compute_uv=False)
    if spread[0] == 0.0 or spread[1] <= COLLINEAR * spread[0]:
        raise MetricError(f"fit_circle: the {x.size} points lie on a line; no circle is determined")
    scale = float(spread[0]) / math.sqrt(x.size)  # the points' RMS distance from their mean
    u, v = u / scale, v / scale
    a = np.column_stack([u, v, np.ones_like(u)])
    (d, e, f), *_ = np.linalg.lstsq(a, -(u * u + v * v), rcond=None)
    cx, cy = -d / 2.0, -e / 2.0
    r = math.sqrt(max(cx * cx + cy * cy - f, 0.0))
    p = np.array([cx, cy, r])
    for _ in range(GAUSS_NEWTON_STEPS):
        du, dv = u - p[0], v - p[1]
        dist = np.maximum(np.hypot(du, dv), 1e-12)
        residual = dist - p[2]
        jacobian = np.column_stack([-du / dist, -dv / dist, -np.ones_like(dist)])
        step, *_ = np.linalg.lstsq(jacobian, -residual, rcond=None)
        p = p + step
        if np.max(np.abs(step)) < 1e-12:
            break
    cx, cy, r = mx + p[0] * scale, my + p[1] * scale, abs(p[2]) * scale
    rms = math.sqrt(float(np.mean((np.hypot(x - cx, y - cy) - r) ** 2)))
    return float(cx), float(cy), float(r), rms


# --- turning ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class TurningDiameters:
    """A steady turn's diameters [m] (ISO 789-3), its centre (X, Y) [m] in the world, the wheel contact
    that is outermost, whether it was a spin on the spot, and radius_spread [m]: the largest standard
    deviation of any point's distance from the centre (0 in a steady turn; large: not steady);
    outer_point (px, py) [m] in the body frame: the point whose circle is the clearance diameter's
    (the outermost wheel's contact when nothing sticks out further)."""

    turning_diameter: float
    clearance_diameter: float
    centre: Tuple[float, float]
    outer_wheel: str
    spin: bool
    radius_spread: float
    outer_point: Tuple[float, float] = (0.0, 0.0)


def turning_diameters(
    track: Track,
    wheel_contacts: Sequence[Tuple[str, float, float]],
    outline: Sequence[Tuple[float, float]],
    spin_tolerance: float = SPIN_TOLERANCE,
) -> TurningDiameters:
    """The turning and clearance diameters of the turn the track records (pass only its steady part:
    Track.between).

    ISO 789-3: the turning diameter is that of the smallest circle enclosing the path of the outermost
    wheel contact over a steady turn; the clearance diameter that of the smallest circle enclosing the
    path of the robot's outermost point. In a steady turn (constant speed and curvature) the robot
    rotates rigidly about one fixed point, the instantaneous centre of rotation, so every body point
    describes a circle about that same centre, of radius its (fixed) distance from it: the smallest
    circle enclosing a point's path is that circle. So:

    - the centre is the circle fitted to the body origin's path (fit_circle); if the origin stays
      within spin_tolerance [m] of its mean position the robot spins on the spot about the origin
      itself, which then describes no circle, and the centre is the origin's mean position;
    - each body point's radius is the mean distance of its world path from the centre (the mean
      averages out wobble of a turn that is steady only nearly);
    - turning diameter = 2 * the largest radius of the wheel contacts wheel_contacts, (name, px, py)
      [m] in the body frame;
    - clearance diameter = 2 * the largest radius of the points of outline, the body-frame polygon
      (px, py) [m] of the robot's plan outline (frame, wheels, tools), and of the wheel contacts (a
      contact is a point of the robot too, so clearance >= turning always). A polygon's points
      farthest from any centre are vertices (the distance from a point is convex along an edge, so
      its maximum on the edge is at an end): the vertices are enough.

    MetricError when the origin's path is a straight line (not a turn)."""
    if not wheel_contacts:
        raise MetricError("turning_diameters: no wheel contacts")
    if len(track) < 3:
        raise MetricError(f"turning_diameters: {len(track)} poses; a turn needs at least 3")
    mx, my = float(np.mean(track.x)), float(np.mean(track.y))
    spin = float(np.max(np.hypot(track.x - mx, track.y - my))) <= spin_tolerance
    if spin:
        centre = (mx, my)
    else:
        try:
            cx, cy, _, _ = fit_circle(track.x, track.y)
        except MetricError as error:
            raise MetricError(f"turning_diameters: the track is not a turn ({error})") from None
        centre = (cx, cy)

    def radius(px: float, py: float) -> Tuple[float, float]:
        wx, wy = body_point_path(track, px, py)
        d = np.hypot(wx - centre[0], wy - centre[1])
        return float(np.mean(d)), float(np.std(d))

    wheels = [(name, *radius(px, py), (float(px), float(py))) for name, px, py in wheel_contacts]
    others = [(*radius(px, py), (float(px), float(py))) for px, py in outline]
    outer = max(wheels, key=lambda w: w[1])
    spread = max([w[2] for w in wheels] + [o[1] for o in others])
    # the outermost point: the outer wheel's contact unless a point of the outline is further out
    clearance, point = max([(outer[1], outer[3])] + [(o[0], o[2]) for o in others], key=lambda c: c[0])
    return TurningDiameters(2.0 * outer[1], 2.0 * clearance, centre, outer[0], spin, spread, point)


# --- drift -----------------------------------------------------------------------------------


@dataclass(frozen=True)
class Drift:
    """Lateral drift over a straight traverse: per_m [m/m] sideways per metre along, total [m]
    sideways at the end (positive: to the left of the heading), distance [m] along the heading,
    max_offset [m] the largest sideways offset at any pose (signed, the one of largest size)."""

    per_m: float
    total: float
    distance: float
    max_offset: float


def lateral_drift(track: Track, heading: float) -> Drift:
    """How far a traverse meant to follow the straight line from its start along heading [rad] ended
    up beside it (side slopes, uneven traction).

    With u = (cos heading, sin heading) along the line and n = (-sin heading, cos heading) its left
    normal, the displacement d of the body origin from its start splits into distance = d . u along
    the line and total = d . n across it (positive to the left); per_m = total / distance. A track
    that runs straight at an angle a off the heading has d = s (cos(heading + a), sin(heading + a)),
    so d . u = s cos a, d . n = s sin a and per_m = tan a. MetricError when the robot did not advance
    along the heading."""
    ux, uy = math.cos(heading), math.sin(heading)
    dx, dy = track.x - track.x[0], track.y - track.y[0]
    along = dx * ux + dy * uy
    across = -dx * uy + dy * ux
    distance, total = float(along[-1]), float(across[-1])
    if distance <= 0.0:
        raise MetricError(
            f"lateral_drift: the robot advanced {distance:.3f} m along the heading {heading:.3f} rad; drift needs > 0"
        )
    worst = int(np.argmax(np.abs(across)))
    return Drift(total / distance, total, distance, float(across[worst]))


# --- ramps -----------------------------------------------------------------------------------


@dataclass(frozen=True)
class Climb:
    """The outcome of a ramp climb: reached the top (and stayed there), max_progress_m [m] the
    farthest the body origin got past the ramp's foot (horizontally, along x), slid_back_m [m] how far
    it came back down from there when it did not reach the top, stalled: it did not reach the top and
    made less than the asked progress in the last window (stopped, spinning its wheels, or sliding)."""

    reached: bool
    max_progress_m: float
    slid_back_m: float
    stalled: bool


def climbed(
    track: Track, ramp_start_x: float, ramp_top_x: float, window: float = 2.0, min_progress: float = 0.02
) -> Climb:
    """Whether a robot driven up a ramp along +x reached its top.

    The positions are the body origin's x [m]: ramp_start_x where the origin is at the foot of the
    ramp, ramp_top_x where the origin stands when the robot is on top (the caller adds the distance
    from the origin to the front or rear wheels as the study means it). Then:

    - reached: the final x >= ramp_top_x (got there and did not come back down);
    - max_progress_m = max(x) - ramp_start_x, at least 0;
    - slid_back_m = max(x) - final x when not reached (0 when reached: what the robot does on top is
      not a slide down the ramp);
    - stalled: not reached, and the progress final x - x(t_end - window) over the last window [s] is
      below min_progress [m] (a slide back is negative progress, so it stalls too); with neither, the
      run ended while the robot was still climbing."""
    x = track.x
    x_end = float(x[-1])
    x_max = float(np.max(x))
    reached = x_end >= ramp_top_x
    t_from = max(float(track.t[-1]) - window, float(track.t[0]))
    x_from = float(np.interp(t_from, track.t, x))
    stalled = (not reached) and (x_end - x_from) < min_progress
    slid_back = 0.0 if reached else x_max - x_end
    return Climb(reached, max(x_max - ramp_start_x, 0.0), slid_back, stalled)


# --- plants ----------------------------------------------------------------------------------


@dataclass(frozen=True)
class PlantsTouched:
    """The plants touched over a track: how many, and their indices (increasing) in the plants array."""

    count: int
    indices: Tuple[int, ...]


def plants_touched(
    track: Track,
    footprints: Sequence[Tuple[float, float, float, float]],
    plants,
    plant_radius: float,
) -> PlantsTouched:
    """Which plants the robot touched over the track.

    footprints: body-frame rectangles (cx, cy, length, width) [m], sides along the body axes, of what
    touches plants (wheels, the frame's low parts); plants: (x, y) [m] world positions, each a circle
    of plant_radius [m]. A plant is touched when at some pose its circle meets a footprint:
    in the rectangle's frame the plant's centre q = R(-yaw) (p - origin) - (cx, cy); the rectangle's
    point nearest to it is q clamped to the rectangle, so its distance from the rectangle is
    |(max(|qx| - length/2, 0), max(|qy| - width/2, 0))|, and they meet when that is <= plant_radius
    (a plant grazed is touched; a plant of radius 0 is touched when its centre is in the rectangle).

    The poses are samples: a pose step larger than about plant_radius + the footprint's size along the
    motion can step over a plant; sample the track finely enough.

    Vectorised, culled by distance: no footprint reaches farther than reach = max over footprints of
    |(|cx| + length/2, |cy| + width/2)| from the origin, so a plant farther than reach + plant_radius
    from the origin at a pose cannot be touched at it. The plants are sorted by x once; for each chunk
    of consecutive poses (close together along the track) only the plants within the chunk's bounding
    box grown by that distance (a searchsorted slab in x, then a mask in y), and not touched already,
    go into the full test."""
    pts = np.asarray(plants, dtype=float).reshape(-1, 2)
    rects = np.asarray(footprints, dtype=float).reshape(-1, 4)
    if plant_radius < 0.0:
        raise MetricError(f"plants_touched: plant_radius {plant_radius} m; must be >= 0")
    if rects.size and np.any(rects[:, 2:] <= 0.0):
        raise MetricError("plants_touched: a footprint's length and width must be > 0")
    if pts.shape[0] == 0 or rects.shape[0] == 0:
        return PlantsTouched(0, ())
    half = rects[:, 2:] / 2.0
    reach = float(np.max(np.hypot(np.abs(rects[:, 0]) + half[:, 0], np.abs(rects[:, 1]) + half[:, 1])))
    reach += plant_radius
    r2 = plant_radius * plant_radius
    order = np.argsort(pts[:, 0], kind="stable")
    sx, sy = pts[order, 0], pts[order, 1]
    touched = np.zeros(sx.size, dtype=bool)  # in sorted order
    for start in range(0, len(track), POSES_PER_CHUNK):
        k = slice(start, start + POSES_PER_CHUNK)
        x, y, yaw = track.x[k], track.y[k], track.yaw[k]
        lo = int(np.searchsorted(sx, float(np.min(x)) - reach, side="left"))
        hi = int(np.searchsorted(sx, float(np.max(x)) + reach, side="right"))
        live = np.arange(lo, hi)
        live = live[(sy[lo:hi] >= float(np.min(y)) - reach) & (sy[lo:hi] <= float(np.max(y)) + reach) & ~touched[lo:hi]]
        if live.size == 0:
            continue
        dx = sx[live][None, :] - x[:, None]  # poses x plants
        dy = sy[live][None, :] - y[:, None]
        pose, plant = np.nonzero(dx * dx + dy * dy <= reach * reach)
        if pose.size == 0:
            continue
        c, s = np.cos(yaw[pose]), np.sin(yaw[pose])
        wx, wy = dx[pose, plant], dy[pose, plant]
        bx, by = c * wx + s * wy, -s * wx + c * wy  # R(-yaw) (p - origin): the plant in the body frame
        hit = np.zeros(pose.size, dtype=bool)
        for (cx, cy, _, _), (hx, hy) in zip(rects, half):
            ex = np.maximum(np.abs(bx - cx) - hx, 0.0)
            ey = np.maximum(np.abs(by - cy) - hy, 0.0)
            hit |= ex * ex + ey * ey <= r2
        touched[live[plant[hit]]] = True
    indices = np.sort(order[touched])
    return PlantsTouched(int(indices.size), tuple(int(i) for i in indices))
