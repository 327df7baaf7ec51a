"""The names a robot is spawned under: its model name (as Gazebo's) and its namespace (a legal ROS name).

The model name names the robot in the world, in the simulator's log lines and diagnostics, and in
the services that delete or move it; the namespace is where its topics live. Both come from a
spawn request that any client may send, so the simulator's spawn service checks them as
spawn_robot does. The rules are ROS's own (rosgraph.names, plain string rules: no master, no rospy).
"""

import re
from typing import Any, Optional

import rosgraph.names

from thorvald_model.value_text import value_text

SHOWN = 60  # [characters] of a refused name shown in a message
MAX_MODEL_NAME = 255  # [characters]
_MODEL_NAME = re.compile(r"[A-Za-z0-9_][A-Za-z0-9_.-]*\Z")


def model_name_problem(name: Any) -> Optional[str]:
    """None if name may name a robot in the world, else the message saying why not.

    Model names are Gazebo's, not ROS names (``robot-1`` and ``unit_box.0`` are fine): letters, digits,
    ``_``, ``-`` and ``.``, not starting with ``-`` or ``.``, at most MAX_MODEL_NAME characters; no
    blank, slash or control character, which would break the log lines, diagnostics and services
    that name the robot."""
    if not isinstance(name, str) or not name:
        return "a robot needs a name: -model NAME"
    if len(name) > MAX_MODEL_NAME or not _MODEL_NAME.match(name):
        return (
            f"model name {value_text(name, SHOWN)}: must be letters, digits, '_', '-' and '.', starting with a "
            f"letter, digit or '_', at most {MAX_MODEL_NAME} characters (it names the robot in log lines, "
            "diagnostics and services)"
        )
    return None


def namespace_problem(namespace: Any) -> Optional[str]:
    """None if the robot's topics may live in namespace ("" for the simulator's own), else the
    message saying why not."""
    if not isinstance(namespace, str):
        return f"robot namespace {value_text(namespace, SHOWN)}: must be a string"
    if not rosgraph.names.is_legal_name(namespace):
        return (
            f"robot namespace {value_text(namespace, SHOWN)}: must be a legal ROS name (a letter or / first, "
            "then letters, digits, underscores and slashes, never two slashes together)"
        )
    if namespace.startswith("~"):
        # a private name would put the robot's topics under the simulator node's own
        return f"robot namespace {value_text(namespace, SHOWN)}: must not be private (~): it would be the simulator's"
    return None


__all__ = ["model_name_problem", "namespace_problem"]
