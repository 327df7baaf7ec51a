"""Gazebo's models and world files found as Gazebo Classic 11, started by gazebo_ros, finds them.

What it reads: the environment (``HOME``, ``GAZEBO_MODEL_PATH``, ``GAZEBO_RESOURCE_PATH``, colon
separated), Gazebo's installed share folder (``/usr/share/gazebo-11``, when there), the ROS packages'
``<export><gazebo_ros gazebo_model_path="..." gazebo_media_path="..."/></export>`` (``${prefix}``: the
package's folder), each model's ``model.config`` and the SDF file it names.

Gazebo's order for ``model://NAME[/rest]`` (``gazebo/common/SystemPaths.cc``, sdformat 9's
``sdf::findFile`` and ``addURIPath``, gazebo_ros's ``gazebo_ros_paths_plugin.cpp`` and scripts): the
first folder, in this order, in which ``NAME/rest`` exists:

1. ``~/.gazebo/models`` (SystemPaths puts it first, before the environment's folders; the model
   database downloads into it);
2. ``GAZEBO_MODEL_PATH``, in order: gazebo_ros's ``gazebo``/``gzserver`` scripts source Gazebo's
   ``setup.sh``, which puts ``/usr/share/gazebo-11/models`` (Gazebo's own ``ground_plane`` and
   ``sun``) in front of the user's folders;
3. the packages' ``gazebo_model_path`` exports (the paths plugin appends them after the environment's).

A folder found must hold a ``model.config`` (or the deprecated ``manifest.xml``): Gazebo takes the
first match and stops, so a bare folder earlier on the path hides a good model later on it. Of the
config's ``<sdf version="...">`` elements the highest version not newer than 1.7 (sdformat 9's,
:data:`.sdf.LATEST`) wins, the first of equals; when none qualifies, the first ``<sdf>``; a config
without ``<sdf>`` is refused (Gazebo does not fall back to ``model.sdf``).

World files and relative resources: an existing path as given, else each resource folder in turn
(``/usr/share/gazebo-11`` from ``setup.sh``, ``GAZEBO_RESOURCE_PATH``, the ``gazebo_media_path``
exports), as ``folder/name`` then ``folder/models/name``, ``folder/media/models/name`` and
``folder/Media/models/name``.

What differs from Gazebo: nothing is downloaded from the model database; ``ground_plane`` and ``sun``
are built in, answered only when no folder has them; a mesh's relative path is looked up in base_dir
(the model file's folder) where Gazebo looks in its working directory; ``package://`` is found with
rospkg; rospack's ``plugins`` reads only the packages that depend on gazebo_ros, in no stated order,
where here every package exporting to gazebo_ros counts, sorted by name; sdformat's own fallbacks
between the environment's folders and the packages' (its install folder, ``SDF_PATH``, the working
directory) are not searched; a missing absolute path is not looked for again under the model folders
(Gazebo's log playback does that).

Pure: no pybullet, no ROS (rospkg is imported only to read the packages, when no reader is given).
"""

import functools
import os
import re
import xml.etree.ElementTree as ET
from typing import Callable, Dict, Iterable, List, Mapping, NamedTuple, Optional, Sequence, Tuple

from ..errors import ModelError
from . import reading
from .reading import MeshFinder
from .sdf import LATEST

GAZEBO_SHARE = "/usr/share/gazebo-11"  # where Gazebo 11 installs its worlds, media and models
RESOURCE_SUFFIXES = ("", "models", "media/models", "Media/models")  # SystemPaths' suffixes of resource folders
MODEL_CONFIGS = ("model.config", "manifest.xml")  # manifest.xml: deprecated, still read by sdformat 9
MODEL_SCHEME = "model://"

GROUND_PLANE_SDF = """<?xml version="1.0"?>
<sdf version="1.5">
  <model name="ground_plane">
    <static>true</static>
    <link name="link">
      <collision name="collision">
        <geometry>
          <plane>
            <normal>0 0 1</normal>
            <size>100 100</size>
          </plane>
        </geometry>
        <surface>
          <contact>
            <collide_bitmask>0xffff</collide_bitmask>
          </contact>
          <friction>
            <ode>
              <mu>100</mu>
              <mu2>50</mu2>
            </ode>
          </friction>
        </surface>
      </collision>
      <visual name="visual">
        <cast_shadows>false</cast_shadows>
        <geometry>
          <plane>
            <normal>0 0 1</normal>
            <size>100 100</size>
          </plane>
        </geometry>
        <material>
          <script>
            <uri>file://media/materials/scripts/gazebo.material</uri>
            <name>Gazebo/Grey</name>
          </script>
        </material>
      </visual>
    </link>
  </model>
</sdf>
"""

