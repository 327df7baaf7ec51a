"""``rosrun thorvald_sim spawn_robot`` and ``rosrun gazebo_ros spawn_model``: one program.

``spawn_model`` is gazebo_ros's, with every argument of the original (Noetic) and its behaviour: the
model's text from a file, a parameter, Gazebo's database or stdin, checked as XML, sent to
``<gazebo_namespace>/spawn_urdf_model`` or ``spawn_sdf_model`` with the pose in ``-reference_frame``;
then ``-J`` through ``set_model_configuration``, ``-unpause``, and with ``-b`` it stays and deletes the
model when it ends. The simulator spawns a Thorvald description as a robot (with its topics) and any
other URDF or SDF as a model.

``spawn_robot`` is the same with this workspace's defaults: run inside the robot's namespace, it sends a
URDF to the simulator's own ``~spawn_robot`` (``-simulator``, default /simulator), which takes this
workspace's robot arguments too (``-command_topic``, ``-publish_tf``/``-no_publish_tf``, ``-as_built``,
``-robot_model``). ``spawn_model`` given one of those goes that way as well. The arguments, their rules
and which service spawns: :mod:`thorvald_sim.spawn.args` (pure).

Exit status 0 when the model is in the world (with ``-b``: once deleted again at the end), 1 with the
reason when not, 2 for a wrong argument (argparse's message: the argument, the value and the rule).
"""

import sys
import threading
from typing import List, Optional

import rospy
from geometry_msgs.msg import Point, Pose, Quaternion
from std_srvs.srv import Empty

from gazebo_msgs.msg import ModelStates
from gazebo_msgs.srv import DeleteModel, SetModelConfiguration, SpawnModel
from thorvald_model import ConfigError, load_robot_config
from thorvald_msgs.srv import DeleteRobot, SpawnRobot

from ..errors import SpawnFailed, SpawnInputError
from ..physics.as_built import as_built_for, for_simulator
from .args import (
    ROBOT,
    SPAWN_ROBOT,
    database_text,
    joint_lists,
    prepared_xml,
    quaternion_from_rpy,
    read_file,
    service_name,
    timeout_or_none,
)
from .args import parse_args as _parse_args

__all__ = ["main", "parse_args", "read_as_built", "read_description"]


def parse_args(argv: List[str], prog: str = SPAWN_ROBOT):
    """:func:`thorvald_sim.spawn.args.parse_args` (spawn_robot's by default)."""
    return _parse_args(argv, prog)


def read_description(args) -> str:
    """The model's text from -file, -param, -database or -stdin; SpawnInputError saying why not."""
    if args.file:
        rospy.loginfo("Loading model XML from file %s", args.file)
        return read_file(args.file)
    if args.database:
        rospy.loginfo("Loading model XML from Gazebo Model Database")
        return database_text(args.database)
    if args.stdin:
        rospy.loginfo("Loading model XML from stdin")
        text = sys.stdin.read()
        if text == "":
            raise SpawnInputError("Error: stdin buffer was empty")
        return text
    name = rospy.resolve_name(args.param)
    rospy.loginfo("Loading model XML from ros parameter %s", name)
    if not rospy.has_param(name):
        raise SpawnInputError(f"no parameter {name}: load the model's description there first (model.launch)")
    xml = rospy.get_param(name)
    if not isinstance(xml, str):
        raise SpawnInputError(f"parameter {name} holds a {type(xml).__name__}, not a URDF or SDF")
    if xml == "":
        raise SpawnInputError(f"Error: param {name} does not exist or is empty")
    return xml


def read_as_built(args) -> str:
    """The spawn request's as_built field: "" (as configured) or the resolved as-built robot as JSON;
    ConfigError (file, key path, value, rule) or RuntimeError saying what is wrong."""
    if not args.as_built:
        return ""
    if not args.robot_model:
        raise RuntimeError("-as_built needs -robot_model: the configuration the built robot differs from")
    config = load_robot_config(args.robot_model)
    return for_simulator(as_built_for(args.as_built, config), config).to_json()


