"""A Gazebo world's actors (``<actor>``): their scripts' trajectories on ignition-math 6's splines, as
Gazebo 11's ``PoseAnimation`` plays them (:class:`Actor`, :meth:`Actor.pose_at`), and the model an actor
is simulated as here (:func:`actor_model`). Read from a world by :mod:`~thorvald_sim.world.gazebo_world`,
whose docstring says what Gazebo does and where it says so.

Pure: no pybullet, no ROS.
"""

import bisect
import math
from dataclasses import dataclass, field, replace
from typing import List, Optional, Tuple

from ..models.sdf import parse_sdf_model
from ..models.spec import IDENTITY, Cylinder, ModelSpec, Pose, Vec3

PERSON = Cylinder(0.25, 1.8)  # [m] an actor's body here: a person-sized cylinder, centred on its pose
EPSILON = 1e-6  # ignition::math::equal's default tolerance
CLOSE = 1e-3  # ignition-math's == of vectors and quaternions (each component)


@dataclass(frozen=True)
class Trajectory:
    """One ``<trajectory>`` of an actor's script, as Gazebo keys it: ``times`` sorted, the first 0, and
    the pose at each (``poses``), with the splines' tangents; it lasts ``duration`` (its last waypoint's
    time) from ``start`` in the script. A trajectory without waypoints plays a skeleton animation
    only (``times`` empty)."""

    id: int
    type: str
    times: Tuple[float, ...]
    poses: Tuple[Pose, ...]
    duration: float
    start: float = 0.0
    position_tangents: Tuple[Vec3, ...] = field(default=(), repr=False)
    rotation_tangents: Tuple[Tuple[float, float, float, float], ...] = field(default=(), repr=False)

    @property
    def end(self) -> float:
        return self.start + self.duration

    def pose_at(self, time: float) -> Pose:
        """The pose ``time`` [s] after the trajectory's start (clamped to it), as Gazebo's
        ``PoseAnimation`` interpolates it; the origin for a trajectory without waypoints (Gazebo's
        default pose, which it sets when there is no skeleton animation to add)."""
        if not self.times:
            return IDENTITY
        return _keyframe_pose(self, min(max(time, 0.0), self.duration))


@dataclass(frozen=True)
class Actor:
    """An ``<actor>``: its own ``pose`` (where it stands before and without its script), its
    ``skin`` (as written; ``skin_path``: the file found, or None), and its script."""

    name: str
    pose: Pose
    skin: str = ""
    skin_path: Optional[str] = None
    skin_scale: float = 1.0
    loop: bool = True
    delay_start: float = 0.0  # [s]
    auto_start: bool = True
    trajectories: Tuple[Trajectory, ...] = ()
    body: Cylinder = PERSON

    @property
    def script_length(self) -> float:
        return sum(t.duration for t in self.trajectories)

    def pose_at(self, t: float) -> Pose:
        """The actor's pose at sim time t [s] as Gazebo 11's ``Actor::Update`` sets it (continuously:
        Gazebo does it every 1/30 s at most; without a skin's root bone offset)."""
        if not self.auto_start or not any(tr.times for tr in self.trajectories):
            return self.pose  # nothing plays it (a plugin would), or nothing moves it
        length = self.script_length
        s = t - self.delay_start
        if s < 0:
            return self.pose
        if length <= 0:
            return next(tr.poses[0] for tr in self.trajectories if tr.times)
        if s >= length:
            if not self.loop:
                return self._script_pose(length)
            # each cycle waits delay_start again at the script's first pose (set when it wrapped)
            s = math.fmod(s, length + self.delay_start)
            if s >= length:
                return self._script_pose(0.0)
        return self._script_pose(s)

    def _script_pose(self, s: float) -> Pose:
        for trajectory in self.trajectories:
            if trajectory.start <= s <= trajectory.end:
                return trajectory.pose_at(s - trajectory.start)
        return self.pose


def actor_model(actor: Actor) -> ModelSpec:
    """The model an actor is simulated as: a static cylinder of its body's size, centred on its pose
    (moved by its script: :meth:`thorvald_sim.gazebo.bodies.GazeboBodies.animate`)."""
    radius, length = actor.body.radius, actor.body.length
    shape = f"<geometry><cylinder><radius>{radius!r}</radius><length>{length!r}</length></cylinder></geometry>"
    text = (
        f"<sdf version='1.6'><model name='{actor.name}'><static>true</static><link name='body'>"
        f"<collision name='body'>{shape}</collision><visual name='body'>{shape}"
        "<material><diffuse>0.8 0.5 0.3 1</diffuse></material></visual></link></model></sdf>"
    )
    return replace(parse_sdf_model(text, f"actor {actor.name}"), kinematic=True)


