"""The robot description (URDF) generated from a robot configuration file by xacro (paper 4.1).

``urdf/thorvald_model.xacro`` builds the robot from the configuration; it reads the file with
xacro's ``load_yaml()``. This module runs the real xacro (the ROS 1 flavour, 1.13) with that one
symbol replaced, so that loading the robot configuration goes through the shared loader
(:func:`thorvald_model.config.load_robot_config`): the xacro sees the validated configuration
with every default filled in and every alias resolved (``thorvald_model.config_to_dict``), and a broken
file stops with the loader's list of problems. The xacro never repeats a default or a rule.

Other YAML files (a user's extras loading their sensor table) load with ``yaml.safe_load``, since
xacro 1.13's own ``load_yaml`` calls ``yaml.load`` without a Loader, which PyYAML 6 rejects.

The generated description is then normalised and checked as check_urdf would
(:mod:`thorvald_model.urdf_check`): a link reference written ``/base_link`` (older generators) or
``thorvald_001//base_link`` (the two tf_prefix conventions mixed) means ``base_link`` /
``thorvald_001/base_link``, as in tf2, and a broken tree (a joint naming a link that does not exist)
stops with every problem (:class:`~thorvald_model.errors.UrdfCheckError`) before anything runs.

Pure: no rospy, no messages. ``$(find pkg)`` in a user's extras resolves through rospack.
"""

import contextlib
import functools
import os
import re
from typing import Any, Callable, Dict, Iterator, Optional

import xacro
import yaml

from .config import description_dict, load_robot_config, parse_robot_config
from .datum import load_datum
from .errors import ConfigError, RobotConfigAbort, UrdfCheckError, XacroError
from .frames import normalize_tf_prefix
from .resources import package_folder
from .urdf_check import normalize_document, urdf_problems

# The package folder when this module runs from the source tree (or the devel space, which relays
# to it); in an install space the package's files are under share/thorvald_model instead.
PACKAGE_DIR = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))


def package_file(*parts: str) -> str:
    """A file of the thorvald_model package, in the devel or install space (or the source tree)."""
    return os.path.join(package_folder("thorvald_model", PACKAGE_DIR), *parts)


def xacro_file() -> str:
    """Path of thorvald_model.xacro."""
    return package_file("urdf", "thorvald_model.xacro")


def _is_robot_config_arg(path: str) -> bool:
    arg = xacro.substitution_args_context.get("arg", {}).get("robot_config")
    return bool(arg) and os.path.realpath(arg) == os.path.realpath(path)


def _robot_dict(load: Callable[[], Any]) -> Dict[str, Any]:
    """The canonical dict of a robot configuration with its derived facts (description_dict), or
    its ConfigError carried out of xacro."""
    try:
        return description_dict(load())
    except ConfigError as e:
        raise RobotConfigAbort(e) from None


def _load_yaml(filename: str) -> Any:
    """xacro's load_yaml(): same path and dependency handling, safe loading, robot files validated.

    The robot_config file goes through the shared loader, which words unreadable and malformed
    files the same way for every tool; other YAML files holding ``motor_drives`` are robot
    configurations too and are validated after loading.
    """
    filename = xacro.abs_filename_spec(filename)
    oldstack = xacro.push_file(filename)
    try:
        if _is_robot_config_arg(filename):
            return _robot_dict(lambda: load_robot_config(filename))
        try:
            with open(filename, "rb") as f:
                data = yaml.safe_load(f)
        except (OSError, yaml.YAMLError) as e:
            raise xacro.XacroException(f"cannot load YAML file {filename}: {e}") from None
        if isinstance(data, dict) and "motor_drives" in data:
            return _robot_dict(lambda: parse_robot_config(data, filename))
        return data
    finally:
        xacro.restore_filestack(oldstack)
        xacro.all_includes.append(filename)


_ARG = re.compile(r"^\$\(arg\s+([^\s()]+)\s*\)$")


def _eval_extension(text: str, _original: Callable[[str], Any]) -> Any:
    """``$(arg name)`` straight from xacro's arguments; anything else (``$(find pkg)``) through
    roslaunch as xacro does. roslaunch pulls in message modules, which the pure core avoids."""
    m = _ARG.match(text)
    args = xacro.substitution_args_context.get("arg") or {}
    if m and m.group(1) in args:
        return args[m.group(1)]
    return _original(text)


