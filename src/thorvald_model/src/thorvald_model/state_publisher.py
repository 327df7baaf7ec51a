"""``rosrun thorvald_model state_publisher [--joint-states TOPIC] [ROS args]``: robot_state_publisher
in the sub-namespace ``rsp`` of a robot's namespace, as the original's ``model.launch`` ran it.

The original's users' files show robot_state_publisher in ``<robot namespace>/rsp`` reading
``<robot namespace>/base_driver/joint_states`` (reconstruction notes, section 6): their launch files
include ``model.launch`` and start no robot_state_publisher of their own. A launch file cannot name
the topic relative to the robot's namespace from inside ``rsp`` (a remap resolves in the node's own
namespace, and roslaunch has no substitution for the namespace), so this shim does: it resolves
TOPIC (default ``base_driver/joint_states``) against the namespace around its own (the one
model.launch was included in), adds the remap, and replaces itself with robot_state_publisher, the
C++ node, with every other argument passed on. A remap of ``joint_states`` given on the command line
(a user's ``<remap>``) wins. Being in ``rsp`` also keeps robot_state_publisher from finding a
``tf_prefix`` parameter of base_driver's: it would prefix the already prefixed link names again.

Needs no ROS master: the name is resolved from ``__ns:=`` or ``ROS_NAMESPACE`` (what roslaunch sets).
"""

import os
import sys
from typing import List, Optional, Sequence, Tuple

import rosgraph.names

from .errors import StatePublisherError

DEFAULT_JOINT_STATES = "base_driver/joint_states"
EXIT_USAGE = 2


def robot_namespace(node_namespace: str) -> str:
    """The namespace around a node's own: ``/thorvald_001/`` for ``/thorvald_001/rsp/``; ``/`` at the root."""
    ns = rosgraph.names.make_global_ns(node_namespace).rstrip("/")
    return rosgraph.names.make_global_ns(rosgraph.names.namespace(ns)) if ns else "/"


def joint_states_topic(node_namespace: str, topic: str = DEFAULT_JOINT_STATES) -> str:
    """The global name of the joint states robot_state_publisher reads: topic resolved in the robot's
    namespace (the one around the node's own); a global topic as it is."""
    if not topic or topic.startswith("~") or not rosgraph.names.is_legal_name(topic):
        raise StatePublisherError(f"--joint-states {topic!r}: must be a legal ROS topic name, not private")
    return rosgraph.names.ns_join(robot_namespace(node_namespace), topic) if topic[0] != "/" else topic


def split_args(argv: Sequence[str]) -> Tuple[str, List[str]]:
    """(the --joint-states topic, every other argument in order) of the shim's command line."""
    topic, rest, it = DEFAULT_JOINT_STATES, [], iter(argv)
    for a in it:
        if a == "--joint-states":
            topic = next(it, "")
        elif a.startswith("--joint-states="):
            topic = a.split("=", 1)[1]
        else:
            rest.append(a)
    return topic, rest


def command(argv: Sequence[str], environ: Optional[dict] = None, executable: Optional[str] = None) -> List[str]:
    """robot_state_publisher's command line for the shim's own: its arguments, and the joint_states remap
    unless one is given already."""
    topic, rest = split_args(argv)
    ns = rosgraph.names.get_ros_namespace(env=os.environ if environ is None else environ, argv=list(argv))
    remap = joint_states_topic(ns, topic)
    if not any(a.split(":=", 1)[0] in ("joint_states", "~joint_states") and ":=" in a for a in rest):
        rest.append(f"joint_states:={remap}")
    return [executable or find_robot_state_publisher(), *rest]


def find_robot_state_publisher() -> str:
    import roslib.packages  # noqa: PLC0415  (rospkg-based, no master: only when the shim runs)

    found = roslib.packages.find_node("robot_state_publisher", "robot_state_publisher")
    if not found:
        raise StatePublisherError("robot_state_publisher is not installed (its package has no such executable)")
    return found[0]


def main(argv: Optional[List[str]] = None) -> int:
    args = sys.argv[1:] if argv is None else argv
    try:
        cmd = command(args)
    except StatePublisherError as e:
        print(f"state_publisher: {e}", file=sys.stderr)
        return EXIT_USAGE
    os.execv(cmd[0], cmd)
    return 0  # not reached: execv replaces the process
