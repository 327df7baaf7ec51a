"""A model that is not a Thorvald robot, as values: what an SDF ``<model>`` or a generic URDF says, read
once (:mod:`.sdf`, :mod:`.urdf_model`) and built in pybullet by :mod:`.build`. Pure: no pybullet, no ROS.

Frames, all resolved by the readers (SDF's ``relative_to``, ``expressed_in`` and versions, URDF's joint
origins), so the builder never asks which format a model came from:

- a link's ``pose``: the link frame in the model frame;
- a collision's, visual's and inertial's ``pose``: in its link's frame;
- a joint's ``pose``: the joint frame in its child link's frame (SDF's convention; identity from a URDF,
  whose child link frame is the joint frame); its ``axis``: a unit vector in the joint frame.

A pose is ``((x, y, z), (qx, qy, qz, qw))`` [m], a unit quaternion; SI units throughout.
"""

import math
from dataclasses import dataclass, replace
from typing import Dict, List, Optional, Tuple, Union

from thorvald_model.joint_tree import compose, inverse, quaternion_from_rpy, rotate

from ..errors import ModelError

__all__ = ["compose", "inverse"]  # re-exported for the readers

Vec3 = Tuple[float, float, float]
Quat = Tuple[float, float, float, float]
Pose = Tuple[Vec3, Quat]
Matrix3 = Tuple[Vec3, Vec3, Vec3]

IDENTITY: Pose = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))
IDENTITY_INERTIA: Matrix3 = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))  # [kg m^2], SDF's default

WORLD = "world"  # a joint's parent that is the world (SDF and URDF both spell it so)

JOINT_TYPES = ("fixed", "revolute", "prismatic")  # a continuous joint is a revolute one without limits
FIXED, REVOLUTE, PRISMATIC = JOINT_TYPES


# ---- poses ----------------------------------------------------------------------------------------
def pose_from_xyz_rpy(xyz: Vec3, rpy: Vec3) -> Pose:
    """The pose of a translation [m] and roll, pitch, yaw [rad] about fixed axes (SDF's and URDF's)."""
    return (tuple(xyz), quaternion_from_rpy(*rpy))  # type: ignore[return-value]


def chain(*poses: Pose) -> Pose:
    """The transforms one after the other, each expressed in the frame the previous one gives."""
    result = IDENTITY
    for pose in poses:
        result = compose(result, pose)
    return result


def relative(frame: Pose, of: Pose) -> Pose:
    """``of`` (in some frame A) expressed in ``frame`` (also in A)."""
    return compose(inverse(frame), of)


def rotate_vector(pose: Pose, v: Vec3) -> Vec3:
    """v rotated by the pose's orientation (no translation: a direction)."""
    return rotate(pose[1], v)


# ---- geometry -------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Box:
    size: Vec3  # [m] full lengths along x, y, z


@dataclass(frozen=True)
class Cylinder:
    radius: float  # [m]
    length: float  # [m] along the cylinder's own z, centred


@dataclass(frozen=True)
class Sphere:
    radius: float  # [m]


@dataclass(frozen=True)
class Plane:
    normal: Vec3  # unit vector in the collision's frame
    size: Tuple[float, float]  # [m] as SDF gives it (drawn; it collides as an infinite plane, as in Gazebo)


@dataclass(frozen=True)
class Mesh:
    path: str  # absolute path of the file (.obj, .stl or .dae), as the finder resolved it
    scale: Vec3 = (1.0, 1.0, 1.0)
    uri: str = ""  # as the file wrote it (messages)


Geometry = Union[Box, Cylinder, Sphere, Plane, Mesh]


# ---- surfaces, shapes, links, joints --------------------------------------------------------------
@dataclass(frozen=True)
class Surface:
    """Gazebo's ODE surface of one collision: friction coefficients along the first and second
    friction directions, the contact's stiffness [N/m] and damping [N s/m] when given (``None``: rigid,
    as Gazebo's default kp of 1e12 is), and the coefficient of restitution."""

    mu: float = 1.0  # SDF's default
    mu2: float = 1.0
    kp: Optional[float] = None  # [N/m]
    kd: Optional[float] = None  # [N s/m]
    restitution: float = 0.0


@dataclass(frozen=True)
class CollisionSpec:
    name: str  # as Gazebo names it (a URDF's: as Gazebo's URDF conversion names it)
    pose: Pose  # in the link frame
    geometry: Geometry
    surface: Surface = Surface()


@dataclass(frozen=True)
class VisualSpec:
    name: str
    pose: Pose  # in the link frame
    geometry: Geometry
    rgba: Optional[Tuple[float, float, float, float]] = None  # None: the file's own colours, or grey


@dataclass(frozen=True)
class Inertial:
    mass: float  # [kg]
    pose: Pose = IDENTITY  # the centre of mass and the inertia's axes, in the link frame
    inertia: Matrix3 = IDENTITY_INERTIA  # [kg m^2] about the centre of mass, in the pose's axes


@dataclass(frozen=True)
class LinkSpec:
    name: str  # scoped in its model: ``link``, or ``inner::link`` in a nested model
    pose: Pose  # the link frame in the model frame
    inertial: Inertial
    collisions: Tuple[CollisionSpec, ...] = ()
    visuals: Tuple[VisualSpec, ...] = ()
    self_collide: bool = False