# ---------------------------------------------------------------------------------------------
# An actor's trajectory: ignition-math 6's splines, as Gazebo's PoseAnimation uses them
# ---------------------------------------------------------------------------------------------
_Quat = Tuple[float, float, float, float]  # (w, x, y, z): ignition-math's order, here only


def trajectory(id_: int, kind: str, points: List[Tuple[float, Pose]]) -> Trajectory:
    """A trajectory of (time, pose) sorted by time: the first key moved to time 0 (Actor::LoadScript),
    the keys in order of time (CreateKeyFrame's upper_bound), the splines' tangents made once."""
    duration = points[-1][0]
    keys = [(0.0 if i == 0 and abs(t) > EPSILON else t, pose) for i, (t, pose) in enumerate(points)]
    keys.sort(key=lambda k: k[0])
    positions = [pose[0] for _, pose in keys]
    rotations = [_wxyz(pose[1]) for _, pose in keys]
    return Trajectory(
        id_,
        kind,
        tuple(t for t, _ in keys),
        tuple(pose for _, pose in keys),
        duration,
        position_tangents=tuple(_position_tangents(positions)),
        rotation_tangents=tuple(_rotation_tangents(rotations)),
    )


def _keyframe_pose(trajectory: Trajectory, time: float) -> Pose:
    """PoseAnimation::GetInterpolatedKeyFrame: the keys around time (Animation::GetKeyFramesAtTime),
    the fraction of the time between them, the splines from the first."""
    times = trajectory.times
    j = bisect.bisect_left(times, time)  # the first key at or after time
    if j == len(times):
        t2 = trajectory.duration + times[0]  # none after it: "wrap back to the first"
        j -= 1
    else:
        t2 = times[j]
        if j != 0 and time < times[j]:
            j -= 1
    t1 = times[j]
    t = 0.0 if abs(t1 - t2) <= EPSILON else (time - t1) / (t2 - t1)
    if abs(t) <= EPSILON:
        return trajectory.poses[j]
    return (_position(trajectory, j, t), _xyzw(_rotation(trajectory, j, t)))


def _position_tangents(points: List[Vec3]) -> List[Vec3]:
    """Spline::RecalcTangents, tension 0: Catmull-Rom; an end's from its one neighbour, or (the ends
    equal within 1e-3: closed) the other end's."""
    n = len(points)
    if n < 2:
        return [(0.0, 0.0, 0.0)] * n
    closed = all(abs(a - b) <= CLOSE for a, b in zip(points[0], points[-1]))

    def half(a: Vec3, b: Vec3) -> Vec3:
        return ((a[0] - b[0]) * 0.5, (a[1] - b[1]) * 0.5, (a[2] - b[2]) * 0.5)

    tangents = []
    for i in range(n):
        if i == 0:
            tangents.append(half(points[1], points[n - 2] if closed else points[0]))
        elif i == n - 1:
            tangents.append(tangents[0] if closed else half(points[i], points[i - 1]))
        else:
            tangents.append(half(points[i + 1], points[i - 1]))
    return tangents


def _position(trajectory: Trajectory, i: int, t: float) -> Vec3:
    """Spline::Interpolate(i, t): the cubic Hermite segment from key i (key i itself past the last)."""
    points = [pose[0] for pose in trajectory.poses]
    if i + 1 >= len(points):
        return points[i]
    p0, p1 = points[i], points[i + 1]
    m0, m1 = trajectory.position_tangents[i], trajectory.position_tangents[i + 1]
    t2, t3 = t * t, t * t * t
    h00, h01, h10, h11 = 2 * t3 - 3 * t2 + 1, -2 * t3 + 3 * t2, t3 - 2 * t2 + t, t3 - t2
    return tuple(h00 * a + h01 * b + h10 * c + h11 * d for a, b, c, d in zip(p0, p1, m0, m1))  # type: ignore[return-value]


