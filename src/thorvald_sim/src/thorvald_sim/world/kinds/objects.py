"""Objects (``objects:``, entries ``object0``, ...): single bodies, a box, cylinder, sphere or mesh
file, static or moving, each on the ground under it unless its ``z`` says otherwise.

An object has its shape's dimensions and no other shape's, and its mesh file exists and is a mesh
pybullet can load (:mod:`thorvald_sim.world.mesh_check`: no junk, no STL without triangles or ASCII STL,
no OBJ without faces or with faces naming missing vertices); the mesh files over every object are
held to the world's limit of bytes (each object counts its file: pybullet loads it for each), their
sizes read from the file system before any is read.

In pybullet: a box, cylinder or sphere, or the mesh file (a static mesh collides as its triangles;
a moving one as the convex hull of each object in the file, as bullet can collide nothing else that
moves: the crate of ``worlds/meshes`` is five boxes, so it stays open); one body. Static when its
mass is 0; with a mass it falls, slides and can be pushed, without drag as the robots, and sleeps at
rest until something touches it.
"""

import math
import os
from dataclasses import dataclass, replace
from typing import Dict, List, Optional, Sequence, Tuple

from thorvald_model.errors import MISSING, Problem
from thorvald_model.schema import NON_NEGATIVE, Key, one_of

from ..bodies import p, set_surface
from ..geometry import Point
from ..kind import Context, ElementKind, Entry
from ..limits import bodies_each, over
from ..mesh_check import mesh_problem
from ..rules import COORDINATE, OPTIONAL_LENGTH, RGBA_KEY, UNIT_RANGE, Rgba, broken, file_path
from ..surfaces import Surface, frictions, rgba_text, surface

RGBA_WOOD = (0.60, 0.45, 0.28, 1.0)
MAX_MESH_SCALE = 1000.0  # [-] a mesh drawn in km, or a scale typed in mm instead of m, is a mistake

SHAPES = ("box", "cylinder", "sphere", "mesh")
# the keys of each shape's dimensions: required for it, refused for the others
SHAPE_KEYS = {
    "box": ("size_x", "size_y", "size_z"),
    "cylinder": ("radius", "length"),
    "sphere": ("radius",),
    "mesh": ("file", "scale"),
}
MESH_EXTENSIONS = (".obj", ".stl")


@dataclass(frozen=True)
class WorldObject:
    """One body: a box (``size_x``, ``size_y``, ``size_z``), cylinder (``radius``, ``length`` along
    its own z), sphere (``radius``) or mesh (``file``, an OBJ or binary STL file, checked at load to
    be a mesh pybullet can load (:mod:`thorvald_sim.world.mesh_check`), drawn ``scale`` times).

    Only the shape's own dimensions are set; the others are 0 (``file`` empty). The file's ``z`` is
    the centre's (a mesh's origin's) height above the ground under it, by default resting upright on
    it. Static when its mass is 0; with a mass it falls, slides and can be pushed, without drag as
    the robots.
    """

    name: str
    index: int
    shape: str  # box, cylinder, sphere or mesh
    x: float  # [m] of the centre (a mesh's origin) in the world
    y: float  # [m]
    z: float  # [m] in the world (the file's z is above the ground; this is resolved)
    roll: float  # [rad], pybullet's Euler angles: roll about x, then pitch about y, then yaw about z
    pitch: float  # [rad]
    yaw: float  # [rad]
    size_x: float  # [m] box
    size_y: float  # [m]
    size_z: float  # [m]
    radius: float  # [m] cylinder, sphere
    length: float  # [m] cylinder, along its own z
    file: str  # mesh: the absolute path of an OBJ or STL file
    scale: float  # [-] mesh
    mass: float  # [kg], 0 static
    rgba: Rgba
    surface: Surface

    @property
    def half_height(self) -> float:
        """[m] from the centre to the bottom, upright (a mesh's origin: 0)."""
        return {"box": self.size_z / 2, "cylinder": self.length / 2, "sphere": self.radius}.get(self.shape, 0.0)


