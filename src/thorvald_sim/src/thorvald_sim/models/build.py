"""A :class:`ModelSpec` built in pybullet: :class:`SimModel`, one multibody a model.

How Gazebo's model maps onto pybullet (3.2.7):

- **links and joints**: the links as one tree (:func:`thorvald_sim.models.spec.tree`), the root as the
  multibody's base, every other link a pybullet link whose frame is its joint's frame (pybullet puts a
  joint at its child link's frame origin; an SDF joint may sit elsewhere in its child link, so each
  link's shapes and inertia are given relative to its joint frame, and :meth:`SimModel.link_pose`
  turns back to the link's own frame). Fixed, revolute (continuous: without limits) and prismatic
  joints; a moving joint to the world hangs the model from a fixed, shapeless base.
- **static**: a fixed base, every link fixed where it is and massless: nothing moves it, as in Gazebo.
- **inertia as given**: pybullet takes only a diagonal inertia (``localInertiaDiagonal``) in an
  inertial frame; the full 3x3 tensor is diagonalised and its principal axes folded into the inertial
  frame's orientation, so mass, centre of mass and tensor are exactly the spec's.
- **free joints**: pybullet's default velocity motor on every joint is replaced by one of target
  velocity 0 whose force is the joint's ``friction`` [N m or N] (0: free), which is Coulomb friction
  (it holds the joint below that torque and resists motion with it); ``damping`` is pybullet's
  ``jointDamping``; limits are ``jointLowerLimit``/``jointUpperLimit``; no body damping (pybullet's
  default 0.04 / s is removed: Gazebo has none). ``effort`` and ``velocity`` limits bound motors, and a
  model here has none: they are kept in the spec for the API only.
- **friction**: pybullet has one friction coefficient a link, isotropic, while Gazebo has mu (along the
  first friction direction) and mu2 (along the second) for each collision. A link's lateral friction
  is the mu of its first collision (mu2 is kept in the spec, not simulated); restitution likewise;
  ``kp``/``kd`` become pybullet's contact stiffness and damping (kd 1 N s/m, SDF's default, when only
  kp is given). pybullet multiplies two bodies' frictions where ODE takes the smaller: against the
  simulator's wheels (friction 1.0) the two agree.
- **shapes shared**: collision and visual shapes are kept by a :class:`ShapeCache` of the client,
  keyed by the geometry, its frame and how it collides, so 10,000 instances of one mesh make one shape.
  Meshes: OBJ and binary STL as pybullet reads them, COLLADA and ASCII STL through :mod:`.meshes`;
  a static model's meshes collide as their triangles (concave), a moving model's as the convex hull of
  each object in the file (bullet collides nothing else that moves).

pybullet is imported here only, lazily (``thorvald_sim.bullet``), as physics/engine.py does.
"""

import math
from typing import Any, Dict, List, Optional, Sequence, Tuple

from ..errors import ModelError
from . import reading
from .meshes import pybullet_file
from .spec import (
    FIXED,
    IDENTITY,
    WORLD,
    Box,
    Cylinder,
    Geometry,
    LinkSpec,
    Mesh,
    ModelSpec,
    Plane,
    Pose,
    Sphere,
    Tree,
    compose,
    inverse,
    tree,
)

PLANE_THICKNESS = 0.001  # [m] a plane of a moving model is a box this thick (bullet's plane cannot move)
MIN_INERTIA = 1e-9  # [kg m^2] a principal moment below this (a point mass) is held at it
GREY = (0.7, 0.7, 0.7, 1.0)  # a visual without a colour, as Gazebo draws it


def _p() -> Any:
    from ..bullet import pybullet  # noqa: PLC0415  (pybullet only where models are built)

    return pybullet


class ShapeCache:
    """The collision and visual shapes built in one pybullet client, reused by every model built with
    this cache (pybullet lets bodies share a shape). A cache belongs to one simulation: after the
    client is reset (``resetSimulation``) or disconnected its ids mean nothing; make a new one."""

    def __init__(self, client: int):
        self.client = client
        self.collision: Dict[Tuple, int] = {}
        self.visual: Dict[Tuple, int] = {}


