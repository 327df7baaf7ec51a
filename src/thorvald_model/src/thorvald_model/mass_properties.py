"""A robot description's mass and centre of mass, from its links' ``<inertial>`` blocks.

Pure: URDF text in, numbers out (no ROS, no pybullet). The centre of mass is in the root link's
frame (base_link) with every joint at a position given (0 by default: wheels straight, suspension
at rest), composing each link's pose down the joint tree as robot_state_publisher does
(:class:`thorvald_model.joint_tree.JointTree`) and placing its mass at its inertial origin. A
physics engine loading the same description puts the same mass at the same place (the simulator's
test compares it with pybullet's); what a robot designer reads from it: how its weight is shared
between the wheels, and how high it sits.
"""

import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Dict, Mapping, Optional, Sequence, Tuple, Union

from .errors import UrdfError
from .joint_tree import IDENTITY_TRANSFORM, JointTree, Transform, Vec3, _triple, compose, rotate

__all__ = ["MassProperties", "link_poses", "mass_properties"]


@dataclass(frozen=True)
class MassProperties:
    mass: float  # [kg] of every link
    com: Vec3  # [m] the centre of mass in the root link's frame
    root: str  # the root link
    links: Tuple[Tuple[str, float, Vec3], ...]  # (link, mass [kg], its centre of mass in the root's frame)


def link_poses(
    tree: JointTree, links: Sequence[str], positions: Optional[Mapping[str, float]] = None
) -> Tuple[str, Dict[str, Transform]]:
    """(root link, each link's pose in the root's frame) of a description's links and joint tree, with
    the moving joints at positions (0 if left out)."""
    positions = positions or {}
    children = tree.tree
    roots = [link for link in links if link not in children]
    if len(roots) != 1:
        raise UrdfError(f"the description has {len(roots)} root links ({', '.join(roots)}): it needs one")
    root = roots[0]
    poses: Dict[str, Transform] = {root: IDENTITY_TRANSFORM}

    def pose(link: str, depth: int = 0) -> Transform:
        if link in poses:
            return poses[link]
        if depth > len(children):
            raise UrdfError(f"link {link} is in a loop of joints")
        pj = children[link]
        poses[link] = compose(pose(pj.parent, depth + 1), tree.transform(pj.joint, positions.get(pj.joint, 0.0)))
        return poses[link]

    for link in children:
        pose(link)
    return root, poses


def mass_properties(xml: Union[str, ET.Element], positions: Optional[Mapping[str, float]] = None) -> MassProperties:
    """The description's mass and centre of mass (see the module's docstring); UrdfError if it has no
    mass or an inertial block cannot be read."""
    robot = ET.fromstring(xml) if isinstance(xml, str) else xml
    tree = JointTree(ET.tostring(robot, encoding="unicode"))
    root, poses = link_poses(tree, [link.get("name", "") for link in robot.findall("link")], positions)
    links = []
    total, moment = 0.0, [0.0, 0.0, 0.0]
    for link in robot.findall("link"):
        name = link.get("name", "")
        inertial = link.find("inertial")
        if inertial is None:
            continue
        mass_element = inertial.find("mass")
        try:
            mass = float(mass_element.get("value")) if mass_element is not None else 0.0
        except (TypeError, ValueError):
            raise UrdfError(f"link {name}: inertial mass {mass_element.get('value')!r} is not a number") from None
        origin = inertial.find("origin")
        xyz = _triple(origin.get("xyz") if origin is not None else None, f"link {name} inertial origin")
        (px, py, pz), q = poses.get(name, IDENTITY_TRANSFORM)
        rx, ry, rz = rotate(q, xyz)
        com = (px + rx, py + ry, pz + rz)
        links.append((name, mass, com))
        total += mass
        moment = [m + mass * c for m, c in zip(moment, com)]
    if total <= 0.0:
        raise UrdfError("the description has no mass: no link has an inertial mass above 0")
    return MassProperties(total, tuple(m / total for m in moment), root, tuple(links))
