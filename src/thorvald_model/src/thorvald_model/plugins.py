"""Pluginlib-like plugins the robot file names: finding the packages' exports, loading a class by name.

The robot file names its kinematics calculator (``base_calculator: "pltf_clc_std::PltfClcStd"``),
so turning that name into a class is the configuration's business and lives here, beside the
loader that reads the name. There is one mechanism: base_driver loads its calculator through it
(thorvald_base.plugins configures it for calculators and creates the calculator), and check_config
loads the robot's calculator class through it and applies the calculator's own layout rules
(:func:`calculator_problems`), so a file base_driver refuses, check_config refuses, with the same
words.

This package sits below thorvald_base (which depends on it), so it knows the calculators' package
by name only (:data:`CALCULATORS`: strings). thorvald_base is imported dynamically, when a plugin
is loaded, as pluginlib loads the library a plugin names; no module of this package imports it (a
unit test checks the source and a clean interpreter). A calculator that cannot be loaded (unknown
name, a module that fails to import, a class of the wrong kind, thorvald_base missing) is a
problem of the file: key path ``base_calculator``, the value, the rule. It is never passed over
for want of the calculators' package: base_driver could not run such a file either.

Plugins are exported as pluginlib's are: a catkin package offers calculators by exporting a
description file from its package.xml::

    <export>
      <thorvald_base plugin="${prefix}/calculator_plugins.xml"/>
    </export>

and depending on thorvald_base. The file maps class names to Python classes::

    <library>
      <class name="my_pkg::MyCalc" type="my_pkg.calc:MyCalc" base_class_type="thorvald_base::BaseCalculator">
        <description>What it serves.</description>
      </class>
    </library>

(several ``<library>`` elements may sit in a ``<class_libraries>`` root). The loader finds the
exports of every package on the package path through rospkg, like
``rospack plugins --attrib=plugin thorvald_base`` (which also requires the exporting package to
depend on thorvald_base; see PluginLoader._description_files for why that is not checked here). A
name of the form ``python.module:Class`` is imported directly. A loaded class must derive from the
kind's base class (``BaseCalculator``). Each way loading can fail has its own error (errors.py,
in the style of python-can's interface registry): an unknown name lists the known ones, an import
error names the module and the class. Imports happen only when a class is asked for.
"""

import importlib
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Dict, List, Optional, Tuple

from .errors import (
    PluginDescriptionError,
    PluginError,
    PluginImportError,
    PluginNotFoundError,
    PluginTypeError,
    Problem,
)


@dataclass(frozen=True)
class PluginKind:
    """A family of plugins: where packages export them, what they derive from, and their words."""

    export: str  # the package whose name tags the export in package.xml: <thorvald_base plugin="..."/>
    base_class: str  # "python.module:Class" every plugin derives from, imported when a plugin is loaded
    key: str  # the robot file's key that names one
    what: str  # one plugin, in words
    attribute: str = "plugin"  # the export's attribute holding the description file
    # The exporting package's own description file (relative to its package folder), read when the
    # package is importable but not on the package path: plain Python use of a catkin source tree.
    own_description: str = ""


_WORKSPACE_EXPORTS: Dict[Tuple[str, str, str], List[Tuple[str, str]]] = {}  # PluginLoader._description_files

CALCULATORS = PluginKind(
    export="thorvald_base",
    base_class="thorvald_base.kinematics:BaseCalculator",
    key="base_calculator",
    what="calculator",
    own_description="calculator_plugins.xml",
)
"""The kinematics calculators (``base_calculator``): thorvald_base's, and any package's exporting them."""


@dataclass(frozen=True)
class PluginDescription:
    """One plugin a package exports."""

    name: str  # e.g. "pltf_clc_std::PltfClcStd"
    type: str  # "python.module:Class"
    description: str
    package: str
    source: str  # the description file


