"""Gazebo's ROS API on the simulator: the ``/gazebo`` services and topics users' nodes call.

gazebo_ros's api plugin offers them under ``/gazebo`` (``~gazebo_namespace`` here, as
``spawn_model -gazebo_namespace``): spawning and deleting models, their and their links' states and
properties, teleports, wrenches and joint efforts, the physics' properties, pause, unpause and the
two resets, and the topics ``model_states``, ``link_states`` (published after every physics step
while somebody subscribes, nothing otherwise) and ``set_model_state``, ``set_link_state``. Each
service answers as Gazebo's does: the same fields, ``success: false`` and a message for an unknown
name (Gazebo's text, then what is known), and the same frame arithmetic
(:mod:`thorvald_sim.gazebo.frames`).

This module is the ROS side: it resolves names and reference frames over the world's entities
(:mod:`thorvald_sim.gazebo.entities`), and asks the world holding a model (the node's physics, or
the physics worker holding it) through the physics interface's ``ask`` (answered by
:class:`thorvald_sim.gazebo.bodies.GazeboBodies`). Robots are spawned by the simulator's own path
(:class:`thorvald_sim.node.services.SimulatorServices`), so a robot spawned either way has its topics and
is a model here. What differs from Gazebo is in docs/coming-from-gazebo.md.
"""

import io
import math
import os
import struct
import threading
import xml.etree.ElementTree as ET
from dataclasses import replace
from typing import Dict, Optional, Tuple

import rospy
from geometry_msgs.msg import Point, Pose, Quaternion, Twist, Vector3
from std_srvs.srv import Empty, EmptyResponse

from gazebo_msgs.msg import LinkState, LinkStates, ModelState, ModelStates, ODEPhysics
from gazebo_msgs.srv import (
    ApplyBodyWrench,
    ApplyBodyWrenchResponse,
    ApplyJointEffort,
    ApplyJointEffortResponse,
    BodyRequest,
    BodyRequestResponse,
    DeleteModel,
    DeleteModelResponse,
    GetJointProperties,
    GetJointPropertiesResponse,
    GetLinkProperties,
    GetLinkPropertiesResponse,
    GetLinkState,
    GetLinkStateResponse,
    GetModelProperties,
    GetModelPropertiesResponse,
    GetModelState,
    GetModelStateResponse,
    GetPhysicsProperties,
    GetPhysicsPropertiesResponse,
    GetWorldProperties,
    GetWorldPropertiesResponse,
    JointRequest,
    JointRequestResponse,
    SetLinkState,
    SetLinkStateResponse,
    SetModelConfiguration,
    SetModelConfigurationResponse,
    SetModelState,
    SetModelStateResponse,
    SetPhysicsProperties,
    SetPhysicsPropertiesResponse,
    SpawnModel,
    SpawnModelResponse,
)
from thorvald_base.publishing import NonBlockingPublisher
from thorvald_base.rate_grid import RateGrid

from ..errors import SpawnError, WorkerError
from ..physics.robot import Pose2D
from . import frames
from .bodies import MODEL_FRAME, STATES_LINKS, STATES_MODELS, Job
from .entities import GROUND, GROUND_KIND, MODEL, ROBOT, WORLD, Entities, Entity, Joint, Link, Model
from .frames import ORIGIN

ZERO = (0.0, 0.0, 0.0)
MAX_FORCE = 1e7  # [N] and [N m]: a wrench or an effort beyond this is refused (pybullet would fly the body away)
MAX_POSITION = 1e6  # [m] from the origin: a pose beyond this is refused


def _vec(v) -> Tuple[float, float, float]:
    return (v.x, v.y, v.z)


def _pose(msg: Pose):
    o = msg.orientation
    return _vec(msg.position), frames.normalised((o.x, o.y, o.z, o.w))


def _pose_msg(pose) -> Pose:
    (x, y, z), (qx, qy, qz, qw) = pose
    return Pose(Point(x, y, z), Quaternion(qx, qy, qz, qw))


def _twist_msg(linear, angular) -> Twist:
    return Twist(Vector3(*linear), Vector3(*angular))


def _pose_problem(msg: Pose) -> str:
    """Why a requested pose cannot be used, or ""."""
    o = msg.orientation
    values = (msg.position.x, msg.position.y, msg.position.z, o.x, o.y, o.z, o.w)
    if not all(math.isfinite(v) for v in values):
        return "the pose must be finite numbers"
    if max(abs(v) for v in values[:3]) > MAX_POSITION:
        return f"the pose is more than {MAX_POSITION:g} m from the origin"
    return ""


def _finite(*vectors) -> bool:
    return all(math.isfinite(v) for vec in vectors for v in vec)