class SimModel:
    """A model built in the client at the pose (position [m], orientation quaternion xyzw) of its model
    frame in the world (the caller composes the spawn pose with ``spec.pose`` as Gazebo does).

    ``links``: link name -> pybullet link index (the root -1); ``joints``: joint name -> index of its
    child link (pybullet's joint index); ``collisions``: ``link::collision`` (Gazebo's collision name
    scoped in its model; Gazebo's full name is ``model::link::collision``) -> link index.
    """

    def __init__(
        self,
        client: int,
        spec: ModelSpec,
        position: Sequence[float] = (0.0, 0.0, 0.0),
        orientation: Sequence[float] = (0.0, 0.0, 0.0, 1.0),
        *,
        shapes: Optional[ShapeCache] = None,
        visuals: bool = True,
    ):
        p = _p()
        self.client = client
        self.spec = spec
        self.name = spec.name
        self.static = spec.static
        _check_pose(spec, position, orientation)
        links_tree = tree(spec)
        _check_budget(spec, links_tree)
        if shapes is None:
            shapes = ShapeCache(client)
        elif shapes.client != client:
            raise ModelError(spec.source, spec.name, f"a shape cache of client {shapes.client} used in client {client}")
        self.shapes = shapes
        plan = _Plan(spec, links_tree)
        self._frames = plan.frames  # pybullet index -> the pybullet link frame in the link's own frame
        self._root_in_model = plan.root_in_model  # the base's pybullet frame in the model frame
        build = _Builder(p, client, shapes, plan, visuals)
        model_pose = ((position[0], position[1], position[2]), tuple(orientation))
        base_world = compose(model_pose, plan.root_in_model)  # type: ignore[arg-type]
        self.body = build.body(base_world)
        self.rigid = build.rigid
        self.links: Dict[str, int] = dict(plan.index)
        self.joints: Dict[str, int] = {joint.name: plan.index[joint.child] for joint in plan.joints}
        self.collisions: Dict[str, int] = {
            f"{link.name}::{c.name}": plan.index[link.name] for link in spec.links for c in link.collisions
        }
        # a rigid body's inertial frame is the one it was made with (pybullet reads back no orientation)
        self._inertial_base = IDENTITY if self.rigid else p.getDynamicsInfo(self.body, -1, physicsClientId=client)[3:5]

    # ---- state ----------------------------------------------------------------------------------
    def pose(self) -> Pose:
        """The model frame's pose in the world."""
        p = _p()
        position, orientation = p.getBasePositionAndOrientation(self.body, physicsClientId=self.client)
        base = compose((position, orientation), inverse(self._inertial_base))  # type: ignore[arg-type]
        return compose(base, inverse(self._root_in_model))

    def set_pose(
        self,
        position: Sequence[float],
        orientation: Sequence[float],
        linear: Sequence[float] = (0.0, 0.0, 0.0),
        angular: Sequence[float] = (0.0, 0.0, 0.0),
    ) -> None:
        """Teleports the model frame to the pose, its base moving at linear [m/s] (its centre of mass)
        and angular [rad/s] velocities in the world frame (a static model: the velocities are ignored).
        The joints keep their positions and speeds, as Gazebo's set_model_state keeps them."""
        _check_pose(self.spec, position, orientation, linear, angular)
        p = _p()
        target = ((position[0], position[1], position[2]), tuple(orientation))
        com = compose(compose(target, self._root_in_model), self._inertial_base)  # type: ignore[arg-type]
        p.resetBasePositionAndOrientation(self.body, com[0], com[1], physicsClientId=self.client)
        if not self.static:
            p.resetBaseVelocity(self.body, list(linear), list(angular), physicsClientId=self.client)

    def link_pose(self, name: str) -> Pose:
        """A link's own frame's pose in the world (KeyError for a link the model has not)."""
        p = _p()
        index = self.links[name]
        if index == -1:
            position, orientation = p.getBasePositionAndOrientation(self.body, physicsClientId=self.client)
            frame = compose((position, orientation), inverse(self._inertial_base))  # type: ignore[arg-type]
        else:
            state = p.getLinkState(self.body, index, computeForwardKinematics=True, physicsClientId=self.client)
            frame = (state[4], state[5])
        return compose(frame, inverse(self._frames[index]))

    def remove(self) -> None:
        """The body out of the simulation (its shapes stay in the cache for other instances)."""
        _p().removeBody(self.body, physicsClientId=self.client)