def parse_plugin_file(path: str, package: str = "") -> List[PluginDescription]:
    """The plugins one description file lists; PluginDescriptionError if it is unreadable."""
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as e:
        raise PluginDescriptionError(f"{path}: cannot read the plugin description ({e})") from None
    if root.tag not in ("library", "class_libraries"):
        raise PluginDescriptionError(f"{path}: root element must be <library> or <class_libraries>, not <{root.tag}>")
    libraries = [root] if root.tag == "library" else root.findall("library")
    out = []
    for lib in libraries:
        for cls in lib.findall("class"):
            name = cls.get("name")
            type_ = cls.get("type")
            if not name or not type_ or ":" not in type_:
                raise PluginDescriptionError(
                    f'{path}: each <class> needs name="ns::Class" and type="python.module:Class" (got name={name!r}, '
                    f"type={type_!r})"
                )
            desc = (cls.findtext("description") or "").strip()
            out.append(PluginDescription(name, type_, desc, package, path))
    return out


def _import_class(target: str) -> Tuple[str, str, object]:
    """(module name, class name, the module's attribute or None) of ``python.module:Class``;
    PluginImportError (rule only: the caller names the plugin) if the module cannot be imported."""
    module_name, _, class_name = target.partition(":")
    if not module_name or not class_name:
        rule = f"'{target}' is not of the form 'python.module:Class'"
        raise PluginImportError(rule, rule)
    try:
        module = importlib.import_module(module_name)
    except Exception as e:  # a plugin's module can fail any way: missing, a syntax error, an error it raises
        reason = str(e) if isinstance(e, ImportError) else f"{type(e).__name__}: {e}"
        rule = f"cannot import module '{module_name}': {reason}"
        raise PluginImportError(rule, rule) from None
    return module_name, class_name, getattr(module, class_name, None)


