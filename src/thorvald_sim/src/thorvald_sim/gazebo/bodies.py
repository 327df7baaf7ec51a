"""The Gazebo API's operations on one world's bodies (pybullet; no ROS): an Engine's side of it.

The node (:mod:`thorvald_sim.gazebo.api`) resolves names and reference frames, and asks the Engine
holding a model for what is in the world's frame: a model's or a link's pose and velocity, a
teleport, a link's mass properties, a joint's state, a configuration, a wrench or a joint effort over
a window of simulated time, gravity, a model of the API spawned or deleted, and every model's and
link's state after a step (``model_states``, ``link_states``). :class:`GazeboBodies` answers them over
the Engine's Simulation: its robots, and the other models spawned through the API
(:class:`thorvald_sim.models.build.SimModel`).

Conventions, as Gazebo's:

* a model's pose is its model frame's (a URDF's root link frame, a robot's base_link; an SDF model's
  own frame), a link's its link frame's; a linear velocity is the frame origin's; all in the
  world's axes;
* a teleport sets the base's centre of mass velocity to the linear velocity asked, its angular
  velocity to the angular one, and the joints' velocities to none (Gazebo's ``Model::SetLinearVel``
  and ``SetAngularVel`` give every link the same); a link other than the base is reached by moving
  the whole model so that link has the pose (pybullet moves a multibody by its base; the joints
  keep their positions);
* a wrench acts on the link's centre of mass, in the world's axes, at each step whose start time
  is in ``[start, start + duration]`` (duration < 0: until cleared), as Gazebo's ``SetForce`` and
  ``SetTorque`` do; a joint effort acts between the joint's parent and child links about (along)
  its axis, added to whatever the joint's motor does.
"""

from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple, Union

from ..bullet import pybullet as p
from ..errors import SpawnError
from ..physics.robot import point_velocity
from . import frames
from .frames import Pose, Vec3

MAX_SINK = 0.05  # [m] a teleport that puts a dynamic model deeper than this into the static world is refused
STATES_MODELS = 1  # step(states=): each model's state after the step
STATES_LINKS = 2  # ... and each link's
MODEL_FRAME = None  # state(link=): the model's own frame, not one of its links'


@dataclass
class Job:
    """A wrench on a link, or an effort on a joint, over a window of simulated time."""

    model: str
    index: int  # the link's (a wrench) or the joint's (an effort)
    force: Vec3  # [N] world axes; an effort: (effort, 0, 0)
    torque: Vec3  # [N m] world axes
    start: float  # [s] simulated
    duration: float  # [s]; < 0: until cleared

    def acts(self, now: float) -> bool:
        return now >= self.start and (self.duration < 0.0 or now <= self.start + self.duration)

    def over(self, now: float) -> bool:
        return self.duration >= 0.0 and now > self.start + self.duration


