"""What the simulator reads from a robot description (URDF), without pybullet or ROS.

From the generator's simulator block (``<gazebo><plugin>``, as the original generator emitted it for
its Gazebo plugin): the command and odometry topics, the odometry and base frames, and one
``<drive>`` per drive in drive order (steering joint, wheel joint, wheel radius, acceleration limit,
and its motors under the robot file's keys, ``prp_motor_kt`` ... ``str_gear_eff``: a key the element
lacks, as from an older generator, is the robot file's default). From the joints:
the motors' limits (``<limit effort velocity>``), the suspension springs (``<springStiffness>`` in
the joint's ``<gazebo reference>`` and the joint's damping) and the passive joints (casters, support
wheels) with their friction. A URDF without the block (any other robot) is a passive model.
"""

import copy
import math
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from types import SimpleNamespace
from typing import Callable, Dict, Iterable, List, Mapping, Optional, Tuple

from thorvald_model.datum import Datum, parse_datum
from thorvald_model.errors import ConfigError, UrdfError
from thorvald_model.joint_tree import (  # noqa: F401  (Origin: for the sensors)
    IDENTITY_TRANSFORM,
    Origin,
    ParentJoint,
    compose,
    quaternion_from_rpy,
    rotate,
)
from thorvald_model.joint_tree import link_tree as _link_tree
from thorvald_model.keys import DRIVE_KEYS
from thorvald_model.motors import PROPULSION_KEYS, STEERING_KEYS, Motor, propulsion_motor, steering_motor
from thorvald_model.urdf_check import checked_tree, normalize_frame

from ..errors import DescriptionError
from ..sensors.blocks import SensorBlocks, read_sensor_blocks


@dataclass(frozen=True)
class JointInfo:
    name: str
    type: str  # URDF joint type
    effort: float  # [N m] or [N]; 0 when the URDF gives none
    velocity: float  # [rad/s] or [m/s]; 0 when the URDF gives none
    damping: float  # [N m s/rad] or [N s/m]
    friction: float  # [N m] or [N]


# The robot file's keys a drive's motors are made of, with their defaults (a Thorvald module's).
MOTOR_KEYS = {k.name: k.default for k in DRIVE_KEYS if k.name in PROPULSION_KEYS + STEERING_KEYS}
DEFAULT_PROPULSION_MOTOR = propulsion_motor(SimpleNamespace(**MOTOR_KEYS))
DEFAULT_STEERING_MOTOR = steering_motor(SimpleNamespace(**MOTOR_KEYS))


@dataclass(frozen=True)
class DriveJoints:
    """One drive of the simulator block: the joints base_state's entry of index ``index`` moves."""

    index: int
    steerable: bool  # the generator's steerable="true" (type 0); a type-1 drive's steering joint is fixed
    steering_joint: str
    wheel_joint: str
    wheel_radius: float  # [m]
    max_acceleration: float = 0.0  # the drive controller's rim acceleration limit [m/s^2]; 0: none
    propulsion_motor: Motor = DEFAULT_PROPULSION_MOTOR  # its motors behind their gears (thorvald_model.motors)
    steering_motor: Motor = DEFAULT_STEERING_MOTOR  # a drive that does not steer has one too: nothing reads it


@dataclass(frozen=True)
class Spring:
    """A sprung suspension joint: force -stiffness (q - reference) - damping q' along the joint."""

    joint: str
    stiffness: float  # [N/m]
    damping: float  # [N s/m]
    reference: float = 0.0  # [m]


@dataclass(frozen=True)
class RobotDescription:
    name: str
    joints: Dict[str, JointInfo]
    drives: Tuple[DriveJoints, ...]  # empty: a passive model
    springs: Tuple[Spring, ...]
    command_topic: str = "base_state"
    odometry_topic: str = "odometry/gazebo"
    odometry_frame: str = "odom"
    base_frame: str = "base_link"
    datum: Optional[Datum] = None  # the generator's <datum> (from model.launch's datum_file)

    @property
    def passive_joints(self) -> Tuple[JointInfo, ...]:
        """Moving joints no motor drives and no spring holds: casters, support wheels."""
        driven = {d.wheel_joint for d in self.drives} | {d.steering_joint for d in self.drives if d.steerable}
        sprung = {s.joint for s in self.springs}
        return tuple(
            j for j in self.joints.values() if j.type != "fixed" and j.name not in driven and j.name not in sprung
        )

    @property
    def passive_wheels(self) -> Tuple[JointInfo, ...]:
        """The passive joints that are wheels on the ground (the generator's ``passiveN_wheel``; a caster's
        ``passiveN_swivel`` is not): their tyres are narrowed and, on soft tyres, softened as a drive's."""
        return tuple(j for j in self.passive_joints if j.name.endswith("wheel"))