def _rotation_tangents(points: List[_Quat]) -> List[_Quat]:
    """RotationSpline::RecalcTangents (Shoemake): p exp(-(log(p^-1 next) + log(p^-1 previous)) / 4)."""
    n = len(points)
    if n < 2:
        return list(points)
    closed = all(abs(a - b) <= CLOSE for a, b in zip(points[0], points[-1]))
    tangents = []
    for i, p in enumerate(points):
        inverse = _qinverse(p)
        if i == 0:
            part1 = _qlog(_qmul(inverse, points[1]))
            part2 = _qlog(_qmul(inverse, points[n - 2] if closed else p))
        elif i == n - 1:
            part1 = _qlog(_qmul(inverse, points[1] if closed else p))
            part2 = _qlog(_qmul(inverse, points[i - 1]))
        else:
            part1 = _qlog(_qmul(inverse, points[i + 1]))
            part2 = _qlog(_qmul(inverse, points[i - 1]))
        tangents.append(_qmul(p, _qexp(tuple((a + b) * -0.25 for a, b in zip(part1, part2)))))  # type: ignore[arg-type]
    return tangents


def _rotation(trajectory: Trajectory, i: int, t: float) -> _Quat:
    """RotationSpline::Interpolate(i, t, shortest path): squad between keys i and i + 1."""
    points = [_wxyz(pose[1]) for pose in trajectory.poses]
    if i + 1 >= len(points):
        return points[i]
    if abs(t) <= EPSILON:
        return points[i]
    if abs(t - 1.0) <= EPSILON:
        return points[i + 1]
    a, b = trajectory.rotation_tangents[i], trajectory.rotation_tangents[i + 1]
    return _squad(t, points[i], a, b, points[i + 1], shortest=True)


def _squad(t: float, p: _Quat, a: _Quat, b: _Quat, q: _Quat, *, shortest: bool) -> _Quat:
    return _slerp(2.0 * t * (1.0 - t), _slerp(t, p, q, shortest), _slerp(t, a, b, False), False)


def _slerp(t: float, p: _Quat, q: _Quat, shortest: bool) -> _Quat:
    """Quaternion::Slerp: the standard slerp, or (within 1e-3 of the same or opposite) a normalised lerp."""
    cos = sum(a * b for a, b in zip(p, q))
    if cos < 0.0 and shortest:
        cos, q = -cos, (-q[0], -q[1], -q[2], -q[3])
    if abs(cos) < 1 - 1e-3:
        sin = math.sqrt(1 - cos * cos)
        angle = math.atan2(sin, cos)
        c0, c1 = math.sin((1.0 - t) * angle) / sin, math.sin(t * angle) / sin
        return (p[0] * c0 + q[0] * c1, p[1] * c0 + q[1] * c1, p[2] * c0 + q[2] * c1, p[3] * c0 + q[3] * c1)
    mixed = tuple(a * (1.0 - t) + b * t for a, b in zip(p, q))
    norm = math.sqrt(sum(c * c for c in mixed))
    if norm <= EPSILON:
        return (1.0, 0.0, 0.0, 0.0)
    return (mixed[0] / norm, mixed[1] / norm, mixed[2] / norm, mixed[3] / norm)


def _qmul(a: _Quat, b: _Quat) -> _Quat:
    aw, ax, ay, az = a
    bw, bx, by, bz = b
    return (
        aw * bw - ax * bx - ay * by - az * bz,
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
    )


def _qinverse(q: _Quat) -> _Quat:
    s = sum(c * c for c in q)
    if abs(s) <= EPSILON:
        return (1.0, 0.0, 0.0, 0.0)
    return (q[0] / s, -q[1] / s, -q[2] / s, -q[3] / s)


def _qlog(q: _Quat) -> _Quat:
    w, x, y, z = q
    if abs(w) < 1.0:
        angle = math.acos(w)
        sin = math.sin(angle)
        if abs(sin) >= 1e-3:
            c = angle / sin
            return (0.0, c * x, c * y, c * z)
    return (0.0, x, y, z)


def _qexp(q: _Quat) -> _Quat:
    _, x, y, z = q
    angle = math.sqrt(x * x + y * y + z * z)
    sin = math.sin(angle)
    if abs(sin) >= 1e-3:
        c = sin / angle
        return (math.cos(angle), c * x, c * y, c * z)
    return (math.cos(angle), x, y, z)


def _wxyz(q) -> _Quat:
    return (q[3], q[0], q[1], q[2])


def _xyzw(q: _Quat):
    return (q[1], q[2], q[3], q[0])