# ---- what the multibody is made of --------------------------------------------------------------
class _Plan:
    """The spec as pybullet's multibody: the base and links in order, each pybullet link frame."""

    def __init__(self, spec: ModelSpec, links_tree: Tree):
        self.spec = spec
        self.static = spec.static
        root = links_tree.root
        world_joint = links_tree.parent_joint.get(root.name)
        moving_world = world_joint is not None and world_joint.type != FIXED and not spec.static
        self.fixed_base = spec.static or world_joint is not None
        self.anchor = moving_world  # a shapeless fixed base the root hangs from
        self.joints = [
            links_tree.parent_joint[link.name] for link in links_tree.links if link.name in links_tree.parent_joint
        ]
        self.joints = [j for j in self.joints if j.parent != WORLD or moving_world]
        order: List[LinkSpec] = list(links_tree.links)
        # each link's pybullet frame in its own frame: its joint's frame (the root's: its own frame)
        own: Dict[str, Pose] = {}
        for link in order:
            joint = links_tree.parent_joint.get(link.name)
            own[link.name] = joint.pose if joint is not None and (joint.parent != WORLD or moving_world) else IDENTITY
        self.model_frame: Dict[str, Pose] = {link.name: compose(link.pose, own[link.name]) for link in order}
        self.index: Dict[str, int] = {}
        self.links: List[LinkSpec] = []  # the pybullet links, in index order (the base is not one)
        self.parents: List[int] = []
        self.joint_types: List[str] = []
        self.axes: List[Tuple[float, float, float]] = []
        self.frames: Dict[int, Pose] = {}
        if self.anchor:
            self.base: Optional[LinkSpec] = None
            self.root_in_model = compose(self.model_frame[root.name], IDENTITY)
            first = 0
        else:
            self.base = root
            self.index[root.name] = -1
            self.frames[-1] = own[root.name]
            self.root_in_model = self.model_frame[root.name]
            first = 1
        for link in order[first:]:
            i = len(self.links)
            self.index[link.name] = i
            self.links.append(link)
            self.frames[i] = own[link.name]
            joint = links_tree.parent_joint.get(link.name)
            if joint is None or joint.parent == WORLD:  # a loose link of a static model, or the anchored root
                self.parents.append(-1)
                self.joint_types.append(FIXED if joint is None or spec.static else joint.type)
                self.axes.append(joint.axis if joint is not None else (0.0, 0.0, 1.0))
            else:
                self.parents.append(self.index[joint.parent])
                self.joint_types.append(FIXED if spec.static else joint.type)
                self.axes.append(joint.axis)

    def parent_frame(self, i: int) -> Pose:
        """The pybullet frame of link i's parent (the base's) in the model frame."""
        parent = self.parents[i]
        if parent == -1:
            return self.root_in_model
        return self.model_frame[self.links[parent].name]