OBJECT_KEYS = (
    Key("shape", str, check=one_of(*SHAPES), rule="must be one of " + ", ".join(SHAPES)),
    Key("x", float, **COORDINATE),
    Key("y", float, **COORDINATE),
    Key("z", float, None, **COORDINATE),
    Key("roll", float, 0.0),
    Key("pitch", float, 0.0),
    Key("yaw", float, 0.0),
    Key("size_x", float, **OPTIONAL_LENGTH),
    Key("size_y", float, **OPTIONAL_LENGTH),
    Key("size_z", float, **OPTIONAL_LENGTH),
    Key("radius", float, **OPTIONAL_LENGTH),
    Key("length", float, **OPTIONAL_LENGTH),
    Key("file", str, None, check=bool, rule="must not be empty"),
    Key("scale", float, None, check=lambda v: 0.0 < v <= MAX_MESH_SCALE, rule=f"must be in (0, {MAX_MESH_SCALE:g}]"),
    Key("mass", float, 0.0, **NON_NEGATIVE),
    RGBA_KEY,
    *frictions(0.8),
    Key("restitution", float, 0.0, **UNIT_RANGE),
)


def make(entry: Entry, context: Context) -> WorldObject:
    """The object; a mesh's (key path, value, absolute file) goes to the context's meshes, read by
    :func:`check`."""
    name, index, v, raw = entry.name, entry.index, entry.values, entry.raw
    problems = context.problems
    path = f"objects.{name}"
    shape = v["shape"]
    others = {k for keys in SHAPE_KEYS.values() for k in keys} - set(SHAPE_KEYS[shape])
    for k in sorted(others & set(raw)):
        wanted = ", ".join(SHAPE_KEYS[shape])
        problems.append(Problem(f"{path}.{k}", raw[k], f"is not a key of a {shape} (it takes {wanted})"))
    for k in SHAPE_KEYS[shape]:
        if v[k] is None and k != "scale" and not broken(problems, path, k):
            problems.append(Problem(f"{path}.{k}", MISSING, f"is required for a {shape}"))
    dims = {k: v[k] or 0.0 for k in ("size_x", "size_y", "size_z", "radius", "length")}
    file = ""
    if shape == "mesh" and v["file"]:
        found = len(problems)
        file = file_path(v["file"], context.base_dir, f"{path}.file", problems, MESH_EXTENSIONS)
        if len(problems) == found:
            context.meshes.append((f"{path}.file", v["file"], file))
    colour = v["rgba"] or RGBA_WOOD
    thing = WorldObject(
        name, index, shape, v["x"], v["y"], 0.0, v["roll"], v["pitch"], v["yaw"], **dims, file=file,
        scale=v["scale"] or 1.0, mass=v["mass"], rgba=colour, surface=surface(v),
    )  # fmt: skip
    above = thing.half_height if v["z"] is None else v["z"]
    return replace(thing, z=context.ground_at(v["x"], v["y"]) + above)


def check(objects: Tuple[WorldObject, ...], context: Context) -> None:
    _mesh_problems(context.meshes, context.problems, context.limits.mesh_bytes)


def _mesh_problems(meshes: Sequence[Tuple[str, str, str]], problems: List[Problem], limit: int) -> None:
    """Problems of the mesh files (key path, value, absolute file) the objects name: their sizes over
    the limit first (nothing is read then), else each file that is not a mesh pybullet can load."""
    sized = []
    for path, value, file in meshes:
        try:
            sized.append((path, value, file, float(os.path.getsize(file))))
        except OSError as e:
            problems.append(Problem(path, value, f"cannot be read ({file}): {e.strerror}"))
    shares = [(path, value, size) for path, value, _, size in sized]
    # each object loads its file: pybullet makes a collision shape and a visual shape of each
    too_much = over(shares, limit, "bytes of mesh files over the world's objects (each object's counted)")
    if too_much is not None:
        problems.append(too_much)
        return
    reasons: Dict[str, Optional[str]] = {}
    for path, value, file, _ in sized:
        if file not in reasons:
            reasons[file] = mesh_problem(file)
        if reasons[file]:
            problems.append(Problem(path, value, f"is not a mesh pybullet can load ({file}): {reasons[file]}"))


