"""The names a robot is spawned under: its model name and its namespace, each a legal ROS name.

The model name names the robot in the world, in the simulator's log lines and diagnostics, and in
the services that delete or move it; the namespace is where its topics live. Both come from a
spawn request that any client may send, so the simulator's spawn service checks them as
spawn_robot does. The rules are ROS's own (rosgraph.names, plain string rules: no master, no rospy).
"""

from typing import Any, Optional

import rosgraph.names

from thorvald_model.value_text import value_text

SHOWN = 60  # [characters] of a refused name shown in a message


def model_name_problem(name: Any) -> Optional[str]:
    """None if name may name a robot in the world, else the message saying why not."""
    if not isinstance(name, str) or not name:
        return "a robot needs a name: -model NAME"
    if not rosgraph.names.is_legal_base_name(name):
        return (
            f"model name {value_text(name, SHOWN)}: must be a ROS base name, a letter then letters, digits and "
            "underscores (it names the robot in log lines, diagnostics and services)"
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
