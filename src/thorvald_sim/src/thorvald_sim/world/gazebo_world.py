"""A Gazebo Classic world file (``<sdf version="1.4">`` to ``1.7`` with one ``<world>``) read as it is,
into a :class:`GazeboWorld`: a frozen value of what the simulator needs to build the world (the
physics' step and rates, gravity, the GNSS datum, every model with its pose, the actors and their
scripts, the height field), nothing built. Pure: no pybullet, no rospy (numpy and PIL for a heightmap
only, imported when one is read).

:func:`read_gazebo_world` reads it; :func:`is_gazebo_world` tells such a file from our YAML worlds by
its first bytes. Models are read by :func:`thorvald_sim.models.sdf.parse_sdf_model`, found through
:class:`thorvald_sim.models.gazebo_paths.GazeboPaths`; a heightmap becomes our height field's keys
through :func:`thorvald_sim.world.gazebo_heightmap.as_height_field` (the loader makes the field:
:func:`thorvald_sim.world.loader.gazebo_world_config`); actors are :mod:`~thorvald_sim.world.gazebo_actors`'
and populations' places :mod:`~thorvald_sim.world.gazebo_population`'s.

What Gazebo 11 does, and what is done here (files named are gazebo-classic's, the gazebo11 branch,
unless another project is named: sdformat 9, ignition-math 6)
----------------------------------------------------------------------------------------------------
1. The file: ``gzserver`` reads it with ``sdf::readFile`` (``gazebo/Server.cc`` ``LoadFile``): the root
   must be ``<sdf>``; a file of SDF 1.4 to 1.6 is converted up (sdformat's ``1_5.convert``,
   ``1_6.convert``, ``1_7.convert``). Read here: 1.4 to 1.7 (a newer version is read as 1.7, as
   :mod:`~thorvald_sim.models.sdf` does), one ``<world>``.
2. Physics (``gazebo/physics/World.cc`` ``Load``, sdformat ``sdf/1.6/physics.sdf``): the ``<physics>``
   marked ``default="true"`` (the first such), else the first; ``max_step_size`` (0.001 s),
   ``real_time_update_rate`` (1000 Hz, 0: as fast as possible) and ``real_time_factor`` (1). Gravity
   is the world's ``<gravity>`` from SDF 1.5 on (default ``0 0 -9.8``); SDF 1.4 has it in ``<physics>``
   (``1_5.convert`` moves it out), and a ``<gravity>`` in the other place is not read (noted).
3. ``<spherical_coordinates>`` (``World.cc`` ``Load``; ``gazebo/common/SphericalCoordinates.cc``):
   ``surface_model`` (EARTH_WGS84, the only one: another is logged and WGS84 used), ``latitude_deg``,
   ``longitude_deg``, ``elevation``, ``heading_deg`` (all 0 by default). Gazebo 11 converts its world
   frame to east-north-up with ``east = -x cos h - y sin h``, ``north = x sin h - y cos h``
   (``PositionTransform``, case LOCAL, heading negated in ``UpdateTransformationMatrix``): the world's
   x axis points at an ENU yaw of ``pi - h``, so with ``heading_deg`` 0 it points west. That is the
   180 degree error ignition-math kept for compatibility (its later ``LOCAL2`` frame fixes it); the
   :class:`~thorvald_model.datum.Datum` here is what Gazebo 11's own GPS sensor uses, ``yaw = pi - h``
   (its documented meaning, sdformat's ``heading_deg``, would be ``-h``). ``world_frame_orientation``
   is not read by Gazebo 11 (noted when it is not ENU).
4. Models (``World.cc`` ``LoadEntities``, ``LoadModel``): every ``<model>`` and every ``<include>``
   (sdformat expands it where it is: ``<uri>``, and ``<name>``, ``<pose>``, ``<static>`` replacing the
   model's own) in file order. A second model of a name that is taken is not inserted: Gazebo 11 logs
   "Model with name [x] already exists. Not inserting model." and keeps the first (``LoadModel``;
   ``Server.cc`` also prints sdformat's "Non-unique names detected" and "SDF is not valid"); so
   here, with a note. ``model://sun`` is a ``<light>`` (skipped without a note); ``model://ground_plane``
   is a static plane model like any other (both built in when no model folder has them).
5. ``<population>`` (``gazebo/physics/Population.cc``, run by ``World::Init`` after the models): one
   ``<model>`` (an ``<include>`` is expanded into one by sdformat), a ``<pose>``, a ``<distribution>``
   of ``type`` random (default), uniform, grid, linear-x, linear-y or linear-z, and for all but grid
   a ``model_count`` (default 1) and a region, ``<box><size>`` or ``<cylinder><radius><length>``.
   Each instance is named ``NAME_clone_I`` (I from 0, NAME the model's name) and placed at a position
   only (its orientation is identity: the ``<pose>`` Gazebo inserts comes before the model's own,
   which is therefore not used). Positions: ``R o + p`` (``(offset + pose).Pos()``, R and p the
   population pose's rotation and position) where, for a box region, p is first moved by minus half
   the box in world axes; random: o uniform in the box, or in a cylinder as angle and radius each
   uniform (so denser at the axis) and height uniform in [0, length); grid: rows along y and columns
   along x, ``step`` apart, p first moved so the grid is centred (row i, column j is clone
   ``i cols + j``); linear-x: o.x = size.x i / count (the last one short of the far side), o.y and o.z
   at half the box; uniform: the centroids of ignition-math's k-means (``Kmeans.cc``: the first
   ``count`` observations as initial centroids, repeated until at most n/1024 labels change) of
   observations every 0.1 m over the box's x and y (or 10 000 random points in the cylinder) at a
   random height. Gazebo ignores a population (``gzerr``/``gzwarn``, "Population ignored") that lacks
   ``<pose>``, ``<distribution>``, ``rows``, ``cols`` or ``step`` of a grid, or a region, or has a count
   or size not above 0, or a linear distribution in a cylinder; refused here instead, each problem
   named, as a world that silently lacks its crop is not what its author wrote. Gazebo's random
   places are drawn anew each run (ignition-math's generator, seeded per run unless ``gzserver
   --seed``); here they are drawn from a generator seeded by ``seed`` and the population's place in
   the file, so a world loads the same every time. The instances are counted (``rows cols`` or
   ``model_count``) against :attr:`Limits.bodies` before one is made: a population of 10^7 is refused
   in constant memory.
6. ``<actor>`` (``gazebo/physics/Actor.cc``; ``gazebo/common/Animation.cc``; ignition-math
   ``Spline.cc``, ``RotationSpline.cc``, ``Quaternion.hh``): a ``<skin>`` (a COLLADA mesh found as any
   resource; without it the actor still follows its script), and a ``<script>`` (``loop`` true,
   ``delay_start`` 0, ``auto_start`` true) of ``<trajectory id type>`` s played one after the other in
   order of id, each of ``<waypoint><time><pose>`` s (in the world frame, one per time: a later one of
   the same time replaces the earlier; the first is moved to time 0; the trajectory lasts until its
   last waypoint's time). Between waypoints a trajectory is *not* linear: the position follows
   ignition-math's cubic Hermite spline with Catmull-Rom tangents (half the difference of the
   neighbouring waypoints, at an end of the one segment; an end equal to the other closes the loop),
   the parameter being the fraction of the time between the two waypoints, and the orientation
   follows squad with Shoemake's tangents, the shortest way. Timing (``Actor::Update``): the script
   time is ``t - delay_start``; before 0 the actor stays at its own ``<pose>``; past the end it stays
   at the last pose, or with ``loop`` starts again after waiting ``delay_start`` again at the first
   waypoint. :meth:`Actor.pose_at` gives that pose for the sim time t, continuously (Gazebo moves an
   actor at most every 1/30 s of sim time), as Gazebo sets it for an actor without a skin (a skin's
   root bone adds its animation's offset). Its body here is a person-sized cylinder
   (:data:`~thorvald_sim.world.gazebo_actors.PERSON`); whether its skin was found is recorded.
7. Heightmaps (``gazebo/physics/HeightmapShape.cc``; the convention of
   :mod:`~thorvald_sim.world.gazebo_heightmap`): a ``<collision>`` of ``<heightmap>`` geometry, in a
   ``<model>`` of the world or in an included model file (its image found from that file's folder,
   then Gazebo's), becomes the world's height field (one; a second is refused): its differences from
   Gazebo's are noted; ODE's field is not moved by the model's, link's and collision's translation,
   so neither is this one (noted); a rotated one is refused. Its ``<visual>`` s go with it; a
   heightmap in visuals only is drawn by Gazebo and collides with nothing: ignored, noted. A model
   left without a collision or visual is the height field only. The image's pixels (from its header)
   and bytes are held to :attr:`Limits.field_points` and :attr:`Limits.image_bytes` before it is
   decoded.
8. Elements that mean nothing to this simulator (lights, the scene, the GUI, plugins, audio, wind,
   the atmosphere, the magnetic field, saved states, roads, world joints, ...) and elements SDF does
   not have (in the world, an include, a population, an actor and its script, spherical_coordinates;
   within a model, what parse_sdf_model notes): one note a kind, with its element path
   (``world 'default' > light 'sun' (and 2 more): lights are not simulated (ignored)``), never a
   problem.

Problems: every problem of the file is collected (each with the file, the line where its element
starts, the element path and the rule) and raised together as one
:class:`~thorvald_model.errors.ConfigError`, as our YAML worlds' loader does. ElementTree keeps no line
numbers: the text is read once by :func:`thorvald_sim.models.reading.read_xml` (its limits, and the
line and column of broken XML) and once by ``xml.parsers.expat``, whose start lines are matched to the
elements in document order (lxml is not installed). Budgets (:class:`~thorvald_sim.world.limits.Limits`:
bodies, mesh bytes, a heightmap's pixels and bytes; :data:`thorvald_sim.models.reading.MAX_NESTING`
for includes within includes) are checked before what they count is made. A recursive ``<include>``
is refused with its chain; a model that cannot be found names its URI and every folder searched.
"""