SUN_SDF = """<?xml version="1.0"?>
<sdf version="1.5">
  <light type="directional" name="sun">
    <cast_shadows>true</cast_shadows>
    <pose>0 0 10 0 0 0</pose>
    <diffuse>0.8 0.8 0.8 1</diffuse>
    <specular>0.2 0.2 0.2 1</specular>
    <attenuation>
      <range>1000</range>
      <constant>0.9</constant>
      <linear>0.01</linear>
      <quadratic>0.001</quadratic>
    </attenuation>
    <direction>-0.5 0.1 -0.9</direction>
  </light>
</sdf>
"""

BUILT_IN: Dict[str, str] = {"ground_plane": GROUND_PLANE_SDF, "sun": SUN_SDF}
"""The models Gazebo installs with itself (``/usr/share/gazebo-11/models``): sun is a ``<light>``."""

INCLUDED_KINDS = ("model", "actor", "light")  # what sdformat 9 accepts as an <include>d file's top element


class PackageExport(NamedTuple):
    """One ``<gazebo_ros .../>`` export of a ROS package: its attributes as written (``${prefix}`` in them)."""

    package: str
    folder: str  # the package's folder, which ${prefix} stands for
    attributes: Mapping[str, str]


ExportsReader = Callable[[], Iterable[PackageExport]]


class Folder(NamedTuple):
    """A folder searched, and why it is on the path."""

    path: str
    origin: str  # "GAZEBO_MODEL_PATH", "gazebo_model_path of package farm_worlds", ...


def ros_package_exports() -> List[PackageExport]:
    """Every ROS package's exports to gazebo_ros, read with rospkg, sorted by package name (a package
    whose manifest cannot be read exports nothing, as rospack skips it)."""
    import rospkg  # noqa: PLC0415  (only when no reader of the exports is given)

    pack = rospkg.RosPack()
    found = []
    for name in sorted(pack.list()):
        try:
            folder = pack.get_path(name)
            exports = pack.get_manifest(name).exports
        except Exception:  # rospkg's, catkin_pkg's and the file system's errors alike
            continue
        found.extend(PackageExport(name, folder, dict(e.attrs)) for e in exports if e.tag == "gazebo_ros")
    return found


def included_kind(sdf_text: str) -> Optional[str]:
    """What an ``<include>`` of this SDF text adds, as sdformat 9 reads it: ``"model"``, ``"actor"`` or
    ``"light"`` (the built-in sun), None when it has none of them (or is not XML)."""
    try:
        root = reading.read_xml(sdf_text, "included")
    except ModelError:
        return None
    if root.tag in INCLUDED_KINDS:
        return root.tag
    if root.tag != "sdf":
        return None
    for kind in INCLUDED_KINDS:
        if root.find(kind) is not None:
            return kind
    return None


def sdf_version(text: Optional[str]) -> Optional[Tuple[int, int, int]]:
    """A model.config ``<sdf version>`` as a semantic version (major, minor, patch); None when unreadable."""
    match = re.match(r"\s*(\d+)(?:\.(\d+))?(?:\.(\d+))?", text or "")
    if not match:
        return None
    return (int(match.group(1)), int(match.group(2) or 0), int(match.group(3) or 0))


def choose_sdf(config: ET.Element) -> Optional[ET.Element]:
    """The ``<sdf>`` element of a model.config's ``<model>`` Gazebo reads: the highest version not newer
    than 1.7 (the first of equals), else the first ``<sdf>``; None when it has none."""
    elements = config.findall("sdf")
    newest = (LATEST[0], LATEST[1], 0)
    best: Optional[ET.Element] = None
    best_version = (0, 0, 0)
    for element in elements:
        version = sdf_version(element.get("version"))
        if version is not None and best_version < version <= newest:
            best, best_version = element, version
    if best is not None:
        return best
    return elements[0] if elements else None