class PluginLoader:
    """Finds and loads the plugins of one kind.

    rospack: a rospkg.RosPack (pass one with your own ros_paths in tests); by default one over
    ROS_PACKAGE_PATH (the devel or install space). If the exporting package itself is not on the
    package path (plain Python use of the source tree), its own description file is read instead.
    """

    def __init__(self, kind: PluginKind, rospack=None):
        self.kind = kind
        self._rospack = rospack
        self._plugins: Optional[Dict[str, PluginDescription]] = None

    def _rp(self):
        if self._rospack is None:
            import rospkg  # noqa: PLC0415  (rospkg only when the workspace is searched)

            self._rospack = rospkg.RosPack()
        return self._rospack

    def _own_description(self) -> Optional[str]:
        """The exporting package's own description file in a catkin source tree (its Python package in
        <package>/src/<name>/). The package is imported for its path (its top module only; a plugin of
        it would import it anyway): in a devel space, catkin's __init__.py adds the source folder."""
        if not self.kind.own_description:
            return None
        try:
            folders = list(importlib.import_module(self.kind.export).__path__)
        except Exception:  # not importable (or not a package): there is no own file to read
            return None
        for folder in folders:
            path = os.path.normpath(os.path.join(folder, "..", "..", self.kind.own_description))
            if os.path.isfile(path):
                return path
        return None

    def _description_files(self) -> List[Tuple[str, str]]:
        """(package, description file) of every export of this kind. The workspace's (no rospack
        given) is searched once per process and ROS_PACKAGE_PATH: reading every package's manifest
        takes about 90 ms, which a design study's runs paid at every robot they spawned."""
        if self._rospack is not None:
            return self._search()
        key = (self.kind.export, self.kind.attribute, os.environ.get("ROS_PACKAGE_PATH", ""))
        if key not in _WORKSPACE_EXPORTS:
            _WORKSPACE_EXPORTS[key] = self._search()
        return list(_WORKSPACE_EXPORTS[key])

    def _search(self) -> List[Tuple[str, str]]:
        import rospkg  # noqa: PLC0415

        rp = self._rp()
        try:
            rp.get_path(self.kind.export)
        except rospkg.ResourceNotFound:
            own = self._own_description()
            if own is None:
                raise PluginDescriptionError(
                    f"{self.kind.export} is not on ROS_PACKAGE_PATH, so no {self.kind.what} plugin can be found: "
                    "source the workspace's devel/setup.bash or install/setup.bash"
                ) from None
            return [(self.kind.export, own)]
        # Every package's exports, not only those of get_depends_on(): rospkg reads the dependencies
        # of a format-2/3 package.xml only through an initialised rosdep, which a fresh machine lacks.
        files = []
        for pkg in sorted(rp.list()):
            try:
                manifest = rp.get_manifest(pkg)
            except (rospkg.ResourceNotFound, rospkg.InvalidManifest):
                continue
            for path in manifest.get_export(self.kind.export, self.kind.attribute):
                files.append((pkg, path))
        return files

    @property
    def plugins(self) -> Dict[str, PluginDescription]:
        """Every plugin of this kind exported in the workspace, by name."""
        if self._plugins is None:
            found: Dict[str, PluginDescription] = {}
            for pkg, path in self._description_files():
                for p in parse_plugin_file(path, pkg):
                    if p.name in found and found[p.name].type != p.type:
                        raise PluginDescriptionError(
                            f"{self.kind.what} '{p.name}' is exported twice: by {found[p.name].package} "
                            f"({found[p.name].type}) and by {pkg} ({p.type})"
                        )
                    found[p.name] = p
            self._plugins = found
        return self._plugins

    def known_names(self) -> List[str]:
        return sorted(self.plugins)

    def _not_found(self, name: str) -> PluginNotFoundError:
        kind = self.kind
        known = self.known_names()
        listed = ", ".join(known) if known else f"none (no package exports {kind.export} plugins)"
        known_text = f"known {kind.what}s are {listed} (or give a 'python.module:Class')"
        return PluginNotFoundError(
            f"unknown {kind.key} '{name}': {known_text}", f"must name a {kind.what} plugin: {known_text}", name, known
        )

    def class_for(self, name: str) -> type:
        """The class a name stands for (an exported name or ``python.module:Class``), checked to
        derive from the kind's base class."""
        what = self.kind.what
        if "::" in name or ":" not in name:
            plugin = self.plugins.get(name)
            if plugin is None:
                raise self._not_found(name)
            target, via = plugin.type, f" (exported by {plugin.package} as '{plugin.type}')"
        else:
            target, via = name, ""

        def fail(error_type, rule):
            return error_type(f"{what} '{name}': {rule}", rule)

        try:
            module_name, class_name, cls = _import_class(target)
        except PluginImportError as e:
            raise fail(PluginImportError, e.rule + via) from None
        if cls is None:
            raise fail(PluginImportError, f"module '{module_name}' has no class '{class_name}'{via}")
        try:
            base_module, base_name, base = _import_class(self.kind.base_class)
        except PluginImportError as e:
            raise fail(PluginImportError, f"{e.rule} (the module of every {what}'s base class)") from None
        if not (isinstance(cls, type) and isinstance(base, type) and issubclass(cls, base)):
            raise fail(PluginTypeError, f"{module_name}.{class_name} is not a subclass of {base_module}.{base_name}")
        return cls

    def create(self, name: str, **options):
        """A new instance of the plugin; options go to its constructor."""
        cls = self.class_for(name)
        try:
            return cls(**options)
        except PluginError:
            raise
        except TypeError as e:
            rule = f"cannot construct {cls.__name__}: {e}"
            raise PluginTypeError(f"{self.kind.what} '{name}': {rule}", rule) from None


def calculator_loader(rospack=None) -> PluginLoader:
    """The loader of kinematics calculators (``base_calculator``)."""
    return PluginLoader(CALCULATORS, rospack)


def calculator_problems(config, loader: Optional[PluginLoader] = None) -> List[Problem]:
    """The problems of the robot's layout for its calculator: the calculator's class, loaded by name
    as base_driver loads it, applies the rules every calculator shares and then its own (its
    ``layout_problems``). A calculator that cannot be loaded is one problem of ``base_calculator``."""
    loader = loader if loader is not None else calculator_loader()
    try:
        cls = loader.class_for(config.base_calculator)
    except PluginError as e:
        return [Problem(loader.kind.key, config.base_calculator, e.rule)]
    return list(cls.layout_problems(config.drives, config.passive_wheels))