def _float(text: Optional[str], what: str) -> float:
    try:
        return float(text) if text not in (None, "") else 0.0
    except ValueError:
        raise DescriptionError(f"{what}: {text!r} is not a number") from None


def parse_description(xml: str) -> RobotDescription:
    """The simulator's view of a URDF; DescriptionError saying why it cannot be used."""
    if not xml or not xml.strip():
        raise DescriptionError("the robot description is empty")
    try:
        root = ET.fromstring(xml)
    except ET.ParseError as e:
        raise DescriptionError(f"the robot description is not valid XML ({e})") from None
    return description_of(root)


def description_of(root: ET.Element) -> RobotDescription:
    """The simulator's view of a parsed ``<robot>``; DescriptionError saying why it cannot be used."""
    if root.tag != "robot":
        raise DescriptionError(f"the robot description's root element is <{root.tag}>, not <robot>")
    if root.find("link") is None:
        raise DescriptionError("the robot description has no <link>")
    joints = {}
    for j in root.findall("joint"):
        name = j.get("name")
        limit = j.find("limit")
        dynamics = j.find("dynamics")
        joints[name] = JointInfo(
            name,
            j.get("type", ""),
            _float(limit.get("effort") if limit is not None else None, f"joint {name} effort"),
            _float(limit.get("velocity") if limit is not None else None, f"joint {name} velocity"),
            _float(dynamics.get("damping") if dynamics is not None else None, f"joint {name} damping"),
            _float(dynamics.get("friction") if dynamics is not None else None, f"joint {name} friction"),
        )
    springs = []
    for g in root.findall("gazebo"):
        stiffness = g.findtext("springStiffness")
        ref = g.get("reference")
        if stiffness is not None and ref in joints:
            springs.append(
                Spring(
                    ref,
                    _float(stiffness, f"joint {ref} springStiffness"),
                    joints[ref].damping,
                    _float(g.findtext("springReference"), f"joint {ref} springReference"),
                )
            )
    plugin = _drive_block(root)
    if plugin is None:
        return RobotDescription(root.get("name", ""), joints, (), tuple(springs))
    drives = []
    for k, e in enumerate(plugin.findall("drive")):
        index = int(_float(e.get("index"), "drive index"))
        if index != k:
            raise DescriptionError(f"the simulator block's drives are not in order: drive {index} comes {k}th")
        drive = DriveJoints(
            index,
            e.get("steerable") == "true",  # the loader's answer, written by the generator
            e.get("steering_joint", ""),
            e.get("wheel_joint", ""),
            _float(e.get("wheel_radius"), f"drive {index} wheel_radius"),
            _float(e.get("max_acceleration"), f"drive {index} max_acceleration"),
            *_motors(e, index),
        )
        for joint in (drive.wheel_joint, drive.steering_joint):
            if joint not in joints:
                raise DescriptionError(f"drive {index} names joint {joint!r}, which the description does not have")
        if drive.wheel_radius <= 0:
            raise DescriptionError(f"drive {index}: wheel_radius must be > 0")
        drives.append(drive)
    return RobotDescription(
        root.get("name", ""),
        joints,
        tuple(drives),
        tuple(springs),
        plugin.findtext("commandTopic") or "base_state",
        plugin.findtext("odometryTopic") or "odometry/gazebo",
        # frames as tf2 reads them: an older generator's /base_link is base_link
        normalize_frame(plugin.findtext("odometryFrame") or "odom"),
        normalize_frame(plugin.findtext("robotBaseFrame") or "base_link"),
        _datum(plugin.find("datum")),
    )


def _motors(element: ET.Element, index: int) -> Tuple[Motor, Motor]:
    """A ``<drive>``'s (propulsion, steering) motors from its attributes, defaults for those it lacks."""
    values = {
        name: _float(element.get(name), f"drive {index} {name}") if element.get(name) is not None else default
        for name, default in MOTOR_KEYS.items()
    }
    keys = SimpleNamespace(**values)
    try:
        return propulsion_motor(keys), steering_motor(keys)
    except ValueError as e:
        raise DescriptionError(f"drive {index}: {e}") from None