def _read_text(path: str) -> Tuple[Optional[str], str]:
    """A file's text (UTF-8, at most reading.MAX_XML_CHARS characters) or why not."""
    try:
        with open(path, encoding="utf-8") as f:
            text = f.read(reading.MAX_XML_CHARS + 1)
    except OSError as e:
        return None, f"{path} cannot be read: {e.strerror or e}"
    except UnicodeDecodeError:
        return None, f"{path} is not UTF-8 text"
    if len(text) > reading.MAX_XML_CHARS:
        return None, f"{path} has more than {reading.MAX_XML_CHARS} characters"
    return text, ""


def _split(path_list: Optional[str]) -> List[str]:
    return [p for p in (path_list or "").split(":") if p]


class GazeboPaths:
    """Gazebo's model and resource folders of one environment, and the lookups of model://, file://,
    package:// URIs and world names in them; every answer is (found or None, why not)."""

    def __init__(
        self,
        environ: Optional[Mapping[str, str]] = None,
        exports: Optional[ExportsReader] = None,
        gazebo_share: Optional[str] = GAZEBO_SHARE,
        package_folder: Optional[Callable[[str], Optional[str]]] = None,
    ) -> None:
        """environ: the environment (default os.environ, read now); exports: the packages' exports to
        gazebo_ros (default :func:`ros_package_exports`); gazebo_share: Gazebo's installed share folder,
        used when it is a folder (None: no Gazebo); package_folder: a ROS package's folder, for
        package:// (default :func:`thorvald_sim.physics.description.installed_package_path`)."""
        env = dict(os.environ if environ is None else environ)
        self.problems: List[str] = []
        if package_folder is None:
            from ..physics.description import installed_package_path as package_folder  # noqa: PLC0415
        self._package_folder = package_folder
        models: List[Folder] = []
        resources: List[Folder] = []
        home = env.get("HOME")
        if home and os.path.isdir(os.path.join(home, ".gazebo", "models")):
            models.append(Folder(os.path.join(home, ".gazebo", "models"), "~/.gazebo/models"))
        if gazebo_share and os.path.isdir(gazebo_share):
            resources.append(Folder(gazebo_share, "Gazebo's own"))
            if os.path.isdir(os.path.join(gazebo_share, "models")):
                models.append(Folder(os.path.join(gazebo_share, "models"), "Gazebo's own"))
        models += [Folder(p, "GAZEBO_MODEL_PATH") for p in _split(env.get("GAZEBO_MODEL_PATH"))]
        resources += [Folder(p, "GAZEBO_RESOURCE_PATH") for p in _split(env.get("GAZEBO_RESOURCE_PATH"))]
        for export in self._exports(exports or ros_package_exports):
            for attribute, folders in (("gazebo_model_path", models), ("gazebo_media_path", resources)):
                value = export.attributes.get(attribute)
                if isinstance(value, str) and value:
                    value = value.replace("${prefix}", export.folder)
                    folders += [Folder(p, f"{attribute} of package {export.package}") for p in _split(value)]
        self.model_folders: Tuple[Folder, ...] = _unique(models)
        self.resource_folders: Tuple[Folder, ...] = _unique(resources)

    def _exports(self, reader: ExportsReader) -> List[PackageExport]:
        try:
            return [PackageExport(*e) for e in reader()]
        except ImportError:
            self.problems.append("the packages' gazebo_ros exports are not read: rospkg is not installed")
        except Exception as e:  # any failure of the reader leaves the environment's folders
            self.problems.append(f"the packages' gazebo_ros exports could not be read: {e}")
        return []

    # ---- what is searched -------------------------------------------------------------------------
    def searched(self) -> str:
        """Every folder searched, in order: the model folders, then the resource folders."""
        return (
            f"model folders: {_listing(self.model_folders) or 'none'}; "
            f"resource folders: {_listing(self.resource_folders) or 'none'}" + self._problems()
        )

    def _problems(self) -> str:
        return "".join(f"; {p}" for p in self.problems)

    def _not_found(self, what: str, folders: Sequence[Folder], kind: str) -> str:
        if not folders:
            where = {
                "model": "GAZEBO_MODEL_PATH is not set, there is no ~/.gazebo/models and no package exports "
                "gazebo_model_path",
                "resource": "GAZEBO_RESOURCE_PATH is not set and no package exports gazebo_media_path",
            }.get(kind, "")
            return f"{what} not found: no {kind} folders ({where})" + self._problems()
        return f"{what} not found in: {_listing(folders)}" + self._problems()

    # ---- models -----------------------------------------------------------------------------------
    def _model_suffix(self, uri: str) -> Tuple[Optional[str], Optional[str], str]:
        """(NAME, NAME[/rest]) of a model:// URI, or why it names no model."""
        uri = (uri or "").strip()
        if not uri.startswith(MODEL_SCHEME):
            return None, None, f"{uri!r} is not a model:// URI"
        suffix = uri[len(MODEL_SCHEME) :]
        name = suffix.split("/", 1)[0]
        if name in ("", ".", ".."):
            return None, None, f"{uri!r} names no model (model://NAME)"
        return name, suffix, ""

    def _first(self, folders: Sequence[Folder], suffix: str) -> Optional[Tuple[str, Folder]]:
        for folder in folders:
            path = os.path.join(folder.path, suffix)
            if os.path.exists(path):
                return path, folder
        return None

    def find_model(self, uri: str) -> Tuple[Optional[str], str]:
        """The folder model://NAME[/rest] names: NAME[/rest] in the first model folder that has it, as
        Gazebo finds an ``<include>``; None and why (the URI and every folder searched) otherwise."""
        name, suffix, why = self._model_suffix(uri)
        if suffix is None:
            return None, why
        uri = uri.strip()
        found = self._first(self.model_folders, suffix)
        if found is None:
            why = self._not_found(uri, self.model_folders, "model")
            if suffix.rstrip("/") in BUILT_IN:
                why += f" (model://{name} is built in: its SDF is read without a folder)"
            return None, why
        path, folder = found
        if not os.path.isdir(path):
            return None, f"{uri}: {path} ({folder.origin}) is not a folder, and Gazebo takes the first match"
        return path, ""

    def model_sdf(self, uri: str) -> Tuple[Optional[Tuple[str, str]], str]:
        """The SDF text of the model model://NAME names and its file, chosen by its model.config as
        Gazebo chooses it (the built-in ground_plane and sun when no folder has them); None and why
        otherwise. An ``IncludeLoader`` of :mod:`.sdf`."""
        folder, why = self.find_model(uri)
        if folder is None:
            _, suffix, _ = self._model_suffix(uri)
            name = (suffix or "").rstrip("/")
            if name in BUILT_IN and self._first(self.model_folders, suffix or "") is None:
                return (BUILT_IN[name], f"model://{name}/model.sdf (built in)"), ""
            return None, why
        uri = uri.strip()
        configs = [os.path.join(folder, c) for c in MODEL_CONFIGS if os.path.isfile(os.path.join(folder, c))]
        if not configs:
            has_sdf = os.path.exists(os.path.join(folder, "model.sdf"))
            hint = " (it has a model.sdf: a model.config must name it)" if has_sdf else ""
            return None, f"{uri}: {folder} has no model.config, which Gazebo needs to include a model{hint}"
        config_path = configs[0]
        text, why = _read_text(config_path)
        if text is None:
            return None, f"{uri}: {why}"
        try:
            root = reading.read_xml(text, config_path)
        except ModelError as e:
            return None, f"{uri}: {e}"
        if root.tag != "model":
            return None, f"{uri}: {config_path} has <{root.tag}>, not <model>, at its top"
        chosen = choose_sdf(root)
        file_name = (chosen.text or "").strip() if chosen is not None else ""
        if not file_name:
            return None, f"{uri}: {config_path} names no SDF file (<sdf version=...>model.sdf</sdf>)"
        sdf_path = os.path.join(folder, file_name)
        if not os.path.isfile(sdf_path):
            return None, f"{uri}: {config_path} names {file_name}, and there is no such file in {folder}"
        text, why = _read_text(sdf_path)
        if text is None:
            return None, f"{uri}: {why}"
        return (text, sdf_path), ""

    # ---- files ------------------------------------------------------------------------------------
    def find_file(self, uri: str, base_dir: Optional[str] = None) -> Tuple[Optional[str], str]:
        """A mesh's (or any resource's) file: model://NAME/path in the model folders (the first that
        has it), package://PKG/path (rospkg), file:// and absolute paths, a relative path in base_dir
        then the resource folders. A :data:`.reading.MeshFinder` (with base_dir: :meth:`finder`)."""
        uri = (uri or "").strip()
        if not uri:
            return None, "an empty URI names no file"
        if uri.startswith(MODEL_SCHEME):
            _, suffix, why = self._model_suffix(uri)
            if suffix is None:
                return None, why
            found = self._first(self.model_folders, suffix)
            if found is None:
                return None, self._not_found(uri, self.model_folders, "model")
            path, folder = found
            if not os.path.isfile(path):
                return None, f"{uri}: {path} ({folder.origin}) is not a file"
            return path, ""
        if uri.startswith("package://"):
            package, _, rest = uri[len("package://") :].partition("/")
            folder = self._package_folder(package) if package else None
            if folder is None:
                return None, f"{uri}: package {package!r} is not installed"
            path = os.path.join(folder, rest)
            return (path, "") if os.path.isfile(path) else (None, f"{uri}: package {package} has no {rest}")
        path = uri[len("file://") :] if uri.startswith("file://") else uri
        if "://" in path:
            return None, f"{uri}: only model://, package://, file:// URIs and paths are read here"
        if os.path.isabs(path):
            return (path, "") if os.path.isfile(path) else (None, f"{uri}: no such file")
        if base_dir is not None and os.path.isfile(os.path.join(base_dir, path)):
            return os.path.join(base_dir, path), ""
        found = self._resource(path)
        if found is not None:
            return found, ""
        folders = ([Folder(base_dir, "the model's folder")] if base_dir is not None else []) + list(
            self.resource_folders
        )
        return None, self._not_found(uri, folders, "resource")

    def finder(self, base_dir: Optional[str] = None) -> MeshFinder:
        """:meth:`find_file` with base_dir: a MeshFinder for the models of one file."""
        return lambda uri: self.find_file(uri, base_dir)

    def _resource(self, name: str) -> Optional[str]:
        for folder in self.resource_folders:
            for suffix in RESOURCE_SUFFIXES:
                path = os.path.join(folder.path, suffix, name)
                if os.path.isfile(path):
                    return path
        return None

    def find_world(self, name: str) -> Tuple[Optional[str], str]:
        """The world file a ``world_name`` (gazebo_ros's empty_world.launch) names: an existing path as
        it is, else name in each resource folder (``worlds/empty.world``: ``<folder>/worlds/empty.world``)."""
        name = (name or "").strip()
        if not name:
            return None, "an empty world_name names no world"
        if name.startswith(MODEL_SCHEME):
            return self.find_file(name)
        path = name[len("file://") :] if name.startswith("file://") else name
        if "://" in path:
            return None, f"{name}: a world is a file path (or file://), not another URI"
        if os.path.isfile(path):
            return path, ""
        if os.path.isdir(path):
            return None, f"{name}: a folder, not a world file"
        if os.path.isabs(path):
            return None, f"{name}: no such file"
        found = self._resource(path)
        if found is not None:
            return found, ""
        return None, self._not_found(f"world {name}", self.resource_folders, "resource")


