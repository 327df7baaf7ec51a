"""A robot description's joints as robot_state_publisher reads them, and the transforms they give.

Pure: URDF text in, tuples out (no ROS, no pybullet). ``link_tree`` gives each child link's joint
(the simulator mounts sensors with it); ``JointTree`` turns joint positions into the transforms
robot_state_publisher publishes: parent link -> child link for every moving joint (revolute,
continuous, prismatic; a mimic joint follows its joint as ``multiplier * q + offset``), and once
for every fixed one. A transform is ``((x, y, z), (qx, qy, qz, qw))``: the joint's origin, then its
motion along or about its axis, as URDF defines them.
"""

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Dict, Iterable, List, Mapping, Optional, Tuple, Union

from .errors import UrdfError

Vec3 = Tuple[float, float, float]
Quat = Tuple[float, float, float, float]
Transform = Tuple[Vec3, Quat]
MOVING = ("revolute", "continuous", "prismatic")  # URDF joint types
FIXED = "fixed"


@dataclass(frozen=True)
class Origin:
    """A joint's <origin>: translation [m], then roll, pitch, yaw [rad] about fixed axes."""

    xyz: Vec3 = (0.0, 0.0, 0.0)
    rpy: Vec3 = (0.0, 0.0, 0.0)


@dataclass(frozen=True)
class Mimic:
    """<mimic joint multiplier offset>: this joint's position is multiplier * q(joint) + offset."""

    joint: str
    multiplier: float = 1.0
    offset: float = 0.0


@dataclass(frozen=True)
class ParentJoint:
    """How a link hangs from its parent: the joint's name, type and origin (and axis, mimic)."""

    parent: str
    joint: str
    type: str
    origin: Origin
    axis: Vec3 = (1.0, 0.0, 0.0)  # URDF's default
    mimic: Optional[Mimic] = None


def _triple(text: Optional[str], what: str, default: Vec3 = (0.0, 0.0, 0.0)) -> Vec3:
    if not text:
        return default
    try:
        values = tuple(float(v) for v in text.split())
    except ValueError:
        values = ()
    if len(values) != 3:
        raise UrdfError(f"{what}: {text!r} is not 3 numbers")
    return values  # type: ignore[return-value]


def link_tree(xml: Union[str, ET.Element]) -> Dict[str, ParentJoint]:
    """Each child link's joint to its parent (the root link has none), of a description's text or
    its parsed ``<robot>``; UrdfError if unreadable."""
    if isinstance(xml, str):
        try:
            root = ET.fromstring(xml)
        except ET.ParseError as e:
            raise UrdfError(f"the robot description is not valid XML: {e}") from None
    else:
        root = xml
    tree = {}
    for j in root.findall("joint"):
        parent, child = j.find("parent"), j.find("child")
        if parent is None or child is None:
            continue
        name = j.get("name", "")
        origin = j.find("origin")
        xyz = _triple(origin.get("xyz") if origin is not None else None, f"joint {name} origin xyz")
        rpy = _triple(origin.get("rpy") if origin is not None else None, f"joint {name} origin rpy")
        axis_element = j.find("axis")
        axis = _triple(axis_element.get("xyz") if axis_element is not None else None, f"joint {name} axis", (1, 0, 0))
        norm = math.sqrt(sum(a * a for a in axis))
        if norm == 0.0 and j.get("type") in MOVING:
            raise UrdfError(f"joint {name} axis: {axis!r} has no direction")
        if norm:
            axis = (axis[0] / norm, axis[1] / norm, axis[2] / norm)
        mimic = None
        m = j.find("mimic")
        if m is not None:
            try:
                mimic = Mimic(m.get("joint", ""), float(m.get("multiplier", 1.0)), float(m.get("offset", 0.0)))
            except ValueError:
                raise UrdfError(f"joint {name} mimic: multiplier or offset is not a number") from None
        tree[child.get("link", "")] = ParentJoint(
            parent.get("link", ""), name, j.get("type", ""), Origin(xyz, rpy), axis, mimic
        )
    return tree


