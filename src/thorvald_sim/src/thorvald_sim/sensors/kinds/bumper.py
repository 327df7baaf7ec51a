"""Contact sensors: ``bumper`` (gazebo_msgs/ContactsState), from a Gazebo ``contact`` sensor with
gazebo_ros_bumper.

The block, as in Gazebo (``<gazebo reference="LINK"><sensor type="contact">``): ``<contact>`` names
one or more ``<collision>`` by the names Gazebo's URDF conversion (SDFormat 9's ``parser_urdf.cc``,
as :mod:`thorvald_sim.models.urdf_model` follows it) gives them, on the sensor's link as Gazebo has
it, the link LINK is lumped into by fixed joints: a link's first collision is ``<link>_collision``,
the next ``<link>_collision_1``, and a collision of a link lumped into its parent is
``<parent>_fixed_joint_lump__<child>_collision``, numbered on among the parent's
(``..._collision_2``). The name a lumped link's collision would have without the lumping
(``bumper_link_collision``) is taken for that collision too: Gazebo rewrites it to a name no
collision has, and its bumper then reports nothing. A name that is neither is refused, with the
names there are. The plugin's ``bumperTopicName`` (``bumper_states``), ``frameName`` (``world``)
and ``robotNamespace`` are gazebo_ros_bumper's; the sensor's ``update_rate`` paces it.

What it publishes is what gazebo_ros_bumper (ROS Noetic) publishes: a ContactsState per reading, even
without contact, stamped with the reading's instant, ``frame_id`` the resolved ``frameName``; one
ContactState per pair of collisions in contact, ``collision1_name`` the bumper's collision
(``model::link::collision``) and ``collision2_name`` the other's, and per contact point:

- the position [m] (on the bumper's surface) and the unit normal, in the **world** frame whatever
  ``frameName`` says (gazebo_ros_bumper's transform into frameName is commented out in Noetic), the
  normal pointing from the other body into the bumper's (ODE's convention: moving the bumper along
  it separates them);
- the depth [m], how far the two overlap (>= 0);
- the wrench on the bumper's link: the force [N] the contact puts on it and its torque [N m] about
  the link's centre of mass, both in the **link's** axes (Gazebo's ODE feedback, rotated into the
  link frame); ``total_wrench`` their sum.

The other body of a contact is named as the /gazebo API names it where pybullet tells it: the
world's ground and static scene (walls, rows, posts) as Gazebo's ``ground_plane::link::collision``;
a body loaded from a URDF as ``<its robot name>::<link>::collision``, the link pybullet keeps (which
of its collisions is not known here).

A contact belongs to the named collision when its point lies on that collision's box, cylinder or
sphere (within :data:`ON_SURFACE`): pybullet merges the links joined by fixed joints into one rigid
body, which reports every contact of it. A mesh collision, or a block read without the description's
collisions, reports every contact of the rigid body it is part of.
"""

import math
import sys
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from ...errors import BlockError, ModelError
from ...models.urdf_model import gazebo_collision_names
from .block import FRAME_TF_RESOLVE, Found, Pose, SensorSpec, Vec3, read_namespace, read_pose, unpack
from .kind import SensorKind, no_display
from .model import Quat, Sensor, Transform, compose, p, transform

BUMPER_PLUGINS = ("libgazebo_ros_bumper.so",)
ON_SURFACE = 0.01  # [m] a contact point this far outside a collision's shape is still on it
GROUND = "ground_plane::link::collision"  # the world's ground and static scene, as the /gazebo API names them


# ---------------------------------------------------------------------------------------------
# The block
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Shape:
    """A collision's geometry, in its own frame: ``box`` (x, y, z sizes [m]), ``cylinder`` (radius,
    length [m], along z) or ``sphere`` (radius [m])."""

    kind: str
    size: Tuple[float, ...]


@dataclass(frozen=True)
class BumperCollision:
    name: str  # as Gazebo names it, e.g. base_link_fixed_joint_lump__bumper_link_collision_1
    link: str  # the URDF link it is written in, e.g. bumper_link
    origin: Pose  # in that link
    shape: Optional[Shape]  # None: every contact of its rigid body (a mesh, or not known)


@dataclass(frozen=True)
class BumperConfig:
    collisions: Tuple[BumperCollision, ...]
    link: str  # the link holding them in Gazebo (the sensor's link after lumping); "" when not known