class _Builder:
    def __init__(self, p: Any, client: int, shapes: ShapeCache, plan: _Plan, visuals: bool):
        self.p = p
        self.client = client
        self.shapes = shapes
        self.plan = plan
        self.visuals = visuals
        self.rigid = False  # built as a static rigid body (body())

    def body(self, base_world: Pose) -> int:
        p, plan, c = self.p, self.plan, self.client
        concave_base = plan.fixed_base
        # a static model of one link that nothing moves is a static rigid body: bullet updates every
        # multibody every step, a fixed one too (10,000 plants: 21 ms a step), a static rigid body never
        self.rigid = plan.static and not plan.links and not plan.spec.kinematic
        link_args: Dict[str, list] = {k: [] for k in LINK_KEYS}
        base = plan.base
        if base is not None:
            base_mass, base_inertial, base_diagonal = self.inertial(base, plan.frames[-1])
            if plan.fixed_base:  # pybullet's fixed base is a base of mass 0
                base_mass, base_diagonal = 0.0, None
            if self.rigid:  # its frame its link's
                base_inertial = IDENTITY
            base_collision = self.collision_shape(base, plan.frames[-1], concave_base)
            base_visual = self.visual_shape(base, plan.frames[-1])
        else:
            base_mass, base_inertial, base_diagonal = 0.0, IDENTITY, None
            base_collision = base_visual = -1
        for i, link in enumerate(plan.links):
            frame = plan.frames[i]
            mass, inertial, diagonal = self.inertial(link, frame)
            in_parent = compose(inverse(plan.parent_frame(i)), plan.model_frame[link.name])
            link_args["linkMasses"].append(mass)
            link_args["linkCollisionShapeIndices"].append(self.collision_shape(link, frame, plan.static))
            link_args["linkVisualShapeIndices"].append(self.visual_shape(link, frame))
            link_args["linkPositions"].append(in_parent[0])
            link_args["linkOrientations"].append(in_parent[1])
            link_args["linkInertialFramePositions"].append(inertial[0])
            link_args["linkInertialFrameOrientations"].append(inertial[1])
            link_args["linkParentIndices"].append(plan.parents[i] + 1)  # pybullet counts the base as 0 here
            link_args["linkJointTypes"].append(JOINT_TYPES[plan.joint_types[i]](p))
            link_args["linkJointAxis"].append(plan.axes[i])
            link_args["_diagonals"].append(diagonal)
        flags = 0
        colliding = [link for link in self.plan.spec.links if link.self_collide]
        if len(colliding) >= 2:
            flags = p.URDF_USE_SELF_COLLISION | p.URDF_USE_SELF_COLLISION_EXCLUDE_PARENT
        diagonals = link_args.pop("_diagonals")
        body = p.createMultiBody(
            baseMass=base_mass,
            baseCollisionShapeIndex=base_collision,
            baseVisualShapeIndex=base_visual,
            basePosition=base_world[0],
            baseOrientation=base_world[1],
            baseInertialFramePosition=base_inertial[0],
            baseInertialFrameOrientation=base_inertial[1],
            flags=flags,
            useMaximalCoordinates=self.rigid,
            physicsClientId=c,
            **link_args,
        )
        if body < 0:
            raise ModelError(plan.spec.source, plan.spec.name, "pybullet could not build the model")
        self.dynamics(body, base_diagonal, diagonals)
        if flags:
            self.self_collision(body)
        return body

    # ---- shapes ---------------------------------------------------------------------------------
    def collision_shape(self, link: LinkSpec, frame: Pose, concave: bool) -> int:
        if not link.collisions:
            return -1
        to_frame = inverse(frame)
        parts = tuple(
            (_shape_key(c.geometry, self.plan.static), _rounded(compose(to_frame, c.pose))) for c in link.collisions
        )
        key = (parts, concave)
        cache = self.shapes.collision
        if key not in cache:
            p, c = self.p, self.client
            args = [self.geometry_args(collision.geometry, concave) for collision in link.collisions]
            poses = [compose(to_frame, collision.pose) for collision in link.collisions]
            if len(args) == 1:
                kind, values = args[0]
                values = {k: v for k, v in values.items() if k != "length"}
                shape = p.createCollisionShape(
                    kind, collisionFramePosition=poses[0][0], collisionFrameOrientation=poses[0][1], physicsClientId=c,
                    **values,
                )  # fmt: skip
            else:
                shape = p.createCollisionShapeArray(
                    shapeTypes=[kind for kind, _ in args],
                    radii=[v.get("radius", 0.5) for _, v in args],
                    halfExtents=[v.get("halfExtents", (0.5, 0.5, 0.5)) for _, v in args],
                    lengths=[v.get("height", 1.0) for _, v in args],
                    fileNames=[v.get("fileName", "") for _, v in args],
                    meshScales=[v.get("meshScale", (1.0, 1.0, 1.0)) for _, v in args],
                    planeNormals=[v.get("planeNormal", (0.0, 0.0, 1.0)) for _, v in args],
                    flags=[v.get("flags", 0) for _, v in args],
                    collisionFramePositions=[pose[0] for pose in poses],
                    collisionFrameOrientations=[pose[1] for pose in poses],
                    physicsClientId=c,
                )
            if shape < 0:
                raise ModelError(self.plan.spec.source, link.name, "pybullet could not make its collision shape")
            cache[key] = shape
        return cache[key]

    def visual_shape(self, link: LinkSpec, frame: Pose) -> int:
        if not self.visuals or not link.visuals:
            return -1
        to_frame = inverse(frame)
        parts = tuple((_shape_key(v.geometry, True), _rounded(compose(to_frame, v.pose)), v.rgba) for v in link.visuals)
        cache = self.shapes.visual
        if parts not in cache:
            p, c = self.p, self.client
            args = [self.geometry_args(visual.geometry, False, visual=True) for visual in link.visuals]
            poses = [compose(to_frame, visual.pose) for visual in link.visuals]
            if len(args) == 1:
                kind, values = args[0]
                values = {k: v for k, v in values.items() if k not in ("height", "flags")}
                shape = p.createVisualShape(
                    kind, rgbaColor=link.visuals[0].rgba or GREY, visualFramePosition=poses[0][0],
                    visualFrameOrientation=poses[0][1], physicsClientId=c, **values,
                )  # fmt: skip
            else:  # pybullet gives an array of visuals one colour: the first's
                shape = p.createVisualShapeArray(
                    shapeTypes=[kind for kind, _ in args],
                    radii=[v.get("radius", 0.5) for _, v in args],
                    halfExtents=[v.get("halfExtents", (0.5, 0.5, 0.5)) for _, v in args],
                    lengths=[v.get("length", 1.0) for _, v in args],
                    fileNames=[v.get("fileName", "") for _, v in args],
                    meshScales=[v.get("meshScale", (1.0, 1.0, 1.0)) for _, v in args],
                    planeNormals=[v.get("planeNormal", (0.0, 0.0, 1.0)) for _, v in args],
                    visualFramePositions=[pose[0] for pose in poses],
                    visualFrameOrientations=[pose[1] for pose in poses],
                    physicsClientId=c,
                )
            if shape < 0:
                raise ModelError(self.plan.spec.source, link.name, "pybullet could not make its visual shape")
            cache[parts] = shape
        return cache[parts]

    def geometry_args(self, geometry: Geometry, concave: bool, visual: bool = False) -> Tuple[int, Dict[str, Any]]:
        p = self.p
        if isinstance(geometry, Box):
            return p.GEOM_BOX, {"halfExtents": tuple(s / 2 for s in geometry.size)}
        if isinstance(geometry, Cylinder):
            return p.GEOM_CYLINDER, {"radius": geometry.radius, "height": geometry.length, "length": geometry.length}
        if isinstance(geometry, Sphere):
            return p.GEOM_SPHERE, {"radius": geometry.radius}
        if isinstance(geometry, Plane):
            if self.plan.static and not visual:
                return p.GEOM_PLANE, {"planeNormal": geometry.normal}
            size = geometry.size
            return p.GEOM_BOX, {"halfExtents": (size[0] / 2, size[1] / 2, PLANE_THICKNESS / 2)}
        assert isinstance(geometry, Mesh)
        values = {"fileName": pybullet_file(geometry.path), "meshScale": geometry.scale}
        if concave and not visual:
            values["flags"] = p.GEOM_FORCE_CONCAVE_TRIMESH
        return p.GEOM_MESH, values

    # ---- masses, joints, surfaces -----------------------------------------------------------------
    def inertial(self, link: LinkSpec, frame: Pose) -> Tuple[float, Pose, Optional[Tuple[float, float, float]]]:
        """(mass, inertial frame in the pybullet link frame, principal moments) of a link; a static
        model's links are massless (pybullet's static), and pybullet's own inertia is kept for them."""
        if self.plan.static:
            return 0.0, compose(inverse(frame), link.inertial.pose), None
        moments, axes = principal(link.inertial.inertia)
        pose = compose(compose(inverse(frame), link.inertial.pose), ((0.0, 0.0, 0.0), axes))
        return link.inertial.mass, pose, moments

    def dynamics(self, body: int, base_diagonal, diagonals: List) -> None:
        p, c, plan = self.p, self.client, self.plan
        indices: List[Tuple[int, Optional[LinkSpec], Any]] = []
        if plan.base is not None:
            indices.append((-1, plan.base, base_diagonal))
        else:
            indices.append((-1, None, None))
        indices.extend((i, link, diagonals[i]) for i, link in enumerate(plan.links))
        joints = {j.child: j for j in plan.joints}
        for index, link, diagonal in indices:
            values: Dict[str, Any] = {"linearDamping": 0.0, "angularDamping": 0.0}
            if diagonal is not None:
                values["localInertiaDiagonal"] = diagonal
            if link is not None and link.collisions:
                surface = link.collisions[0].surface
                values["lateralFriction"] = surface.mu
                values["restitution"] = surface.restitution
                if surface.kp is not None:
                    values["contactStiffness"] = surface.kp
                    values["contactDamping"] = surface.kd if surface.kd is not None else 1.0
            joint = joints.get(link.name) if link is not None and index >= 0 else None
            if joint is not None and not plan.static and joint.type != FIXED:
                values["jointDamping"] = joint.damping
                if joint.limited:
                    values["jointLowerLimit"] = joint.lower if math.isfinite(joint.lower) else -1e30
                    values["jointUpperLimit"] = joint.upper if math.isfinite(joint.upper) else 1e30
            if not plan.static and not plan.fixed_base and index == -1:
                # a moving model at rest sleeps, as objects do; a contact wakes it
                values["activationState"] = p.ACTIVATION_STATE_ENABLE_SLEEPING
            p.changeDynamics(body, index, physicsClientId=c, **values)
        moving = [(plan.index[j.child], j.friction) for j in plan.joints if j.type != FIXED and not plan.static]
        if moving:
            p.setJointMotorControlArray(
                body,
                [i for i, _ in moving],
                p.VELOCITY_CONTROL,
                targetVelocities=[0.0] * len(moving),
                forces=[f for _, f in moving],
                physicsClientId=c,
            )

    def self_collision(self, body: int) -> None:
        """Gazebo's rule: two links of a model collide when both self-collide."""
        p, plan = self.p, self.plan
        colliding = {plan.index[link.name] for link in plan.spec.links if link.self_collide}
        every = sorted(plan.index.values())
        for a in every:
            for b in every:
                if a < b and not (a in colliding and b in colliding):
                    p.setCollisionFilterPair(body, body, a, b, 0, physicsClientId=self.client)