# ---- rotations: quaternions (x, y, z, w) ----------------------------------------------------------
def quaternion_from_rpy(roll: float, pitch: float, yaw: float) -> Quat:
    """Roll about x, then pitch about y, then yaw about z, all about fixed axes (URDF's rpy)."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )


def quaternion_multiply(a: Quat, b: Quat) -> Quat:
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    )


def rotate(q: Quat, v: Vec3) -> Vec3:
    """v rotated by the unit quaternion q."""
    x, y, z, w = q
    # t = 2 q_v x v; v' = v + w t + q_v x t
    tx = 2 * (y * v[2] - z * v[1])
    ty = 2 * (z * v[0] - x * v[2])
    tz = 2 * (x * v[1] - y * v[0])
    return (
        v[0] + w * tx + (y * tz - z * ty),
        v[1] + w * ty + (z * tx - x * tz),
        v[2] + w * tz + (x * ty - y * tx),
    )


IDENTITY_TRANSFORM: Transform = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))


def compose(a: Transform, b: Transform) -> Transform:
    """The transform a then b (b expressed in a's child frame)."""
    (ax, ay, az), qa = a
    bx, by, bz = rotate(qa, b[0])
    return (ax + bx, ay + by, az + bz), quaternion_multiply(qa, b[1])


def inverse(t: Transform) -> Transform:
    """The inverse transform: ``compose(t, inverse(t))`` is the identity."""
    (x, y, z), (qx, qy, qz, qw) = t
    conj = (-qx, -qy, -qz, qw)
    tx, ty, tz = rotate(conj, (x, y, z))
    return (-tx, -ty, -tz), conj


class JointTree:
    """The transforms of a robot description's joints, as robot_state_publisher computes them."""

    def __init__(self, xml: str):
        self.tree = link_tree(xml)
        self.joints: Dict[str, Tuple[str, ParentJoint]] = {pj.joint: (child, pj) for child, pj in self.tree.items()}
        self._origins = {pj.joint: (pj.origin.xyz, quaternion_from_rpy(*pj.origin.rpy)) for pj in self.tree.values()}
        self.mimics: Dict[str, List[str]] = {}
        for pj in self.tree.values():
            if pj.mimic is not None and pj.type in MOVING:
                if pj.mimic.joint not in self.joints:
                    raise UrdfError(f"joint {pj.joint} mimic: no joint {pj.mimic.joint!r}")
                self.mimics.setdefault(pj.mimic.joint, []).append(pj.joint)

    def moving(self, name: str) -> bool:
        entry = self.joints.get(name)
        return entry is not None and entry[1].type in MOVING

    def transform(self, name: str, position: float) -> Transform:
        """The joint's parent -> child transform at position [rad or m]."""
        _, pj = self.joints[name]
        xyz, q = self._origins[name]
        axis = pj.axis
        if pj.type == "prismatic":
            offset = rotate(q, (axis[0] * position, axis[1] * position, axis[2] * position))
            return (xyz[0] + offset[0], xyz[1] + offset[1], xyz[2] + offset[2]), q
        if pj.type in ("revolute", "continuous"):
            s = math.sin(position / 2)
            return xyz, quaternion_multiply(q, (axis[0] * s, axis[1] * s, axis[2] * s, math.cos(position / 2)))
        return xyz, q

    def moving_transforms(self, positions: Mapping[str, float]) -> List[Tuple[str, str, Transform]]:
        """(parent link, child link, transform) of each moving joint in positions, and of the joints
        that mimic one of them; joints that are not moving ones of this description are skipped."""
        out = []
        for name, q in positions.items():
            if not self.moving(name):
                continue
            child, pj = self.joints[name]
            out.append((pj.parent, child, self.transform(name, q)))
            for follower in self.mimics.get(name, ()):
                fchild, fpj = self.joints[follower]
                mimic = fpj.mimic
                out.append((fpj.parent, fchild, self.transform(follower, mimic.multiplier * q + mimic.offset)))
        return out

    def fixed_transforms(self) -> List[Tuple[str, str, Transform]]:
        """(parent link, child link, transform) of every fixed joint."""
        return [
            (pj.parent, child, self.transform(pj.joint, 0.0)) for child, pj in self.tree.items() if pj.type == FIXED
        ]


def joint_positions(names: Iterable[str], positions: Iterable[float]) -> Dict[str, float]:
    """A JointState's names and positions paired, non-finite positions left out."""
    return {n: float(q) for n, q in zip(names, positions) if math.isfinite(q)}
