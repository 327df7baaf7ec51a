"""A generic URDF (a trailer, a gate, a box: anything but a Thorvald robot) read into a :class:`ModelSpec`
as Gazebo 11 sees it: through SDFormat 9's URDF-to-SDF conversion (gazebosim/sdformat,
``src/parser_urdf.cc``, tag sdformat9_9.10.1; urdfdom's ``model.h`` for the order of children):

- **fixed joints lumped**: a link joined to its parent by a fixed joint is merged into the parent
  (children first, depth first; children in the order of their joints' names, as urdfdom keeps its
  joints in a ``std::map``): its mass and inertia added to the parent's about their common centre of
  mass (kept in the parent's inertial axes), its collisions and visuals moved into the parent's frame
  and appended to the parent's, the joints of its moving children re-attached to the parent with the
  fixed joints' origins composed in. A joint's ``<gazebo reference>`` ``preserveFixedJoint`` or
  ``disableFixedJointLumping`` keeps it a joint;
- **collision names** (:func:`gazebo_collision_names`): the n-th collision of a link (n from 0, over
  its own then the lumped ones) is ``<name>_collision``, ``_<n>`` appended when n > 0, where name is
  the URDF ``<collision name>`` if given, else the link it was written in; when that does not begin
  with the link's name, ``<link>_fixed_joint_lump__`` is put before it. So a link's first own
  unnamed collision is ``base_link_collision``, the next ``base_link_collision_1``, and an unnamed
  collision of ``bumper`` lumped into ``base_link`` as its second collision is
  ``base_link_fixed_joint_lump__bumper_collision_1``;
- **links without ``<inertial>``** (or of mass 0, within 1e-6) are not simulated, nor is anything
  below them (Gazebo says "has no inertia, not modeled in sdf"): they are dropped, and said in
  ``notes``; one whose fixed children bring mass is lumped with it first. A model left without
  links is refused;
- ``<gazebo><static>true</static></gazebo>``: a static model; ``<gazebo reference="link">``
  ``mu1``, ``mu2``, ``kp``, ``kd`` on the link's own collisions (a lumped link's on the collisions it
  brought: their names hold ``_fixed_joint_lump__<link>_collision``), ``selfCollide``, and
  ``material`` (``Gazebo/<Colour>``) on its visuals;
- joints: continuous -> revolute without limits; revolute and prismatic with ``<limit>`` lower and
  upper (swapped when lower > upper, as Gazebo does), effort, velocity; ``<dynamics damping friction>``;
  the axis (URDF's default 1 0 0) in the joint frame, which is the child link's frame; floating and
  planar joints are refused (Gazebo leaves such a link free; a moving model here is one tree);
- a root link named ``world``: its joints fix the model to the world.

Pure: no pybullet, no ROS.
"""

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Tuple

from ..errors import ModelError
from . import reading
from .reading import MeshFinder, flag, numbers, tag_path
from .sdf import GAZEBO_COLOURS, default_finder
from .spec import (
    FIXED,
    IDENTITY,
    WORLD,
    Box,
    CollisionSpec,
    Cylinder,
    Geometry,
    Inertial,
    JointSpec,
    LinkSpec,
    Matrix3,
    Mesh,
    ModelSpec,
    Pose,
    Sphere,
    Surface,
    VisualSpec,
    checked_tree,
    compose,
    pose_from_xyz_rpy,
)

LUMP = "_fixed_joint_lump__"  # parser_urdf.cc's kLumpPrefix
COLLISION = "_collision"  # kCollisionExt
VISUAL = "_visual"  # kVisualExt
ZERO_MASS = 1e-6  # [kg] ignition::math::equal's tolerance: a mass this close to 0 is none


@dataclass(frozen=True)
class GazeboCollision:
    """One collision of a URDF as Gazebo names it after its conversion."""

    name: str  # e.g. base_link_fixed_joint_lump__bumper_collision_1
    link: str  # the link that holds it in Gazebo (after fixed joints are lumped), e.g. base_link
    origin_link: str  # the URDF link it was written in, e.g. bumper
    index: int  # its place among the collisions origin_link writes (from 0)


