"""An SDF ``<model>`` (SDF 1.4 to 1.7, in ``<sdf version=...>`` or bare) read into a :class:`ModelSpec`.

As SDFormat 9 (Gazebo 11's) reads it (gazebosim/sdformat, ``sdf/1.4`` ... ``sdf/1.7`` and the
``1_5.convert``, ``1_6.convert``, ``1_7.convert`` files between them):

- ``<static>``, ``<self_collide>`` (of the model, the default of its links), ``<pose>`` (six numbers,
  x y z roll pitch yaw);
- frames: a link's pose is in the model frame, a joint's in its child link's frame, a ``<frame>``'s
  in its ``attached_to`` frame, a nested model's in its parent model's frame, a collision's and a
  visual's in its link's frame, unless ``relative_to`` (1.7; 1.5 and 1.6's ``frame`` attribute, which
  SDFormat 9 turns into ``relative_to``) names another frame of the model: ``__model__``, a link,
  joint, frame or nested model, or a frame inside a nested model (``inner::link``); a loop of them is
  refused;
- a joint's axis: 1.4 gives it in the model frame (SDFormat adds ``use_parent_model_frame`` true when
  it converts 1.4 up); 1.5 and 1.6 in the joint frame unless ``use_parent_model_frame`` is true; 1.7 in
  the joint frame unless ``<xyz expressed_in=...>`` names another;
- ``<inertial>``: SDF's defaults when absent (mass 1 kg, identity inertia 1 kg m^2 on the diagonal);
- geometry box (size, default 1 1 1), cylinder (radius 1, length 1), sphere (radius 1), plane
  (normal 0 0 1, size 1 1), mesh (uri, scale) found through the caller's finder; ``<empty/>`` and no
  geometry collide with nothing;
- ``<surface>``: ``friction/ode/mu`` and ``mu2`` (default 1), ``contact/ode/kp`` and ``kd`` (when
  given), ``bounce/restitution_coefficient``; a visual's colour from ``material/diffuse`` (else
  ``ambient``, else a ``Gazebo/<Colour>`` script of the common ones);
- joints fixed, revolute (no ``<limit>`` or SDF's default +-1e16: continuous), prismatic; Gazebo's
  ``continuous`` spelling of URDF is read as a revolute without limits; ``<limit>`` lower, upper,
  effort and velocity (-1: none), ``<dynamics>`` damping and friction;
- nested ``<model>`` s and ``<include>`` s (through the caller's loader) flattened into one model,
  their links and joints named with Gazebo's scopes (``inner::link``; Gazebo's full name of it is
  ``outer::inner::link``), their poses composed.

Refused with a :class:`ModelError` naming the source and element path: broken XML, no model, a
budget exceeded (:mod:`.reading`), a joint whose parent or child is not a link of the model, a loop
of joints, two links (joints, collisions of one link) of one name, a number that is not finite, a
negative size or mass, a mesh that cannot be found or read, a joint type not simulated here.

Pure: no pybullet, no ROS.
"""

import math
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field, replace
from typing import Callable, Dict, List, Optional, Set, Tuple

from ..errors import ModelError
from . import reading
from .reading import MeshFinder, child_number, flag, numbers, tag_path
from .spec import (
    IDENTITY,
    WORLD,
    Box,
    CollisionSpec,
    Cylinder,
    Geometry,
    Inertial,
    JointSpec,
    LinkSpec,
    Mesh,
    ModelSpec,
    Plane,
    Pose,
    Sphere,
    Surface,
    Vec3,
    VisualSpec,
    checked_tree,
    compose,
    inverse,
    pose_from_xyz_rpy,
    relative,
    rotate_vector,
)

LATEST = (1, 7)  # the newest SDF version read as itself; a newer file is read as 1.7
MODEL_FRAME = "__model__"
UNLIMITED = 1e16  # SDF's default joint limits: no limit

IncludeLoader = Callable[[str], Tuple[Optional[Tuple[str, str]], str]]
"""uri of an ``<include>`` -> ((the model's SDF text, its source), "") or (None, where it looked)."""