LINK_KEYS = (
    "linkMasses", "linkCollisionShapeIndices", "linkVisualShapeIndices", "linkPositions", "linkOrientations",
    "linkInertialFramePositions", "linkInertialFrameOrientations", "linkParentIndices", "linkJointTypes",
    "linkJointAxis", "_diagonals",
)  # fmt: skip

JOINT_TYPES = {
    "fixed": lambda p: p.JOINT_FIXED,
    "revolute": lambda p: p.JOINT_REVOLUTE,
    "prismatic": lambda p: p.JOINT_PRISMATIC,
}


def principal(inertia) -> Tuple[Tuple[float, float, float], Tuple[float, float, float, float]]:
    """(principal moments, the quaternion of their axes) of a symmetric 3x3 inertia: R diag(m) R^T."""
    import numpy as np  # noqa: PLC0415

    matrix = np.array(inertia, dtype=float)
    if np.allclose(matrix, np.diag(np.diag(matrix))):
        d = np.diag(matrix)
        return tuple(max(float(v), MIN_INERTIA) for v in d), (0.0, 0.0, 0.0, 1.0)  # type: ignore[return-value]
    values, vectors = np.linalg.eigh(matrix)
    if np.linalg.det(vectors) < 0:
        vectors[:, 0] = -vectors[:, 0]
    moments = tuple(max(float(v), MIN_INERTIA) for v in values)
    return moments, _quaternion(vectors)  # type: ignore[return-value]