def _load_datum(filename: str) -> Dict[str, float]:
    """The datum file (model.launch's datum_file) for the simulator block; its ConfigError carried out
    of xacro like a robot file's."""
    try:
        datum = load_datum(xacro.abs_filename_spec(filename))
    except ConfigError as e:
        raise RobotConfigAbort(e) from None
    xacro.all_includes.append(filename)
    return {"latitude": datum.latitude, "longitude": datum.longitude, "yaw": datum.yaw, "altitude": datum.altitude}


@contextlib.contextmanager
def shared_loader() -> Iterator[None]:
    """Within the block, xacro's load_yaml() is :func:`_load_yaml`, $(arg) needs no roslaunch, and
    ``normalize_tf_prefix()`` is the one rule of :mod:`thorvald_model.frames` for the xacro, and
    ``load_datum()`` reads a datum file through :mod:`thorvald_model.datum`."""
    previous_load = xacro.global_symbols.get("load_yaml")
    previous_extension = xacro.eval_extension
    xacro.global_symbols["load_yaml"] = _load_yaml
    xacro.global_symbols["normalize_tf_prefix"] = normalize_tf_prefix
    xacro.global_symbols["load_datum"] = _load_datum
    xacro.eval_extension = functools.partial(_eval_extension, _original=previous_extension)
    try:
        yield
    finally:
        xacro.global_symbols["load_yaml"] = previous_load
        xacro.global_symbols.pop("normalize_tf_prefix", None)
        xacro.global_symbols.pop("load_datum", None)
        xacro.eval_extension = previous_extension


def xacro_args(
    robot_config: str,
    tf_prefix: str = "",
    model_extras: str = "",
    robot_name: Optional[str] = None,
    datum_file: str = "",
) -> Dict[str, str]:
    """The xacro arguments of thorvald_model.xacro; robot_name defaults to the file's base name."""
    if robot_name is None:
        robot_name = os.path.splitext(os.path.basename(robot_config))[0]
    return {
        "robot_name": robot_name,
        "tf_prefix": tf_prefix,
        "robot_config": os.path.abspath(robot_config),
        "model_extras": os.path.abspath(model_extras) if model_extras else "",
        "datum_file": os.path.abspath(datum_file) if datum_file else "",
    }


def generate_urdf(
    robot_config: str,
    tf_prefix: str = "",
    model_extras: str = "",
    robot_name: Optional[str] = None,
    datum_file: str = "",
) -> str:
    """The URDF of the robot described by the configuration file robot_config.

    Raises ConfigError (every problem of the file), UrdfCheckError (a ConfigError: every problem of
    the robot's tree, e.g. an extras' joint naming a link that does not exist; named after the extras
    file when there is one) or XacroError (e.g. an extras file that is missing or broken).
    """
    mappings = xacro_args(robot_config, tf_prefix, model_extras, robot_name, datum_file)
    try:
        with shared_loader():
            doc = xacro.process_file(xacro_file(), mappings=mappings, in_order=True)
    except RobotConfigAbort as abort:
        raise abort.error from None
    except xacro.XacroException as e:
        raise XacroError(_xacro_message(e)) from None
    except Exception as e:  # xml.parsers.expat.ExpatError from a malformed extras file, among others
        raise XacroError(f"{type(e).__name__}: {e}") from None
    finally:
        xacro.substitution_args_context["arg"] = {}
    check_document(doc, mappings["model_extras"] or mappings["robot_config"])
    return doc.toprettyxml(indent="  ")


def check_document(doc: Any, source: str) -> None:
    """Normalises the link references of xacro's result (a ``xml.dom.minidom`` document) in place,
    keeping its formatting, and checks it as check_urdf would; UrdfCheckError naming source with
    every problem. A document that is not a ``<robot>`` (xacro makes other files too) is left alone."""
    root = doc.documentElement
    if root is None or root.tagName != "robot":
        return
    normalize_document(doc)
    problems = urdf_problems(doc.toxml())
    if problems:
        raise UrdfCheckError(source, problems)


def _xacro_message(e: Exception) -> str:
    text = str(e)
    stack = [f for f in xacro.filestack if f]
    if stack:
        text += f" (in {stack[-1]})"
    return text