# the colours of Gazebo's common material scripts (gazebo.material), for visuals that name only those
GAZEBO_COLOURS = {
    "Gazebo/Black": (0.0, 0.0, 0.0, 1.0),
    "Gazebo/Blue": (0.0, 0.0, 1.0, 1.0),
    "Gazebo/DarkGrey": (0.175, 0.175, 0.175, 1.0),
    "Gazebo/Green": (0.0, 1.0, 0.0, 1.0),
    "Gazebo/Grey": (0.7, 0.7, 0.7, 1.0),
    "Gazebo/Orange": (1.0, 0.5088, 0.0468, 1.0),
    "Gazebo/Purple": (1.0, 0.0, 1.0, 1.0),
    "Gazebo/Red": (1.0, 0.0, 0.0, 1.0),
    "Gazebo/White": (1.0, 1.0, 1.0, 1.0),
    "Gazebo/Wood": (0.6, 0.45, 0.28, 1.0),
    "Gazebo/Yellow": (1.0, 1.0, 0.0, 1.0),
}


def default_finder(base_dir: Optional[str] = None, model: Optional[MeshFinder] = None) -> MeshFinder:
    """A finder of mesh URIs: ``package://`` (through rospack), ``file://`` and absolute paths as
    :func:`thorvald_sim.physics.description.mesh_finder` finds a robot's meshes; a relative path in base_dir
    (the model file's folder); ``model://`` through model (Gazebo's model path: the caller's)."""
    packages: List[MeshFinder] = []

    def find(uri: str) -> Tuple[Optional[str], str]:
        if uri.startswith("model://"):
            if model is None:
                return None, "model:// URIs are found on GAZEBO_MODEL_PATH, and no model finder was given"
            return model(uri)
        if "://" in uri or os.path.isabs(uri) or base_dir is None:
            if not packages:
                from ..physics.description import (  # noqa: PLC0415  (thorvald_model: only once a mesh is named)
                    installed_package_path,
                    mesh_finder,
                )

                packages.append(mesh_finder(installed_package_path))
            return packages[0](uri)
        path = os.path.join(base_dir, uri)
        return (path, "") if os.path.isfile(path) else (None, f"no such file in {base_dir}")

    return find


def parse_sdf_model(
    xml_text: str,
    source: str,
    find: Optional[MeshFinder] = None,
    include: Optional[IncludeLoader] = None,
) -> ModelSpec:
    """The model of an SDF text (``<sdf version=...><model>`` or a bare ``<model>``); find resolves
    mesh URIs (default: :func:`default_finder`), include loads ``<include>`` d models (none: an
    include is refused). ModelError naming source and the element path of the first problem."""
    find = find or default_finder()
    budget = reading.Budget()
    root = reading.read_xml(xml_text, source, budget)
    reader = _Reader(source, find, include, budget)
    version, model, path = reader.top(root)
    scope = reader.model(model, path, version, depth=1, static=False)
    spec = ModelSpec(
        name=scope.name,
        static=scope.static,
        links=tuple(scope.links),
        joints=tuple(scope.joints),
        source=source,
        notes=tuple(reader.notes),
        pose=scope.pose,
    )
    checked_tree(spec, path)
    return spec


@dataclass
class _Scope:
    """One model read: its links and joints in its own model frame, and every frame it names."""

    name: str
    static: bool
    pose: Pose  # of the model in its parent (its own <pose>, relative_to resolved by the parent)
    pose_relative_to: str
    links: List[LinkSpec] = field(default_factory=list)
    joints: List[JointSpec] = field(default_factory=list)
    frames: Dict[str, Pose] = field(default_factory=dict)  # scoped name -> pose in this model frame
    attached: Dict[str, str] = field(default_factory=dict)  # scoped frame name -> the link it moves with