def _quaternion(r) -> Tuple[float, float, float, float]:
    """The unit quaternion (x, y, z, w) of a rotation matrix."""
    trace = r[0, 0] + r[1, 1] + r[2, 2]
    if trace > 0:
        s = math.sqrt(trace + 1.0) * 2
        return ((r[2, 1] - r[1, 2]) / s, (r[0, 2] - r[2, 0]) / s, (r[1, 0] - r[0, 1]) / s, 0.25 * s)
    if r[0, 0] > r[1, 1] and r[0, 0] > r[2, 2]:
        s = math.sqrt(1.0 + r[0, 0] - r[1, 1] - r[2, 2]) * 2
        return (0.25 * s, (r[0, 1] + r[1, 0]) / s, (r[0, 2] + r[2, 0]) / s, (r[2, 1] - r[1, 2]) / s)
    if r[1, 1] > r[2, 2]:
        s = math.sqrt(1.0 + r[1, 1] - r[0, 0] - r[2, 2]) * 2
        return ((r[0, 1] + r[1, 0]) / s, 0.25 * s, (r[1, 2] + r[2, 1]) / s, (r[0, 2] - r[2, 0]) / s)
    s = math.sqrt(1.0 + r[2, 2] - r[0, 0] - r[1, 1]) * 2
    return ((r[0, 2] + r[2, 0]) / s, (r[1, 2] + r[2, 1]) / s, 0.25 * s, (r[1, 0] - r[0, 1]) / s)