def gazebo_collision_names(xml_text: str, source: str) -> Tuple[GazeboCollision, ...]:
    """Every collision of a URDF with the name Gazebo's URDF conversion gives it, in Gazebo's order
    (links in the converted model's order, each link's collisions in order). Collisions of links
    Gazebo drops (no inertial) are not there. Meshes are not looked for. ModelError on a bad URDF."""
    robot = _read(xml_text, source, None)
    return tuple(
        GazeboCollision(c.gazebo_name, link.name, c.origin_link, c.index)
        for link in robot.kept
        for c in link.collisions
    )


def parse_urdf_model(xml_text: str, source: str, find: Optional[MeshFinder] = None) -> ModelSpec:
    """The model of a generic URDF as Gazebo simulates it (see the module); find resolves mesh URIs
    (default: :func:`thorvald_sim.models.sdf.default_finder`). ModelError naming source and element
    path of the first problem."""
    robot = _read(xml_text, source, find or default_finder())
    links = []
    for link in robot.kept:
        collisions = tuple(CollisionSpec(c.gazebo_name, c.origin, c.geometry, c.surface) for c in link.collisions)
        visuals = tuple(VisualSpec(v.gazebo_name, v.origin, v.geometry, v.rgba) for v in link.visuals)
        inertial = link.inertial
        assert inertial is not None  # a kept link has one
        links.append(
            LinkSpec(
                link.name,
                robot.model_pose[link.name],
                Inertial(inertial.mass, inertial.origin, inertial.inertia),
                collisions,
                visuals,
                link.self_collide,
            )
        )
    spec = ModelSpec(robot.name, robot.static, tuple(links), tuple(robot.joints), source, tuple(robot.notes))
    checked_tree(spec, f"robot[{robot.name}]")
    return spec


# ---- the URDF as urdfdom reads it ---------------------------------------------------------------
@dataclass
class _Inertial:
    mass: float
    origin: Pose
    inertia: Matrix3


@dataclass
class _Shape:
    name: str  # the URDF name ("" when none), then the name lumping gives
    origin: Pose  # in the link that holds it
    geometry: Optional[Geometry]  # None when meshes are not looked for
    origin_link: str
    index: int
    rgba: Optional[Tuple[float, float, float, float]] = None
    surface: Surface = field(default_factory=Surface)
    gazebo_name: str = ""


@dataclass
class _Link:
    name: str
    path: str
    inertial: Optional[_Inertial]
    collisions: List[_Shape]
    visuals: List[_Shape]
    parent_joint: Optional["_Joint"] = None
    children: List["_Joint"] = field(default_factory=list)
    self_collide: bool = False


@dataclass
class _Joint:
    name: str
    path: str
    type: str
    parent: str
    child: str
    origin: Pose
    axis: Tuple[float, float, float]
    limit: Optional[Tuple[float, float, float, float]]  # lower, upper, effort, velocity
    damping: float
    friction: float
    keep: bool = False  # preserveFixedJoint / disableFixedJointLumping


@dataclass
class _Robot:
    name: str
    static: bool
    links: Dict[str, _Link]
    root: _Link
    notes: List[str]
    kept: List[_Link] = field(default_factory=list)
    joints: List[JointSpec] = field(default_factory=list)
    model_pose: Dict[str, Pose] = field(default_factory=dict)
    surfaces: Dict[str, Dict[str, float]] = field(default_factory=dict)  # link -> its <gazebo> mu, mu2, kp, kd


def _read(xml_text: str, source: str, find: Optional[MeshFinder]) -> _Robot:
    root = reading.read_xml(xml_text, source)
    if root.tag != "robot":
        raise ModelError(source, root.tag, f"<{root.tag}> is not <robot>: not a URDF")
    name = root.get("name")
    if not name:
        raise ModelError(source, "robot", "a <robot> needs a name")
    path = f"robot[{name}]"
    reader = _UrdfReader(source, find, path)
    return reader.robot(root, name)


