"""``rosrun thorvald_sim spawn_robot -param robot_description -model NAME -x X -y Y -Y YAW``.

gazebo_ros's spawn_model for thorvald_sim, with its arguments, so the original's users' launch
files need only the package and type changed. Run it inside the robot's namespace: the description
is that namespace's parameter, and the robot's topics live there.

  -param P | -file F     the URDF: a parameter (relative to the namespace) or a file
  -urdf                  accepted (the description is always URDF)
  -model NAME            the robot's name in the world, as Gazebo's: letters, digits, '_', '-', '.'
                         (not first: '-', '.')
  -x X -y Y -z Z -Y YAW  base_link's spawn pose [m, rad]; -R and -P (roll, pitch) must be 0
  -robot_namespace NS    where its topics live (default: this node's namespace): a legal ROS name,
                         not private (~)
  -gazebo_namespace S    the simulator node (default /simulator); -simulator S is the same
  -command_topic T       follow T instead of the description's (base_state)
  -publish_tf / -no_publish_tf   odom -> base_link from ground truth (default: the simulator's ~publish_tf)
  -as_built SPEC         build the robot as an as-built file says, or a profile drawn with a seed
                         (field:7); needs -robot_model (thorvald_sim.as_built). base_driver never sees it
  -robot_model FILE      the robot's configuration file (what the as-built robot differs from)
  -unpause               unpause the simulation after spawning
  -timeout T             seconds to wait for the simulator (default 60)

Exit status 0 when the robot is in the world, 1 with the reason when not, 2 for a wrong argument
(argparse's message: the argument, the value and the rule).
"""

import argparse
import sys
from typing import List, Optional

import rospy
from std_srvs.srv import Empty

from thorvald_model import ConfigError, load_robot_config
from thorvald_msgs.srv import SpawnRobot

from .as_built import as_built_for, for_simulator
from .spawn_names import model_name_problem, namespace_problem


def _checked(problem_of):
    """An argparse type that refuses a value problem_of finds a problem with, saying it."""

    def check(value: str) -> str:
        problem = problem_of(value)
        if problem:
            raise argparse.ArgumentTypeError(problem)
        return value

    return check


def parse_args(argv: List[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="spawn_robot", description="Spawn a robot in thorvald_sim.")
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("-param", help="parameter holding the URDF, e.g. robot_description")
    source.add_argument("-file", help="URDF file")
    parser.add_argument("-urdf", action="store_true", help="accepted: the description is URDF")
    parser.add_argument(
        "-model",
        required=True,
        type=_checked(model_name_problem),
        help="the robot's name in the world (letters, digits, '_', '-', '.')",
    )
    for axis in ("x", "y", "z", "R", "P", "Y"):
        parser.add_argument("-" + axis, type=float, default=0.0)
    parser.add_argument("-robot_namespace", type=_checked(namespace_problem), default=None)
    parser.add_argument("-gazebo_namespace", "-simulator", dest="simulator", default="/simulator")
    parser.add_argument("-command_topic", default="")
    tf = parser.add_mutually_exclusive_group()
    tf.add_argument("-publish_tf", dest="publish_tf", action="store_const", const=1, default=-1)
    tf.add_argument("-no_publish_tf", dest="publish_tf", action="store_const", const=0)
    parser.add_argument("-as_built", default="")
    parser.add_argument("-robot_model", default="")
    parser.add_argument("-unpause", action="store_true")
    parser.add_argument("-timeout", type=float, default=60.0)
    return parser.parse_args(argv)


def read_description(args) -> str:
    if args.file:
        try:
            with open(args.file, encoding="utf-8") as f:
                return f.read()
        except (OSError, UnicodeDecodeError) as e:
            raise RuntimeError(
                f"{args.file}: cannot read the description: {getattr(e, 'strerror', None) or e}"
            ) from None
    name = rospy.resolve_name(args.param)
    if not rospy.has_param(name):
        raise RuntimeError(f"no parameter {name}: load the robot's description there first (model.launch)")
    xml = rospy.get_param(name)
    if not isinstance(xml, str):
        raise RuntimeError(f"parameter {name} holds a {type(xml).__name__}, not a URDF")
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


def main(argv: Optional[List[str]] = None) -> int:
    # the arguments first: a wrong one is refused (exit status 2) without a master
    args = parse_args(rospy.myargv(argv if argv is not None else sys.argv)[1:])
    rospy.init_node("spawn_robot", anonymous=True)
    if args.R or args.P:
        print("spawn_robot: -R and -P must be 0: robots are spawned upright on the ground", file=sys.stderr)
        return 1
    try:
        xml = read_description(args)
        as_built = read_as_built(args)
    except (RuntimeError, ConfigError) as e:
        print(f"spawn_robot: {e}", file=sys.stderr)
        return 1
    simulator = args.simulator.rstrip("/")
    try:
        rospy.wait_for_service(simulator + "/spawn_robot", timeout=args.timeout)
    except rospy.ROSException:
        print(f"spawn_robot: no simulator answers at {simulator}/spawn_robot after {args.timeout:g} s", file=sys.stderr)
        return 1
    namespace = args.robot_namespace if args.robot_namespace is not None else rospy.get_namespace()
    response = rospy.ServiceProxy(simulator + "/spawn_robot", SpawnRobot)(
        args.model, namespace, xml, args.x, args.y, args.z, args.Y, args.command_topic, args.publish_tf, as_built
    )
    if not response.success:
        print(f"spawn_robot: {response.message}", file=sys.stderr)
        return 1
    rospy.loginfo("spawn_robot: %s", response.message)
    if args.unpause:
        rospy.ServiceProxy(simulator + "/unpause", Empty)()
    return 0
