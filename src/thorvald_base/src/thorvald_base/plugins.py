"""Pluginlib-like loading of kinematics calculators (``base_calculator`` in the robot file).

A catkin package offers calculators by exporting a description file from its package.xml::

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
depend on thorvald_base; see _description_files for why that is not checked here). A name of
the form ``python.module:Class`` is imported directly. Each way loading can fail has its own
error (errors.py), in the style of python-can's interface registry; imports happen only when a
calculator is created.
"""

import importlib
import os
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from typing import Dict, List, Optional

from thorvald_model.errors import ConfigError, Problem

from .errors import PluginDescriptionError, PluginError, PluginImportError, PluginNotFoundError, PluginTypeError
from .kinematics.calculator import BaseCalculator

PACKAGE = "thorvald_base"
EXPORT_ATTRIBUTE = "plugin"


@dataclass(frozen=True)
class PluginDescription:
    """One calculator a package exports."""

    name: str  # e.g. "pltf_clc_std::PltfClcStd"
    type: str  # "python.module:Class"
    description: str
    package: str
    source: str  # the description file


def parse_plugin_file(path: str, package: str = "") -> List[PluginDescription]:
    """The calculators one description file lists; PluginDescriptionError if it is unreadable."""
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as e:
        raise PluginDescriptionError(f"{path}: cannot read the calculator plugin description ({e})") from None
    libraries = [root] if root.tag == "library" else root.findall("library")
    if root.tag not in ("library", "class_libraries"):
        raise PluginDescriptionError(f"{path}: root element must be <library> or <class_libraries>, not <{root.tag}>")
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


class CalculatorLoader:
    """Finds and creates calculator plugins.

    rospack: a rospkg.RosPack (pass one with your own ros_paths in tests); by default one over
    ROS_PACKAGE_PATH (the devel or install space). If thorvald_base itself is not on the package
    path (plain Python use of the source tree), its own description file next to the sources is
    read instead.
    """

    def __init__(self, rospack=None):
        self._rospack = rospack
        self._plugins: Optional[Dict[str, PluginDescription]] = None

    def _rp(self):
        if self._rospack is None:
            import rospkg  # noqa: PLC0415  (rospkg only when the workspace is searched)

            self._rospack = rospkg.RosPack()
        return self._rospack

    def _description_files(self):
        import rospkg  # noqa: PLC0415

        rp = self._rp()
        files = []
        # Every package's exports, not only those of get_depends_on(): rospkg reads the dependencies
        # of a format-2/3 package.xml only through an initialised rosdep, which a fresh machine lacks.
        try:
            rp.get_path(PACKAGE)
        except rospkg.ResourceNotFound:
            # Plain Python use of the source tree, without a ROS environment: our own file.
            own = os.path.normpath(os.path.join(os.path.dirname(__file__), "..", "..", "calculator_plugins.xml"))
            if not os.path.isfile(own):
                raise PluginDescriptionError(
                    "thorvald_base is not on ROS_PACKAGE_PATH, so no calculator plugin can be found: source the "
                    "workspace's devel/setup.bash or install/setup.bash"
                ) from None
            return [(PACKAGE, own)]
        for pkg in sorted(rp.list()):
            try:
                manifest = rp.get_manifest(pkg)
            except (rospkg.ResourceNotFound, rospkg.InvalidManifest):
                continue
            for path in manifest.get_export(PACKAGE, EXPORT_ATTRIBUTE):
                files.append((pkg, path))
        return files

    @property
    def plugins(self) -> Dict[str, PluginDescription]:
        """Every calculator exported in the workspace, by name."""
        if self._plugins is None:
            found: Dict[str, PluginDescription] = {}
            for pkg, path in self._description_files():
                for p in parse_plugin_file(path, pkg):
                    if p.name in found and found[p.name].type != p.type:
                        raise PluginDescriptionError(
                            f"calculator '{p.name}' is exported twice: by {found[p.name].package} "
                            f"({found[p.name].type}) and by {pkg} ({p.type})"
                        )
                    found[p.name] = p
            self._plugins = found
        return self._plugins

    def known_names(self) -> List[str]:
        return sorted(self.plugins)

    def class_for(self, name: str) -> type:
        """The calculator class a name stands for (exported name or ``python.module:Class``)."""
        if "::" in name or ":" not in name:
            plugin = self.plugins.get(name)
            if plugin is None:
                raise PluginNotFoundError(name, self.plugins)
            target = plugin.type
        else:
            target = name
        module_name, _, class_name = target.partition(":")
        try:
            module = importlib.import_module(module_name)
        except ImportError as e:
            raise PluginImportError(f"calculator '{name}': cannot import module '{module_name}': {e}") from None
        cls = getattr(module, class_name, None)
        if cls is None:
            raise PluginImportError(f"calculator '{name}': module '{module_name}' has no class '{class_name}'")
        if not (isinstance(cls, type) and issubclass(cls, BaseCalculator)):
            raise PluginTypeError(
                f"calculator '{name}': {module_name}.{class_name} is not a subclass of "
                f"thorvald_base.kinematics.BaseCalculator"
            )
        return cls

    def create(self, name: str, **options) -> BaseCalculator:
        """A new, uninitialised calculator; options go to its constructor (estimator, seed)."""
        cls = self.class_for(name)
        try:
            return cls(**options)
        except PluginError:
            raise
        except TypeError as e:
            raise PluginTypeError(f"calculator '{name}': cannot construct {cls.__name__}: {e}") from None


def load_calculator(config, rospack=None, **options) -> BaseCalculator:
    """The robot configuration's base_calculator, created and initialised with its drives.

    A layout the calculator declares it cannot serve (its ``layout_rules``) is a ConfigError of
    the robot file, worded as the loader words its own problems (file, key path, value, rule).
    """
    calc = CalculatorLoader(rospack).create(config.base_calculator, **options)
    problems = calc.layout_problems(config.drives, config.passive_wheels)
    if problems:
        raise ConfigError(config.source, problems)
    calc.initialize(config.drives, config.passive_wheels)
    return calc


def calculator_layout_problems(config, rospack=None) -> List[Problem]:
    """The problems of the configuration's layout for its calculator (its own rules, the shared
    ones having passed the loader); an unknown or unloadable calculator is a problem of
    ``base_calculator`` itself."""
    try:
        cls = CalculatorLoader(rospack).class_for(config.base_calculator)
    except PluginError as e:
        return [Problem("base_calculator", config.base_calculator, str(e))]
    return cls.layout_problems(config.drives, config.passive_wheels)