def _shape_key(geometry: Geometry, static: bool) -> Tuple:
    return (geometry, static)


def _rounded(pose: Pose) -> Tuple:
    return tuple(round(v, 12) for v in (*pose[0], *pose[1]))


def _check_pose(spec: ModelSpec, *vectors: Sequence[float]) -> None:
    for vector in vectors:
        if not all(isinstance(v, (int, float)) and math.isfinite(v) for v in vector):
            raise ModelError(spec.source, spec.name, f"pose or velocity {tuple(vector)}: must be finite numbers")
    if len(vectors) > 1:
        q = vectors[1]
        norm = math.sqrt(sum(v * v for v in q))
        if len(q) != 4 or abs(norm - 1.0) > 1e-3:
            raise ModelError(spec.source, spec.name, f"orientation {tuple(q)}: must be a unit quaternion x y z w")


def _check_budget(spec: ModelSpec, links_tree: Tree) -> None:
    """A spec made by hand is held to the readers' limits before pybullet allocates anything."""
    collisions = sum(len(link.collisions) for link in spec.links)
    for count, limit, what in (
        (len(spec.links), reading.MAX_LINKS, "links"),
        (len(spec.joints), reading.MAX_JOINTS, "joints"),
        (collisions, reading.MAX_COLLISIONS, "collisions"),
        (sum(len(link.visuals) for link in spec.links), reading.MAX_VISUALS, "visuals"),
    ):
        if count > limit:
            raise ModelError(spec.source, spec.name, f"{count} {what}, more than the {limit} a model may have")
    if not spec.static:
        for link in spec.links:
            joint = links_tree.parent_joint.get(link.name)
            fixed_base = link is links_tree.root and joint is not None and joint.type == FIXED
            if not link.inertial.mass > 0 and not fixed_base:
                raise ModelError(
                    spec.source,
                    f"{spec.name}/link[{link.name}]",
                    "mass 0 in a moving model: give it a mass, or make the model static",
                )
