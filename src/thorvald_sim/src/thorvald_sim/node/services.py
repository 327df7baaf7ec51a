"""The simulator node's services: ``~pause``, ``~unpause``, ``~reset`` (std_srvs/Empty, as Gazebo's),
``~spawn_robot``, ``~delete_robot`` and ``~snapshot`` (thorvald_msgs), over the node's physics
(:mod:`thorvald_sim.physics.engine`) and its robots' ROS sides (:class:`thorvald_sim.node.robot_io.RobotIO`)."""

import math
import os
import tempfile

import rospy
from std_srvs.srv import Empty, EmptyResponse

from thorvald_msgs.srv import (
    DeleteRobot,
    DeleteRobotResponse,
    Snapshot,
    SnapshotResponse,
    SpawnRobot,
    SpawnRobotResponse,
)

from ..errors import SpawnError, WorkerError
from ..gazebo.frames import euler_of
from ..physics.as_built import SimAsBuilt
from ..physics.robot import Pose2D
from ..physics.simulation import Camera, save_png
from .robot_io import RobotIO


class SimulatorServices:
    """The services of a simulator node (its lock, physics, robots, tf watch and lockstep)."""

    def __init__(self, node):
        self.node = node
        self.missing_meshes_said = set()  # mesh URIs warned about: once each, however many robots name them
        rospy.Service("~pause", Empty, self.srv_pause)
        rospy.Service("~unpause", Empty, self.srv_unpause)
        rospy.Service("~reset", Empty, self.srv_reset)
        rospy.Service("~spawn_robot", SpawnRobot, self.srv_spawn)
        rospy.Service("~delete_robot", DeleteRobot, self.srv_delete)
        rospy.Service("~snapshot", Snapshot, self.srv_snapshot)

    def srv_pause(self, _req):
        with self.node.lock:
            self.node.paused = True
        return EmptyResponse()

    def srv_unpause(self, _req):
        with self.node.lock:
            self.node.paused = False
        return EmptyResponse()

    def srv_reset(self, _req):
        with self.node.lock:
            self.node.reset_world()
        return EmptyResponse()

    def srv_spawn(self, req):
        from ..spawn.names import model_name_problem, namespace_problem  # noqa: PLC0415 (the spawn's own rules)

        # any client may call: the names are checked before either appears in a line or a topic
        problem = model_name_problem(req.model_name) or namespace_problem(req.robot_namespace)
        if problem:
            rospy.logerr("simulator: refused to spawn: %s", problem)
            return SpawnRobotResponse(False, problem)
        pose = Pose2D(req.x, req.y, req.z, req.yaw)
        if not all(math.isfinite(v) for v in (req.x, req.y, req.z, req.yaw)):
            return SpawnRobotResponse(False, f"{req.model_name}: the spawn pose must be finite")
        as_built = None
        if req.as_built:
            try:
                as_built = SimAsBuilt.from_json(req.as_built)  # its drives are counted at the spawn
            except ValueError as e:
                rospy.logerr("simulator: refused to spawn %s: %s", req.model_name, e)
                return SpawnRobotResponse(False, f"{req.model_name}: {e}")
        with self.node.lock:
            ok, message = self.spawn_robot(
                req.model_name, req.robot_namespace, req.robot_description, pose,
                command_topic=req.command_topic, publish_tf=req.publish_tf, as_built=as_built,
            )  # fmt: skip
        return SpawnRobotResponse(ok, message)

    def spawn_robot(self, name, namespace, description, pose, *, command_topic="", publish_tf=-1, as_built=None):
        """A robot into the world with its topics (the caller holds the node's lock): (spawned, what
        was done or why not)."""
        if self.node.gazebo.entities.model(name) is not None:
            message = f"a model named {name!r} exists already"
            rospy.logerr("simulator: refused to spawn: %s", message)
            return False, message
        try:
            robot = self.node.sim.spawn(name, description, pose, as_built)
        except SpawnError as e:
            rospy.logerr("simulator: refused to spawn: %s", e)
            return False, str(e)
        for mesh in robot.missing_meshes:
            if mesh.uri not in self.missing_meshes_said:
                self.missing_meshes_said.add(mesh.uri)
                rospy.logwarn(
                    "simulator: %s: mesh %s not found (%s): link %s drawn from its other geometry",
                    name,
                    mesh.uri,
                    mesh.reason,
                    mesh.link,
                )
        self.say_sensors(name, robot)
        topic = command_topic or robot.description.command_topic
        # by default a robot with the generator's block (odometry/gazebo's frames), not a passive model:
        # a post's "odom -> base_link" would be another robot's
        tf = self.node.default_tf and bool(robot.description.drives) if publish_tf < 0 else bool(publish_tf)
        self.node.io[name] = RobotIO(self.node, robot, namespace, topic, tf)
        if tf:
            self.node.tf_watch.watch.watch(name, robot.description.base_frame)
            self.node.tf_watch.poll()
        self.node.gazebo.robot_spawned(name, robot, ((pose.x, pose.y, pose.z), pose.quaternion))
        kind = f"{len(robot.wheels)} drives following {topic}" if robot.wheels else "passive (no drive block)"
        message = f"spawned {name} in {namespace or '/'} at ({pose.x:g}, {pose.y:g}), {kind}"
        if tf:
            d = robot.description
            message += f", {d.odometry_frame} -> {d.base_frame} on /tf from ground truth"
        if as_built is not None:
            message += f", as built: {as_built.source}"
        message += self.node.sim.placed(robot)
        rospy.loginfo("simulator: %s", message)
        return True, message

    @staticmethod
    def say_sensors(name, robot):
        """The robot's sensors at spawn: what is simulated, what is not (once, by name and link), and
        what is refused (the link, the element path and the rule)."""
        blocks = robot.sensor_blocks
        for other in blocks.unsupported:
            rospy.logwarn(
                "simulator: %s: %s%s not simulated", name, other.what, f" on link {other.link}" if other.link else ""
            )
        for refused in blocks.refused:
            rospy.logerr("simulator: %s: sensor refused: %s", name, refused)
        for problem in robot.sensor_problems:
            rospy.logerr("simulator: %s: sensor refused: %s", name, problem)
        if robot.sensors:
            rospy.loginfo(
                "simulator: %s: sensors %s",
                name,
                ", ".join(f"{s.spec.kind} {s.spec.name} ({s.spec.rate:g} Hz)" for s in robot.sensors),
            )

    def srv_delete(self, req):
        with self.node.lock:
            if req.model_name not in self.node.io:
                return DeleteRobotResponse(
                    False, f"no robot named {req.model_name!r}; robots: {', '.join(sorted(self.node.io)) or 'none'}"
                )
            ok, message = self.delete_robot(req.model_name)
        return DeleteRobotResponse(ok, message)

    def delete_robot(self, name):
        """A robot out of the world with its topics (the caller holds the node's lock)."""
        try:
            self.node.sim.delete(name)
        except SpawnError as e:
            return False, str(e)
        self.node.io.pop(name).close()
        self.node.tf_watch.watch.forget(name)
        self.node.waits.forget(name)
        self.node.gazebo.model_deleted(name)
        return True, f"deleted {name}"

    # ---- the Gazebo API's spawns and deletes (thorvald_sim.gazebo.api) ----------------------------
    def spawn_any(self, name, xml, kind, namespace, pose):
        """spawn_urdf_model / spawn_sdf_model (the caller holds the lock; pose in the world): a
        Thorvald robot (a URDF with the generator's drive block) as ~spawn_robot spawns it, any other
        model as a model of the API (thorvald_sim.models)."""
        from gazebo_msgs.srv import SpawnModelResponse  # noqa: PLC0415  (the Gazebo API's messages)

        from ..physics.description import is_thorvald_robot  # noqa: PLC0415
        from ..spawn.names import model_name_problem, namespace_problem  # noqa: PLC0415 (the spawn's own rules)

        problem = model_name_problem(name) or namespace_problem(namespace)
        if problem:
            return SpawnModelResponse(False, f"SpawnModel: Failure - {problem}")
        (x, y, z), q = pose
        if kind == "urdf" and is_thorvald_robot(xml):
            roll, pitch, yaw = euler_of(q)
            if abs(roll) > 1e-6 or abs(pitch) > 1e-6:
                rospy.logwarn(
                    "simulator: %s: a robot spawns upright: roll %.3f and pitch %.3f rad left out", name, roll, pitch
                )
            ok, message = self.spawn_robot(name, namespace, xml, Pose2D(x, y, z, yaw))
            return SpawnModelResponse(
                ok, "SpawnModel: Successfully spawned entity" if ok else f"SpawnModel: Failure - {message}"
            )
        try:
            message = self.node.gazebo.add_model(name, xml, kind, namespace, pose)
        except SpawnError as e:
            rospy.logerr("simulator: refused to spawn: %s", e)
            return SpawnModelResponse(False, f"SpawnModel: Failure - {e}")
        rospy.loginfo("simulator: %s", message)
        return SpawnModelResponse(True, "SpawnModel: Successfully spawned entity")

    def delete_any(self, model):
        """delete_model (the caller holds the lock): (deleted, why not)."""
        if model.name in self.node.io:
            return self.delete_robot(model.name)
        self.node.gazebo.remove_model(model)
        rospy.loginfo("simulator: deleted model %s", model.name)
        return True, ""

    def srv_snapshot(self, req):
        camera = Camera()
        for name in ("eye", "target"):
            values = tuple(getattr(req, name))
            if values:
                if len(values) != 3 or not all(math.isfinite(v) for v in values):
                    return SnapshotResponse(False, f"{name} must be 3 finite numbers [m]", "")
                camera = Camera(**{**camera.__dict__, name: values})
        if req.width or req.height:
            camera = Camera(camera.eye, camera.target, req.width or camera.width, req.height or camera.height)
        path = req.path or tempfile.mkstemp(prefix="thorvald_sim_", suffix=".png")[1]
        with self.node.lock:  # on physics workers one world is drawn: the answer says whose
            try:
                image, whose = self.node.sim.render(camera)
            except WorkerError as e:
                return SnapshotResponse(False, str(e), "")
        try:
            save_png(image, path)
        except OSError as e:
            return SnapshotResponse(False, f"{path}: {e.strerror}", "")
        return SnapshotResponse(True, f"{camera.width} x {camera.height} px{whose}", os.path.abspath(path))