# the environment variables a GazeboPaths reads (rospkg reads ROS_PACKAGE_PATH for the exports)
ENVIRONMENT = ("HOME", "GAZEBO_MODEL_PATH", "GAZEBO_RESOURCE_PATH", "ROS_PACKAGE_PATH")


def gazebo_paths() -> GazeboPaths:
    """This process's Gazebo paths (its environment and the ROS packages' exports), read once for as
    long as the environment stays the same: the world's loader, its name's lookup and the Gazebo API
    share them (reading the packages' exports costs about 0.3 s)."""
    return _paths_for(tuple(os.environ.get(name) for name in ENVIRONMENT))


@functools.lru_cache(maxsize=4)
def _paths_for(_environment: Tuple[Optional[str], ...]) -> GazeboPaths:
    return GazeboPaths()


def _unique(folders: Sequence[Folder]) -> Tuple[Folder, ...]:
    """Each folder once, where it first comes (SystemPaths' InsertUnique)."""
    seen = set()
    kept = []
    for folder in folders:
        if folder.path not in seen:
            seen.add(folder.path)
            kept.append(folder)
    return tuple(kept)


def _listing(folders: Sequence[Folder]) -> str:
    """``/a, /b (GAZEBO_MODEL_PATH), /c (gazebo_model_path of package farm)``: runs of one origin
    together, a folder that does not exist marked so."""
    runs: List[Tuple[str, List[str]]] = []
    for folder in folders:
        shown = folder.path if os.path.isdir(folder.path) else f"{folder.path} [no such folder]"
        if runs and runs[-1][0] == folder.origin:
            runs[-1][1].append(shown)
        else:
            runs.append((folder.origin, [shown]))
    return ", ".join(f"{', '.join(paths)} ({origin})" for origin, paths in runs)