import math
import os
import random
import re
import xml.etree.ElementTree as ET
from dataclasses import dataclass, replace
from typing import Any, Dict, Iterator, List, Optional, Sequence, Set, Tuple
from xml.parsers import expat

from thorvald_model.datum import Datum
from thorvald_model.errors import MISSING, ConfigError, Problem

from ..errors import ModelError
from ..models import reading
from ..models.gazebo_paths import GazeboPaths, gazebo_paths, included_kind
from ..models.sdf import LATEST, parse_sdf_model
from ..models.spec import IDENTITY, Mesh, ModelSpec, Pose, Vec3, compose, pose_from_xyz_rpy, tree
from .gazebo_actors import Actor, Trajectory, actor_model, trajectory
from .gazebo_population import POPULATION_TYPES, population_count, population_places
from .limits import LIMITS, Limits
from .rules import WHAT as WORLD
from .terrain import check_image_budget, image_size

WHAT = "Gazebo world"
OLDEST = (1, 4)  # the oldest SDF version read here (LATEST, 1.7, the newest)
SNIFF_BYTES = 65536  # of a file read to tell a Gazebo world from a YAML one
READ_PIECE = 1 << 16  # characters of a world file read at a time

# Gazebo's defaults (sdformat sdf/1.6/physics.sdf, world.sdf, spherical_coordinates.sdf)
MAX_STEP_SIZE = 0.001  # [s]
REAL_TIME_UPDATE_RATE = 1000.0  # [Hz]
REAL_TIME_FACTOR = 1.0
GRAVITY: Vec3 = (0.0, 0.0, -9.8)  # [m/s^2]
SURFACE_MODEL = "EARTH_WGS84"

SUN = "model://sun"

# What the simulator leaves out, by world element: one note a kind
IGNORED = {
    "light": "lights are not simulated (ignored)",
    "scene": "the scene's look (ambient light, sky, shadows, fog, grid) is not simulated (ignored)",
    "gui": "the GUI's settings are not used (ignored)",
    "plugin": "world plugins are not loaded (ignored)",
    "audio": "audio is not simulated (ignored)",
    "wind": "wind is not simulated (ignored)",
    "atmosphere": "the atmosphere model is not simulated (ignored)",
    "magnetic_field": "the magnetic field is not simulated (ignored)",
    "state": "a saved state is not restored: the models start at their poses (ignored)",
    "road": "roads are drawn only, in Gazebo too: nothing collides with them (ignored)",
    "joint": "world joints are not loaded by Gazebo 11 (ignored)",
}
WORLD_READ = ("physics", "gravity", "spherical_coordinates", "model", "include", "actor", "population", "frame")
INCLUDE_CHILDREN = ("uri", "name", "pose", "static")
POPULATION_CHILDREN = ("model", "include", "pose", "distribution", "model_count", "box", "cylinder", "frame")
ACTOR_IGNORED = {
    "animation": "skeleton animations are not played: the actor moves along its script (ignored)",
    "link": "an actor's own links are not simulated: its body is a person-sized cylinder (ignored)",
    "joint": "an actor's joints are not simulated (ignored)",
    "plugin": "actor plugins are not loaded (ignored)",
    "static": "actors are static in Gazebo (ignored)",
}
ACTOR_READ = ("pose", "skin", "script", "frame")
PHYSICS_READ = ("max_step_size", "real_time_update_rate", "real_time_factor", "gravity")
SPHERICAL_READ = ("surface_model", "latitude_deg", "longitude_deg", "elevation", "heading_deg")


# ---------------------------------------------------------------------------------------------
# The values
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class SphericalCoordinates:
    """The world's ``<spherical_coordinates>`` as written."""

    surface_model: str = SURFACE_MODEL
    latitude_deg: float = 0.0
    longitude_deg: float = 0.0
    elevation: float = 0.0  # [m]
    heading_deg: float = 0.0

    @property
    def datum(self) -> Datum:
        """The GNSS datum Gazebo 11 uses (its world frame's x axis at an ENU yaw of pi - heading)."""
        yaw = math.pi - math.radians(self.heading_deg)
        yaw = math.atan2(math.sin(yaw), math.cos(yaw))
        return Datum(self.latitude_deg, self.longitude_deg, yaw, self.elevation)


@dataclass(frozen=True)
class WorldModel:
    """One model of the world: ``pose`` is its model frame in the world (its own ``<pose>``, or an
    ``<include>`` 's, or a population's place; ``spec.pose`` is not to be applied again), ``static``
    the model's own or the ``<include>`` 's."""

    name: str
    spec: ModelSpec
    pose: Pose
    static: bool