def gazebo_link(robot: ET.Element, link: str) -> str:
    """The link that holds ``link`` in Gazebo: up the fixed joints Gazebo's conversion lumps (not one
    to ``world``, nor one kept by ``preserveFixedJoint`` or ``disableFixedJointLumping``)."""
    parents = {}
    for joint in robot.findall("joint"):
        parent, child = joint.find("parent"), joint.find("child")
        if parent is not None and child is not None:
            parents[child.get("link", "")] = (joint.get("name", ""), joint.get("type", ""), parent.get("link", ""))
    kept = set()
    for block in robot.findall("gazebo"):
        for tag in ("preserveFixedJoint", "disableFixedJointLumping"):
            if (block.findtext(tag) or "").strip().lower() in ("true", "yes", "1"):
                kept.add(block.get("reference", ""))
    seen = {link}
    while link in parents:
        joint, kind, parent = parents[link]
        if kind != "fixed" or joint in kept or parent == "world" or parent in seen:
            break
        seen.add(parent)
        link = parent
    return link


def _own_name(link: str, name: str, n: int) -> str:
    """The name a link's n-th collision (URDF name ``name``, "" for none) has in Gazebo when nothing
    is lumped into the link (parser_urdf.cc's CreateCollisions and CreateCollision)."""
    full = (name or link) + "_collision" + (f"_{n}" if n > 0 else "")
    return full if full.startswith(link) else f"{link}_fixed_joint_lump__{full}"


def _floats(text: Optional[str], count: int, path: str) -> Tuple[float, ...]:
    try:
        values = tuple(float(v) for v in (text or "").split())
    except ValueError:
        values = ()
    if len(values) != count or not all(math.isfinite(v) for v in values):
        raise BlockError(path, f"{text!r} must be {count} finite numbers")
    return values


def _collision_value(element: ET.Element, name: str, link: str, path: str) -> BumperCollision:
    origin = element.find("origin")
    pose = Pose()
    if origin is not None:
        xyz = _floats(origin.get("xyz", "0 0 0"), 3, f"{path}/origin@xyz")
        rpy = _floats(origin.get("rpy", "0 0 0"), 3, f"{path}/origin@rpy")
        pose = Pose(xyz, rpy)  # type: ignore[arg-type]
    geometry = element.find("geometry")
    shape = None
    for g in list(geometry) if geometry is not None else []:
        if g.tag == "box":
            shape = Shape("box", _floats(g.get("size"), 3, f"{path}/geometry/box@size"))
        elif g.tag == "cylinder":
            shape = Shape("cylinder", _floats(f"{g.get('radius')} {g.get('length')}", 2, f"{path}/geometry/cylinder"))
        elif g.tag == "sphere":
            shape = Shape("sphere", _floats(g.get("radius"), 1, f"{path}/geometry/sphere@radius"))
        break
    return BumperCollision(name, link, pose, shape)


def resolve_collisions(robot: ET.Element, link: str, names: Sequence[str], path: str) -> BumperConfig:
    """The named collisions of a contact sensor on ``link`` of the description ``robot``, each on the
    link holding the sensor in Gazebo; BlockError naming the first unknown one and the names there are."""
    try:
        collisions = gazebo_collision_names(ET.tostring(robot, encoding="unicode"), "the robot description")
    except ModelError as e:
        raise BlockError(path, f"the description's collisions cannot be named as Gazebo names them: {e.rule}") from None
    holder = gazebo_link(robot, link)
    links = {element.get("name", ""): element for element in robot.findall("link")}
    by_name: Dict[str, Tuple[str, int]] = {}  # a name a block may write -> (URDF link, its n-th collision)
    for c in collisions:
        if c.link != holder:
            continue
        by_name[c.name] = (c.origin_link, c.index)
        if c.origin_link != holder:  # the lumped link's own name for it, which Gazebo rewrites
            element = links[c.origin_link].findall("collision")[c.index]
            by_name.setdefault(_own_name(c.origin_link, element.get("name", ""), c.index), (c.origin_link, c.index))
    found = []
    for name in names:
        if name not in by_name:
            lumped = f" (link {link} is lumped into it by fixed joints)" if link != holder else ""
            known = [c.name for c in collisions if c.link == holder]
            there = f"its collisions: {', '.join(known)}" if known else "it has none"
            raise BlockError(path, f"{name!r}: link {holder}{lumped} has no collision of that name in Gazebo; {there}")
        origin_link, index = by_name[name]
        element = links[origin_link].findall("collision")[index]
        value = _collision_value(element, name, origin_link, f"link[@name='{origin_link}']/collision[{index + 1}]")
        found.append(value)
    return BumperConfig(tuple(found), holder)