def model_format(xml: str) -> Optional[str]:
    """ "urdf" (a <robot>), "sdf" (an <sdf> or <gazebo>: Gazebo's test), or None, by the root element
    as gazebo_ros tells them apart (its first element, declarations and comments aside)."""

    try:
        for _, element in ET.iterparse(io.StringIO(xml), events=("start",)):
            return {"robot": "urdf", "sdf": "sdf", "gazebo": "sdf"}.get(element.tag)
    except ET.ParseError:
        return None
    return None


def _database_uri(xml: str) -> Optional[str]:
    """The URI gazebo_ros's ``spawn_model -database NAME`` sends (``<sdf><world><include><uri>``, the
    world holding no model of its own: Gazebo loads the included model), else None."""
    if "<world" not in xml[:4096]:
        return None
    try:
        root = ET.fromstring(xml)
    except ET.ParseError:
        return None
    world = root.find("world") if root.tag == "sdf" else None
    if world is None or world.find("model") is not None:
        return None
    uri = world.findtext("include/uri")
    return uri.strip() if uri and uri.strip() else None


class GazeboApi:
    """The /gazebo services and topics of a simulator node (its lock, physics, robots and pause)."""

    def __init__(self, node, namespace: str = "/gazebo", states_rate: float = 50.0):
        self.node = node
        self.grid = RateGrid(states_rate, node.sim.dt)  # model_states and link_states (0: every step)
        self._paths = None  # Gazebo's model path (model_path), read when the first model comes
        self.entities = Entities()
        self.entities.add(Model(GROUND, GROUND_KIND, (Link("link", -1, ("collision",)),), static=True, workers=()))
        self.get_state_counts = {}  # get_model_state's header.seq, per model, as Gazebo counts
        self.ode = ODEPhysics(
            auto_disable_bodies=False,
            sor_pgs_precon_iters=0,
            sor_pgs_iters=node.sim.solver_iterations,
            sor_pgs_w=1.3,
            sor_pgs_rms_error_tol=0.0,
            contact_surface_layer=0.001,
            contact_max_correcting_vel=100.0,
            cfm=0.0,
            erp=0.2,
            max_contacts=20,
        )  # fmt: skip  (what get_physics_properties reports: the solver's iterations are pybullet's)
        self.said = set()  # warnings said once
        self.lock = threading.Lock()  # the topics' subscriber counts, read in the loop
        ns = "/" + namespace.strip("/") + "/" if namespace.strip("/") else "/"
        self.namespace = ns
        services = (
            ("spawn_urdf_model", SpawnModel, self.spawn_urdf_model),
            ("spawn_sdf_model", SpawnModel, self.spawn_sdf_model),
            ("delete_model", DeleteModel, self.delete_model),
            ("get_model_state", GetModelState, self.get_model_state),
            ("set_model_state", SetModelState, self.set_model_state),
            ("get_link_state", GetLinkState, self.get_link_state),
            ("set_link_state", SetLinkState, self.set_link_state),
            ("get_model_properties", GetModelProperties, self.get_model_properties),
            ("get_world_properties", GetWorldProperties, self.get_world_properties),
            ("get_link_properties", GetLinkProperties, self.get_link_properties),
            ("get_joint_properties", GetJointProperties, self.get_joint_properties),
            ("get_physics_properties", GetPhysicsProperties, self.get_physics_properties),
            ("set_physics_properties", SetPhysicsProperties, self.set_physics_properties),
            ("set_model_configuration", SetModelConfiguration, self.set_model_configuration),
            ("apply_body_wrench", ApplyBodyWrench, self.apply_body_wrench),
            ("clear_body_wrenches", BodyRequest, self.clear_body_wrenches),
            ("apply_joint_effort", ApplyJointEffort, self.apply_joint_effort),
            ("clear_joint_forces", JointRequest, self.clear_joint_forces),
            ("pause_physics", Empty, self.pause_physics),
            ("unpause_physics", Empty, self.unpause_physics),
            ("reset_simulation", Empty, self.reset_simulation),
            ("reset_world", Empty, self.reset_world),
        )
        self.services = [rospy.Service(ns + name, kind, handler) for name, kind, handler in services]
        # written in the loop, as /clock and /tf are (thorvald_base.publishing)
        self.model_states = NonBlockingPublisher(ns + "model_states", ModelStates)
        self.link_states = NonBlockingPublisher(ns + "link_states", LinkStates)
        self.subscribers = [
            rospy.Subscriber(ns + "set_model_state", ModelState, self.on_model_state, queue_size=10),
            rospy.Subscriber(ns + "set_link_state", LinkState, self.on_link_state, queue_size=10),
        ]

    # ---- the world's models -------------------------------------------------------------------
    def robot_spawned(self, name: str, robot, pose) -> None:
        """A robot spawned (by ~spawn_robot or spawn_urdf_model): a model of the world from now on."""
        info = robot.entity
        links = tuple(Link(n, k, c) for n, k, c in info["links"])
        joints = tuple(Joint(n, k, kind) for n, k, kind in info["joints"])
        self.entities.add(Model(name, ROBOT, links, joints, False, (robot.worker,), pose))

    def model_deleted(self, name: str) -> None:
        if self.entities.model(name) is not None:
            self.entities.remove(name)
        self.get_state_counts.pop(name, None)

    def _ask(self, model: Model, request: tuple):
        """A request to the world holding model (the first live one holding it)."""
        live = set(self.node.sim.live_workers())
        for worker in model.workers:
            if worker in live:
                return self.node.sim.ask(worker, request)
        raise WorkerError(f"the physics worker holding {model.name} is dead")

    def _state(self, entity: Entity):
        """(pose, linear velocity, angular velocity) of an entity's frame in the world (a collision's:
        its link's)."""
        if entity.kind == "world" or entity.model.kind == GROUND_KIND:
            return ORIGIN, ZERO, ZERO
        link = entity.link.index if entity.link is not None else MODEL_FRAME
        return self._ask(entity.model, ("state", entity.model.name, link))

    def add_model(self, name: str, xml: str, kind: str, namespace: str, pose) -> str:
        """A model of the API (not a Thorvald robot) into the world (the caller holds the node's lock):
        read once here, built in every world when static, else in the world its place falls to
        (its strip's physics worker). SpawnError when refused; what was done."""
        from ..models import parse_sdf_model, parse_urdf_model  # noqa: PLC0415

        paths = self.model_path()
        source, base_dir = name, None
        uri = _database_uri(xml) if kind == "sdf" else None
        if uri is not None:  # gazebo_ros's -database: the model's own SDF from Gazebo's model path
            found, why = paths.model_sdf(uri)
            if found is None:
                raise SpawnError(f"{name}: {why}")
            xml, source = found
            base_dir = os.path.dirname(source)
        find = paths.finder(base_dir)  # model://, package://, file:// as Gazebo finds them
        # ModelError (a SpawnError) for whatever they refuse
        if kind == "sdf":
            spec = parse_sdf_model(xml, source, find, paths.model_sdf)
        else:
            spec = parse_urdf_model(xml, source, find)
        return self.add_spec(name, spec, frames.in_parent(spec.pose, pose))  # the file's own pose, from the spawn pose

    def add_spec(self, name: str, spec, model_pose) -> str:
        """A model read (a ModelSpec) into the world at model_pose (its model frame in the world; the
        caller holds the node's lock): built in every world when static, else in the world its place
        falls to. SpawnError when refused; what was done."""
        spec = replace(spec, name=name)
        for note in spec.notes:
            if (name, note) not in self.said:
                self.said.add((name, note))
                rospy.logwarn("simulator: %s: %s", name, note)
        physics = self.node.sim
        if spec.static:
            workers = physics.live_workers()
        else:
            workers = (physics.placement(Pose2D(model_pose[0][0], model_pose[0][1], model_pose[0][2], 0.0)),)
        info = None
        done = []
        for worker in workers:
            answer = physics.ask(worker, ("spawn_model", name, spec, model_pose))
            if isinstance(answer, str):
                for other in done:  # the worlds that took it let it go again
                    physics.ask(other, ("delete_model", name))
                raise SpawnError(f"{name}: {answer}")
            done.append(worker)
            info = answer
        links = tuple(Link(n, k, c) for n, k, c in info["links"])
        joints = tuple(Joint(n, k, j) for n, k, j in info["joints"])
        self.entities.add(Model(name, MODEL, links, joints, spec.static, tuple(done), model_pose))
        where = "" if len(done) == 1 or not physics.pids else ", in every physics worker's world"
        return (
            f"spawned model {name} ({'static' if spec.static else 'dynamic'}, {len(links)} links, "
            f"{len(joints)} moving joints) at ({model_pose[0][0]:g}, {model_pose[0][1]:g}, {model_pose[0][2]:g}){where}"
        )

    def add_world_models(self, world) -> None:
        """The models of a Gazebo world file (WorldConfig.models), each built as :meth:`add_spec` builds a
        spawned one, so that the API lists and moves them as Gazebo does; what was left out of the file
        said once each. ConfigError naming the world file and the model a world cannot take."""
        from ..world.gazebo_world import world_bodies  # noqa: PLC0415  (a Gazebo world's only)

        for note in world.notes:
            rospy.logwarn("simulator: %s: %s", os.path.basename(world.source), note)
        for body in world_bodies(world):  # an actor: a static model in every world, moved by its script in each
            try:
                self.add_spec(body.name, body.spec, body.pose)
            except SpawnError as e:
                raise body.refused(world.source, str(e)) from None
            if body.actor is not None:
                for worker in self.entities.model(body.name).workers:
                    self.node.sim.ask(worker, ("animate", body.name, body.actor))

    def model_path(self):
        """Gazebo's model path as this process's environment and the ROS packages' exports give it
        (:class:`~thorvald_sim.models.gazebo_paths.GazeboPaths`), read at the first spawn."""
        if self._paths is None:
            from ..models.gazebo_paths import gazebo_paths  # noqa: PLC0415  (rospkg: only when a model comes)

            self._paths = gazebo_paths()
        return self._paths

    def remove_model(self, model: Model) -> None:
        """A model of the API out of every world holding it (the caller holds the node's lock)."""
        live = set(self.node.sim.live_workers())
        for worker in model.workers:
            if worker in live:
                self.node.sim.ask(worker, ("delete_model", model.name))
        self.model_deleted(model.name)

    # ---- spawning --------------------------------------------------------------------------------
    def spawn_urdf_model(self, req):
        return self._spawn(req, "urdf")

    def spawn_sdf_model(self, req):
        return self._spawn(req, "sdf")

    def _spawn(self, req, service: str):
        kind = model_format(req.model_xml)
        if kind is None or (service == "urdf" and kind != "urdf"):
            message = (
                "SpawnModel: Failure - entity format is invalid."
                if service == "urdf"
                else "GazeboRosApiPlugin SpawnModel Failure: input model_xml not SDF or URDF, or cannot be converted "
                "to Gazebo compatible format."
            )
            return SpawnModelResponse(False, message)
        problem = _pose_problem(req.initial_pose)
        if problem:
            return SpawnModelResponse(False, f"SpawnModel: Failure - {problem}")
        with self.node.lock:
            frame = self.entities.frame(req.reference_frame)
            if frame is None:
                return SpawnModelResponse(
                    False,
                    "SpawnModel: reference reference_frame not found, did you forget to scope the link by model "
                    f"name? ({req.reference_frame!r} is no model, link or collision; {self._known()})",
                )
            if self.entities.model(req.model_name) is not None:
                return SpawnModelResponse(
                    False, f"SpawnModel: Failure - entity already exists: a model named {req.model_name!r}"
                )
            try:
                pose = frames.in_parent(_pose(req.initial_pose), self._state(frame)[0])
                return self.node.services.spawn_any(req.model_name, req.model_xml, kind, req.robot_namespace, pose)
            except WorkerError as e:
                return SpawnModelResponse(False, f"SpawnModel: Failure - {e}")

    def _known(self) -> str:
        return "models: " + ", ".join(self.entities.names())

    def delete_model(self, req):
        with self.node.lock:
            model = self.entities.model(req.model_name)
            if model is None or model.kind == GROUND_KIND:
                what = "does not exist" if model is None else "is the world's ground, which stays"
                return DeleteModelResponse(False, f"DeleteModel: model {req.model_name!r} {what} ({self._known()})")
            ok, message = self.node.services.delete_any(model)
        return DeleteModelResponse(ok, "DeleteModel: successfully deleted model" if ok else f"DeleteModel: {message}")

    # ---- states ----------------------------------------------------------------------------------
    def get_model_state(self, req):
        res = GetModelStateResponse()
        with self.node.lock:
            model = self.entities.model(req.model_name)
            if model is None:
                res.status_message = f"GetModelState: model {req.model_name!r} does not exist ({self._known()})"
                return res
            frame = self.entities.frame(req.relative_entity_name)
            if frame is None:
                res.status_message = (
                    "GetModelState: reference relative_entity_name not found, did you forget to scope the body by "
                    f"model name? ({req.relative_entity_name!r}; {self._known()})"
                )
                return res
            try:
                pose, linear, angular = self._state(Entity("model", model))
                fpose, flin, fang = self._state(frame)
            except WorkerError as e:
                res.status_message = f"GetModelState: {e}"
                return res
            now = rospy.Time.from_sec(self.node.sim.time)
        seq = self.get_state_counts[model.name] = self.get_state_counts.get(model.name, 0) + 1
        if frame is not WORLD:
            pose = frames.seen_from(pose, fpose)
            linear, angular = frames.twist_seen_from(linear, angular, fpose, flin, fang)
        res.header.seq, res.header.stamp, res.header.frame_id = seq, now, req.relative_entity_name
        res.pose, res.twist = _pose_msg(pose), _twist_msg(linear, angular)
        res.success, res.status_message = True, "GetModelState: got properties"
        return res

    def set_model_state(self, req):
        ok, message = self._set_model_state(req.model_state)
        return SetModelStateResponse(ok, message)

    def on_model_state(self, msg):
        ok, message = self._set_model_state(msg)
        if not ok:
            rospy.logwarn_throttle(5.0, "%s: %s", self.namespace + "set_model_state", message)

    def _set_model_state(self, state) -> Tuple[bool, str]:
        problem = _pose_problem(state.pose)
        if problem or not _finite(_vec(state.twist.linear), _vec(state.twist.angular)):
            return False, f"SetModelState: {problem or 'the twist must be finite numbers'}"
        with self.node.lock:
            model = self.entities.model(state.model_name)
            if model is None or model.kind == GROUND_KIND:
                what = "does not exist" if model is None else "is the world's ground"
                return False, f"SetModelState: model {state.model_name!r} {what} ({self._known()})"
            frame = self.entities.frame(state.reference_frame)
            if frame is None:
                return False, (
                    f"SetModelState: specified reference frame entity {state.reference_frame!r} does not exist "
                    f"({self._known()})"
                )
            try:
                fpose = self._state(frame)[0]
                pose = frames.in_parent(_pose(state.pose), fpose)
                linear = frames.rotate(fpose[1], _vec(state.twist.linear))
                angular = frames.rotate(fpose[1], _vec(state.twist.angular))
                refused = self._teleport(model, MODEL_FRAME, pose, linear, angular)
            except WorkerError as e:
                return False, f"SetModelState: {e}"
        if refused:
            return False, f"SetModelState: {state.model_name}: {refused}"
        return True, "SetModelState: set model state done"

    def _teleport(self, model: Model, link: int, pose, linear, angular) -> Optional[str]:
        """Every world holding model moves it; why it was refused, or None."""
        request = ("teleport", model.name, link, pose, (linear, angular), model.static)
        for worker in model.workers:
            if worker in self.node.sim.live_workers():
                refused = self.node.sim.ask(worker, request)
                if refused:
                    return refused
        return None

    def get_link_state(self, req):
        res = GetLinkStateResponse()
        with self.node.lock:
            link = self.entities.link(req.link_name)
            if link is None:
                res.status_message = (
                    f"GetLinkState: link not found, did you forget to scope the link by model name? ({req.link_name!r})"
                )
                return res
            frame = self.entities.frame(req.reference_frame)
            if frame is None:
                res.status_message = (
                    "GetLinkState: reference reference_frame not found, did you forget to scope the link by model "
                    f"name? ({req.reference_frame!r})"
                )
                return res
            try:
                pose, linear, angular = self._state(link)
                fpose, flin, fang = self._state(frame)
            except WorkerError as e:
                res.status_message = f"GetLinkState: {e}"
                return res
        if frame is not WORLD:
            pose = frames.seen_from(pose, fpose)
            linear, angular = frames.twist_seen_from(linear, angular, fpose, flin, fang)
        res.link_state = LinkState(req.link_name, _pose_msg(pose), _twist_msg(linear, angular), req.reference_frame)
        res.success, res.status_message = True, "GetLinkState: got state"
        return res

    def set_link_state(self, req):
        ok, message = self._set_link_state(req.link_state)
        return SetLinkStateResponse(ok, message)

    def on_link_state(self, msg):
        ok, message = self._set_link_state(msg)
        if not ok:
            rospy.logwarn_throttle(5.0, "%s: %s", self.namespace + "set_link_state", message)

    def _set_link_state(self, state) -> Tuple[bool, str]:
        problem = _pose_problem(state.pose)
        if problem or not _finite(_vec(state.twist.linear), _vec(state.twist.angular)):
            return False, f"SetLinkState: {problem or 'the twist must be finite numbers'}"
        with self.node.lock:
            link = self.entities.link(state.link_name)
            if link is None or link.model.kind == GROUND_KIND:
                return False, f"SetLinkState: link {state.link_name!r} does not exist"
            frame = self.entities.frame(state.reference_frame)
            if frame is None:
                return (
                    False,
                    f"SetLinkState: failed: reference frame {state.reference_frame!r} is not a valid entity name",
                )
            try:
                fpose, flin, fang = self._state(frame)
                pose = frames.in_parent(_pose(state.pose), fpose)
                # as gazebo_ros: the frame's velocities taken off, the axes left as given
                linear = frames.sub(_vec(state.twist.linear), flin)
                angular = frames.sub(_vec(state.twist.angular), fang)
                refused = self._teleport(link.model, link.link.index, pose, linear, angular)
            except WorkerError as e:
                return False, f"SetLinkState: {e}"
        if refused:
            return False, f"SetLinkState: {state.link_name}: {refused}"
        return True, "SetLinkState: success"

    # ---- properties ----------------------------------------------------------------------------
    def get_model_properties(self, req):
        res = GetModelPropertiesResponse()
        model = self.entities.model(req.model_name)
        if model is None:
            res.status_message = f"GetModelProperties: model {req.model_name!r} does not exist ({self._known()})"
            return res
        res.canonical_body_name = model.canonical.name
        res.body_names = [link.name for link in model.links]
        res.geom_names = [c for link in model.links for c in link.collisions]
        res.joint_names = [joint.name for joint in model.joints]
        res.is_static = model.static
        res.success, res.status_message = True, "GetModelProperties: got properties"
        return res

    def get_world_properties(self, _req):
        res = GetWorldPropertiesResponse()
        res.sim_time = self.node.sim.time
        res.model_names = self.entities.names()
        res.rendering_enabled = True  # cameras and ~snapshot draw with pybullet's software renderer
        res.success, res.status_message = True, "GetWorldProperties: got properties"
        return res

    def get_link_properties(self, req):
        res = GetLinkPropertiesResponse()
        with self.node.lock:
            link = self.entities.link(req.link_name)
            if link is None or link.model.kind == GROUND_KIND:
                res.status_message = (
                    "GetLinkProperties: link not found, did you forget to scope the link by model name? "
                    f"({req.link_name!r})"
                )
                return res
            try:
                mass, com, inertia, gravity = self._ask(
                    link.model, ("link_properties", link.model.name, link.link.index)
                )
            except WorkerError as e:
                res.status_message = f"GetLinkProperties: {e}"
                return res
        res.com = _pose_msg((com, frames.IDENTITY))
        res.gravity_mode, res.mass = gravity, mass
        res.ixx, res.iyy, res.izz, res.ixy, res.ixz, res.iyz = inertia
        res.success, res.status_message = True, "GetLinkProperties: got properties"
        return res

    def get_joint_properties(self, req):
        res = GetJointPropertiesResponse()
        with self.node.lock:
            found = self.entities.joint(req.joint_name)
            if found is None:
                res.status_message = f"GetJointProperties: joint not found ({req.joint_name!r})"
                return res
            model, joint = found
            try:
                position, rate = self._ask(model, ("joint_state", model.name, joint.index))
            except WorkerError as e:
                res.status_message = f"GetJointProperties: {e}"
                return res
        res.type = res.REVOLUTE  # whatever the joint, as gazebo_ros's api plugin answers (its "FIXME")
        res.position, res.rate = [position], [rate]
        res.success, res.status_message = True, "GetJointProperties: got properties"
        return res

    def get_physics_properties(self, _req):
        res = GetPhysicsPropertiesResponse()
        with self.node.lock:
            try:
                gravity = self.node.sim.ask(self.node.sim.live_workers()[0], ("gravity",))
            except (WorkerError, IndexError) as e:
                res.status_message = f"GetPhysicsProperties: {e or 'every physics worker died'}"
                return res
        res.time_step = self.node.sim.dt
        res.pause = self.node.paused
        factor = self.node.real_time_factor
        res.max_update_rate = factor / self.node.sim.dt if factor else 0.0
        res.gravity = Vector3(*gravity)
        res.ode_config = self.ode
        res.success, res.status_message = True, "GetPhysicsProperties: got properties"
        return res

    def set_physics_properties(self, req):
        values = (req.time_step, req.max_update_rate, req.gravity.x, req.gravity.y, req.gravity.z)
        if not all(math.isfinite(v) for v in values) or req.max_update_rate < 0:
            return SetPhysicsPropertiesResponse(
                False, "physics engine not updated: the values must be finite, the rate >= 0"
            )
        if abs(req.time_step - self.node.sim.dt) > 1e-9:
            return SetPhysicsPropertiesResponse(
                False,
                f"physics engine not updated: the time step is {self.node.sim.dt:g} s (~physics_rate "
                f"{1.0 / self.node.sim.dt:g} Hz) for the simulator's life; asked {req.time_step:g} s",
            )
        g = _vec(req.gravity)
        if max(abs(v) for v in g) > 1000.0:
            return SetPhysicsPropertiesResponse(False, "physics engine not updated: gravity over 1000 m/s^2")
        with self.node.lock:
            try:
                for worker in self.node.sim.live_workers():
                    self.node.sim.ask(worker, ("gravity", g))
            except WorkerError as e:
                return SetPhysicsPropertiesResponse(False, f"physics engine not updated: {e}")
            # max_update_rate x time_step is the real-time factor (0: as fast as it can); a new anchor
            node = self.node
            node.real_time_factor = node.pacer.factor = req.max_update_rate * node.sim.dt
            node.pacer.paused()
            self.ode = req.ode_config
        return SetPhysicsPropertiesResponse(True, "physics engine updated")

    def set_model_configuration(self, req):
        with self.node.lock:
            model = self.entities.model(req.model_name)
            if model is None:
                return SetModelConfigurationResponse(False, "SetModelConfiguration: model does not exist")
            if len(req.joint_names) != len(req.joint_positions):
                return SetModelConfigurationResponse(
                    False, "SetModelConfiguration: joint name and position list have different lengths"
                )
            positions = {}
            for name, position in zip(req.joint_names, req.joint_positions):
                joint = model.joint(name)
                if joint is None:
                    return SetModelConfigurationResponse(
                        False,
                        f"SetModelConfiguration: {model.name} has no joint {name!r} "
                        f"(joints: {', '.join(j.name for j in model.joints) or 'none'})",
                    )
                if not math.isfinite(position):
                    return SetModelConfigurationResponse(False, f"SetModelConfiguration: {name}: position not finite")
                positions[joint.index] = position
            try:
                for worker in model.workers:
                    if worker in self.node.sim.live_workers():
                        self.node.sim.ask(worker, ("configure", model.name, positions))
            except WorkerError as e:
                return SetModelConfigurationResponse(False, f"SetModelConfiguration: {e}")
        return SetModelConfigurationResponse(True, "SetModelConfiguration: success")

    # ---- wrenches and efforts ------------------------------------------------------------------------
    def _window(self, start, duration) -> Tuple[float, float]:
        now = self.node.sim.time
        return max(start.to_sec(), now), duration.to_sec()

    def apply_body_wrench(self, req):
        force, torque, point = _vec(req.wrench.force), _vec(req.wrench.torque), _vec(req.reference_point)
        if not _finite(force, torque, point) or not math.isfinite(req.duration.to_sec()):
            return ApplyBodyWrenchResponse(False, "ApplyBodyWrench: the wrench, point and duration must be finite")
        if max(abs(v) for v in force + torque) > MAX_FORCE:
            return ApplyBodyWrenchResponse(
                False, f"ApplyBodyWrench: a force or torque over {MAX_FORCE:g} N (N m) is refused"
            )
        with self.node.lock:
            body = self.entities.link(req.body_name)
            if body is None or body.model.kind == GROUND_KIND:
                return ApplyBodyWrenchResponse(False, f"ApplyBodyWrench: body {req.body_name!r} does not exist")
            frame = self.entities.frame(req.reference_frame)
            if frame is None:
                return ApplyBodyWrenchResponse(
                    False, f"ApplyBodyWrench: reference_frame {req.reference_frame!r} not found"
                )
            try:
                if frame is WORLD:  # as gazebo_ros: in the world's axes, the point moving the torque alone
                    f, t = force, frames.add(torque, frames.cross(point, force))
                else:
                    f, t = frames.wrench_on_body(force, torque, point, self._state(frame)[0], self._state(body)[0])
                start, duration = self._window(req.start_time, req.duration)
                job = Job(body.model.name, body.link.index, f, t, start, duration)
                self._ask(body.model, ("add_wrench", job))
            except WorkerError as e:
                return ApplyBodyWrenchResponse(False, f"ApplyBodyWrench: {e}")
        return ApplyBodyWrenchResponse(True, "")

    def clear_body_wrenches(self, req):
        with self.node.lock:
            body = self.entities.link(req.body_name)
            if body is not None and body.model.kind != GROUND_KIND:
                self._ask_quietly(body.model, ("clear_wrenches", body.model.name, body.link.index))
        return BodyRequestResponse()

    def apply_joint_effort(self, req):
        if not math.isfinite(req.effort) or not math.isfinite(req.duration.to_sec()):
            return ApplyJointEffortResponse(False, "ApplyJointEffort: the effort and duration must be finite")
        if abs(req.effort) > MAX_FORCE:
            return ApplyJointEffortResponse(False, f"ApplyJointEffort: an effort over {MAX_FORCE:g} is refused")
        with self.node.lock:
            found = self.entities.joint(req.joint_name)
            if found is None:
                return ApplyJointEffortResponse(False, "ApplyJointEffort: joint not found")
            model, joint = found
            start, duration = self._window(req.start_time, req.duration)
            try:
                self._ask(
                    model, ("add_effort", Job(model.name, joint.index, (req.effort, 0.0, 0.0), ZERO, start, duration))
                )
            except WorkerError as e:
                return ApplyJointEffortResponse(False, f"ApplyJointEffort: {e}")
        return ApplyJointEffortResponse(True, "ApplyJointEffort: effort set")

    def clear_joint_forces(self, req):
        with self.node.lock:
            found = self.entities.joint(req.joint_name)
            if found is not None:
                model, joint = found
                self._ask_quietly(model, ("clear_efforts", model.name, joint.index))
        return JointRequestResponse()

    def _ask_quietly(self, model: Model, request: tuple) -> None:
        try:
            self._ask(model, request)
        except WorkerError:  # its world is gone, and its jobs with it
            pass

    # ---- pause and resets -----------------------------------------------------------------------------
    def pause_physics(self, _req):
        with self.node.lock:
            self.node.paused = True
        return EmptyResponse()

    def unpause_physics(self, _req):
        with self.node.lock:
            self.node.paused = False
        return EmptyResponse()

    def reset_world(self, _req):
        with self.node.lock:
            self.node.reset_world()
        return EmptyResponse()

    def reset_simulation(self, _req):
        with self.node.lock:
            self.node.reset_world()
            self.node.restart_time()
        return EmptyResponse()

    # ---- topics -------------------------------------------------------------------------------------
    def wanted(self, now: float) -> int:
        """What the step ending at now reads for the topics: nothing while nobody subscribes, else at
        the grid's instants (~gazebo_states_rate)."""
        which = STATES_MODELS if self.model_states.get_num_connections() else 0
        if self.link_states.get_num_connections():
            which |= STATES_MODELS | STATES_LINKS
        if not which:
            self.grid.pause()
            return 0
        return which if self.grid.due(now) else 0

    def publish(self, states) -> None:
        """model_states and link_states from what the step read (states: the physics' gazebo_states),
        serialised straight from the numbers (:func:`packed_states`)."""
        if states is None:
            return
        models, links = states
        at_rest = (ORIGIN, ZERO, ZERO)  # the ground's, and its link's
        if self.model_states.get_num_connections():
            rows = []
            for model in self.entities:
                state = at_rest if model.kind == GROUND_KIND else models.get(model.name)
                if state is not None:
                    rows.append((model.name, state))
            self.model_states.publish(_packed_rows(ModelStates, rows))
        if links and self.link_states.get_num_connections():
            rows = []
            for model in self.entities:
                read = [at_rest] if model.kind == GROUND_KIND else links.get(model.name, ())
                rows += [(f"{model.name}::{link.name}", st) for link, st in zip(model.links, read)]
            self.link_states.publish(_packed_rows(LinkStates, rows))


