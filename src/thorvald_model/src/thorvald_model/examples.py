"""The example robots (``config/NAME/NAME.yaml``), and a robot as every tool takes it: an example
robot's name or a robot file.

One rule for every tool that takes a robot (``run_robot``, a design study's ``robot:``;
``sim.launch robot:=`` and ``odometry_report --robot`` read the same folder): a value that ends in
``.yaml`` or ``.yml``, or holds a path separator, is a file; anything else is an example robot's
name. A name that is none of them is refused with the closest one ("did you mean") and the list, so a
mistyped name never reads as a missing file.

Pure (rospkg finds the package's folder, :mod:`thorvald_model.resources`).
"""

import difflib
import os
from typing import Optional, Sequence, Tuple

from .description import package_file
from .errors import UnknownRobotError

YAML_SUFFIXES = (".yaml", ".yml")
# The examples' common prefix: tables and people call them by the rest (std, 4wd4ws_std, 9wd9ws).
PREFIX = "thorvald_ii_"


def example_robots() -> Tuple[str, ...]:
    """The example robots' names, sorted: each folder of ``config/`` holding its ``NAME.yaml``."""
    folder = package_file("config")
    try:
        names = os.listdir(folder)
    except OSError:
        return ()
    return tuple(sorted(n for n in names if os.path.isfile(os.path.join(folder, n, n + ".yaml"))))


def names_a_file(value: str) -> bool:
    """A value that names a robot file (``.yaml``/``.yml``, or a path), not an example robot."""
    return value.endswith(YAML_SUFFIXES) or os.sep in value or bool(os.altsep and os.altsep in value)


def example_robot_file(name: str) -> str:
    """The file of the example robot ``name``; :class:`UnknownRobotError` if there is none of that name."""
    if name and not names_a_file(name) and name not in (os.curdir, os.pardir):
        path = package_file("config", name, name + ".yaml")
        if os.path.isfile(path):
            return path
    raise UnknownRobotError(name, unknown_robot_rule(name, example_robots()))


def robot_file(value: str, base_dir: str = os.curdir) -> str:
    """The robot file a tool's argument names: an example robot's file for a name
    (:class:`UnknownRobotError` if none has it), else the path, a relative one from ``base_dir``
    (whether the file exists is the loader's to say, with the reason)."""
    if names_a_file(value):
        return os.path.normpath(os.path.join(base_dir, os.path.expanduser(value)))
    return example_robot_file(value)


def unknown_robot_rule(name: str, known: Sequence[str]) -> str:
    """The rule an unknown name breaks, with the example it most likely means and every example."""
    close = closest_robot(name, known)
    hint = f" (did you mean {close!r}?)" if close else ""
    examples = ", ".join(known) or "none found"
    return (
        f"no example robot of that name{hint}; the examples: {examples}; "
        "a robot file is a path ending in .yaml (./my_robot.yaml)"
    )


def closest_robot(name: str, known: Sequence[str]) -> Optional[str]:
    """The example robot ``name`` most likely means: the one example whose name holds it (``9wd``,
    ``4wd4ws_wide``), else the closest spelling (difflib's ratio 0.6 or more) of a whole name or of
    the part after ``thorvald_ii_`` (``4wd4ws_sdt``); None when two are as likely (``6wd6ws``: asym or
    susp), since a wrong guess would mislead."""
    text = str(name).strip().lower()
    holding = [k for k in known if text and text in k]
    if holding:
        return holding[0] if len(holding) == 1 else None
    scores = {}
    for k in known:
        forms = (k, k[len(PREFIX) :]) if k.startswith(PREFIX) else (k,)
        scores[k] = max(difflib.SequenceMatcher(None, text, form).ratio() for form in forms)
    ranked = sorted(scores.items(), key=lambda item: -item[1])
    if not ranked or ranked[0][1] < 0.6 or (len(ranked) > 1 and ranked[1][1] == ranked[0][1]):
        return None
    return ranked[0][0]


__all__ = [
    "UnknownRobotError",
    "closest_robot",
    "example_robot_file",
    "example_robots",
    "names_a_file",
    "robot_file",
    "unknown_robot_rule",
]