@dataclass(frozen=True)
class WorldBody:
    """A model to build of a loaded Gazebo world (:func:`world_bodies`): its spec ready to build (named,
    the ``<include>`` 's static applied; an actor's cylinder), its pose in the world, and for an actor the
    script that moves it."""

    name: str
    spec: ModelSpec
    pose: Pose
    what: str  # "model" or "actor", as a refusal names it
    source: str  # where it was read from, as a refusal gives it
    actor: Optional[Actor] = None

    def refused(self, world_source: str, why: str) -> ConfigError:
        """The error of a world whose body this is, which the physics would not build (why)."""
        problem = Problem(f"{self.what} '{self.name}'", self.source, f"is built here: {why}")
        return ConfigError(world_source, [problem], WORLD)


def world_bodies(world) -> Iterator[WorldBody]:
    """The models, then the actors, of a Gazebo world loaded as ours (WorldConfig.models and .actors),
    as the simulator node and run_robot build them."""
    for model in world.models:
        spec = replace(model.spec, name=model.name, static=model.static)
        yield WorldBody(model.name, spec, model.pose, "model", model.spec.source)
    for actor in world.actors:
        yield WorldBody(actor.name, actor_model(actor), actor.pose_at(0.0), "actor", world.source, actor)


@dataclass(frozen=True)
class GazeboWorld:
    """A Gazebo world file, read (:func:`read_gazebo_world`)."""

    source: str  # the file
    name: str  # the world's
    version: str  # its SDF version, as written
    max_step_size: float = MAX_STEP_SIZE  # [s]
    real_time_update_rate: float = REAL_TIME_UPDATE_RATE  # [Hz], 0: as fast as possible
    real_time_factor: float = REAL_TIME_FACTOR
    gravity: Vec3 = GRAVITY  # [m/s^2] in the world frame
    spherical_coordinates: Optional[SphericalCoordinates] = None  # None: the file has none
    models: Tuple[WorldModel, ...] = ()  # in file order (a population's where it is)
    actors: Tuple[Actor, ...] = ()
    height_field: Optional[Dict[str, Any]] = None  # our world file's height_field keys (loader.parse_world makes it)
    notes: Tuple[str, ...] = ()  # what was read and left out, each with its element path, one a kind

    @property
    def datum(self) -> Optional[Datum]:
        """The GNSS datum of the world's spherical coordinates (None without them)."""
        return None if self.spherical_coordinates is None else self.spherical_coordinates.datum

    def model(self, name: str) -> WorldModel:
        for model in self.models:
            if model.name == name:
                return model
        raise KeyError(name)


# ---------------------------------------------------------------------------------------------
# The entry points
# ---------------------------------------------------------------------------------------------
def is_gazebo_world(path: str) -> bool:
    """Whether the file is an XML (SDF) world rather than one of our YAML worlds, by its first bytes:
    XML (``<?xml``, ``<sdf``, a comment) that names ``<sdf`` early, or any XML file named ``.world`` or
    ``.sdf``. A YAML file is never taken, whatever its name."""
    try:
        with open(path, "rb") as f:
            head = f.read(SNIFF_BYTES)
    except OSError:
        return False
    text = head[3:] if head.startswith(b"\xef\xbb\xbf") else head
    if not text.lstrip().startswith(b"<"):
        return False
    return b"<sdf" in text or os.path.splitext(path)[1].lower() in (".world", ".sdf")


def read_gazebo_world(
    path: str, paths: Optional[GazeboPaths] = None, limits: Limits = LIMITS, seed: int = 0
) -> GazeboWorld:
    """The world of a Gazebo world file (module docstring: what is read, as Gazebo 11 reads it).

    paths: Gazebo's model and resource folders (default: this environment's); limits: the budgets;
    seed: of the random populations' places. ConfigError naming every problem, each with its line.
    """
    return _Reader(path, paths if paths is not None else gazebo_paths(), limits, seed).read()


# ---------------------------------------------------------------------------------------------
# The reader
# ---------------------------------------------------------------------------------------------
class _Counted(reading.Budget):
    """read_xml's budget of a world file: its elements are counted (read_xml's MAX_ELEMENTS), not held
    to one model's limits (a world has many models; the world's budgets are Limits')."""

    def add(self, tag: str, source: str) -> None:
        pass


