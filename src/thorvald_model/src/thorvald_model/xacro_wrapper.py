"""``rosrun thorvald_model xacro FILE [name:=value ...]``: the real xacro, fit for robot files.

Runs xacro's own ``main()`` (xacro 1.13, the ROS 1 flavour: same options, same output, same
``$(find pkg)``) after two changes:

1. ``yaml.load`` gets a safe default Loader: xacro 1.13 calls it without one, which PyYAML 6
   rejects, so any other YAML a user's xacro loads works as it did with PyYAML 5.
2. xacro's ``load_yaml()`` loads a robot configuration through the shared loader (see
   :mod:`thorvald_model.description`): a broken file prints the loader's problems, one per line,
   and exits 2, without xacro's traceback or file stack.
3. A ``<robot>`` it makes is normalised and checked as check_urdf would
   (:func:`thorvald_model.description.check_document`): link references written with a leading
   slash or doubled slashes are rewritten as tf2 reads them, and a broken tree (a joint naming a
   link that does not exist, two root links, ...) prints every problem and exits 2, before anything
   is written (``-o``) or started from the output. ``--deps`` lists the files without checking.

xacro evaluates the ``<robot name="$(arg robot_name)">`` attribute before the ``<xacro:arg>``
elements inside it, so an absent ``robot_name:=`` gets the robot file's base name here, as
:func:`thorvald_model.description.generate_urdf` does. A relative ``robot_config:=`` is taken from
the working directory, as a user typing it expects (xacro would look next to the xacro file).

Launch files call it by name (``command="rosrun thorvald_model xacro ..."``): the PyPI xacro is
not a ROS package, so ``$(find xacro)/xacro`` does not exist here.
"""

import contextlib
import functools
import os
import sys
from typing import Any, Callable, Iterator, List, Optional

import xacro
import yaml

from .description import check_document, shared_loader
from .errors import RobotConfigAbort, UrdfCheckError


def _safe_default_loader() -> None:
    if getattr(yaml.load, "_thorvald_safe_default", False):
        return
    original = yaml.load

    @functools.wraps(original)
    def load(stream, Loader=None, **kwargs):
        return original(stream, Loader=Loader or yaml.SafeLoader, **kwargs)

    load._thorvald_safe_default = True
    yaml.load = load


def _with_robot_name(argv: List[str]) -> List[str]:
    argv = [_absolute_config(a) for a in argv]
    names = [a.split(":=", 1)[0] for a in argv if ":=" in a and not a.startswith("_")]
    if "robot_name" in names:
        return argv
    configs = [a.split(":=", 1)[1] for a in argv if a.startswith("robot_config:=")]
    name = os.path.splitext(os.path.basename(configs[-1]))[0] if configs and configs[-1] else "thorvald_ii"
    return [*argv, "robot_name:=" + name]


def _absolute_config(arg: str) -> str:
    key, sep, value = arg.partition(":=")
    if key == "robot_config" and sep and value and not value.startswith("$") and not os.path.isabs(value):
        return "robot_config:=" + os.path.abspath(value)
    return arg


def _checked_process_file(input_file_name: str, _original: Callable[..., Any], **kwargs: Any) -> Any:
    """xacro's process_file(), its result checked (:func:`check_document`); the problems carried out
    of xacro's main() like a robot file's, named after the model_extras file when there is one."""
    doc = _original(input_file_name, **kwargs)
    if kwargs.get("just_deps"):
        return doc
    args = kwargs.get("mappings") or {}  # xacro's arguments (name:=value)
    try:
        check_document(doc, args.get("model_extras") or input_file_name)
    except UrdfCheckError as e:
        raise RobotConfigAbort(e) from None
    return doc


@contextlib.contextmanager
def _checked_output() -> Iterator[None]:
    original = xacro.process_file
    xacro.process_file = functools.partial(_checked_process_file, _original=original)
    try:
        yield
    finally:
        xacro.process_file = original


def main(argv: Optional[List[str]] = None) -> int:
    if argv is not None:
        sys.argv = [sys.argv[0], *argv]
    sys.argv = _with_robot_name(sys.argv)
    _safe_default_loader()
    try:
        with shared_loader(), _checked_output():
            xacro.main()  # exits 2 itself on xacro's own errors
    except RobotConfigAbort as abort:
        print(abort.error, file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main())
