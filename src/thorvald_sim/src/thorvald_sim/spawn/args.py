"""The arguments of ``spawn_model`` and ``spawn_robot`` (one program, :mod:`thorvald_sim.spawn.spawn_robot`),
and what they make of the model's text: pure (argparse, XML, arithmetic; no rospy, no master).

gazebo_ros's ``spawn_model`` arguments, with its names, defaults and meanings:

  -urdf | -sdf              the text's format (spawn_model: one is required, as gazebo_ros's;
                            spawn_robot: -urdf by default)
  -file F | -param P | -database NAME | -stdin
                            where the text comes from (one is required); -database sends Gazebo's
                            template naming model://NAME
  -model NAME               the model's name in the world (letters, digits, '_', '-', '.')
  -x -y -z [m] -R -P -Y [rad]   the initial pose, in -reference_frame
  -J JOINT POSITION         a joint's initial position [rad or m] (repeatable), set after the spawn
  -reference_frame F        the entity the pose is given in ("" or world: the world)
  -robot_namespace NS       where the model's topics live (default: this node's namespace)
  -gazebo_namespace G       where Gazebo's ROS API is (default /gazebo)
  -unpause                  unpause the simulation after spawning
  -wait MODEL               first wait until MODEL is in the world (G/model_states)
  -package_to_model         mesh filenames package://... become model://...
  -b                        bond: delete the model when this program ends

and this workspace's, for a robot spawned through the simulator's own ``~spawn_robot`` service:

  -simulator S              the simulator node (default /simulator)
  -command_topic T          follow T instead of the description's (base_state)
  -publish_tf | -no_publish_tf   odom -> base_link from ground truth (default: the simulator's ~publish_tf)
  -as_built SPEC            build the robot as an as-built file says (needs -robot_model)
  -robot_model FILE         the robot's configuration file
  -timeout T                seconds to wait for each service (default 60; 0: for ever)

Which service spawns (:func:`route`): ``spawn_robot`` sends a URDF to the simulator's
``~spawn_robot`` (a Thorvald robot with its topics, any other URDF a passive robot, as it always
has); ``spawn_model`` sends the text to Gazebo's ``spawn_urdf_model`` / ``spawn_sdf_model``, whose
simulator spawns a Thorvald description as ``~spawn_robot`` does and anything else as a model,
unless one of this workspace's robot arguments is given, which only ``~spawn_robot`` takes. An SDF
always goes to Gazebo's service.

A wrong argument is refused by argparse (exit status 2) with the argument, the value and the rule.
"""

import argparse
import math
import os
import xml.etree.ElementTree as ET
from typing import List, Optional, Sequence, Tuple
from urllib.parse import SplitResult, urlsplit

from ..errors import SpawnInputError
from .names import model_name_problem, namespace_problem

SPAWN_MODEL = "spawn_model"
SPAWN_ROBOT = "spawn_robot"
PROGRAMS = (SPAWN_MODEL, SPAWN_ROBOT)

# gazebo_ros's spawn_model, verbatim: what -database sends
MODEL_DATABASE_TEMPLATE = """\
<sdf version="1.4">
    <world name="default">
        <include>
            <uri>model://{}</uri>
        </include>
    </world>
</sdf>"""

ROBOT = "robot"  # the simulator's ~spawn_robot (thorvald_msgs/SpawnRobot)
GAZEBO = "gazebo"  # Gazebo's <gazebo_namespace>/spawn_urdf_model or spawn_sdf_model (gazebo_msgs/SpawnModel)
WORLD_FRAMES = ("", "world", "map")  # Gazebo's names of the world frame
# this workspace's arguments that only the simulator's ~spawn_robot takes (dest: the value when not given)
ROBOT_ONLY = {"simulator": None, "command_topic": "", "publish_tf": -1, "as_built": "", "robot_model": ""}
DEFAULT_SIMULATOR = "/simulator"


def _checked(problem_of):
    """An argparse type that refuses a value problem_of finds a problem with, saying it."""

    def check(value: str) -> str:
        problem = problem_of(value)
        if problem:
            raise argparse.ArgumentTypeError(problem)
        return value

    return check


def _finite(value: str) -> float:
    try:
        number = float(value)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{value!r} is not a number") from None
    if not math.isfinite(number):
        raise argparse.ArgumentTypeError(f"{value!r}: must be a finite number")
    return number


def _timeout(value: str) -> float:
    number = _finite(value)
    if number < 0:
        raise argparse.ArgumentTypeError(f"{value!r}: must be 0 (wait for ever) or more [s]")
    return number


def _global_namespace(value: str) -> str:
    """-gazebo_namespace and -simulator: a global ROS name (as the simulator's ~gazebo_namespace)."""
    problem = namespace_problem(value)
    if problem is None and not value.startswith("/"):
        problem = f"{value!r}: must be a global ROS name, starting with /"
    if problem:
        raise argparse.ArgumentTypeError(problem.replace("robot namespace ", "", 1))
    return value.rstrip("/") if value != "/" else value