def _datum(element) -> Optional[Datum]:
    """The generator's ``<datum latitude= longitude= yaw= altitude=/>`` (from the robot_localization datum
    file model.launch was given: degrees, degrees, ENU yaw of the world's x axis [rad], metres), checked
    by the datum file's own rules."""
    if element is None:
        return None
    values = [_float(element.get(k), f"datum {k}") for k in ("latitude", "longitude", "yaw", "altitude")]
    try:
        return parse_datum({"datum": values[:3], "altitude": values[3]}, "the simulator block's <datum>")
    except ConfigError as e:
        raise DescriptionError(str(e)) from None


def link_tree(xml: str) -> Dict[str, ParentJoint]:
    """Each child link's joint to its parent (the root link has none): thorvald_model.joint_tree's,
    its errors as DescriptionError."""
    try:
        return _link_tree(xml)
    except UrdfError as e:
        raise DescriptionError(str(e)) from None


# The collisions the generator names for a drive's rail wheel (thorvald_model's wheel macro: a tread
# between two flanges, paper 3.1's double wheels): not the tyre, so left as generated.
RAIL_WHEEL_COLLISIONS = ("rail_tread", "rail_flange")


def tyre_cylinders(link: ET.Element) -> List[ET.Element]:
    """The collision cylinders of a wheel link that are its tyre's (and its hub's), not those of a
    rail wheel on its axle (collisions named as :data:`RAIL_WHEEL_COLLISIONS`)."""
    return [
        cylinder
        for collision in link.findall("collision")
        if collision.get("name") not in RAIL_WHEEL_COLLISIONS
        for cylinder in collision.findall("geometry/cylinder")
    ]


def with_tyre_contact(xml: str, wheel_joints: Iterable[str], width: float) -> str:
    """The URDF with the tyres' collision cylinders of the given wheels' links narrowed to width [m].

    pybullet touches a cylinder lying on a plane at one rim, not across its width, so a wheel's
    contact lies half its collision width beside the wheel's centre line: 8 cm for a 0.16 m wheel,
    enough to turn a differential robot's arcs 3 % tight and walk a spinning robot off its spot. A
    thin disc puts the contact within width / 2 of the centre line, where a crowned tyre's patch
    is. The visual shapes, masses and inertias stay as they are, and so does a rail wheel on the
    axle (:func:`tyre_cylinders`): its tread is as wide as a pipe's top needs, and its flanges must
    reach either side of the pipe where they are.
    """
    root = ET.fromstring(xml)
    narrow_tyres(root, wheel_joints, width)
    return ET.tostring(root, encoding="unicode")


def narrow_tyres(root: ET.Element, wheel_joints: Iterable[str], width: float) -> None:
    """:func:`with_tyre_contact` on a parsed ``<robot>``, in place."""
    joints = set(wheel_joints)
    wheel_links = {j.find("child").get("link") for j in root.findall("joint") if j.get("name") in joints}
    for link in root.findall("link"):
        if link.get("name") not in wheel_links:
            continue
        for cylinder in tyre_cylinders(link):
            cylinder.set("length", repr(min(float(cylinder.get("length")), width)))


ROOT_MASS = 1e-6  # [kg] the root link keeps (pybullet makes a body of mass 0 static)
ROOT_CENTRE = "{}__centre_of_mass"  # the link that carries the root link's own mass


def centre_fixed_links(root: ET.Element) -> None:
    """Moves the frame of every link joined by a fixed joint to its centre of mass, in place, the
    robot unchanged: its joint's origin, its visuals', collisions' and inertial origins and its child
    joints' origins are composed to match. The root link's own mass moves to a link of its own
    (ROOT_CENTRE) fixed at its centre of mass; the root keeps ROOT_MASS.

    pybullet 3.2.7 merging fixed links (``URDF_MERGE_FIXED_LINKS``, the simulator's: 8 bodies of the
    standard robot instead of 34) puts each merged link's mass at the link's origin, not at its
    inertial origin, the root's included: a battery whose frame is its mounting point 10 cm above its
    middle, base_link's kilogram at the ground; the standard robot's centre of mass 1.4 cm high, the
    tricycle's 3.9 cm (a design study tipped it 1.1 degrees early). With every merged link's frame at
    its centre of mass, the merge puts each mass where the description does."""
    _root_mass_apart(root)
    joints = root.findall("joint")
    by_child = {j.find("child").get("link"): j for j in joints if j.find("child") is not None}
    for link in root.findall("link"):
        joint = by_child.get(link.get("name"))
        inertial = link.find("inertial")
        if joint is None or joint.get("type") != "fixed" or inertial is None:
            continue
        centre = _origin(inertial)
        if centre == IDENTITY_TRANSFORM:
            continue
        back = _inverse(centre)
        _set_origin(joint, compose(_origin(joint), centre))
        _set_origin(inertial, IDENTITY_TRANSFORM)
        for element in (*link.findall("visual"), *link.findall("collision")):
            _set_origin(element, compose(back, _origin(element)))
        for child_joint in joints:
            parent = child_joint.find("parent")
            if parent is not None and parent.get("link") == link.get("name"):
                _set_origin(child_joint, compose(back, _origin(child_joint)))


