"""Where a node's names are, so one process can hold several robots' nodes (``fleet_driver``).

A node of its own uses rospy's relative and private names, and roslaunch's remappings reach it
through rospy; one robot of a fleet_driver process gets its namespace (``/robot_1/``), its private
namespace (``/robot_1/base_driver/``) and the remappings its own process would have had.
"""

import math
import time

import rospy

WARN_PERIOD = 5.0  # [s] between repeats of one warning


class Names:
    """Where one robot's driver finds its names: a process of its own (the default: rospy's relative
    and private names, the launch file's remappings applied by rospy) or one robot of a fleet_driver
    process (namespace ``/robot_1/``, private namespace ``/robot_1/base_driver/``, and the remappings
    robot.launch gives its own process, given here)."""

    def __init__(self, namespace: str = "", private: str = "~", remap=None):
        self.namespace = namespace
        self.private = private
        self.remap = dict(remap or {})

    def topic(self, name: str) -> str:
        name = self.remap.get(name, name)
        return name if name.startswith("/") else self.namespace + name

    def param(self, name: str = "") -> str:
        return self.private + name

    @property
    def robot(self) -> str:
        """The robot's namespace without slashes ("" at the root), as /diagnostics name it."""
        return (self.namespace or rospy.get_namespace()).strip("/")

    @property
    def node(self) -> str:
        """The node's resolved name, as log lines and /diagnostics name it."""
        return rospy.get_name() if self.private == "~" else self.private.rstrip("/")

    def label(self, own: str) -> str:
        """What the node's log lines start with: own (its plain name) in a process of its own, the
        robot's node name in a fleet_driver process (which robot says it)."""
        return own if self.private == "~" else self.node


class Throttle:
    """rospy.logwarn_throttle kept per object: rospy's is kept per line of code, so in a fleet_driver
    one robot's warning would silence the same warning of every other robot."""

    def __init__(self, period: float = WARN_PERIOD):
        self.period = period
        self.last = {}

    def warn(self, fmt: str, *args) -> None:
        now = time.monotonic()
        if now - self.last.get(fmt, -math.inf) >= self.period:
            self.last[fmt] = now
            rospy.logwarn(fmt, *args)