_PACKED = {}
_NAMES: Dict[Tuple[str, ...], bytes] = {}  # the serialised name arrays last sent (the same message after message)


def _packed_rows(kind, rows):
    """packed_states of (name, (pose, linear, angular)) rows, the numbers gathered flat."""
    names, pose_values, twist_values = [], [], []
    for name, ((position, orientation), linear, angular) in rows:
        names.append(name)
        pose_values += position
        pose_values += orientation
        twist_values += linear
        twist_values += angular
    return _packed(kind, names, pose_values, twist_values)


def packed_states(kind, names, poses, twists):
    """A ModelStates or LinkStates (``string[] name, Pose[] pose, Twist[] twist``) that serialises to
    the bytes genpy would write, from the numbers (poses: x y z qx qy qz qw; twists: linear, angular):
    building a message of objects cost the simulator more than 2 % of its CPU with 20 robots."""
    return _packed(kind, names, [v for pose in poses for v in pose], [v for twist in twists for v in twist])


def _packed(kind, names, pose_values, twist_values):
    cls = _PACKED.get(kind)
    if cls is None:
        cls = _PACKED[kind] = type("Packed" + kind.__name__, (kind,), {"__slots__": ("_data",), "serialize": _write})
    key = tuple(names)
    head = _NAMES.get(key)
    if head is None:
        parts = [struct.pack("<I", len(names))]
        for name in names:
            encoded = name.encode()
            parts.append(struct.pack("<I", len(encoded)))
            parts.append(encoded)
        head = b"".join(parts)
        if len(_NAMES) >= 8:  # the models come and go: keep the last few name lists only
            _NAMES.pop(next(iter(_NAMES)))
        _NAMES[key] = head
    poses, twists = len(pose_values) // 7, len(twist_values) // 6
    msg = cls.__new__(cls)
    msg._data = head + struct.pack(f"<I{7 * poses}dI{6 * twists}d", poses, *pose_values, twists, *twist_values)
    return msg


def _write(self, buff) -> None:
    buff.write(self._data)