class _Reader:
    def __init__(self, path: str, paths: GazeboPaths, limits: Limits, seed: int) -> None:
        self.source = str(path)
        self.base_dir = os.path.dirname(os.path.abspath(self.source))
        self.paths = paths
        self.limits = limits
        self.seed = seed
        self.problems: List[Problem] = []
        self.note_entries: List[List[Any]] = []  # [element path, text, count]
        self.noted: Dict[Any, int] = {}  # kind -> its entry
        self.lines: Dict[ET.Element, int] = {}
        self.parents: Dict[ET.Element, ET.Element] = {}
        self.foreign: Optional[Tuple[ET.Element, str]] = None  # (the <include>, the file) of an included actor
        self.version_text = ""
        self.version = LATEST
        # <include>s: model_sdf's answers, the heights of whole include trees, parsed models
        self.loaded: Dict[str, Tuple[Optional[Tuple[str, str]], str]] = {}
        self.heights: Dict[str, int] = {}
        self.refused: Set[str] = set()
        self.specs: Dict[str, Optional[ModelSpec]] = {}
        self.frames: Dict[str, Tuple[str, Pose, ET.Element]] = {}
        self.resolved: Dict[str, Optional[Pose]] = {}
        self.models: List[WorldModel] = []
        self.model_elements: List[Tuple[ET.Element, ModelSpec, int]] = []  # (element, spec, instances)
        self.names: Dict[str, ET.Element] = {}
        self.actors: List[Actor] = []
        self.height_field: Optional[Dict[str, Any]] = None
        self.height_field_element: Optional[ET.Element] = None
        self.over_budget = False

    # ---- the file ------------------------------------------------------------------------------
    def read(self) -> GazeboWorld:
        world = self.world_element(self.parse(self.text()))
        name = world.get("name", "")
        physics = self.physics(world)
        gravity = self.gravity(world)
        spherical = self.spherical(world)
        self.collect_frames(world)
        self.count_bodies(world)
        populations = 0
        for child in world:
            tag = child.tag
            if tag == "model":
                self.world_model(child)
            elif tag == "include":
                self.world_include(child)
            elif tag == "actor":
                self.actor(child)
            elif tag == "population":
                self.population(child, populations)
                populations += 1
            elif tag in IGNORED:
                self.note(child, IGNORED[tag], ("world", tag))
            elif tag not in WORLD_READ or (tag == "frame" and self.version < (1, 7)):
                self.note(child, "not an element of an SDF world: Gazebo ignores it (ignored)", ("world", "?"))
        self.check_mesh_budget()
        if self.problems:
            raise ConfigError(self.source, self.problems, WHAT)
        step, rate, factor = physics
        return GazeboWorld(
            source=self.source,
            name=name,
            version=self.version_text,
            max_step_size=step,
            real_time_update_rate=rate,
            real_time_factor=factor,
            gravity=gravity,
            spherical_coordinates=spherical,
            models=tuple(self.models),
            actors=tuple(self.actors),
            height_field=self.height_field,
            notes=tuple(self.notes()),
        )

    def stop(self, rule: str, element: Optional[ET.Element] = None) -> ConfigError:
        """The error of a file that is not a world at all (its one problem)."""
        if element is None:
            self.problems.append(Problem("", MISSING, rule))
        else:
            self.problems.append(Problem(self.where(element), _shown(element), rule))
        return ConfigError(self.source, self.problems, WHAT)

    def text(self) -> str:
        try:
            with open(self.source, encoding="utf-8") as f:
                # in pieces: read(MAX_XML_CHARS + 1) would take that much memory for a file of any size
                pieces, length = [], 0
                while length <= reading.MAX_XML_CHARS:
                    piece = f.read(READ_PIECE)
                    if not piece:
                        break
                    pieces.append(piece)
                    length += len(piece)
                text = "".join(pieces)
        except IsADirectoryError:
            raise self.stop("is a folder, not a world file") from None
        except OSError as e:
            raise self.stop(f"cannot be read: {e.strerror or e}") from None
        except UnicodeDecodeError:
            raise self.stop("is not UTF-8 text") from None
        return text

    def parse(self, text: str) -> ET.Element:
        """The root element; every element's start line recorded (expat, in document order)."""
        try:
            root = reading.read_xml(text, self.source, _Counted())
        except ModelError as e:
            raise self.stop(f"{e.path}: {e.rule}" if e.path else e.rule) from None
        starts: List[int] = []
        parser = expat.ParserCreate()
        parser.StartElementHandler = lambda name, attributes: starts.append(parser.CurrentLineNumber)
        try:
            parser.Parse(text, True)
        except expat.ExpatError:
            starts = []
        elements = list(root.iter())
        if len(starts) == len(elements):
            self.lines = dict(zip(elements, starts))
        for parent in elements:
            for child in parent:
                self.parents[child] = parent
        return root

    def world_element(self, root: ET.Element) -> ET.Element:
        if root.tag != "sdf":
            raise self.stop(f"<{root.tag}> at the top: a Gazebo world is an <sdf> file with a <world>", root)
        text = (root.get("version") or "").strip()
        match = re.fullmatch(r"(\d+)\.(\d+)(?:\.\d+)?", text)
        if not match:
            raise self.stop(f"<sdf version={text!r}>: not an SDF version such as 1.6", root)
        version = (int(match.group(1)), int(match.group(2)))
        if version < OLDEST:
            raise self.stop(
                f"SDF {text}: read here are 1.4 to 1.7 (convert it: gz sdf -p FILE, as Gazebo 11 does)", root
            )
        if version > LATEST:
            self.note(root, f"SDF {text} is read as SDF 1.7", ("sdf", "version"))
            version = LATEST
        self.version = version
        self.version_text = text
        worlds = root.findall("world")
        if len(worlds) != 1:
            what = "no <world>" if not worlds else f"{len(worlds)} <world>s"
            models = " (a model file: spawn it, or include it in a world)" if root.find("model") is not None else ""
            raise self.stop(f"{what}: a world file here has one{models}", root)
        return worlds[0]

    # ---- what the problems and notes say ------------------------------------------------------
    def describe(self, element: ET.Element) -> str:
        """``world 'default' > model 'wall' > link 'link'``: the element's path in the file."""
        steps = []
        at: Optional[ET.Element] = element
        while at is not None and at.tag != "sdf":
            name = at.get("name")
            steps.append(f"{at.tag} '{name}'" if name is not None else at.tag)
            at = self.parents.get(at)
        return " > ".join(reversed(steps))

    def where(self, element: ET.Element) -> str:
        line = self.lines.get(element)
        return f"line {line}: {self.describe(element)}" if line else self.describe(element)

    def problem(self, element: ET.Element, rule: str, value: Any = None) -> None:
        if value is None:
            value = _shown(element)
        if element not in self.lines and self.foreign is not None:
            anchor, source = self.foreign
            rule = f"{source}: {self.describe(element)}: {rule}"
            element = anchor
        self.problems.append(Problem(self.where(element), value, rule))

    def model_problem(self, element: ET.Element, error: ModelError) -> None:
        """A ModelError of parse_sdf_model on element's text, at the element it names (its path)."""
        if error.source != self.source:
            rule = f"{error.source}: {error.path}: {error.rule}" if error.path else f"{error.source}: {error.rule}"
            self.problem(element, rule)
            return
        target = _find(element, error.path)
        self.problem(target, error.rule, _shown(target))

    def note(self, element: ET.Element, text: str, kind: Any = None, within: str = "") -> None:
        """A note of what was read and left out; one a kind (the first element's path, and how many).
        within: where in the element's model text (parse_sdf_model's notes)."""
        key = kind if kind is not None else (self.describe(element), text)
        if key in self.noted:
            self.note_entries[self.noted[key]][2] += 1
            return
        self.noted[key] = len(self.note_entries)
        path = self.describe(element)
        if element not in self.lines and self.foreign is not None:
            anchor, source = self.foreign
            path = f"{self.describe(anchor)} ({source}: {path})"
        elif within:
            path = f"{path} ({within})"
        self.note_entries.append([path, text, 1])

    def model_note(self, element: ET.Element, note: str, source: str = "") -> None:
        """A note of parse_sdf_model (``sdf/model[m]/link[l]/sensor[s]: text``), one a kind over the world."""
        where, _, text = note.partition(": ")
        where = where[len("sdf/") :] if where.startswith("sdf/") else where
        self.note(element, text, ("model", text), f"{source}: {where}" if source else where)

    def notes(self) -> List[str]:
        return [
            f"{path} (and {count - 1} more): {text}" if count > 1 else f"{path}: {text}"
            for path, text, count in self.note_entries
        ]

    # ---- numbers --------------------------------------------------------------------------------
    def number(self, parent: Optional[ET.Element], tag: str, default: float, **rules) -> float:
        child = None if parent is None else parent.find(tag)
        if child is None:
            return default
        try:
            return reading.number(child.text, self.source, "", **rules)
        except ModelError as e:
            self.problem(child, _bare(e.rule, child.text), (child.text or "").strip())
            return default

    def integer(self, parent: ET.Element, tag: str, default: int) -> Optional[int]:
        child = parent.find(tag)
        if child is None:
            return default
        text = (child.text or "").strip()
        if not re.fullmatch(r"[+-]?\d+", text):
            self.problem(child, "must be a whole number", text)
            return None
        return int(text)

    def vector(self, parent: Optional[ET.Element], tag: str, default: Vec3) -> Vec3:
        child = None if parent is None else parent.find(tag)
        if child is None:
            return default
        try:
            x, y, z = reading.numbers(child.text, 3, self.source, "")
        except ModelError as e:
            self.problem(child, _bare(e.rule, child.text), (child.text or "").strip())
            return default
        return (x, y, z)

    def flag(self, parent: Optional[ET.Element], tag: str, default: bool) -> bool:
        child = None if parent is None else parent.find(tag)
        if child is None:
            return default
        try:
            return reading.flag(child.text, self.source, "")
        except ModelError as e:
            self.problem(child, _bare(e.rule, child.text), (child.text or "").strip())
            return default

    def pose(self, element: ET.Element) -> Tuple[Pose, str]:
        """An element's own ``<pose>`` (identity without one) and the frame it is relative to."""
        child = element.find("pose")
        if child is None:
            return IDENTITY, ""
        text = (child.text or "").strip()
        if not text:
            values: Sequence[float] = (0.0,) * 6
        else:
            try:
                values = reading.numbers(text, 6, self.source, "")
            except ModelError as e:
                self.problem(child, _bare(e.rule, child.text), text)
                values = (0.0,) * 6
        relative_to = (child.get("relative_to") or child.get("frame") or "").strip()
        return pose_from_xyz_rpy(tuple(values[:3]), tuple(values[3:])), relative_to

    # ---- physics, gravity, the datum --------------------------------------------------------------
    def physics(self, world: ET.Element) -> Tuple[float, float, float]:
        elements = world.findall("physics")
        if not elements:
            return MAX_STEP_SIZE, REAL_TIME_UPDATE_RATE, REAL_TIME_FACTOR
        chosen = next((p for p in elements if (p.get("default") or "").strip().lower() in ("true", "1")), elements[0])
        for other in elements:
            if other is not chosen:
                self.note(
                    other, "another physics profile: Gazebo uses the default one (ignored)", ("physics", "preset")
                )
        for child in chosen:
            if child.tag in PHYSICS_READ:
                continue
            self.note(child, "the physics engine's own settings are not used: pybullet steps the world (ignored)")
        return (
            self.number(chosen, "max_step_size", MAX_STEP_SIZE, positive=True),
            self.number(chosen, "real_time_update_rate", REAL_TIME_UPDATE_RATE, minimum=0.0),
            self.number(chosen, "real_time_factor", REAL_TIME_FACTOR, minimum=0.0),
        )

    def gravity(self, world: ET.Element) -> Vec3:
        """The world's gravity (SDF 1.5 on), or its physics' (SDF 1.4); the other place noted."""
        in_physics = [g for p in world.findall("physics") for g in p.findall("gravity")]
        in_world = world.findall("gravity")
        if self.version < (1, 5):
            read, other, why = in_physics, in_world, "SDF 1.4 has gravity in <physics>"
        else:
            read, other, why = in_world, in_physics, "SDF 1.5 and later have gravity in <world>"
        for element in other:
            self.note(element, f"{why}: not read (ignored)", ("gravity", "other"))
        if not read:
            return GRAVITY
        owner = self.parents.get(read[0], world)
        return self.vector(owner, "gravity", GRAVITY)

    def spherical(self, world: ET.Element) -> Optional[SphericalCoordinates]:
        element = world.find("spherical_coordinates")
        if element is None:
            return None
        model = (element.findtext("surface_model") or SURFACE_MODEL).strip()
        if model != SURFACE_MODEL:
            self.note(element.find("surface_model"), f"Gazebo knows {SURFACE_MODEL} only and uses it (as here)")
            model = SURFACE_MODEL
        orientation = element.find("world_frame_orientation")
        if orientation is not None and (orientation.text or "").strip() != "ENU":
            self.note(orientation, "Gazebo 11 does not read it: its world frame is turned from ENU (ignored)")
        for child in element:
            if child.tag not in (*SPHERICAL_READ, "world_frame_orientation"):
                self.note(child, "not an element of spherical_coordinates (ignored)")
        latitude = self.number(element, "latitude_deg", 0.0)
        longitude = self.number(element, "longitude_deg", 0.0)
        for tag, value, bound in (("latitude_deg", latitude, 90.0), ("longitude_deg", longitude, 180.0)):
            if abs(value) > bound:
                self.problem(element.find(tag), f"must be in [-{bound:g}, {bound:g}] [deg]")
        return SphericalCoordinates(
            model, latitude, longitude, self.number(element, "elevation", 0.0), self.number(element, "heading_deg", 0.0)
        )

    # ---- world frames (relative_to) ----------------------------------------------------------
    def collect_frames(self, world: ET.Element) -> None:
        """The world's named poses: models, includes with a <name>, and (SDF 1.7) frames."""
        for child in world:
            if child.tag == "include":
                name = (child.findtext("name") or "").strip()
            elif child.tag in ("model", "frame", "actor"):
                name = child.get("name") or ""
            else:
                continue
            if not name or name in self.frames:
                continue
            pose, relative_to = self.pose(child)
            if child.tag == "frame" and not relative_to:
                relative_to = (child.get("attached_to") or "").strip()
            self.frames[name] = (relative_to, pose, child)

    def world_pose(self, element: ET.Element, pose: Pose, relative_to: str) -> Pose:
        if relative_to in ("", "world"):
            return pose
        base = self.frame_pose(relative_to, element, ())
        return pose if base is None else compose(base, pose)

    def frame_pose(self, name: str, asker: ET.Element, visiting: Tuple[str, ...]) -> Optional[Pose]:
        if name in ("", "world"):
            return IDENTITY
        if name in self.resolved:
            return self.resolved[name]
        if name in visiting:
            self.problem(asker, "poses relative to each other in a loop: " + " -> ".join((*visiting, name)))
            return None
        if name not in self.frames:
            self.problem(asker, f"relative_to {name!r}: no model or frame of the world is named so")
            return None
        relative_to, pose, element = self.frames[name]
        base = self.frame_pose(relative_to, element, (*visiting, name))
        self.resolved[name] = None if base is None else compose(base, pose)
        return self.resolved[name]

    # ---- the budget of bodies --------------------------------------------------------------------
    def count_bodies(self, world: ET.Element) -> None:
        """Every model, actor and population instance counted against Limits.models (with the ground)
        before any is read: a population of 10^7 is refused here, at its count."""
        shares: List[Tuple[ET.Element, int]] = []
        for child in world:
            if child.tag in ("model", "include", "actor"):
                shares.append((child, 1))
            elif child.tag == "population":
                shares.append((child, population_count(child)))
        total = sum(n for _, n in shares) + 1
        if total <= self.limits.models:
            return
        self.over_budget = True
        element, largest = max(shares, key=lambda share: share[1])
        here = f", {largest} of them here" if largest < total - 1 else ""
        self.problem(
            element,
            f"makes {total} bodies (models, actors, population instances and the ground{here}); "
            f"at most {self.limits.models} (Limits.models)",
            largest if element.tag == "population" else None,
        )

    def check_mesh_budget(self) -> None:
        """The mesh files' bytes, each file once (the instances of a mesh share its shape), within
        Limits.mesh_bytes."""
        shares = []
        sizes: Dict[str, int] = {}
        for element, spec, _instances in self.model_elements:
            paths = {
                shape.geometry.path
                for link in spec.links
                for shape in (*link.collisions, *link.visuals)
                if isinstance(shape.geometry, Mesh)
            }
            total = 0
            for path in paths:
                if path not in sizes:
                    try:
                        sizes[path] = os.path.getsize(path)
                    except OSError:
                        sizes[path] = 0
                    total += sizes[path]
            shares.append((element, total))
        total = sum(n for _, n in shares)
        if total > self.limits.mesh_bytes:
            element, largest = max(shares, key=lambda share: share[1])
            self.problem(
                element,
                f"its meshes make {total} bytes of mesh files over the world's models ({largest} first read here); "
                f"at most {self.limits.mesh_bytes} (Limits.mesh_bytes)",
            )

    # ---- models ---------------------------------------------------------------------------------
    def add_model(self, element: ET.Element, model: WorldModel) -> bool:
        """The model into the world, unless its name is taken: Gazebo 11 keeps the first (a note)."""
        first = self.names.get(model.name)
        if first is not None:
            self.note(
                element,
                f"a second model named {model.name!r} (the first: {self.where(first)}): Gazebo 11 does not insert it "
                "('Model with name already exists'), nor is it here",
            )
            return False
        self.names[model.name] = element
        self.models.append(model)
        return True

    def world_model(self, element: ET.Element) -> None:
        spec = self.model_spec(element, heightmaps=True)
        if spec is None:
            return
        own, relative_to = self.pose(element)
        if self.add_model(
            element, WorldModel(spec.name, spec, self.world_pose(element, own, relative_to), spec.static)
        ):
            self.model_elements.append((element, spec, 1))

    def model_spec(self, element: ET.Element, heightmaps: bool) -> Optional[ModelSpec]:
        """A <model> of this file read by parse_sdf_model (its includes checked first; its heightmaps
        taken out, the collisions' one made the height field). None, with its problems, if it cannot."""
        whole = True
        for include in element.iter("include"):
            uri = (include.findtext("uri") or "").strip()
            if uri and not self.scan(uri, (), include):
                whole = False
        if not whole:
            return None
        if self.strip_heightmaps(element, heightmaps, self.base_dir, None):
            self.note(element, "holds the heightmap only: it is the world's height field")
            return None
        version = f"{self.version[0]}.{self.version[1]}"  # a newer file's is read as 1.7, noted once
        text = f'<sdf version="{version}">{ET.tostring(element, encoding="unicode")}</sdf>'
        try:
            spec = parse_sdf_model(text, self.source, self.paths.finder(self.base_dir), self.include_loader)
        except ModelError as e:
            self.model_problem(element, e)
            return None
        for note in spec.notes:
            self.model_note(element, note)
        return spec

    def include_loader(self, uri: str) -> Tuple[Optional[Tuple[str, str]], str]:
        """parse_sdf_model's IncludeLoader: GazeboPaths.model_sdf, each URI read once."""
        if uri not in self.loaded:
            self.loaded[uri] = self.paths.model_sdf(uri)
        return self.loaded[uri]

    def scan(self, uri: str, chain: Tuple[str, ...], asker: ET.Element) -> bool:
        """Whether uri's include tree is whole: every model found, none including itself, none nested
        deeper than reading.MAX_NESTING; each problem once, at asker (the element of this file)."""
        if uri in chain:
            self.problem(asker, "recursive <include>: " + " -> ".join((*chain, uri)))
            return False
        if uri in self.refused:
            return False
        if len(chain) >= reading.MAX_NESTING:
            self.problem(asker, f"<include>s nested more than {reading.MAX_NESTING} deep: " + " -> ".join(chain))
            return False
        if uri not in self.heights:
            loaded, why = self.include_loader(uri)
            if loaded is None:
                within = f" (included by {' -> '.join(chain)})" if chain else ""
                self.problem(asker, f"<include> of {uri}{within} cannot be found: {why}")
                self.refused.add(uri)
                return False
            text, source = loaded
            try:
                root = reading.read_xml(text, source)
            except ModelError as e:
                self.problem(asker, f"<include> of {uri}: {e}")
                self.refused.add(uri)
                return False
            height = 0
            for include in root.iter("include"):
                inner = (include.findtext("uri") or "").strip()
                if not inner:
                    continue  # parse_sdf_model names it
                if not self.scan(inner, (*chain, uri), asker):
                    self.refused.add(uri)
                    return False
                height = max(height, self.heights[inner])
            self.heights[uri] = height + 1
        if len(chain) + self.heights[uri] > reading.MAX_NESTING:
            self.problem(
                asker, f"<include>s nested more than {reading.MAX_NESTING} deep, from {' -> '.join((*chain, uri))}"
            )
            return False
        return True

    def included_spec(
        self, uri: str, text: str, source: str, element: ET.Element, heightmaps: bool
    ) -> Optional[ModelSpec]:
        """The model a model:// URI names, read once however often it is included (its heightmaps
        taken out first, as a <model> of the world's own: with heightmaps, the first include's)."""
        if uri not in self.specs:
            self.specs[uri] = self.read_included(text, source, element, heightmaps)
        return self.specs[uri]

    def read_included(self, text: str, source: str, element: ET.Element, heightmaps: bool) -> Optional[ModelSpec]:
        folder = os.path.dirname(source)
        if "heightmap" in text:
            root = reading.read_xml(text, source)  # read whole by scan already
            model = root if root.tag == "model" else root.find("model")
            if model is not None:
                for parent in root.iter():
                    for child in parent:
                        self.parents[child] = parent
                placed = self.pose(element)[0] if element.find("pose") is not None else None
                self.foreign = (element, source)
                try:
                    empty = self.strip_heightmaps(model, heightmaps, folder, placed)
                finally:
                    self.foreign = None
                if empty:
                    self.note(element, f"{source} holds the heightmap only: it is the world's height field")
                    return None
                body = ET.tostring(model, encoding="unicode")
                text = f'<sdf version="{root.get("version", "1.7")}">{body}</sdf>' if root.tag == "sdf" else body
        try:
            spec = parse_sdf_model(text, source, self.paths.finder(folder), self.include_loader)
        except ModelError as e:
            self.model_problem(element, e)
            return None
        for note in spec.notes:
            self.model_note(element, note, source)
        return spec

    def include_children(self, element: ET.Element) -> None:
        for child in element:
            if child.tag == "plugin":
                self.note(child, IGNORED["plugin"].replace("world", "model"), ("include", "plugin"))
            elif child.tag == "placement_frame":
                self.note(child, "Gazebo 11 does not read it: the model's own frame is placed (ignored)")
            elif child.tag not in INCLUDE_CHILDREN:
                self.note(child, "not an element of an SDF <include> (ignored)", ("include", "?"))

    def load_include(self, element: ET.Element) -> Optional[Tuple[str, str, str, str]]:
        """(uri, the file's text, the file, what it adds: model, actor or light) of an <include>."""
        uri = (element.findtext("uri") or "").strip()
        if not uri:
            self.problem(element, "an <include> needs a <uri>")
            return None
        self.include_children(element)
        if not self.scan(uri, (), element):
            return None
        (text, source), _ = self.include_loader(uri)  # type: ignore[misc]  (scan found it)
        kind = included_kind(text)
        if kind is None:
            self.problem(element, f"{uri} ({source}) has no <model>, <actor> or <light>")
            return None
        return uri, text, source, kind

    def world_include(self, element: ET.Element) -> None:
        loaded = self.load_include(element)
        if loaded is None:
            return
        uri, text, source, kind = loaded
        if kind == "light":
            if uri.rstrip("/") != SUN:
                self.note(element, IGNORED["light"], ("world", "light"))
            return
        if kind == "actor":
            root = ET.fromstring(text)
            actor = root if root.tag == "actor" else root.find("actor")
            self.foreign = (element, source)
            try:
                self.actor(actor, element)  # type: ignore[arg-type]
            finally:
                self.foreign = None
            return
        spec = self.included_spec(uri, text, source, element, heightmaps=True)
        if spec is None:
            return
        name = (element.findtext("name") or "").strip() or spec.name
        static = self.flag(element, "static", spec.static)
        if name != spec.name or static != spec.static:
            spec = replace(spec, name=name, static=static)
            try:
                tree(spec)
            except ModelError as e:
                self.problem(element, f"{source}: <static>false</static> here: {e.rule}")
                return
        pose = spec.pose
        if element.find("pose") is not None:
            own, relative_to = self.pose(element)
            pose = self.world_pose(element, own, relative_to)
        if self.add_model(element, WorldModel(name, spec, pose, static)):
            self.model_elements.append((element, spec, 1))

    # ---- heightmaps -----------------------------------------------------------------------------
    def strip_heightmaps(self, model: ET.Element, make: bool, base_dir: str, placed: Optional[Pose]) -> bool:
        """Takes the model's heightmap collisions and visuals out of it (its collision's one made the
        height field when make: its image found from base_dir; placed, an <include>'s pose replacing the
        model's); whether the model is then empty (no collision or visual left)."""
        collisions, visuals = [], []
        for link in model.iter("link"):
            for child in list(link):
                if child.tag in ("collision", "visual") and child.find("geometry/heightmap") is not None:
                    link.remove(child)
                    (collisions if child.tag == "collision" else visuals).append(child)
        if not collisions and not visuals:
            return False
        for collision in collisions:
            if make:
                self.heightmap(collision, base_dir, placed)
            else:
                self.problem(collision, "a heightmap in a population: the world's ground is one height field")
        if not collisions:
            for visual in visuals:
                self.note(visual, "a heightmap in a visual only is drawn by Gazebo and collides with nothing (ignored)")
        return not any(child.tag in ("collision", "visual") for link in model.iter("link") for child in link)

    def heightmap(self, collision: ET.Element, base_dir: str, placed: Optional[Pose]) -> None:
        from .gazebo_heightmap import as_height_field  # noqa: PLC0415  (numpy and PIL, for a heightmap only)

        shape = collision.find("geometry/heightmap")
        if self.height_field is not None:
            first = self.where(self.height_field_element) if self.height_field_element is not None else ""
            self.problem(shape, f"a second heightmap (the first: {first}): the world's ground is one height field")
            return
        uri = (shape.findtext("uri") or "").strip()
        found, why = self.paths.find_file(uri, base_dir)
        if found is None:
            self.problem(shape.find("uri") if shape.find("uri") is not None else shape, f"cannot be found: {why}", uri)
            return
        size = self.vector(shape, "size", (1.0, 1.0, 1.0))
        pos = self.vector(shape, "pos", (0.0, 0.0, 0.0))
        sampling = self.integer(shape, "sampling", 2)
        if sampling is None:
            return
        used = sampling if sampling > 0 and not sampling & (sampling - 1) else 2  # Gazebo's: a power of 2, else 2
        rotation, translation = self.collision_pose(collision, placed)
        if max(abs(c) for c in rotation[:3]) > 1e-9:
            self.problem(collision, "a rotated heightmap: the height field here lies in the world's axes")
            return
        try:
            check_image_budget(found, self.limits)
            width, height = image_size(found)
            points = ((max(width, height) - 1) * used + 1) ** 2  # Gazebo's grid: our field's is the pixels
            # a 16-bit image whole, its brightest pixel at size z, as Gazebo Sim reads it: Gazebo Classic 11
            # reads each pixel's low byte (gazebo_heightmap's item 4), so no Classic world relied on one
            keys = as_height_field(found, size, pos, sampling, sixteen_bit="full", max_points=max(points, 4))
            if keys.kind == "16-bit":
                self.note(shape, "a 16-bit image: read whole, its brightest pixel at size z, as Gazebo Sim reads it "
                          "(Gazebo Classic 11 reads each pixel's low byte)")  # fmt: skip
        except ValueError as e:
            self.problem(shape, f"{uri} ({found}) {e}", uri)
            return
        # our world file's keys: an image gives the grid, so no resolution key
        self.height_field = {k: v for k, v in keys.keywords.items() if k != "resolution"}
        self.height_field_element = shape
        for difference in keys.differences:
            self.note(shape, f"our height field differs from Gazebo's: {difference}")
        if any(abs(c) > 1e-12 for c in translation):
            self.note(
                collision,
                "Gazebo's physics (ODE) does not move a heightmap by its model's, link's and collision's position "
                "(its visual moves): nor does this height field",
            )

    def collision_pose(self, collision: ET.Element, placed: Optional[Pose]) -> Tuple[Any, Vec3]:
        """(rotation, translation) of the collision in the world: its, its link's and its models' poses
        (placed: the outermost model's, an <include>'s)."""
        chain = []
        at: Optional[ET.Element] = collision
        while at is not None and at.tag not in ("world", "sdf"):
            parent = self.parents.get(at)
            outermost = at.tag == "model" and (parent is None or parent.tag != "model")
            if outermost and placed is not None:
                chain.append(placed)
            elif at.tag in ("collision", "link", "model"):
                chain.append(self.pose(at)[0])
            at = parent
        pose = IDENTITY
        for step in reversed(chain):
            pose = compose(pose, step)
        return pose[1], pose[0]

    # ---- populations ------------------------------------------------------------------------------
    def population(self, element: ET.Element, index: int) -> None:
        for child in element:
            if child.tag not in POPULATION_CHILDREN:
                self.note(child, "not an element of an SDF population (ignored)", ("population", "?"))
        models = [c for c in element if c.tag in ("model", "include")]
        before = len(self.problems)
        if len(models) != 1:
            self.problem(element, f"has {len(models)} <model>s and <include>s: a population places one model")
            return
        params = self.population_params(element)
        spec = self.population_spec(models[0])
        if spec is None or params is None or len(self.problems) > before or self.over_budget:
            return
        places = population_places(params, random.Random(f"{self.seed}:{index}:{element.get('name', '')}"))
        if isinstance(places, str):
            self.problem(element, places)
            return
        if params["type"] in ("random", "uniform"):
            self.note(
                element,
                "placed at random as Gazebo places it, but the same places at every load (seeded); Gazebo draws "
                "new ones each run",
                ("population", "random"),
            )
        if models[0].tag == "model" and models[0].find("pose") is not None:
            self.note(
                models[0].find("pose"), "Gazebo places each clone at its place only: the model's pose is not used"
            )
        added = 0
        for i, position in enumerate(places):
            added += self.add_model(
                element, WorldModel(f"{spec.name}_clone_{i}", spec, (position, IDENTITY[1]), spec.static)
            )
        self.model_elements.append((element, spec, added))

    def population_spec(self, model: ET.Element) -> Optional[ModelSpec]:
        if model.tag == "model":
            return self.model_spec(model, heightmaps=False)
        loaded = self.load_include(model)
        if loaded is None:
            return None
        uri, text, source, kind = loaded
        if kind != "model":
            self.problem(model, f"{uri} is a {kind}: a population places a model")
            return None
        spec = self.included_spec(uri, text, source, model, heightmaps=False)
        if spec is None:
            return None
        name = (model.findtext("name") or "").strip() or spec.name
        static = self.flag(model, "static", spec.static)
        return replace(spec, name=name, static=static)

    def population_params(self, element: ET.Element) -> Optional[Dict[str, Any]]:
        """Population::ParseSdf's parameters; a problem for each that Gazebo would ignore it for."""
        ignored = "Gazebo ignores the population ('Population ignored')"
        pose_element = element.find("pose")
        distribution = element.find("distribution")
        if pose_element is None:
            self.problem(element, f"needs a <pose>: without one {ignored}")
        if distribution is None:
            self.problem(element, f"needs a <distribution>: without one {ignored}")
            return None
        kind = (distribution.findtext("type") or "random").strip()
        if kind not in POPULATION_TYPES:
            self.problem(distribution.find("type"), f"must be one of {', '.join(POPULATION_TYPES)}", kind)
            return None
        pose, _ = self.pose(element)
        params: Dict[str, Any] = {"type": kind, "pose": pose}
        if kind == "grid":
            for tag in ("rows", "cols", "step"):
                if distribution.find(tag) is None:
                    self.problem(distribution, f"a grid needs <{tag}>: without it {ignored}")
            for tag in ("rows", "cols"):
                value = self.integer(distribution, tag, 1)
                if value is not None and value <= 0:
                    self.problem(distribution.find(tag), f"must be > 0: else {ignored}")
                params[tag] = value
            params["step"] = self.vector(distribution, "step", (0.5, 0.5, 0.0))
            return params
        count = self.integer(element, "model_count", 1)
        if count is not None and count <= 0:
            self.problem(element.find("model_count"), f"must be > 0: else {ignored}")
        params["count"] = count
        box, cylinder = element.find("box"), element.find("cylinder")
        if box is not None:
            params["region"] = "box"
            params["size"] = size = self.vector(box, "size", (1.0, 1.0, 1.0))
            if min(size) <= 0:
                self.problem(box.find("size") if box.find("size") is not None else box, f"must be > 0: else {ignored}")
        elif cylinder is not None:
            params["region"] = "cylinder"
            params["radius"] = self.number(cylinder, "radius", 1.0)
            params["length"] = self.number(cylinder, "length", 1.0)
            for tag in ("radius", "length"):
                if params[tag] <= 0:
                    at = cylinder.find(tag)
                    self.problem(at if at is not None else cylinder, f"must be > 0: else {ignored}")
            if kind.startswith("linear-"):
                self.problem(distribution.find("type"), f"{kind} in a cylinder: Gazebo knows it in a box only", kind)
        else:
            self.problem(element, f"needs a region, <box> or <cylinder>: without one {ignored}")
        return params

    # ---- actors ---------------------------------------------------------------------------------
    def actor(self, element: ET.Element, include: Optional[ET.Element] = None) -> None:
        name = element.get("name") or ""
        pose, relative_to = self.pose(element)
        if include is not None:
            name = (include.findtext("name") or "").strip() or name
            if include.find("pose") is not None:
                pose, relative_to = self.pose(include)
                pose = self.world_pose(include, pose, relative_to)
        else:
            pose = self.world_pose(element, pose, relative_to)
        if not name:
            self.problem(element, "an <actor> needs a name")
            return
        for child in element:
            if child.tag in ACTOR_IGNORED:
                self.note(child, ACTOR_IGNORED[child.tag], ("actor", child.tag))
            elif child.tag not in ACTOR_READ:
                self.note(child, "not an element of an SDF actor (ignored)", ("actor", "?"))
        skin, skin_path, scale = "", None, 1.0
        skin_element = element.find("skin")
        if skin_element is not None:
            skin = (skin_element.findtext("filename") or "").strip()
            scale = self.number(skin_element, "scale", 1.0, positive=True)
            skin_path, why = self.paths.find_file(skin, self.base_dir) if skin else (None, "no <filename>")
            if skin_path is None:
                self.note(skin_element, f"skin {skin!r} not found ({why}): the actor follows its script without it")
        script = element.find("script")
        trajectories: List[Trajectory] = []
        for written in script.findall("trajectory") if script is not None else ():
            made = self.trajectory(written)
            if made is not None:
                trajectories.append(made)
        trajectories.sort(key=lambda t: t.id)  # stable: Gazebo inserts one after those of its id
        start = 0.0
        for i, played in enumerate(trajectories):
            trajectories[i] = replace(played, start=start)
            start += played.duration
        for child in script if script is not None else ():
            if child.tag not in ("loop", "delay_start", "auto_start", "trajectory"):
                self.note(child, "not an element of an actor's script (ignored)", ("script", "?"))
        self.actors.append(
            Actor(
                name=name,
                pose=pose,
                skin=skin,
                skin_path=skin_path,
                skin_scale=scale,
                loop=self.flag(script, "loop", True),
                delay_start=self.number(script, "delay_start", 0.0, minimum=0.0),
                auto_start=self.flag(script, "auto_start", True),
                trajectories=tuple(trajectories),
            )
        )

    def trajectory(self, element: ET.Element) -> Optional[Trajectory]:
        text = (element.get("id") or "0").strip()
        if not re.fullmatch(r"[+-]?\d+", text):
            self.problem(element, f"id {text!r}: must be a whole number")
            return None
        points: Dict[float, Pose] = {}
        for waypoint in element.findall("waypoint"):
            time = self.number(waypoint, "time", 0.0, minimum=0.0)
            points[time] = self.pose(waypoint)[0]  # a later one of the same time replaces it (std::map)
        for child in element:
            if child.tag != "waypoint":
                self.note(child, "not an element of a trajectory (ignored)", ("trajectory", "?"))
        kind = element.get("type") or "__default__"
        if not points:
            self.note(element, "a trajectory without waypoints plays a skeleton animation only: it does not move")
            return Trajectory(int(text), kind, (), (), 0.0)
        return trajectory(int(text), kind, sorted(points.items()))