def footprint(ob: WorldObject) -> List[Point]:
    """A sphere around its centre (a mesh's: its origin)."""
    reach = {
        "box": math.sqrt(ob.size_x**2 + ob.size_y**2 + ob.size_z**2) / 2,
        "cylinder": math.hypot(ob.radius, ob.length / 2),
        "sphere": ob.radius,
    }.get(ob.shape, 0.0)
    return [(ob.x - reach, ob.y - reach), (ob.x + reach, ob.y + reach)]


def build(client: int, world, thing: WorldObject, name: str, bodies: dict) -> None:
    c = client
    if thing.shape == "box":
        half = (thing.size_x / 2, thing.size_y / 2, thing.size_z / 2)
        shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=c)
        visual = p.createVisualShape(p.GEOM_BOX, halfExtents=half, rgbaColor=thing.rgba, physicsClientId=c)
    elif thing.shape == "cylinder":
        shape = p.createCollisionShape(p.GEOM_CYLINDER, radius=thing.radius, height=thing.length, physicsClientId=c)
        visual = p.createVisualShape(
            p.GEOM_CYLINDER, radius=thing.radius, length=thing.length, rgbaColor=thing.rgba, physicsClientId=c
        )
    elif thing.shape == "sphere":
        shape = p.createCollisionShape(p.GEOM_SPHERE, radius=thing.radius, physicsClientId=c)
        visual = p.createVisualShape(p.GEOM_SPHERE, radius=thing.radius, rgbaColor=thing.rgba, physicsClientId=c)
    else:
        scale = (thing.scale,) * 3
        # bullet collides a moving body with a convex shape only: its hull; a static one keeps its triangles
        flags = p.GEOM_FORCE_CONCAVE_TRIMESH if thing.mass == 0 else 0
        shape = p.createCollisionShape(
            p.GEOM_MESH, fileName=thing.file, meshScale=scale, flags=flags, physicsClientId=c
        )
        visual = p.createVisualShape(
            p.GEOM_MESH, fileName=thing.file, meshScale=scale, rgbaColor=thing.rgba, physicsClientId=c
        )
    body = p.createMultiBody(
        thing.mass,
        shape,
        visual,
        basePosition=(thing.x, thing.y, thing.z),
        baseOrientation=p.getQuaternionFromEuler((thing.roll, thing.pitch, thing.yaw)),
        physicsClientId=c,
    )
    set_surface(client, body, thing.surface)
    if thing.mass > 0:
        # No drag, as the robots (pybullet gives every new body a velocity damping of 0.04 / s). An
        # object at rest sleeps, as bullet lets it: awake, a resting 2 kg crate cost a sixth of the step
        # with one robot; a contact wakes it.
        p.changeDynamics(
            body,
            -1,
            linearDamping=0.0,
            angularDamping=0.0,
            activationState=p.ACTIVATION_STATE_ENABLE_SLEEPING,
            physicsClientId=c,
        )
    bodies[name] = body


OBJECTS = ElementKind(
    "objects", "object", OBJECT_KEYS, make=make, builder=build, budget=bodies_each(looks=True),
    footprint=footprint, counted=("object", "objects"),
    check=check, doc="single bodies: a box, cylinder, sphere or mesh file, static or moving",
    defaults={
        "z": "resting upright on the ground; a mesh's origin on it", "size_x": "required for a box",
        "size_y": "required for a box", "size_z": "required for a box",
        "radius": "required for a cylinder or a sphere", "length": "required for a cylinder",
        "file": "required for a mesh", "scale": "1, a mesh's", "rgba": rgba_text("wood brown", RGBA_WOOD),
    },
)  # fmt: skip