class _Reader:
    def __init__(self, source: str, find: MeshFinder, include: Optional[IncludeLoader], budget: reading.Budget):
        self.source = source
        self.find = find
        self.include = include
        self.budget = budget
        self.notes: List[str] = []
        self.noted: Set[str] = set()

    def fail(self, path: str, rule: str, source: Optional[str] = None) -> ModelError:
        return ModelError(source or self.source, path, rule)

    def note(self, path: str, text: str) -> None:
        if path not in self.noted:
            self.noted.add(path)
            self.notes.append(f"{path}: {text}")

    # ---- the document ---------------------------------------------------------------------------
    def top(self, root: ET.Element) -> Tuple[Tuple[int, int], ET.Element, str]:
        if root.tag == "model":
            return LATEST, root, tag_path("", root)
        if root.tag != "sdf":
            raise self.fail(root.tag, f"<{root.tag}> is neither <sdf> nor <model>: not an SDF model")
        version = self.version(root.get("version"), "sdf")
        models = root.findall("model")
        if not models:
            what = ", ".join(sorted({f"<{c.tag}>" for c in root})) or "nothing"
            raise self.fail("sdf", f"no <model> in it (it has {what}); a world is loaded as a world, not spawned")
        if len(models) > 1:
            self.note(
                "sdf", f"{len(models)} models; the first, {models[0].get('name')!r}, is read, as Gazebo spawns it"
            )
        return version, models[0], tag_path("sdf", models[0])

    def version(self, text: Optional[str], path: str) -> Tuple[int, int]:
        try:
            major, minor = (int(w) for w in (text or "").strip().split("."))
        except ValueError:
            raise self.fail(path, f"version {text!r}: not an SDF version such as 1.6") from None
        if (major, minor) > LATEST:
            self.note(path, f"SDF {text} is read as SDF 1.7")
            return LATEST
        return (major, minor)

    # ---- a model, its nested models and includes ------------------------------------------------
    def model(self, element: ET.Element, path: str, version, depth: int, static: bool) -> _Scope:
        if depth > reading.MAX_NESTING:
            raise self.fail(path, f"models nested more than {reading.MAX_NESTING} deep")
        name = element.get("name")
        if not name:
            raise self.fail(path, "a <model> needs a name")
        own_static = self.bool_child(element, "static", path, False)
        if static and element.find("static") is not None and not own_static:
            self.note(path, "a model inside a static model is static")
        pose, relative_to = self.pose(element, path)
        scope = _Scope(name, own_static or static, pose, relative_to)
        self_collide = self.bool_child(element, "self_collide", path, False)
        raw: Dict[str, Tuple[str, Pose, str, str, str]] = {MODEL_FRAME: ("", IDENTITY, MODEL_FRAME, path, "")}
        links: List[Tuple[ET.Element, str]] = []
        joints: List[Tuple[ET.Element, str]] = []
        nested: List[Tuple[_Scope, str]] = []
        for child in element:
            child_path = tag_path(path, child)
            if child.tag in ("link", "joint", "frame", "model", "include"):
                if child.tag == "model":
                    inner = self.model(child, child_path, version, depth + 1, scope.static)
                elif child.tag == "include":
                    inner = self.included(child, child_path, depth + 1, scope.static)
                else:
                    inner = None
                item_name = inner.name if inner is not None else child.get("name")
                if not item_name:
                    raise self.fail(child_path, f"a <{child.tag}> needs a name")
                if "::" in item_name:
                    raise self.fail(child_path, f"name {item_name!r}: '::' separates scopes and is not part of a name")
                if item_name in (MODEL_FRAME, WORLD):
                    raise self.fail(child_path, f"name {item_name!r} is reserved")
                if item_name in raw and (raw[item_name][2] == child.tag or version >= (1, 7)):
                    raise self.fail(
                        child_path, f"a second {child.tag} named {item_name!r} (the first: {raw[item_name][3]})"
                    )
                if child.tag == "joint":
                    default = attached_to = (child.findtext("child") or "").strip()
                elif child.tag == "frame":
                    default = attached_to = child.get("attached_to") or MODEL_FRAME
                else:
                    default, attached_to = MODEL_FRAME, item_name
                if inner is not None:
                    rel, child_pose = inner.pose_relative_to, inner.pose
                    nested.append((inner, child_path))
                else:
                    child_pose, rel = self.pose(child, child_path)
                if item_name not in raw:
                    raw[item_name] = (rel or default, child_pose, child.tag, child_path, attached_to)
                if child.tag == "link":
                    links.append((child, child_path))
                elif child.tag == "joint":
                    joints.append((child, child_path))
            elif child.tag in ("plugin", "gripper"):
                self.note(child_path, f"<{child.tag}> is not read by the model builder")
        if not links and not nested:
            raise self.fail(path, "a model without links")
        frames = _Frames(self, raw, nested)
        for joint_element, joint_path in joints:  # each end named before any frame is resolved
            for end in ("parent", "child"):
                text = (joint_element.findtext(end) or "").strip()
                if not text:
                    raise self.fail(f"{joint_path}/{end}", f"a joint needs a <{end}>")
                if not (text in raw or (end == "parent" and text == WORLD) or frames.known(text)):
                    known = ", ".join(sorted(n for n, r in raw.items() if r[2] == "link")[:10])
                    raise self.fail(
                        f"{joint_path}/{end}", f"{text!r} is not a link or frame of the model (its links: {known})"
                    )
        scope.frames = frames.all()
        canonical = links[0][0].get("name") if links else None
        for link_element, link_path in links:
            scope.links.append(self.link(link_element, link_path, frames, self_collide))
        for inner, _ in nested:
            prefix = inner.name + "::"
            for link in inner.links:
                scope.links.append(
                    replace(link, name=prefix + link.name, pose=compose(frames.pose(inner.name), link.pose))
                )
            for joint in inner.joints:
                parent = joint.parent if joint.parent == WORLD else prefix + joint.parent
                scope.joints.append(replace(joint, name=prefix + joint.name, parent=parent, child=prefix + joint.child))
            if canonical is None and inner.links:
                canonical = prefix + inner.links[0].name
        if not links and nested and all(inner.static for inner, _ in nested):
            scope.static = True  # a wrapper of static models only (a population's <model><include>): as each is
        scope.attached = frames.attachments(canonical or "")
        for joint_element, joint_path in joints:
            scope.joints.append(self.joint(joint_element, joint_path, frames, scope, version))
        reading.unique([(link.name, path) for link in scope.links], "link", self.source)
        return scope

    def included(self, element: ET.Element, path: str, depth: int, static: bool) -> _Scope:
        uri = (element.findtext("uri") or "").strip()
        if not uri:
            raise self.fail(path, "an <include> needs a <uri>")
        if self.include is None:
            raise self.fail(path, f"<include> of {uri}: no loader of included models was given")
        loaded, reason = self.include(uri)
        if loaded is None:
            raise self.fail(path, f"<include> of {uri} cannot be found: {reason}")
        text, source = loaded
        root = reading.read_xml(text, source, self.budget)
        outer = self.source
        self.source = source
        try:
            version, model, model_path = self.top(root)
            if element.find("name") is not None:
                model.set("name", (element.findtext("name") or "").strip())
            if element.find("static") is not None:
                static = static or self.bool_child(element, "static", path, False)
            scope = self.model(model, model_path, version, depth, static)
        finally:
            self.source = outer
        if element.find("pose") is not None:
            scope.pose, scope.pose_relative_to = self.pose(element, path)
        return scope

    # ---- links ----------------------------------------------------------------------------------
    def link(self, element: ET.Element, path: str, frames: "_Frames", self_collide: bool) -> LinkSpec:
        name = element.get("name", "")
        pose = frames.pose(name)
        collisions = []
        visuals = []
        for child in element:
            child_path = tag_path(path, child)
            if child.tag in ("collision", "visual"):
                if not child.get("name"):
                    raise self.fail(child_path, f"a <{child.tag}> needs a name")
                own, rel = self.pose(child, child_path)
                at = own if not rel else relative(pose, compose(frames.pose(rel, child_path), own))
                geometry = self.geometry(child, child_path)
                if child.tag == "collision":
                    if geometry is None:
                        self.note(child_path, "no geometry: it collides with nothing")
                        continue
                    surface = self.surface(child.find("surface"), f"{child_path}/surface")
                    collisions.append(CollisionSpec(child.get("name", ""), at, geometry, surface))
                elif geometry is not None:
                    visuals.append(VisualSpec(child.get("name", ""), at, geometry, self.colour(child, child_path)))
            elif child.tag in ("sensor", "plugin", "projector", "light", "battery", "audio_source", "particle_emitter"):
                self.note(child_path, f"<{child.tag}> is not read by the model builder")
        reading.unique(
            [(c.name, f"{path}/collision[{c.name}]") for c in collisions], "collision of this link", self.source
        )
        return LinkSpec(
            name=name,
            pose=pose,
            inertial=self.inertial(element.find("inertial"), f"{path}/inertial"),
            collisions=tuple(collisions),
            visuals=tuple(visuals),
            self_collide=self.bool_child(element, "self_collide", path, self_collide),
        )

    def inertial(self, element: Optional[ET.Element], path: str) -> Inertial:
        if element is None:
            return Inertial(1.0)  # SDF's default
        mass = child_number(element, "mass", 1.0, self.source, path, minimum=0.0)
        pose, _ = self.pose(element, path)
        inertia = element.find("inertia")
        where = f"{path}/inertia"
        values = {
            k: child_number(inertia, k, 1.0 if k in ("ixx", "iyy", "izz") else 0.0, self.source, where)
            for k in INERTIA_KEYS
        }
        for k in ("ixx", "iyy", "izz"):
            if values[k] < 0:
                raise self.fail(f"{where}/{k}", f"{values[k]:g}: a moment of inertia must be >= 0")
        return Inertial(mass, pose, inertia_matrix(values))

    def geometry(self, element: ET.Element, path: str) -> Optional[Geometry]:
        geometry = element.find("geometry")
        if geometry is None:
            return None
        path = f"{path}/geometry"
        shapes = [c for c in geometry if isinstance(c.tag, str)]
        if not shapes:
            return None
        shape = shapes[0]
        where = f"{path}/{shape.tag}"
        src = self.source
        if shape.tag == "empty":
            return None
        if shape.tag == "box":
            size = self.vector(shape.find("size"), f"{where}/size", (1.0, 1.0, 1.0))
            for v in size:
                if not v > 0:
                    raise self.fail(f"{where}/size", f"{v:g}: a box's sizes must be > 0")
            return Box(size)
        if shape.tag == "cylinder":
            return Cylinder(
                child_number(shape, "radius", 1.0, src, where, positive=True),
                child_number(shape, "length", 1.0, src, where, positive=True),
            )
        if shape.tag == "sphere":
            return Sphere(child_number(shape, "radius", 1.0, src, where, positive=True))
        if shape.tag == "plane":
            normal = self.vector(shape.find("normal"), f"{where}/normal", (0.0, 0.0, 1.0))
            length = math.sqrt(sum(v * v for v in normal))
            if length == 0:
                raise self.fail(f"{where}/normal", "must not be zero")
            size_element = shape.find("size")
            size = numbers(size_element.text, 2, src, f"{where}/size") if size_element is not None else (1.0, 1.0)
            if min(size) < 0:
                raise self.fail(f"{where}/size", "a plane's sizes must be >= 0")
            return Plane((normal[0] / length, normal[1] / length, normal[2] / length), (size[0], size[1]))
        if shape.tag == "mesh":
            uri = (shape.findtext("uri") or "").strip()
            scale = self.vector(shape.find("scale"), f"{where}/scale", (1.0, 1.0, 1.0))
            scale = reading.positive_scale(scale, src, f"{where}/scale")
            if shape.find("submesh") is not None:
                self.note(f"{where}/submesh", "the whole mesh is used, not the submesh")
            return Mesh(reading.mesh_file(uri, self.find, src, f"{where}/uri"), scale, uri)
        raise self.fail(
            where, f"a {shape.tag} geometry is not simulated in a model here (box, cylinder, sphere, plane, mesh)"
        )

    def surface(self, element: Optional[ET.Element], path: str) -> Surface:
        if element is None:
            return Surface()
        src = self.source
        ode = element.find("friction/ode")
        contact = element.find("contact/ode")
        kp = contact.find("kp") if contact is not None else None
        kd = contact.find("kd") if contact is not None else None
        return Surface(
            mu=child_number(ode, "mu", 1.0, src, f"{path}/friction/ode", minimum=0.0),
            mu2=child_number(ode, "mu2", 1.0, src, f"{path}/friction/ode", minimum=0.0),
            kp=None if kp is None else reading.number(kp.text, src, f"{path}/contact/ode/kp", positive=True),
            kd=None if kd is None else reading.number(kd.text, src, f"{path}/contact/ode/kd", minimum=0.0),
            restitution=min(
                1.0,
                child_number(
                    element.find("bounce"), "restitution_coefficient", 0.0, src, f"{path}/bounce", minimum=0.0
                ),
            ),
        )

    def colour(self, visual: ET.Element, path: str):
        material = visual.find("material")
        if material is None:
            return None
        for tag in ("diffuse", "ambient"):
            element = material.find(tag)
            if element is not None:
                words = (element.text or "").split()
                values = numbers(
                    element.text, len(words) if len(words) in (3, 4) else 4, self.source, f"{path}/material/{tag}"
                )
                rgba = tuple(min(1.0, max(0.0, v)) for v in values)
                return rgba if len(rgba) == 4 else (*rgba, 1.0)
        name = (material.findtext("script/name") or "").strip()
        return GAZEBO_COLOURS.get(name)

    # ---- joints ---------------------------------------------------------------------------------
    def joint(self, element: ET.Element, path: str, frames: "_Frames", scope: _Scope, version) -> JointSpec:
        name = element.get("name", "")
        kind = (element.get("type") or "").strip()
        if kind not in ("fixed", "revolute", "prismatic", "continuous"):
            raise self.fail(path, f"joint type {kind!r} is not simulated here (fixed, revolute, prismatic)")
        ends = []
        for end in ("parent", "child"):
            text = (element.findtext(end) or "").strip()
            if not text:
                raise self.fail(f"{path}/{end}", f"a joint needs a <{end}>")
            if text == WORLD and end == "parent":
                ends.append(WORLD)
                continue
            link = scope.attached.get(text)
            if link is None:
                known = ", ".join(sorted(link.name for link in scope.links)[:10])
                raise self.fail(f"{path}/{end}", f"{text!r} is not a link or frame of the model (its links: {known})")
            ends.append(link)
        parent, child = ends
        if parent == child:
            raise self.fail(path, f"joins link {child!r} to itself")
        child_pose = scope.frames[child]
        joint_in_model = frames.pose(name)
        pose = relative(child_pose, joint_in_model)
        if kind == "fixed":
            return JointSpec(name, "fixed", parent, child, pose)
        axis_element = element.find("axis")
        axis_path = f"{path}/axis"
        xyz_element = axis_element.find("xyz") if axis_element is not None else None
        axis = self.vector(xyz_element, f"{axis_path}/xyz", (0.0, 0.0, 1.0))
        length = math.sqrt(sum(v * v for v in axis))
        if length == 0:
            raise self.fail(f"{axis_path}/xyz", "a joint's axis must not be zero")
        axis = (axis[0] / length, axis[1] / length, axis[2] / length)
        expressed_in = ""
        if version < (1, 5):
            expressed_in = MODEL_FRAME
        elif version < (1, 7):
            if self.bool_child(axis_element, "use_parent_model_frame", axis_path, False):
                expressed_in = MODEL_FRAME
        elif xyz_element is not None:
            expressed_in = xyz_element.get("expressed_in", "")
        if expressed_in:
            in_model = rotate_vector(frames.pose(expressed_in, f"{axis_path}/xyz"), axis)
            axis = rotate_vector(inverse(joint_in_model), in_model)
        limit = axis_element.find("limit") if axis_element is not None else None
        dynamics = axis_element.find("dynamics") if axis_element is not None else None
        src = self.source
        lower = child_number(limit, "lower", -UNLIMITED, src, f"{axis_path}/limit", allow_infinite=True)
        upper = child_number(limit, "upper", UNLIMITED, src, f"{axis_path}/limit", allow_infinite=True)
        if kind == "continuous" or (lower <= -UNLIMITED and upper >= UNLIMITED):
            lower, upper = -math.inf, math.inf
            kind = "revolute" if kind == "continuous" else kind
        elif lower > upper:
            raise self.fail(f"{axis_path}/limit", f"lower {lower:g} is above upper {upper:g}")
        effort = child_number(limit, "effort", -1.0, src, f"{axis_path}/limit", allow_infinite=True)
        velocity = child_number(limit, "velocity", -1.0, src, f"{axis_path}/limit", allow_infinite=True)
        return JointSpec(
            name, kind, parent, child, pose, axis,
            lower=lower if math.isfinite(lower) else -math.inf,
            upper=upper if math.isfinite(upper) else math.inf,
            effort=effort if effort >= 0 else math.inf,
            velocity=velocity if velocity >= 0 else math.inf,
            damping=child_number(dynamics, "damping", 0.0, src, f"{axis_path}/dynamics", minimum=0.0),
            friction=child_number(dynamics, "friction", 0.0, src, f"{axis_path}/dynamics", minimum=0.0),
        )  # fmt: skip

    # ---- small values ---------------------------------------------------------------------------
    def pose(self, element: ET.Element, path: str) -> Tuple[Pose, str]:
        """An element's own <pose> and the frame it is relative to ("" when it says none)."""
        pose = element.find("pose")
        if pose is None:
            return IDENTITY, ""
        where = f"{path}/pose"
        text = (pose.text or "").strip()
        values = numbers(text, 6, self.source, where) if text else (0.0,) * 6
        relative_to = (pose.get("relative_to") or pose.get("frame") or "").strip()
        return pose_from_xyz_rpy(values[:3], values[3:]), relative_to

    def vector(self, element: Optional[ET.Element], path: str, default: Vec3) -> Vec3:
        if element is None:
            return default
        x, y, z = numbers(element.text, 3, self.source, path)
        return (x, y, z)

    def bool_child(self, element: Optional[ET.Element], tag: str, path: str, default: bool) -> bool:
        child = None if element is None else element.find(tag)
        return default if child is None else flag(child.text, self.source, f"{path}/{tag}")


