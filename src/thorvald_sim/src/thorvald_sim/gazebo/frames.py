"""Poses and twists in reference frames, as Gazebo's ROS API computes them (no ROS, no pybullet).

A pose is ``(position, orientation)``: a 3-tuple [m] and a unit quaternion ``(x, y, z, w)``, the
pose of a frame in its parent (the world, or a reference entity). Gazebo writes its frame arithmetic
with ignition's ``Pose3`` operators, where ``a + b`` is ``a`` expressed in ``b`` taken to ``b``'s
parent (``b`` composed with ``a``) and ``a - b`` is ``a`` seen from ``b``; here they are
:func:`in_parent` and :func:`seen_from`, and every service of :mod:`thorvald_sim.gazebo.api` uses
them as gazebo_ros's api plugin does:

* get_model_state / get_link_state: the pose seen from the reference entity; velocities made relative
  (minus the entity's) and turned into its axes;
* set_model_state / spawn: the requested pose taken from the reference entity to the world;
  velocities turned from its axes into the world's (set_link_state: minus the entity's, not turned);
* apply_body_wrench: a wrench at a point of the reference entity moved to the body's origin
  (:func:`wrench_on_body`).
"""

import math
from typing import Sequence, Tuple

from thorvald_model.joint_tree import compose, inverse, rotate

Vec3 = Tuple[float, float, float]
Quat = Tuple[float, float, float, float]  # x, y, z, w
Pose = Tuple[Vec3, Quat]

IDENTITY: Quat = (0.0, 0.0, 0.0, 1.0)
ORIGIN: Pose = ((0.0, 0.0, 0.0), IDENTITY)


def normalised(q: Sequence[float]) -> Quat:
    """q of length one; a quaternion of length zero is the identity, as ignition's Normalize makes it
    (a message's default orientation is all zeros)."""
    x, y, z, w = (float(v) for v in q)
    n = math.sqrt(x * x + y * y + z * z + w * w)
    if n < 1e-12:
        return IDENTITY
    return (x / n, y / n, z / n, w / n)


def rotate_reverse(q: Quat, v: Sequence[float]) -> Vec3:
    """v turned by the inverse of q (from the parent's axes into q's frame)."""
    return rotate((-q[0], -q[1], -q[2], q[3]), v)


def add(a: Sequence[float], b: Sequence[float]) -> Vec3:
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


def sub(a: Sequence[float], b: Sequence[float]) -> Vec3:
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def cross(a: Sequence[float], b: Sequence[float]) -> Vec3:
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def in_parent(pose: Pose, frame: Pose) -> Pose:
    """pose, given in frame, in frame's parent (ignition's ``pose + frame``)."""
    position, q = compose(frame, pose)
    return position, normalised(q)


def seen_from(pose: Pose, frame: Pose) -> Pose:
    """pose, given in the parent, seen from frame (ignition's ``pose - frame``)."""
    position, q = compose(inverse(frame), pose)
    return position, normalised(q)


def twist_seen_from(linear: Vec3, angular: Vec3, frame: Pose, frame_linear: Vec3, frame_angular: Vec3):
    """A world twist relative to a moving frame, in its axes (get_model_state, get_link_state)."""
    fq = frame[1]
    return rotate_reverse(fq, sub(linear, frame_linear)), rotate_reverse(fq, sub(angular, frame_angular))


def wrench_on_body(force: Vec3, torque: Vec3, point: Vec3, frame: Pose, body: Pose) -> Tuple[Vec3, Vec3]:
    """apply_body_wrench's arithmetic: a force and torque given in frame's axes at point of frame, as
    the force and torque gazebo_ros hands to the body (``Link::SetForce``, ``SetTorque``): the torque
    first moved to frame's origin (torque + point x force), then both turned by the rotation of
    ``frame - body`` and the torque moved by its position (``transformWrench``)."""
    torque = add(torque, cross(point, force))
    offset = seen_from(frame, body)
    f = rotate(offset[1], force)
    t = rotate(offset[1], torque)
    return f, add(t, cross(offset[0], f))


def euler_of(q: Quat) -> Vec3:
    """(roll, pitch, yaw) [rad] of q: fixed axes x, y, z (URDF's rpy)."""
    x, y, z, w = q
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return roll, pitch, yaw


def finite(*values: Sequence[float]) -> bool:
    """Every number of every sequence is finite."""
    return all(math.isfinite(v) for seq in values for v in seq)
