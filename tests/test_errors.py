"""Every package's errors in one module (STYLE.md: one ``errors.py`` per package): each package with
Python sources has ``<package>/errors.py``, every exception class its sources define (modules, nodes
and scripts) is defined there, and every class defined there derives from the package's base error.

Read from the sources without importing them (:func:`thorvald_testing.sources.exception_classes_of`),
but for the errors modules themselves, which are pure (the purity test checks it). A new package with
Python sources must be named below, with its base error or why it has none.
"""

import functools
import importlib
import os
from typing import Dict, List, Set

import pytest

from thorvald_testing.sources import exception_classes_of

SRC = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "src"))
# each package's base error: every error the package raises derives from it
BASE_ERRORS = {
    "thorvald_base": "ThorvaldBaseError",
    "thorvald_bringup": "ThorvaldBringupError",
    "thorvald_design": "DesignError",
    "thorvald_model": "ThorvaldModelError",
    "thorvald_sim": "ThorvaldSimError",
    "thorvald_teleop": "ThorvaldTeleopError",
}
# packages with Python sources but no errors of their own (they must define no exception class)
NO_ERRORS = {
    "gazebo_ros": "gazebo_ros's helpers under the original's names: they raise what the original's do (rospy's)",
    "thorvald_testing": "test code: a failure is the test's AssertionError",
}
# classes still outside their package's errors module, and why: each must still be where it is named
NOT_YET_MOVED = {}
# classes of an errors module that are not errors of the package, and why
NOT_ERRORS = {
    "thorvald_model": {"RobotConfigAbort": "a BaseException carrying a ConfigError out of xacro, past its handlers"},
}


def is_python(path: str) -> bool:
    if path.endswith(".py"):
        return True
    with open(path, "rb") as f:
        return b"python" in f.readline()  # a node's or script's shebang


def sources(package: str) -> List[str]:
    """The package's Python sources: its modules and its nodes' and scripts' files (not its tests)."""
    found = []
    for folder in ("src", "nodes", "scripts"):
        for root, dirs, files in os.walk(os.path.join(SRC, package, folder)):
            dirs[:] = sorted(d for d in dirs if d != "__pycache__")
            found += [os.path.join(root, name) for name in sorted(files) if is_python(os.path.join(root, name))]
    return found


def python_packages() -> List[str]:
    return sorted(p for p in os.listdir(SRC) if os.path.isfile(os.path.join(SRC, p, "package.xml")) and sources(p))


@functools.lru_cache(maxsize=None)
def defined_exceptions() -> Dict[str, Set[str]]:
    """Every source file of the workspace's packages: the exception classes it defines, subclasses of
    classes another file defines included."""
    return exception_classes_of(path for package in python_packages() for path in sources(package))


def errors_module(package: str) -> str:
    return os.path.join(SRC, package, "src", package, "errors.py")


def test_every_package_with_python_sources_is_named_here():
    assert python_packages() == sorted({**BASE_ERRORS, **NO_ERRORS})


@pytest.mark.parametrize("package", sorted(BASE_ERRORS))
def test_every_exception_class_of_a_package_is_in_its_errors_module(package):
    assert os.path.isfile(errors_module(package)), f"{package} has no errors module"
    elsewhere = {
        os.path.relpath(path, SRC): sorted(classes - set(NOT_YET_MOVED.get(os.path.relpath(path, SRC), ())))
        for path, classes in defined_exceptions().items()
        if path != errors_module(package) and path.startswith(os.path.join(SRC, package) + os.sep)
    }
    assert {path: classes for path, classes in elsewhere.items() if classes} == {}
    for path, waiting in NOT_YET_MOVED.items():  # the list cannot grow stale
        if path.startswith(package + os.sep):
            assert set(waiting) <= defined_exceptions()[os.path.join(SRC, path)], f"{path}: moved? drop it here"


@pytest.mark.parametrize("package", sorted(BASE_ERRORS))
def test_every_class_of_an_errors_module_derives_from_the_packages_base_error(package):
    errors = importlib.import_module(f"{package}.errors")
    base = getattr(errors, BASE_ERRORS[package])
    classes = {
        name: value
        for name, value in vars(errors).items()
        if isinstance(value, type) and issubclass(value, BaseException) and value.__module__ == errors.__name__
    }
    assert set(classes) == defined_exceptions()[errors_module(package)]  # what the sources are read for
    exempt = NOT_ERRORS.get(package, {})
    assert set(exempt) <= set(classes)
    assert sorted(name for name, cls in classes.items() if not issubclass(cls, base) and name not in exempt) == []
    assert all(not issubclass(classes[name], base) for name in exempt)  # the list cannot grow stale


@pytest.mark.parametrize("package", sorted(NO_ERRORS))
def test_a_package_without_errors_defines_no_exception_class(package):
    assert not os.path.exists(errors_module(package))
    defined = {
        os.path.relpath(path, SRC): sorted(classes)
        for path, classes in defined_exceptions().items()
        if classes and path.startswith(os.path.join(SRC, package) + os.sep)
    }
    assert defined == {}