class _UrdfReader:
    def __init__(self, source: str, find: Optional[MeshFinder], path: str):
        self.source = source
        self.find = find
        self.path = path
        self.notes: List[str] = []
        self.materials: Dict[str, Tuple[float, float, float, float]] = {}

    def fail(self, path: str, rule: str) -> ModelError:
        return ModelError(self.source, path, rule)

    def robot(self, root: ET.Element, name: str) -> _Robot:
        for material in root.findall("material"):
            rgba = self.rgba(material, tag_path(self.path, material))
            if rgba is not None and material.get("name"):
                self.materials[material.get("name", "")] = rgba
        links: Dict[str, _Link] = {}
        for element in root.findall("link"):
            link = self.link(element, tag_path(self.path, element))
            if link.name in links:
                raise self.fail(link.path, f"a second link named {link.name!r} (the first: {links[link.name].path})")
            links[link.name] = link
        if not links:
            raise self.fail(self.path, "a URDF without links")
        joints: Dict[str, _Joint] = {}
        for element in root.findall("joint"):
            joint = self.joint(element, tag_path(self.path, element), links)
            if joint.name in joints:
                raise self.fail(joint.path, f"a second joint named {joint.name!r}")
            joints[joint.name] = joint
        for joint_name in sorted(joints):  # urdfdom: a std::map of joints, so children in name order
            joint = joints[joint_name]
            child = links[joint.child]
            if child.parent_joint is not None:
                raise self.fail(
                    joint.path,
                    f"link {joint.child!r} is the child of two joints ({child.parent_joint.name} and {joint.name})",
                )
            child.parent_joint = joint
            links[joint.parent].children.append(joint)
        roots = [link for link in links.values() if link.parent_joint is None]
        if len(roots) != 1:
            if not roots:
                raise self.fail(self.path, "joints in a loop: no link is without a parent (no root)")
            names = ", ".join(link.name for link in roots[:5])
            raise self.fail(self.path, f"{len(roots)} root links ({names}): a URDF is one tree")
        reached = self.reachable(roots[0], links)
        if len(reached) != len(links):
            lost = sorted(set(links) - reached)
            raise self.fail(self.path, "joints in a loop: links " + ", ".join(lost[:5]) + " are not below the root")
        robot = _Robot(name, False, links, roots[0], self.notes)
        self.extensions(root, robot, joints)
        _lump(robot, robot.root)
        self.convert(robot)
        if not robot.kept:
            raise self.fail(
                self.path,
                f"no link Gazebo simulates: link {robot.root.name!r} has no <inertial> (or mass 0), and Gazebo's "
                "URDF conversion leaves out such a link and everything below it",
            )
        return robot

    @staticmethod
    def reachable(root: _Link, links: Dict[str, _Link]) -> set:
        seen = {root.name}
        stack = [root]
        while stack:
            link = stack.pop()
            for joint in link.children:
                if joint.child not in seen:
                    seen.add(joint.child)
                    stack.append(links[joint.child])
        return seen

    # ---- elements -------------------------------------------------------------------------------
    def link(self, element: ET.Element, path: str) -> _Link:
        name = element.get("name")
        if not name:
            raise self.fail(path, "a <link> needs a name")
        inertial = None
        inertial_element = element.find("inertial")
        if inertial_element is not None:
            where = f"{path}/inertial"
            mass_element = inertial_element.find("mass")
            mass = reading.number(
                mass_element.get("value") if mass_element is not None else "0",
                self.source,
                f"{where}/mass",
                minimum=0.0,
            )
            inertia_element = inertial_element.find("inertia")
            values = {}
            for k in ("ixx", "ixy", "ixz", "iyy", "iyz", "izz"):
                text = inertia_element.get(k, "0") if inertia_element is not None else "0"
                values[k] = reading.number(text, self.source, f"{where}/inertia@{k}")
                if k in ("ixx", "iyy", "izz") and values[k] < 0:
                    raise self.fail(f"{where}/inertia@{k}", f"{values[k]:g}: a moment of inertia must be >= 0")
            inertia = (
                (values["ixx"], values["ixy"], values["ixz"]),
                (values["ixy"], values["iyy"], values["iyz"]),
                (values["ixz"], values["iyz"], values["izz"]),
            )
            inertial = _Inertial(mass, self.origin(inertial_element, where), inertia)
        collisions = []
        visuals = []
        for kind, shapes in (("collision", collisions), ("visual", visuals)):
            for index, shape in enumerate(element.findall(kind)):
                where = f"{path}/{kind}[{shape.get('name') or index}]"
                geometry = self.geometry(shape, where)
                rgba = self.visual_rgba(shape, where) if kind == "visual" else None
                shapes.append(_Shape(shape.get("name", ""), self.origin(shape, where), geometry, name, index, rgba))
        return _Link(name, path, inertial, collisions, visuals)

    def joint(self, element: ET.Element, path: str, links: Dict[str, _Link]) -> _Joint:
        name = element.get("name")
        if not name:
            raise self.fail(path, "a <joint> needs a name")
        kind = element.get("type", "")
        if kind in ("floating", "planar"):
            raise self.fail(
                path, f"a {kind} joint: Gazebo leaves its child link free; a moving model here is one tree of joints"
            )
        if kind not in ("fixed", "revolute", "continuous", "prismatic"):
            raise self.fail(
                path, f"joint type {kind!r} is not a URDF joint type (fixed, revolute, continuous, prismatic)"
            )
        ends = []
        for end in ("parent", "child"):
            e = element.find(end)
            link = e.get("link", "") if e is not None else ""
            if link not in links:
                known = ", ".join(sorted(links)[:10])
                raise self.fail(f"{path}/{end}", f"link {link!r} is not a link of the URDF (its links: {known})")
            ends.append(link)
        if ends[0] == ends[1]:
            raise self.fail(path, f"joins link {ends[0]!r} to itself")
        axis = (1.0, 0.0, 0.0)  # URDF's default
        axis_element = element.find("axis")
        if axis_element is not None and kind != "fixed":
            axis = numbers(axis_element.get("xyz", "1 0 0"), 3, self.source, f"{path}/axis@xyz")
            length = math.sqrt(sum(v * v for v in axis))
            if length == 0:
                raise self.fail(f"{path}/axis@xyz", "a joint's axis must not be zero")
            axis = (axis[0] / length, axis[1] / length, axis[2] / length)
        limit = None
        limit_element = element.find("limit")
        if limit_element is not None:
            where = f"{path}/limit"
            values = []
            for k, default in (("lower", "0"), ("upper", "0"), ("effort", None), ("velocity", None)):
                text = limit_element.get(k, default)
                if text is None:
                    raise self.fail(f"{where}@{k}", f"a <limit> needs {k} (URDF requires it)")
                values.append(reading.number(text, self.source, f"{where}@{k}"))
            limit = (values[0], values[1], values[2], values[3])
        elif kind in ("revolute", "prismatic"):
            raise self.fail(path, f"a {kind} joint needs a <limit> (URDF requires it)")
        dynamics = element.find("dynamics")
        damping = friction = 0.0
        if dynamics is not None:
            damping = reading.number(dynamics.get("damping", "0"), self.source, f"{path}/dynamics@damping", minimum=0.0)
            friction = reading.number(
                dynamics.get("friction", "0"), self.source, f"{path}/dynamics@friction", minimum=0.0
            )
        if element.find("mimic") is not None:
            self.notes.append(f"{path}/mimic: not simulated (Gazebo does not simulate it either)")
        return _Joint(name, path, kind, ends[0], ends[1], self.origin(element, path), axis, limit, damping, friction)

    def origin(self, element: ET.Element, path: str) -> Pose:
        origin = element.find("origin")
        if origin is None:
            return IDENTITY
        xyz = numbers(origin.get("xyz", "0 0 0"), 3, self.source, f"{path}/origin@xyz")
        rpy = numbers(origin.get("rpy", "0 0 0"), 3, self.source, f"{path}/origin@rpy")
        return pose_from_xyz_rpy(xyz, rpy)

    def geometry(self, shape: ET.Element, path: str) -> Optional[Geometry]:
        geometry = shape.find("geometry")
        kinds = [c for c in geometry if isinstance(c.tag, str)] if geometry is not None else []
        if not kinds:
            raise self.fail(path, "needs a <geometry> with a box, cylinder, sphere or mesh (URDF requires it)")
        g = kinds[0]
        where = f"{path}/geometry/{g.tag}"
        if g.tag == "box":
            size = numbers(g.get("size"), 3, self.source, f"{where}@size")
            for v in size:
                if not v > 0:
                    raise self.fail(f"{where}@size", f"{v:g}: a box's sizes must be > 0")
            return Box((size[0], size[1], size[2]))
        if g.tag == "cylinder":
            return Cylinder(
                reading.number(g.get("radius"), self.source, f"{where}@radius", positive=True),
                reading.number(g.get("length"), self.source, f"{where}@length", positive=True),
            )
        if g.tag == "sphere":
            return Sphere(reading.number(g.get("radius"), self.source, f"{where}@radius", positive=True))
        if g.tag == "mesh":
            uri = g.get("filename", "")
            scale = reading.positive_scale(
                numbers(g.get("scale", "1 1 1"), 3, self.source, f"{where}@scale"), self.source, f"{where}@scale"
            )
            if self.find is None:
                return None
            return Mesh(reading.mesh_file(uri, self.find, self.source, f"{where}@filename"), scale, uri)
        raise self.fail(where, f"a {g.tag} geometry is not URDF's (box, cylinder, sphere, mesh)")

    def rgba(self, material: ET.Element, path: str) -> Optional[Tuple[float, float, float, float]]:
        color = material.find("color")
        if color is None:
            return None
        r, g, b, a = numbers(color.get("rgba"), 4, self.source, f"{path}/color@rgba")
        return (r, g, b, a)

    def visual_rgba(self, visual: ET.Element, path: str):
        material = visual.find("material")
        if material is None:
            return None
        own = self.rgba(material, f"{path}/material")
        return own if own is not None else self.materials.get(material.get("name", ""))

    # ---- <gazebo> extensions ---------------------------------------------------------------------
    def extensions(self, root: ET.Element, robot: _Robot, joints: Dict[str, _Joint]) -> None:
        """The blocks Gazebo's conversion reads that matter here; each link's surface values are kept
        on its collisions with the link they were written for, to follow them when they are lumped."""
        surfaces: Dict[str, Dict[str, float]] = {}
        for block in root.findall("gazebo"):
            reference = block.get("reference", "")
            where = f"{self.path}/gazebo[{reference}]" if reference else f"{self.path}/gazebo"
            if not reference:
                static = block.find("static")
                if static is not None:
                    robot.static = flag(static.text, self.source, f"{where}/static")
                continue
            if reference in joints:
                for tag in ("preserveFixedJoint", "disableFixedJointLumping"):
                    element = block.find(tag)
                    if element is not None and flag(element.text, self.source, f"{where}/{tag}"):
                        joints[reference].keep = True
                continue
            link = robot.links.get(reference)
            if link is None:
                continue  # Gazebo ignores a block of an unknown reference too
            values = surfaces.setdefault(reference, {})
            for tag, key, rule in (
                ("mu1", "mu", "minimum"),
                ("mu2", "mu2", "minimum"),
                ("kp", "kp", "positive"),
                ("kd", "kd", "minimum"),
            ):
                element = block.find(tag)
                if element is not None:
                    rules = {"minimum": 0.0} if rule == "minimum" else {"positive": True}
                    values[key] = reading.number(element.text, self.source, f"{where}/{tag}", **rules)
            element = block.find("selfCollide")
            if element is not None:
                link.self_collide = flag(element.text, self.source, f"{where}/selfCollide")
            material = (block.findtext("material") or "").strip()
            if material in GAZEBO_COLOURS:
                for visual in link.visuals:
                    visual.rgba = GAZEBO_COLOURS[material]
        robot.surfaces = surfaces

    # ---- the converted model --------------------------------------------------------------------
    def convert(self, robot: _Robot) -> None:
        """The links Gazebo creates (CreateSDF's order: depth first from the root, children in joint
        name order), their poses in the model frame, their joints, their collision names."""

        def visit(link: _Link) -> None:
            inertial = link.inertial
            if link.name != WORLD and (inertial is None or abs(inertial.mass) < ZERO_MASS):
                below = _below(link, robot.links)
                self.notes.append(
                    f"{link.path}: no <inertial> (or mass 0): Gazebo's URDF conversion leaves it out"
                    + (", and the links below it: " + ", ".join(below) if below else "")
                )
                return
            joint = link.parent_joint
            # a lumped link is not created, but what hangs below it is (CreateSDF recurses through it)
            reduced = joint is not None and joint.parent != WORLD and _reducible(joint)
            if link.name != WORLD and not reduced:
                robot.kept.append(link)
                if joint is None:
                    pose = IDENTITY
                elif joint.parent == WORLD:
                    pose = joint.origin
                else:
                    pose = compose(robot.model_pose[joint.parent], joint.origin)
                robot.model_pose[link.name] = pose
                _name_shapes(link, robot.surfaces)
                if joint is not None:
                    robot.joints.append(_joint_spec(joint))
            for child_joint in link.children:
                visit(robot.links[child_joint.child])

        visit(robot.root)