def _flag(dest: str, value) -> str:
    if dest == "publish_tf":
        return "-publish_tf" if value == 1 else "-no_publish_tf"
    return "-" + dest


def build_parser(prog: str = SPAWN_ROBOT) -> argparse.ArgumentParser:
    if prog not in PROGRAMS:
        raise ValueError(f"prog {prog!r}: one of {', '.join(PROGRAMS)}")
    parser = argparse.ArgumentParser(
        prog=prog,
        description="Spawn a model in the simulator through Gazebo's ROS API"
        if prog == SPAWN_MODEL
        else "Spawn a robot in thorvald_sim",
    )
    xmlformat = parser.add_mutually_exclusive_group(required=prog == SPAWN_MODEL)
    xmlformat.add_argument("-urdf", action="store_true", help="the model's text is URDF")
    xmlformat.add_argument("-sdf", action="store_true", help="the model's text is SDF")
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("-file", metavar="FILE_NAME", help="load the model's text from a file")
    source.add_argument("-param", metavar="PARAM_NAME", help="load the model's text from a ROS parameter")
    source.add_argument(
        "-database", metavar="MODEL_NAME", help="Gazebo's model database: send model://MODEL_NAME (SDF)"
    )
    source.add_argument("-stdin", action="store_true", help="load the model's text from stdin")
    parser.add_argument(
        "-model",
        required=True,
        type=_checked(model_name_problem),
        metavar="MODEL_NAME",
        help="the model's name in the world (letters, digits, '_', '-', '.')",
    )
    parser.add_argument("-reference_frame", default="", help='the entity the pose is given in ("" or world: the world)')
    parser.add_argument(
        "-gazebo_namespace", type=_global_namespace, default="/gazebo", help="where Gazebo's ROS API is (/gazebo)"
    )
    parser.add_argument(
        "-robot_namespace",
        type=_checked(namespace_problem),
        default=None,
        help="where the model's topics live (default: this node's namespace)",
    )
    parser.add_argument("-unpause", action="store_true", help="unpause the simulation after spawning")
    parser.add_argument("-wait", metavar="MODEL_NAME", help="first wait until this model is in the world")
    for axis, what in (("x", "[m]"), ("y", "[m]"), ("z", "[m]"), ("R", "roll [rad]"), ("P", "pitch [rad]")):
        parser.add_argument("-" + axis, type=_finite, default=0.0, help=f"initial pose: {axis} {what}")
    parser.add_argument("-Y", type=_finite, default=0.0, help="initial pose: yaw [rad]")
    parser.add_argument(
        "-J",
        dest="joints",
        default=[],
        action="append",
        nargs=2,
        metavar=("JOINT_NAME", "JOINT_POSITION"),
        help="a joint's initial position [rad or m] (repeat for more joints)",
    )
    parser.add_argument(
        "-package_to_model", action="store_true", help='mesh filenames "package://..." become "model://..."'
    )
    parser.add_argument(
        "-b", dest="bond", action="store_true", help="bond: delete the model when this program is interrupted"
    )
    # this workspace's: the simulator's own ~spawn_robot
    parser.add_argument(
        "-simulator",
        type=_global_namespace,
        default=None,
        help=f"the simulator node whose ~spawn_robot spawns a robot ({DEFAULT_SIMULATOR})",
    )
    parser.add_argument("-command_topic", default="", help="the topic the robot follows (the description's)")
    tf = parser.add_mutually_exclusive_group()
    tf.add_argument(
        "-publish_tf", dest="publish_tf", action="store_const", const=1, default=-1, help="odom -> base_link on /tf"
    )
    tf.add_argument("-no_publish_tf", dest="publish_tf", action="store_const", const=0, help="no odom -> base_link")
    parser.add_argument("-as_built", default="", help="an as-built file or profile:seed (field:7)")
    parser.add_argument("-robot_model", default="", help="the robot's configuration file (with -as_built)")
    parser.add_argument("-timeout", type=_timeout, default=60.0, help="[s] to wait for each service (60; 0: for ever)")
    return parser