def _root_mass_apart(root: ET.Element) -> None:
    children = {j.find("child").get("link") for j in root.findall("joint") if j.find("child") is not None}
    roots = [link for link in root.findall("link") if link.get("name") not in children]
    if len(roots) != 1:
        return
    base = roots[0]
    inertial = base.find("inertial")
    if inertial is None or _origin(inertial) == IDENTITY_TRANSFORM:
        return
    name = ROOT_CENTRE.format(base.get("name"))
    base.remove(inertial)
    ET.SubElement(root, "link", name=name).append(inertial)
    joint = ET.SubElement(root, "joint", name=name + "_joint", type="fixed")
    ET.SubElement(joint, "parent", link=base.get("name"))
    ET.SubElement(joint, "child", link=name)
    kept = ET.SubElement(base, "inertial")
    ET.SubElement(kept, "mass", value=repr(ROOT_MASS))
    ET.SubElement(kept, "inertia", ixx="1e-9", iyy="1e-9", izz="1e-9", ixy="0", ixz="0", iyz="0")


def _origin(element: ET.Element):
    """The transform of an element's <origin> (identity without one)."""
    origin = element.find("origin")
    if origin is None:
        return IDENTITY_TRANSFORM
    xyz = tuple(float(v) for v in (origin.get("xyz") or "0 0 0").split())
    rpy = tuple(float(v) for v in (origin.get("rpy") or "0 0 0").split())
    return xyz, quaternion_from_rpy(*rpy)


def _set_origin(element: ET.Element, transform) -> None:
    origin = element.find("origin")
    if origin is None:
        origin = ET.SubElement(element, "origin")
    xyz, q = transform
    origin.set("xyz", " ".join(repr(v) for v in xyz))
    origin.set("rpy", " ".join(repr(v) for v in rpy_from_quaternion(q)))


def _inverse(transform):
    xyz, (x, y, z, w) = transform
    conjugate = (-x, -y, -z, w)
    back = rotate(conjugate, xyz)
    return (-back[0], -back[1], -back[2]), conjugate


def rpy_from_quaternion(q) -> Tuple[float, float, float]:
    """URDF's roll, pitch, yaw [rad] (about fixed x, y, z) of a unit quaternion (x, y, z, w)."""
    x, y, z, w = q
    roll = math.atan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2 * (w * y - z * x))))
    yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return roll, pitch, yaw


def with_wheel_radii(xml: str, radii: Mapping[str, float]) -> str:
    """The URDF with the tyres' collision cylinders of the given wheels' links ({wheel joint: radius
    [m]}) of another radius: an as-built robot's true rolling radii. The visuals, masses and
    inertias, a rail wheel on the axle (:func:`tyre_cylinders`), and what the description says of
    the drives, stay as configured."""
    if not radii:
        return xml
    root = ET.fromstring(xml)
    set_wheel_radii(root, radii)
    return ET.tostring(root, encoding="unicode")


def set_wheel_radii(root: ET.Element, radii: Mapping[str, float]) -> None:
    """:func:`with_wheel_radii` on a parsed ``<robot>``, in place."""
    links = {j.find("child").get("link"): radii[j.get("name")] for j in root.findall("joint") if j.get("name") in radii}
    for link in root.findall("link"):
        if link.get("name") in links:
            for cylinder in tyre_cylinders(link):
                cylinder.set("radius", repr(links[link.get("name")]))


@dataclass(frozen=True)
class MissingMesh:
    """A visual or collision element dropped because its mesh file cannot be found."""

    link: str
    element: str  # "visual" or "collision"
    uri: str  # as the description writes it, e.g. package://velodyne_description/meshes/VLP16_base_1.dae
    reason: str  # e.g. "package velodyne_description is not installed"


MeshFinder = Callable[[str], Tuple[Optional[str], str]]
"""uri -> (absolute path of the file, "") or (None, why it cannot be found)."""