def _below(link: _Link, links: Dict[str, _Link]) -> List[str]:
    """The names of every link below link (its subtree, itself not counted)."""
    names: List[str] = []
    stack = [link]
    while stack:
        for joint in stack.pop().children:
            names.append(joint.child)
            stack.append(links[joint.child])
    return names


def _reducible(joint: _Joint) -> bool:
    return joint.type == FIXED and not joint.keep


def _lump(robot: _Robot, link: _Link) -> None:
    """ReduceFixedJoints: each child joined by a reducible fixed joint is lumped first (depth first),
    then this link into its parent when its own joint is reducible and its parent not the world."""
    for joint in list(link.children):
        if _reducible(joint):
            _lump(robot, robot.links[joint.child])
    joint = link.parent_joint
    if joint is None or joint.parent == WORLD or not _reducible(joint):
        return
    parent = robot.links[joint.parent]
    _lump_inertial(parent, link, joint.origin)
    for shapes, into in ((link.collisions, parent.collisions), (link.visuals, parent.visuals)):
        for shape in shapes:
            if LUMP not in shape.name:
                shape.name = shape.name or link.name
            shape.origin = compose(joint.origin, shape.origin)
            into.append(shape)
        shapes.clear()
    # ReduceJointsToParent: moving children hang from the nearest link that stays, origins composed
    # (they stay in this link's list of children, so Gazebo creates them where this link was)
    for child_joint in link.children:
        if _reducible(child_joint):
            continue
        at = link
        while at.parent_joint is not None and at.parent_joint.parent != WORLD and _reducible(at.parent_joint):
            child_joint.origin = compose(at.parent_joint.origin, child_joint.origin)
            at = robot.links[at.parent_joint.parent]
        child_joint.parent = at.name