def read_bumper(found: Found, robot: Optional[ET.Element] = None) -> SensorSpec:
    """A contact sensor with gazebo_ros_bumper; ``robot``: the description's ``<robot>``, whose
    collisions the block's names are checked against and located in (None: taken as written, each
    on the rigid body of the sensor's link)."""
    sensor, plugin, link, name, filename, rate = unpack(found)
    contact = sensor.required("contact", "a contact sensor names its collisions in <contact><collision>")
    names = [(e.text or "").strip() for e in contact.e.findall("collision")]
    path = f"{contact.path}/collision"
    if not names:
        raise BlockError(path, "missing: the contact sensor needs the collision it reports")
    if not all(names):
        raise BlockError(path, "empty: it must name a collision of the sensor's link")
    if robot is None:
        config = BumperConfig(tuple(BumperCollision(n, link, Pose(), None) for n in names), "")
    else:
        config = resolve_collisions(robot, link, names, path)
    topic = plugin.text("bumperTopicName", "bumper_states")
    return SensorSpec(
        "bumper", name, link, read_pose(sensor), rate, filename, {"bumper": topic},
        plugin.text("frameName", "world"), FRAME_TF_RESOLVE, read_namespace(plugin), config,
    )  # fmt: skip


def _read_sensor(found: Found) -> SensorSpec:
    # the description comes with the block when the block reader hands it over (Found.robot)
    return read_bumper(found, found.robot)


# ---------------------------------------------------------------------------------------------
# The maths: contact points to ContactStates (pure)
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class ContactPoint:
    """One contact point, in the world: where, its normal (into the bumper's body), how deep, and the
    force [N] it puts on the bumper's body."""

    position: Vec3
    normal: Vec3
    depth: float
    force: Vec3


@dataclass(frozen=True)
class ContactStateValue:
    """What a gazebo_msgs/ContactState holds, as numbers (see the module)."""

    collision1: str
    collision2: str
    wrenches: Tuple[Tuple[Vec3, Vec3], ...]  # (force [N], torque [N m]) per point, the link's axes
    total: Tuple[Vec3, Vec3]
    positions: Tuple[Vec3, ...]  # [m] world
    normals: Tuple[Vec3, ...]  # world
    depths: Tuple[float, ...]  # [m]


@dataclass(frozen=True)
class BumperReading:
    states: Tuple[ContactStateValue, ...]
    time: float  # [s] simulated


def rotation(q: Quat) -> np.ndarray:
    """The rotation matrix of a unit quaternion (x, y, z, w)."""
    x, y, z, w = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def contact_state(
    collision1: str, collision2: str, points: Sequence[ContactPoint], orientation: Quat, centre: Vec3
) -> ContactStateValue:
    """The ContactState of a pair of collisions from their contact points; orientation: the bumper's
    link in the world, centre [m]: its centre of mass in the world (wrenches are Gazebo's: each
    point's force and its torque about the centre, in the link's axes)."""
    to_link = rotation(orientation).T
    wrenches = []
    for point in points:
        force = np.asarray(point.force, dtype=float)
        torque = np.cross(np.asarray(point.position, dtype=float) - np.asarray(centre, dtype=float), force)
        wrenches.append((_vec(to_link @ force), _vec(to_link @ torque)))
    total_force = tuple(sum(w[0][i] for w in wrenches) for i in range(3))
    total_torque = tuple(sum(w[1][i] for w in wrenches) for i in range(3))
    return ContactStateValue(
        collision1,
        collision2,
        tuple(wrenches),
        (total_force, total_torque),  # type: ignore[arg-type]
        tuple(_vec(point.position) for point in points),
        tuple(_vec(point.normal) for point in points),
        tuple(float(point.depth) for point in points),
    )


def _vec(v) -> Vec3:
    return (float(v[0]), float(v[1]), float(v[2]))


def on_shape(shape: Shape, point, margin: float = ON_SURFACE) -> bool:
    """Whether a point [m] in the shape's own frame lies in or on it, within margin."""
    x, y, z = point
    if shape.kind == "box":
        return all(abs(c) <= s / 2 + margin for c, s in zip((x, y, z), shape.size))
    if shape.kind == "cylinder":
        radius, length = shape.size
        return math.hypot(x, y) <= radius + margin and abs(z) <= length / 2 + margin
    return math.sqrt(x * x + y * y + z * z) <= shape.size[0] + margin


# ---------------------------------------------------------------------------------------------
# The model
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class _Target:
    name: str  # scoped: model::link::collision
    index: int  # pybullet link index of its rigid body
    frame: Transform  # its shape's frame in that link's frame
    shape: Optional[Shape]