@dataclass(frozen=True)
class JointSpec:
    name: str  # scoped like the links
    type: str  # one of JOINT_TYPES (Gazebo's: a URDF's continuous joint is a revolute one)
    parent: str  # a link's name, or WORLD
    child: str
    pose: Pose = IDENTITY  # the joint frame in the child link's frame
    axis: Vec3 = (0.0, 0.0, 1.0)  # unit vector in the joint frame
    lower: float = -math.inf  # [rad] or [m]; both infinite: no limit
    upper: float = math.inf
    effort: float = math.inf  # [N m] or [N]; Gazebo's -1 (none) is inf here
    velocity: float = math.inf  # [rad/s] or [m/s]
    damping: float = 0.0  # [N m s/rad] or [N s/m]
    friction: float = 0.0  # [N m] or [N]

    @property
    def limited(self) -> bool:
        return math.isfinite(self.lower) or math.isfinite(self.upper)


@dataclass(frozen=True)
class ModelSpec:
    """One model: its links (in the file's order; the first is Gazebo's canonical link) and joints, a
    tree (:func:`tree`). ``pose`` is the model's own ``<pose>`` in the file: Gazebo places a spawned
    model at ``spawn pose * pose`` (an ``<include>`` 's pose replaces it)."""

    name: str
    static: bool
    links: Tuple[LinkSpec, ...]
    joints: Tuple[JointSpec, ...] = ()
    source: str = ""  # where it was read from (messages)
    notes: Tuple[str, ...] = ()  # what was read and left out, each with its element path, said once
    pose: Pose = IDENTITY
    kinematic: bool = False  # static, but put somewhere new every step (an actor): a body bullet moves

    def link(self, name: str) -> LinkSpec:
        for link in self.links:
            if link.name == name:
                return link
        raise KeyError(name)


@dataclass(frozen=True)
class Tree:
    """A model's links as one tree: the root, every link after its parent, each child's joint."""

    root: LinkSpec
    links: Tuple[LinkSpec, ...]  # the root first, then each link after its parent
    parent_joint: Dict[str, JointSpec]  # child link name -> its joint (the root's: to the world, if any)
    loose: Tuple[LinkSpec, ...] = ()  # links of a static model no joint reaches: fixed where they are


def tree(spec: ModelSpec) -> Tree:
    """The model's joints as a tree, checked: every joint joins two links of the model (or the world
    to one), no link has two parent joints, no loop, at most one joint to the world (to the root), one
    root (a static model's loose links are fixed where they are, as Gazebo holds every link of a
    static model still). ModelError naming the joint otherwise."""
    return checked_tree(spec)


def checked_tree(spec: ModelSpec, path: str = "") -> Tree:
    where = path or spec.name
    names = {link.name: link for link in spec.links}
    if len(names) != len(spec.links):
        seen = set()
        for link in spec.links:
            if link.name in seen:
                raise ModelError(spec.source, f"{where}/link[{link.name}]", f"a second link named {link.name!r}")
            seen.add(link.name)
    if not spec.links:
        raise ModelError(spec.source, where, "a model without links")
    parent_joint: Dict[str, JointSpec] = {}
    children: Dict[str, List[str]] = {}
    joint_names = set()
    for joint in spec.joints:
        jpath = f"{where}/joint[{joint.name}]"
        if joint.name in joint_names:
            raise ModelError(spec.source, jpath, f"a second joint named {joint.name!r}")
        joint_names.add(joint.name)
        if joint.type not in JOINT_TYPES:
            raise ModelError(spec.source, jpath, f"joint type {joint.type!r} is not one of " + ", ".join(JOINT_TYPES))
        for end, name in (("parent", joint.parent), ("child", joint.child)):
            if name not in names and not (end == "parent" and name == WORLD):
                raise ModelError(spec.source, f"{jpath}/{end}", f"{name!r} is not a link of the model")
        if joint.child in parent_joint:
            other = parent_joint[joint.child].name
            raise ModelError(
                spec.source, jpath, f"link {joint.child!r} is the child of two joints ({other} and {joint.name})"
            )
        parent_joint[joint.child] = joint
        children.setdefault(joint.parent, []).append(joint.child)
    for joint in spec.joints:  # a loop: walking up from a child comes back to it
        seen_up = [joint.child]
        at = joint.parent
        while at in parent_joint and at != WORLD:
            if at in seen_up:
                loop = " -> ".join(reversed([*seen_up, at]))
                raise ModelError(spec.source, f"{where}/joint[{joint.name}]", f"joints in a loop: {loop}")
            seen_up.append(at)
            at = parent_joint[at].parent
    roots = [link for link in spec.links if link.name not in parent_joint or parent_joint[link.name].parent == WORLD]
    to_world = [link for link in roots if link.name in parent_joint]
    if len(to_world) > 1:
        names_ = ", ".join(parent_joint[link.name].name for link in to_world)
        raise ModelError(spec.source, where, f"more than one joint to the world ({names_}): one is simulated here")
    if len(roots) > 1 and not spec.static:
        names_ = ", ".join(link.name for link in roots[:5])
        raise ModelError(
            spec.source,
            where,
            f"links that no joint connects ({names_}): a moving model here is one tree of joints "
            "(join them with fixed joints, or make the model static)",
        )
    root = to_world[0] if to_world else roots[0]
    ordered: List[LinkSpec] = []
    stack = [root.name]
    while stack:
        name = stack.pop()
        ordered.append(names[name])
        stack.extend(reversed(children.get(name, [])))
    loose = tuple(link for link in roots if link is not root)
    for link in loose:
        stack = [link.name]
        while stack:
            name = stack.pop()
            if name != link.name:
                ordered.append(names[name])
            stack.extend(reversed(children.get(name, [])))
    return Tree(root, tuple(ordered), parent_joint, loose)


def replace_link(spec: ModelSpec, link_name: str, **changes) -> ModelSpec:
    """The spec with link_name's fields changed (dataclasses.replace on that link)."""
    links = tuple(replace(link, **changes) if link.name == link_name else link for link in spec.links)
    return replace(spec, links=links)