class GazeboBodies:
    """The Gazebo API over one Simulation (an Engine's): see the module's docstring."""

    ASKED = (
        "state", "teleport", "link_properties", "joint_state", "configure", "gravity", "add_wrench",
        "add_effort", "clear_wrenches", "clear_efforts", "spawn_model", "delete_model", "animate",
    )  # fmt: skip

    def __init__(self, sim):
        self.sim = sim
        self.client = sim.client
        self.models: Dict[str, object] = {}  # the API's own models (SimModel), by name
        self.spawned: Dict[str, Pose] = {}  # their model frames at spawn (reset_world)
        self.shapes = None  # their shapes, shared (thorvald_sim.models.build.ShapeCache), made with the first
        self.wrenches: List[Job] = []
        self.efforts: List[Job] = []
        # the static models' states as model_states last read them: nothing moves them but the requests
        # of MOVES and a reset, which forget them
        self.at_rest: Dict[str, Tuple[Pose, Vec3, Vec3]] = {}
        # the actors of a Gazebo world: model name -> its Actor (thorvald_sim.world.gazebo_world), which puts
        # the model where its script has it before every step
        self.animated: Dict[str, object] = {}

    MOVES = ("teleport", "configure", "spawn_model", "delete_model")

    def handle(self, op: str, *args):
        """One request of the node (Engine.handle's ``("gazebo", op, *args)``), by method name."""
        if op not in self.ASKED:
            raise ValueError(f"unknown Gazebo request {op!r}")
        if op in self.MOVES:
            self.at_rest.clear()
        return getattr(self, op)(*args)

    # ---- the models' entities ----------------------------------------------------------------
    def describe(self, model: str, collisions: Optional[Dict[str, Sequence[str]]] = None):
        """What the node's entity table holds of a model just spawned: its links ((own name, pybullet
        index, collision names), the base first) and its moving joints ((name, index, kind)).
        collisions: each link's collisions as Gazebo names them."""
        c, body = self.client, self.body(model)
        collisions = collisions or {}
        base = p.getBodyInfo(body, physicsClientId=c)[0].decode()
        built = self.models.get(model)
        names = {index: name for name, index in built.links.items()} if built is not None else {}
        links = [(names.get(-1, base), -1, tuple(collisions.get(names.get(-1, base), ())))]
        joints = []
        for j in range(p.getNumJoints(body, physicsClientId=c)):
            info = p.getJointInfo(body, j, physicsClientId=c)
            name = names.get(j, info[12].decode())
            if built is None or j in names:  # a model's anchors and helpers are not its links
                links.append((name, j, tuple(collisions.get(name, ()))))
            if info[2] == p.JOINT_PRISMATIC:
                joints.append((info[1].decode(), j, "prismatic"))
            elif info[2] == p.JOINT_REVOLUTE:
                joints.append((info[1].decode(), j, "continuous" if info[8] > info[9] else "revolute"))
        if built is not None:  # its joints by the names its file gives them
            by_child = {index: name for name, index in built.joints.items()}
            joints = [(by_child.get(j, name), j, kind) for name, j, kind in joints if j in by_child]
        return {"links": links, "joints": joints}

    def spawn_model(self, name: str, spec, pose: Pose) -> Union[dict, str]:
        """A model of the API built at pose (its model frame in the world): its description for the
        node's entities, or why it was refused (the world unchanged)."""
        from ..models.build import ShapeCache, SimModel  # noqa: PLC0415  (the models' pybullet side)

        if name in self.sim.robots or name in self.models:
            return f"a model named {name!r} exists already"
        if self.shapes is None:
            self.shapes = ShapeCache(self.client)
        try:
            model = SimModel(self.client, spec, pose[0], pose[1], shapes=self.shapes)
        except SpawnError as e:  # ModelError: a mesh pybullet could not read, a budget
            return str(e)
        self.models[name] = model
        self.spawned[name] = pose
        collisions: Dict[str, List[str]] = {}
        for scoped in model.collisions:
            link, _, collision = scoped.rpartition("::")
            collisions.setdefault(link, []).append(collision)
        return self.describe(name, collisions)

    def delete_model(self, name: str) -> None:
        self.animated.pop(name, None)
        model = self.models.pop(name)
        self.spawned.pop(name)
        model.remove()
        self.forget(name)

    # ---- bodies and frames -------------------------------------------------------------------------
    def body(self, model: str) -> int:
        robot = self.sim.robots.get(model)
        if robot is not None:
            return robot.body
        return self.models[model].body

    def has(self, model: str) -> bool:
        return model in self.sim.robots or model in self.models

    def _com(self, body: int, link: int) -> Tuple[Vec3, Vec3, Vec3]:
        """(centre of mass, its linear velocity, angular velocity) of a pybullet link, world axes."""
        c = self.client
        if link < 0:
            com = p.getBasePositionAndOrientation(body, physicsClientId=c)[0]
            v, w = p.getBaseVelocity(body, physicsClientId=c)
            return tuple(com), tuple(v), tuple(w)
        state = p.getLinkState(body, link, computeLinkVelocity=1, computeForwardKinematics=1, physicsClientId=c)
        return tuple(state[0]), tuple(state[6]), tuple(state[7])

    def _frame(self, body: int, link: int) -> Pose:
        """A pybullet link frame (a loaded URDF's link frame) in the world."""
        c = self.client
        if link < 0:
            com, orn = p.getBasePositionAndOrientation(body, physicsClientId=c)
            info = p.getDynamicsInfo(body, -1, physicsClientId=c)
            pos, quat = p.multiplyTransforms(com, orn, *p.invertTransform(info[3], info[4]))
        else:
            state = p.getLinkState(body, link, computeForwardKinematics=1, physicsClientId=c)
            pos, quat = state[4], state[5]
        return tuple(pos), frames.normalised(quat)

    def state(self, model: str, link: Optional[int] = MODEL_FRAME) -> Tuple[Pose, Vec3, Vec3]:
        """A model's frame (link MODEL_FRAME) or a link frame (its pybullet index): world pose, the
        origin's linear velocity, the angular velocity."""
        robot = self.sim.robots.get(model)
        if robot is not None and link is MODEL_FRAME:  # base_link (the topics ask for it every time)
            (position, q), v, w = robot.frame_state()
            return (position, frames.normalised(q)), v, w
        body = self.body(model)
        built = self.models.get(model)
        index = -1 if link is MODEL_FRAME else link
        if built is None:  # a robot: loaded from its URDF, its model frame its base link's
            pose = self._frame(body, index)
        elif link is MODEL_FRAME:
            pose = built.pose()
        else:
            pose = built.link_pose(next(name for name, k in built.links.items() if k == link))
        com, v, w = self._com(body, index)
        return pose, point_velocity(v, w, com, pose[0]), w

    # ---- teleports -----------------------------------------------------------------------------
    def teleport(self, model: str, link, pose: Pose, twist: Tuple[Vec3, Vec3], static: bool) -> Optional[str]:
        """The model moved so that its frame (link MODEL_FRAME) or link's frame has pose (world), its
        base's centre of mass at linear velocity, every link at angular velocity (world axes);
        None, or why it was refused (the model left where it was): a dynamic model whose collisions
        would sink deeper than MAX_SINK into the static world."""
        body = self.body(model)
        linear, angular = twist
        saved = self._saved(body)
        target = pose
        if link is not MODEL_FRAME:  # the model goes where it must for the link to be at pose
            here = self.state(model)[0]
            there = self.state(model, link)[0]
            target = frames.in_parent(frames.seen_from(here, there), pose)
        self._place(model, body, target, linear, angular)
        if static:
            return None
        sink = self.sinking(body)
        if sink is not None:
            self._restore(body, saved)
            return sink
        return None

    def _place(self, model: str, body: int, pose: Pose, linear: Vec3, angular: Vec3) -> None:
        c = self.client
        built = self.models.get(model)
        if built is not None:
            built.set_pose(pose[0], pose[1], linear, angular)
        else:
            info = p.getDynamicsInfo(body, -1, physicsClientId=c)
            com, orn = p.multiplyTransforms(pose[0], pose[1], info[3], info[4])
            p.resetBasePositionAndOrientation(body, com, orn, physicsClientId=c)
            p.resetBaseVelocity(body, linear, angular, physicsClientId=c)
        for j in range(p.getNumJoints(body, physicsClientId=c)):
            if p.getJointInfo(body, j, physicsClientId=c)[2] != p.JOINT_FIXED:
                position = p.getJointState(body, j, physicsClientId=c)[0]
                p.resetJointState(body, j, position, 0.0, physicsClientId=c)

    def sinking(self, body: int) -> Optional[str]:
        """Why body stands too deep in the static world (a scene body or a static model), or None."""
        c = self.client
        p.performCollisionDetection(physicsClientId=c)
        deepest, where = 0.0, None
        static = self._static_bodies()
        for contact in p.getContactPoints(bodyA=body, physicsClientId=c):
            other, depth = contact[2], -contact[8]
            if other in static and depth > deepest:
                deepest, where = depth, (contact[3], static[other])
        if deepest <= MAX_SINK:
            return None
        link, other = where
        info = (
            p.getBodyInfo(body, physicsClientId=c)[0] if link < 0 else p.getJointInfo(body, link, physicsClientId=c)[12]
        )
        return f"{info.decode()} would be {deepest:.3f} m inside {other} (at most {MAX_SINK:g} m): put it higher"

    def _static_bodies(self) -> Dict[int, str]:
        c = self.client
        out = {}
        for name, b in self.sim.scene.bodies.items():
            if p.getDynamicsInfo(b, -1, physicsClientId=c)[0] == 0.0:
                out[b] = "the ground" if name.startswith("ground") else f"the world's {name}"
        for name, model in self.models.items():
            if model.static:
                out[model.body] = name
        return out

    def _saved(self, body: int):
        c = self.client
        base = p.getBasePositionAndOrientation(body, physicsClientId=c), p.getBaseVelocity(body, physicsClientId=c)
        joints = range(p.getNumJoints(body, physicsClientId=c))
        return base, [p.getJointState(body, j, physicsClientId=c)[:2] for j in joints]

    def _restore(self, body: int, saved) -> None:
        c = self.client
        ((com, orn), (v, w)), joints = saved
        p.resetBasePositionAndOrientation(body, com, orn, physicsClientId=c)
        p.resetBaseVelocity(body, v, w, physicsClientId=c)
        for j, (position, rate) in enumerate(joints):
            p.resetJointState(body, j, position, rate, physicsClientId=c)

    # ---- properties ----------------------------------------------------------------------------
    def link_properties(self, model: str, link: int):
        """(mass [kg], centre of mass in the link frame, (ixx, iyy, izz, ixy, ixz, iyz) [kg m^2] about
        it, gravity on): a model's as its file gives them, a robot's as pybullet holds them (its
        merged links' masses together, about its principal axes)."""
        built = self.models.get(model)
        if built is not None:
            name = next(name for name, k in built.links.items() if k == link)
            inertial = next(spec for spec in built.spec.links if spec.name == name).inertial
            (ixx, ixy, ixz), (_, iyy, iyz), (_, _, izz) = inertial.inertia
            return inertial.mass, tuple(inertial.pose[0]), (ixx, iyy, izz, ixy, ixz, iyz), True
        info = p.getDynamicsInfo(self.body(model), link, physicsClientId=self.client)
        ixx, iyy, izz = info[2]
        return info[0], tuple(info[3]), (ixx, iyy, izz, 0.0, 0.0, 0.0), True

    def joint_state(self, model: str, joint: int) -> Tuple[float, float]:
        position, rate = p.getJointState(self.body(model), joint, physicsClientId=self.client)[:2]
        return position, rate

    def configure(self, model: str, positions: Dict[int, float]) -> None:
        body = self.body(model)
        for joint, position in positions.items():
            p.resetJointState(body, joint, position, 0.0, physicsClientId=self.client)

    def gravity(self, g: Optional[Vec3] = None) -> Vec3:
        """The world's gravity [m/s^2], set first when g is given."""
        if g is not None:
            self.sim.set_gravity(g)
        return tuple(self.sim.gravity)

    # ---- wrenches and efforts --------------------------------------------------------------------
    def add_wrench(self, job: Job) -> None:
        self.wrenches.append(job)

    def add_effort(self, job: Job) -> None:
        self.efforts.append(job)

    def clear_wrenches(self, model: str, link: Optional[int] = None) -> None:
        self.wrenches = [j for j in self.wrenches if not (j.model == model and link in (None, j.index))]

    def clear_efforts(self, model: str, joint: Optional[int] = None) -> None:
        self.efforts = [j for j in self.efforts if not (j.model == model and joint in (None, j.index))]

    def animate(self, name: str, actor) -> None:
        """The model (a static one, built for it) follows the actor's script from now on: before every
        step it is put where the script has it at the step's end, as Gazebo's actors are moved (not
        pushed: a robot that meets one is pushed aside)."""
        self.animated[name] = actor
        self._place_actors(self.sim.time)

    def _place_actors(self, t: float) -> None:
        for name, actor in self.animated.items():
            model = self.models.get(name)
            if model is not None:
                position, orientation = actor.pose_at(t)
                model.set_pose(position, orientation)

    def before_step(self) -> None:
        """The actors where their scripts have them at the step's end; the wrenches and efforts acting
        at this step's start (the simulated time now)."""
        if self.animated:
            self._place_actors(self.sim.time + self.sim.dt)
        if not (self.wrenches or self.efforts):
            return
        now, c = self.sim.time, self.client
        for job in self.wrenches:
            if job.acts(now) and self.has(job.model):
                body = self.body(job.model)
                com = self._com(body, job.index)[0]
                p.applyExternalForce(body, job.index, job.force, com, p.WORLD_FRAME, physicsClientId=c)
                p.applyExternalTorque(body, job.index, job.torque, p.WORLD_FRAME, physicsClientId=c)
        for job in self.efforts:
            if job.acts(now) and self.has(job.model):
                self._effort(self.body(job.model), job.index, job.force[0])
        self.wrenches = [j for j in self.wrenches if not j.over(now) and self.has(j.model)]
        self.efforts = [j for j in self.efforts if not j.over(now) and self.has(j.model)]

    def _effort(self, body: int, joint: int, effort: float) -> None:
        """effort [N m or N] between a joint's parent and child, about (along) its axis."""
        c = self.client
        info = p.getJointInfo(body, joint, physicsClientId=c)
        kind, axis, parent = info[2], info[13], info[16]
        child = p.getLinkState(body, joint, computeForwardKinematics=1, physicsClientId=c)
        world_axis = frames.rotate(frames.normalised(child[5]), axis)
        vector = tuple(effort * a for a in world_axis)
        opposite = tuple(-v for v in vector)
        if kind == p.JOINT_PRISMATIC:
            p.applyExternalForce(body, joint, vector, child[0], p.WORLD_FRAME, physicsClientId=c)
            parent_com = self._com(body, parent)[0]
            p.applyExternalForce(body, parent, opposite, parent_com, p.WORLD_FRAME, physicsClientId=c)
        else:
            p.applyExternalTorque(body, joint, vector, p.WORLD_FRAME, physicsClientId=c)
            p.applyExternalTorque(body, parent, opposite, p.WORLD_FRAME, physicsClientId=c)

    # ---- states after a step ---------------------------------------------------------------------
    def states(self, which: int):
        """({model: (pose, linear, angular)} of every model, and with STATES_LINKS {model: [(pose,
        linear, angular) of each link, in :meth:`describe`'s order]})."""
        models, per_link = {}, {}
        for name in list(self.sim.robots) + list(self.models):
            built = self.models.get(name)
            if built is not None and built.static and name not in self.animated:  # where it was (read once)
                state = self.at_rest.get(name)
                if state is None:
                    state = self.at_rest[name] = self.state(name)
                models[name] = state
            else:
                models[name] = self.state(name)
            if which & STATES_LINKS:
                built = self.models.get(name)
                if built is not None:
                    indices = [-1, *sorted(k for k in built.links.values() if k >= 0)]
                else:
                    indices = [-1, *range(p.getNumJoints(self.body(name), physicsClientId=self.client))]
                per_link[name] = [self.state(name, k) for k in indices]
        return models, per_link

    # ---- life ------------------------------------------------------------------------------------
    def forget(self, model: str) -> None:
        """A model deleted: its jobs with it."""
        self.clear_wrenches(model)
        self.clear_efforts(model)

    def reset(self) -> None:
        """Every model of the API back where it was spawned, at rest, its joints at zero (the robots
        reset themselves)."""
        self.at_rest.clear()
        c = self.client
        for name, model in self.models.items():
            pose = self.spawned[name]
            model.set_pose(pose[0], pose[1])
            for j in range(p.getNumJoints(model.body, physicsClientId=c)):
                p.resetJointState(model.body, j, 0.0, 0.0, physicsClientId=c)

    def restart_time(self) -> None:
        """Time set back to zero (reset_simulation): the jobs end with the time they were for."""
        self.wrenches.clear()
        self.efforts.clear()


__all__ = ["MAX_SINK", "MODEL_FRAME", "STATES_LINKS", "STATES_MODELS", "GazeboBodies", "Job"]