class Bumper(Sensor):
    """Reads pybullet's contact points of the rigid body each named collision is on, keeps those on
    the collision's shape where the body is touched (or pushed), and groups them by the body touched."""

    def __init__(self, *args, **kwargs):
        super().__init__(*args, **kwargs)
        c: BumperConfig = self.spec.config
        self.targets: List[_Target] = []
        for collision in c.collisions:
            if collision.shape is None or self.context.mount is None:
                index, frame = self.link_index, self.offset
            else:
                index, link_frame = self.context.mount(collision.link)
                frame = compose(link_frame, transform(collision.origin.xyz, collision.origin.rpy))
            scoped = f"{self.robot.name}::{c.link or self._link_name(index)}::{collision.name}"
            self.targets.append(_Target(scoped, index, frame, collision.shape))

    def _link_name(self, index: int) -> str:
        body, client = self.robot.body, self.client
        if index < 0:
            return p.getBodyInfo(body, physicsClientId=client)[0].decode()
        return p.getJointInfo(body, index, physicsClientId=client)[12].decode()

    def other_name(self, body: int, link: int) -> str:
        """How a contact's other body is named (see the module)."""
        base, model = (v.decode() for v in p.getBodyInfo(body, physicsClientId=self.client))
        if not model:
            return GROUND
        name = base if link < 0 else p.getJointInfo(body, link, physicsClientId=self.client)[12].decode()
        return f"{model}::{name}::collision"

    def read(self, now: float) -> BumperReading:
        body, client = self.robot.body, self.client
        states = []
        for target in self.targets:
            frame_pos, frame_quat, centre, _, _ = self.robot.link_state(target.index)
            shape_pos, shape_quat = compose((frame_pos, frame_quat), target.frame)
            to_shape = rotation(shape_quat).T
            pairs: Dict[Tuple[int, int], List[ContactPoint]] = {}
            for cp in p.getContactPoints(bodyA=body, linkIndexA=target.index, physicsClientId=client):
                other, other_link, position, normal, distance, pushing = cp[2], cp[4], cp[5], cp[7], cp[8], cp[9]
                if other == body or (distance > 0.0 and pushing <= 0.0):
                    continue  # itself, or a point pybullet keeps before bodies touch
                if target.shape is not None:
                    local = to_shape @ (np.asarray(position) - np.asarray(shape_pos))
                    if not on_shape(target.shape, local):
                        continue
                force = pushing * np.asarray(normal) + cp[10] * np.asarray(cp[11]) + cp[12] * np.asarray(cp[13])
                point = ContactPoint(tuple(position), tuple(normal), max(0.0, -distance), _vec(force))
                pairs.setdefault((other, other_link), []).append(point)
            for (other, other_link), points in pairs.items():
                other_name = self.other_name(other, other_link)
                states.append(contact_state(target.name, other_name, points, frame_quat, centre))
        return BumperReading(tuple(states), now)


# ---------------------------------------------------------------------------------------------
# The messages
# ---------------------------------------------------------------------------------------------
def _message_classes(msg):
    """gazebo_msgs' ContactState and geometry_msgs' Wrench and Vector3, from the module of the
    ContactsState the publisher made (a kind imports no message module: it stays pure)."""
    module = sys.modules[type(msg).__module__]
    return module.gazebo_msgs.msg.ContactState, module.geometry_msgs.msg.Wrench, module.geometry_msgs.msg.Vector3


def bumper_messages(out, r: BumperReading, wanted):
    msg = out.message("bumper")
    ContactState, Wrench, Vector3 = _message_classes(msg)

    def wrench(force_torque) -> Wrench:
        return Wrench(Vector3(*force_torque[0]), Vector3(*force_torque[1]))

    n = len(r.states)
    for k, s in enumerate(r.states):
        msg.states.append(
            ContactState(
                info=f"contact {k + 1} of {n} at {r.time:.4f} s: {s.collision1} with {s.collision2}",
                collision1_name=s.collision1,
                collision2_name=s.collision2,
                wrenches=[wrench(w) for w in s.wrenches],
                total_wrench=wrench(s.total),
                contact_positions=[Vector3(*v) for v in s.positions],
                contact_normals=[Vector3(*v) for v in s.normals],
                depths=list(s.depths),
            )
        )
    yield "bumper", msg


BUMPER = SensorKind(
    "bumper",
    blocks="`contact` + `libgazebo_ros_bumper.so`, its `<contact><collision>` named as Gazebo names "
    "collisions (`<link>_collision`, `_1`, ...; `<parent>_fixed_joint_lump__<link>_collision`)",
    published="`gazebo_msgs/ContactsState` on `bumperTopicName` (`bumper_states`): the collision's contacts, "
    "positions and normals in the world, wrenches in its link's axes",
    model=Bumper,
    roles={"bumper": "gazebo_msgs/ContactsState"},
    messages=bumper_messages,
    displays=no_display,
    sensors=(("contact", BUMPER_PLUGINS),),
    read_sensor=_read_sensor,
    example="""<gazebo reference="sensor_link"><sensor type="contact" name="bumper"><update_rate>50</update_rate>
<contact><collision>base_link_collision</collision></contact>
<plugin name="bumper_plugin" filename="libgazebo_ros_bumper.so"><bumperTopicName>bumper_states</bumperTopicName>
<frameName>sensor_link</frameName></plugin></sensor></gazebo>""",
)