def _lump_inertial(parent: _Link, link: _Link, origin: Pose) -> None:
    """ReduceInertialToParent: the child's mass added to the parent's (ODE's dMass sums about the
    parent link's origin), the result about the new centre of mass in the parent's inertial axes."""
    if link.inertial is None:
        return
    if parent.inertial is None:
        parent.inertial = _Inertial(0.0, IDENTITY, ((0.0,) * 3,) * 3)  # type: ignore[arg-type]
    a = parent.inertial
    b = link.inertial
    b_pose = compose(origin, b.origin)
    mass = a.mass + b.mass
    ca = a.origin[0]
    cb = b_pose[0]
    about_origin = _add(
        _shifted(_rotated(a.inertia, a.origin[1]), a.mass, ca), _shifted(_rotated(b.inertia, b_pose[1]), b.mass, cb)
    )
    centre = tuple((a.mass * ca[i] + b.mass * cb[i]) / mass for i in range(3)) if mass > 0 else (0.0, 0.0, 0.0)
    about_centre = _shifted(about_origin, -mass, centre)
    # back into the parent's inertial axes
    conjugate = (-a.origin[1][0], -a.origin[1][1], -a.origin[1][2], a.origin[1][3])
    parent.inertial = _Inertial(mass, (centre, a.origin[1]), _rotated(about_centre, conjugate))  # type: ignore[arg-type]