def parse_args(argv: Sequence[str], prog: str = SPAWN_ROBOT) -> argparse.Namespace:
    """The program's arguments, checked together; argparse's exit (status 2, the argument, the value
    and the rule) for a wrong one. Adds ``route`` (:data:`ROBOT` or :data:`GAZEBO`), ``format``
    ("urdf" or "sdf"), ``joints`` as (name, position) pairs."""
    parser = build_parser(prog)
    args = parser.parse_args(list(argv))
    joints = []
    for name, position in args.joints:
        try:
            joints.append((name, _finite(position)))
        except argparse.ArgumentTypeError as e:
            parser.error(f"argument -J: joint {name!r}: position {e}")
    args.joints = joints
    args.format = "sdf" if args.sdf or args.database else "urdf"
    robot_only = [_flag(dest, getattr(args, dest)) for dest in ROBOT_ONLY if getattr(args, dest) != ROBOT_ONLY[dest]]
    if args.format == "sdf" and robot_only:
        parser.error(
            f"argument {robot_only[0]}: only for a robot (a URDF) spawned through the simulator's ~spawn_robot, "
            "not with -sdf or -database"
        )
    args.route = route(prog, args.format, bool(robot_only))
    if args.route == ROBOT:
        if args.reference_frame not in WORLD_FRAMES:
            parser.error(
                f"argument -reference_frame: {args.reference_frame!r}: a robot spawned through the simulator's "
                "~spawn_robot is placed in the world; for a pose relative to another entity spawn it with "
                "gazebo_ros spawn_model, without this workspace's robot arguments (-simulator, -command_topic, "
                "-publish_tf, -no_publish_tf, -as_built, -robot_model)"
            )
        if args.R or args.P:
            parser.error("argument -R/-P: must be 0: robots are spawned upright on the ground")
        if args.simulator is None:
            args.simulator = DEFAULT_SIMULATOR
    return args


def route(prog: str, xml_format: str, robot_arguments: bool) -> str:
    """Which service spawns: the simulator's ~spawn_robot (:data:`ROBOT`) for spawn_robot's URDFs and
    for a URDF given this workspace's robot arguments; Gazebo's spawn service (:data:`GAZEBO`) else."""
    if xml_format == "urdf" and (prog == SPAWN_ROBOT or robot_arguments):
        return ROBOT
    return GAZEBO


def read_file(path: str) -> str:
    """The text of a model file; SpawnInputError with gazebo_ros's reasons (missing, not a file, empty)."""
    if not os.path.exists(path):
        raise SpawnInputError(f"Error: specified file {path} does not exist")
    if not os.path.isfile(path):
        raise SpawnInputError(f"Error: specified file {path} is not a file")
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read()
    except (OSError, UnicodeDecodeError) as e:
        raise SpawnInputError(f"Error reading file {path}: {getattr(e, 'strerror', None) or e}") from None
    if text == "":
        raise SpawnInputError(f"Error: file {path} is empty")
    return text


def database_text(model: str) -> str:
    return MODEL_DATABASE_TEMPLATE.format(model)


def package_to_model(root: ET.Element) -> int:
    """gazebo_ros's -package_to_model, in place: every ``<mesh filename="package://...">`` becomes
    ``model://...``; how many were changed."""
    changed = 0
    for element in root.iterfind(".//mesh"):
        filename = element.get("filename")
        if filename is None:
            continue
        url = urlsplit(filename)
        if url.scheme == "package":
            element.set("filename", SplitResult("model", *url[1:]).geturl())
            changed += 1
    return changed


def prepared_xml(text: str, to_model: bool = False) -> str:
    """The text to send: parsed first, so broken XML is refused here with the parser's reason
    (SpawnInputError "Invalid XML: ..."), as gazebo_ros does; with to_model, re-serialised after
    :func:`package_to_model` (otherwise sent as it is)."""
    try:
        root = ET.fromstring(text)
    except ET.ParseError as e:
        raise SpawnInputError(f"Invalid XML: {e}") from None
    if not to_model:
        return text
    package_to_model(root)
    return ET.tostring(root, encoding="unicode")


def quaternion_from_rpy(roll: float, pitch: float, yaw: float) -> Tuple[float, float, float, float]:
    """(x, y, z, w) of fixed-axis roll, pitch, yaw [rad] (tf's quaternion_from_euler, 'sxyz')."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (
        sr * cp * cy - cr * sp * sy,
        cr * sp * cy + sr * cp * sy,
        cr * cp * sy - sr * sp * cy,
        cr * cp * cy + sr * sp * sy,
    )


def joint_lists(joints: Sequence[Tuple[str, float]]) -> Tuple[List[str], List[float]]:
    return [name for name, _ in joints], [position for _, position in joints]


def service_name(namespace: str, service: str) -> str:
    """namespace + "/" + service, as gazebo_ros's ``'%s/spawn_urdf_model' % gazebo_namespace``."""
    return namespace.rstrip("/") + "/" + service


def timeout_or_none(timeout: float) -> Optional[float]:
    """rospy.wait_for_service's timeout: None (for ever) for 0."""
    return timeout or None


__all__ = [
    "GAZEBO",
    "MODEL_DATABASE_TEMPLATE",
    "PROGRAMS",
    "ROBOT",
    "SPAWN_MODEL",
    "SPAWN_ROBOT",
    "build_parser",
    "database_text",
    "package_to_model",
    "parse_args",
    "prepared_xml",
    "quaternion_from_rpy",
    "read_file",
    "route",
]