# ---------------------------------------------------------------------------------------------
# Helpers of the reader
# ---------------------------------------------------------------------------------------------
def _shown(element: ET.Element) -> str:
    """An element as a problem shows its value: its text when it holds text only, else its tag."""
    text = (element.text or "").strip()
    return text if text and len(element) == 0 else f"<{element.tag}>"


def _bare(rule: str, text: Optional[str]) -> str:
    """A reading rule without the value it starts with (the problem shows the value)."""
    for prefix in (repr(text), repr((text or "").strip())):
        if rule.startswith(prefix + ": "):
            return rule[len(prefix) + 2 :]
    match = re.match(r"-?[\d.e+-]+(?:inf)?: ", rule)
    return rule[match.end() :] if match else rule


def _find(model: ET.Element, path: str) -> ET.Element:
    """The element a parse_sdf_model path (``sdf/model[m]/link[l]/collision[c]/geometry/box/size``)
    names within model (the model's own text): its deepest element found."""
    steps = [s for s in path.split("/") if s]
    if steps and steps[0] == "sdf":
        steps = steps[1:]
    at = model
    for step in steps[1:]:
        match = re.fullmatch(r"([^\[]+)(?:\[(.*)\])?", step)
        if not match:
            break
        tag, name = match.group(1), match.group(2)
        found = next((c for c in at if c.tag == tag and (name is None or c.get("name") == name)), None)
        if found is None:
            break
        at = found
    return at