def _matrix(q) -> Matrix3:
    x, y, z, w = q
    return (
        (1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)),
        (2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)),
        (2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)),
    )


def _rotated(inertia: Matrix3, q) -> Matrix3:
    """R I R^T: an inertia given in axes rotated by q, expressed in the unrotated axes."""
    r = _matrix(q)
    ri = [[sum(r[i][k] * inertia[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    return tuple(tuple(sum(ri[i][k] * r[j][k] for k in range(3)) for j in range(3)) for i in range(3))  # type: ignore[return-value]


def _shifted(inertia: Matrix3, mass: float, c) -> Matrix3:
    """The parallel axis theorem: the inertia about a point c away (mass negative: back to the centre)."""
    cc = sum(v * v for v in c)
    return tuple(
        tuple(inertia[i][j] + mass * ((cc if i == j else 0.0) - c[i] * c[j]) for j in range(3)) for i in range(3)
    )  # type: ignore[return-value]


def _add(a: Matrix3, b: Matrix3) -> Matrix3:
    return tuple(tuple(a[i][j] + b[i][j] for j in range(3)) for i in range(3))  # type: ignore[return-value]


def _name_shapes(link: _Link, surfaces: Dict[str, Dict[str, float]]) -> None:
    """CreateCollisions / CreateCollision (and the visuals alike), then InsertSDFExtensionCollision:
    each link's surface values on the collisions they belong to."""
    for suffix, shapes in ((COLLISION, link.collisions), (VISUAL, link.visuals)):
        for n, shape in enumerate(shapes):
            name = (shape.name or link.name) + suffix + (f"_{n}" if n > 0 else "")
            shape.gazebo_name = name if name.startswith(link.name) else link.name + LUMP + name
    for shape in link.collisions:
        values: Dict[str, float] = {}
        for reference, given in surfaces.items():
            own = reference == link.name
            if (own and LUMP not in shape.gazebo_name) or (
                not own and LUMP + reference + COLLISION in shape.gazebo_name
            ):
                values.update(given)
        if values:
            shape.surface = Surface(
                mu=values.get("mu", 1.0), mu2=values.get("mu2", 1.0), kp=values.get("kp"), kd=values.get("kd")
            )


def _joint_spec(joint: _Joint) -> JointSpec:
    kind = {"continuous": "revolute"}.get(joint.type, joint.type)
    lower, upper, effort, velocity = -math.inf, math.inf, math.inf, math.inf
    if joint.limit is not None and joint.type != FIXED:
        if joint.type != "continuous":
            lower, upper = sorted(joint.limit[:2])  # Gazebo swaps a lower above the upper
        effort, velocity = joint.limit[2], joint.limit[3]
    return JointSpec(
        joint.name, kind, joint.parent, joint.child, IDENTITY, joint.axis,
        lower, upper, effort, velocity, joint.damping, joint.friction,
    )  # fmt: skip