def _drive_block(root: ET.Element) -> Optional[ET.Element]:
    """The generator's simulator block: the ``<gazebo><plugin>`` with ``<drive>`` elements, or None."""
    return next((p for g in root.findall("gazebo") for p in g.findall("plugin") if p.findall("drive")), None)


def is_thorvald_robot(xml: str) -> bool:
    """Whether a description is a Thorvald robot's: a URDF with the generator's simulator block
    (the Gazebo API spawns it as ``spawn_robot`` does; any other model as a model)."""
    try:
        root = ET.fromstring(xml)
    except ET.ParseError:
        return False
    return root.tag == "robot" and _drive_block(root) is not None


def resolve_meshes(xml: str, find: MeshFinder) -> Tuple[str, Tuple[MissingMesh, ...]]:
    """The URDF with every mesh file an absolute path, for pybullet, which loads the description from a
    file of its own and would look for ``package://`` meshes next to it (and refuse the whole robot).

    A visual or collision element whose mesh cannot be found (users' extras name meshes of packages
    not installed here: ``velodyne_description``, ``kinect2_description``) is dropped, and said, so the
    link is drawn and collides with its other geometry; a link left with none keeps its inertial.
    """
    root = ET.fromstring(xml)
    missing = resolve_meshes_of(root, find)
    return ET.tostring(root, encoding="unicode"), missing


def resolve_meshes_of(root: ET.Element, find: MeshFinder) -> Tuple[MissingMesh, ...]:
    """:func:`resolve_meshes` on a parsed ``<robot>``, in place; the elements left out."""
    missing = []
    for link in root.findall("link"):
        for kind in ("visual", "collision"):
            for element in link.findall(kind):
                mesh = element.find("geometry/mesh")
                if mesh is None:
                    continue
                uri = mesh.get("filename", "")
                path, reason = find(uri)
                if path is None:
                    link.remove(element)
                    missing.append(MissingMesh(link.get("name", ""), kind, uri, reason))
                else:
                    mesh.set("filename", path)
    return tuple(missing)


def installed_package_path(package: str) -> Optional[str]:
    """The folder of a ROS package found through rospack (ROS_PACKAGE_PATH), None if it is not there
    (or rospkg is not installed)."""
    try:
        import rospkg  # noqa: PLC0415  (rospkg is not the ROS runtime; only needed when a package:// file is named)
    except ImportError:
        return None
    try:
        return rospkg.RosPack().get_path(package)
    except rospkg.ResourceNotFound:
        return None


def mesh_finder(package_path: Callable[[str], Optional[str]]) -> MeshFinder:
    """A MeshFinder for ``package://PKG/...`` (package_path(PKG): its folder, None if not installed),
    ``file://...`` and plain absolute paths; anything else (a relative path, Gazebo's ``model://``)
    cannot be found from a description alone."""

    def find(uri: str) -> Tuple[Optional[str], str]:
        if uri.startswith("package://"):
            package, _, rest = uri[len("package://") :].partition("/")
            folder = package_path(package)
            if folder is None:
                return None, f"package {package} is not installed"
            path = os.path.join(folder, rest)
            return (path, "") if os.path.isfile(path) else (None, f"package {package} has no {rest}")
        path = uri[len("file://") :] if uri.startswith("file://") else uri
        if not os.path.isabs(path):
            return None, "not a package://, file:// or absolute path"
        return (path, "") if os.path.isfile(path) else (None, "no such file")

    return find


@dataclass(frozen=True)
class SpawnedDescription:
    """A robot description as a spawn reads it, parsed once: every part of the spawn (the robot and
    its drives, its tyres, its link tree, its sensor blocks) reads this one value, never the text."""

    root: ET.Element  # the <robot>, its link references normalised and checked as check_urdf would
    robot: RobotDescription
    links: Dict[str, ParentJoint]  # each child link's joint to its parent
    sensor_blocks: SensorBlocks

    def for_pybullet(self, find: MeshFinder) -> Tuple[ET.Element, Tuple[MissingMesh, ...]]:
        """A copy of the tree for pybullet to load, its meshes found (the elements left out, too)."""
        root = copy.deepcopy(self.root)
        return root, resolve_meshes_of(root, find)


def spawned_description(xml: str, source: str) -> SpawnedDescription:
    """The description parsed once, normalised and checked (UrdfCheckError naming source and every
    problem), read by the simulator (DescriptionError saying why it cannot be used)."""
    root = checked_tree(xml, source)
    try:
        links = _link_tree(root)
    except UrdfError as e:
        raise DescriptionError(str(e)) from None
    return SpawnedDescription(root, description_of(root), links, read_sensor_blocks(root))