class Spawner:
    """One run of the program on parsed arguments (rospy's node initialised)."""

    def __init__(self, args, prog: str):
        self.args = args
        self.prog = prog
        self.gazebo = args.gazebo_namespace

    # ---- services --------------------------------------------------------------------------------
    def _proxy(self, name: str, kind):
        timeout = timeout_or_none(self.args.timeout)
        rospy.loginfo("Waiting for service %s", name)
        try:
            rospy.wait_for_service(name, timeout=timeout)
        except rospy.ROSInterruptException:
            raise SpawnFailed(f"shut down while waiting for {name}") from None
        except rospy.ROSException:
            raise SpawnFailed(f"no simulator answers at {name} after {self.args.timeout:g} s") from None
        return rospy.ServiceProxy(name, kind)

    def _call(self, name: str, kind, *request):
        proxy = self._proxy(name, kind)
        rospy.loginfo("Calling service %s", name)
        try:
            return proxy(*request)
        except (rospy.ServiceException, rospy.ROSInterruptException) as e:
            raise SpawnFailed(f"Service call failed: {name}: {e}") from None

    # ---- the run ---------------------------------------------------------------------------------
    def run(self) -> int:
        args = self.args
        try:
            if args.wait and not self.wait_for_model(args.wait):
                return 0  # shut down while waiting, as gazebo_ros's
            xml = prepared_xml(read_description(args), args.package_to_model)
            as_built = read_as_built(args)
            namespace = args.robot_namespace if args.robot_namespace is not None else rospy.get_namespace()
            if args.route == ROBOT:
                self.spawn_robot(xml, namespace, as_built)
            else:
                self.spawn_model(xml, namespace)
            if args.joints:
                self.set_configuration()
            if args.unpause:
                self.unpause()
        except (SpawnFailed, SpawnInputError, RuntimeError, ConfigError) as e:
            print(f"{self.prog}: {e}", file=sys.stderr)
            return 1
        if args.bond:
            rospy.on_shutdown(self.delete)
            rospy.loginfo("Waiting for shutdown to delete model %s", args.model)
            rospy.spin()
        return 0

    def wait_for_model(self, name: str) -> bool:
        """Until name is in <gazebo_namespace>/model_states (True), or rospy shuts down (False)."""
        there = threading.Event()

        def on_states(msg):
            if name in msg.name:
                there.set()

        sub = rospy.Subscriber(service_name(self.gazebo, "model_states"), ModelStates, on_states, queue_size=1)
        rospy.loginfo("Waiting for model %s before proceeding.", name)
        try:
            while not rospy.is_shutdown() and not there.wait(0.1):
                pass
        finally:
            sub.unregister()
        return there.is_set()

    def spawn_robot(self, xml: str, namespace: str, as_built: str) -> None:
        """Through the simulator's ~spawn_robot (this workspace's robot arguments)."""
        args = self.args
        response = self._call(
            service_name(args.simulator, "spawn_robot"),
            SpawnRobot,
            args.model, namespace, xml, args.x, args.y, args.z, args.Y,
            args.command_topic, args.publish_tf, as_built,
        )  # fmt: skip
        if not response.success:
            raise SpawnFailed(response.message)
        rospy.loginfo("%s: %s", self.prog, response.message)

    def spawn_model(self, xml: str, namespace: str) -> None:
        """Through Gazebo's spawn_urdf_model / spawn_sdf_model, as gazebo_ros's spawn_model."""
        args = self.args
        pose = Pose(Point(args.x, args.y, args.z), Quaternion(*quaternion_from_rpy(args.R, args.P, args.Y)))
        service = service_name(self.gazebo, f"spawn_{args.format}_model")
        response = self._call(service, SpawnModel, args.model, xml, namespace, pose, args.reference_frame)
        rospy.loginfo("Spawn status: %s", response.status_message)
        if not response.success:
            raise SpawnFailed(f"Spawn service failed: {response.status_message}")

    def set_configuration(self) -> None:
        names, positions = joint_lists(self.args.joints)
        service = service_name(self.gazebo, "set_model_configuration")
        response = self._call(service, SetModelConfiguration, self.args.model, "", names, positions)
        rospy.loginfo("Set model configuration status: %s", response.status_message)
        if not response.success:
            raise SpawnFailed(f"SetModelConfiguration service failed: {response.status_message}")

    def unpause(self) -> None:
        rospy.loginfo("Unpausing physics")
        if self.args.route == ROBOT:
            self._call(service_name(self.args.simulator, "unpause"), Empty)
        else:
            self._call(service_name(self.gazebo, "unpause_physics"), Empty)

    def delete(self) -> None:
        """-b: the model out of the world as this program ends (a shutdown hook: services still answer)."""
        name = self.args.model
        rospy.loginfo("Deleting model %s", name)
        try:
            if self.args.route == ROBOT:
                proxy = rospy.ServiceProxy(service_name(self.args.simulator, "delete_robot"), DeleteRobot)
            else:
                proxy = rospy.ServiceProxy(service_name(self.gazebo, "delete_model"), DeleteModel)
            response = proxy(model_name=name)
        except (rospy.ServiceException, rospy.ROSException) as e:
            rospy.logerr("Delete model service call failed: %s", e)
            return
        ok = response.success
        message = getattr(response, "message", None) or getattr(response, "status_message", "")
        (rospy.loginfo if ok else rospy.logerr)("%s: delete %s: %s", self.prog, name, message)


def main(argv: Optional[List[str]] = None, prog: str = SPAWN_ROBOT) -> int:
    # the arguments first: a wrong one is refused (exit status 2) without a master
    args = parse_args(rospy.myargv(argv if argv is not None else sys.argv)[1:], prog)
    rospy.init_node(prog, anonymous=True)
    return Spawner(args, prog).run()
