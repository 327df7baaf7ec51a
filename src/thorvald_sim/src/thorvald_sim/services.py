"""The simulator node's services: ``~pause``, ``~unpause``, ``~reset`` (std_srvs/Empty, as Gazebo's),
``~spawn_robot``, ``~delete_robot`` and ``~snapshot`` (thorvald_msgs), over the node's physics
(:mod:`thorvald_sim.engine`) and its robots' ROS sides (:class:`thorvald_sim.robot_io.RobotIO`)."""

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

from .as_built import SimAsBuilt
from .errors import SpawnError
from .robot import Pose2D
from .robot_io import RobotIO
from .simulation import Camera, save_png
from .workers import WorkerError


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
            self.node.sim.reset()
        rospy.loginfo("simulator: robots back at their spawn poses")
        return EmptyResponse()

    def srv_spawn(self, req):
        from .spawn_names import model_name_problem, namespace_problem  # noqa: PLC0415 (the spawn's own rules)

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
            try:
                robot = self.node.sim.spawn(req.model_name, req.robot_description, pose, as_built)
            except SpawnError as e:
                rospy.logerr("simulator: refused to spawn: %s", e)
                return SpawnRobotResponse(False, str(e))
            for mesh in robot.missing_meshes:
                if mesh.uri not in self.missing_meshes_said:
                    self.missing_meshes_said.add(mesh.uri)
                    rospy.logwarn(
                        "simulator: %s: mesh %s not found (%s): link %s drawn from its other geometry",
                        req.model_name,
                        mesh.uri,
                        mesh.reason,
                        mesh.link,
                    )
            self.say_sensors(req.model_name, robot)
            topic = req.command_topic or robot.description.command_topic
            # by default a robot with the generator's block (odometry/gazebo's frames), not a passive model:
            # a post's "odom -> base_link" would be another robot's
            tf = self.node.default_tf and bool(robot.description.drives) if req.publish_tf < 0 else bool(req.publish_tf)
            self.node.io[req.model_name] = RobotIO(self.node, robot, req.robot_namespace, topic, tf)
            if tf:
                self.node.tf_watch.watch.watch(req.model_name, robot.description.base_frame)
                self.node.tf_watch.poll()
        kind = f"{len(robot.wheels)} drives following {topic}" if robot.wheels else "passive (no drive block)"
        message = f"spawned {req.model_name} in {req.robot_namespace or '/'} at ({req.x:g}, {req.y:g}), {kind}"
        if tf:
            d = robot.description
            message += f", {d.odometry_frame} -> {d.base_frame} on /tf from ground truth"
        if as_built is not None:
            message += f", as built: {as_built.source}"
        message += self.node.sim.placed(robot)
        rospy.loginfo("simulator: %s", message)
        return SpawnRobotResponse(True, message)

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
            try:
                self.node.sim.delete(req.model_name)
            except SpawnError as e:
                return DeleteRobotResponse(False, str(e))
            self.node.io.pop(req.model_name).close()
            self.node.tf_watch.watch.forget(req.model_name)
            self.node.waits.forget(req.model_name)
        return DeleteRobotResponse(True, f"deleted {req.model_name}")

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