INERTIA_KEYS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")


def inertia_matrix(v: Dict[str, float]):
    return (
        (v["ixx"], v["ixy"], v["ixz"]),
        (v["ixy"], v["iyy"], v["iyz"]),
        (v["ixz"], v["iyz"], v["izz"]),
    )


class _Frames:
    """The frames of one model scope, each resolved to a pose in the model frame on first use."""

    def __init__(
        self, reader: _Reader, raw: Dict[str, Tuple[str, Pose, str, str, str]], nested: List[Tuple[_Scope, str]]
    ):
        self.reader = reader
        self.raw = raw  # name -> (relative_to, pose, kind, element path, attached_to)
        self.nested = {scope.name: scope for scope, _ in nested}
        self.resolved: Dict[str, Pose] = {MODEL_FRAME: IDENTITY}
        self.visiting: List[str] = []

    def known(self, name: str) -> bool:
        """Whether name is a frame of this scope or, scoped, of a nested model."""
        if name in self.raw:
            return True
        outer, _, rest = name.partition("::")
        return bool(rest) and outer in self.nested and rest in self.nested[outer].frames

    def pose(self, name: str, path: str = "") -> Pose:
        if name in self.resolved:
            return self.resolved[name]
        if "::" in name:
            outer, _, rest = name.partition("::")
            inner = self.nested.get(outer)
            if inner is None or rest not in inner.frames:
                raise self.reader.fail(path, f"frame {name!r} is not a frame of the model")
            return compose(self.pose(outer, path), inner.frames[rest])
        if name not in self.raw:
            raise self.reader.fail(
                path, f"frame {name!r} is not a frame of the model ({MODEL_FRAME}, a link, joint, frame or model)"
            )
        if name in self.visiting:
            loop = " -> ".join([*self.visiting[self.visiting.index(name) :], name])
            raise self.reader.fail(self.raw[name][3], f"poses relative to each other in a loop: {loop}")
        self.visiting.append(name)
        relative_to, own, _, element_path, _ = self.raw[name]
        base = self.pose(relative_to, f"{element_path}/pose")
        self.visiting.pop()
        self.resolved[name] = compose(base, own)
        return self.resolved[name]

    def all(self) -> Dict[str, Pose]:
        frames = {name: self.pose(name) for name in self.raw}
        for outer, scope in self.nested.items():
            for name, pose in scope.frames.items():
                if name != MODEL_FRAME:
                    frames[f"{outer}::{name}"] = compose(frames[outer], pose)
        return frames

    def attachments(self, canonical: str) -> Dict[str, str]:
        """Every frame name -> the link it moves with (a joint's: its child link; a model's: its
        canonical link, its first)."""
        kinds = {name: raw[2] for name, raw in self.raw.items()}
        result: Dict[str, str] = {}

        def link_of(name: str, seen: Tuple[str, ...] = ()) -> Optional[str]:
            if name in result:
                return result[name]
            if name in seen:
                return None
            kind = kinds.get(name)
            found: Optional[str]
            if name == MODEL_FRAME:
                found = canonical or None
            elif kind == "link":
                found = name
            elif kind in ("joint", "frame"):
                found = link_of(self.raw[name][4], (*seen, name))
            elif kind in ("model", "include"):
                scope = self.nested[name]
                found = f"{name}::{scope.attached.get(MODEL_FRAME, '')}" if scope.attached.get(MODEL_FRAME) else None
            elif "::" in name:
                outer, _, rest = name.partition("::")
                scope = self.nested.get(outer)
                inner = scope.attached.get(rest) if scope else None
                found = f"{outer}::{inner}" if inner else None
            else:
                found = None
            if found:
                result[name] = found
            return found

        for name in kinds:
            link_of(name)
        for outer, scope in self.nested.items():
            for name, link in scope.attached.items():
                result.setdefault(f"{outer}::{name}", f"{outer}::{link}")
        return result
