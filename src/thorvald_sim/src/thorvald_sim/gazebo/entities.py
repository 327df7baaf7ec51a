"""The world's models as Gazebo names them, and what a name in a request means (no ROS, no pybullet).

Gazebo's world holds models in the order they came (the ground plane first); a model holds links, a
link collisions; a model's joints join its links. A request names an entity as Gazebo's
``World::EntityByName`` finds it: the first entity, models in order and each model's links and
collisions after it, whose scoped name (``model``, ``model::link``, ``model::link::collision``) or
own name (``link``, as ``thorvald_001/base_link``) is the name. ``""``, ``world``, ``map`` and
``/map`` are the world's frame when nothing else is called so.

Here the models are the robots (spawned by ``spawn_robot``/``spawn_model``), the other models spawned
through ``/gazebo/spawn_urdf_model`` and ``spawn_sdf_model``, and the world's ground as Gazebo's
``ground_plane`` (link ``link``, collision ``collision``). Links are the links pybullet keeps: a link
joined to its parent by a fixed joint is part of it, as Gazebo's URDF conversion lumps it.
"""

from dataclasses import dataclass, field
from typing import Dict, Iterator, List, Optional, Tuple

WORLD_NAMES = ("", "world", "map", "/map")
GROUND = "ground_plane"

ROBOT = "robot"  # a Thorvald robot: the simulator's SimRobot
MODEL = "model"  # any other URDF or SDF model
GROUND_KIND = "ground"  # the world's ground and static scene


@dataclass(frozen=True)
class Link:
    name: str  # its own name, as the description writes it
    index: int  # pybullet's link index in its model's body, -1 for the base
    collisions: Tuple[str, ...] = ()  # its collisions' names, as Gazebo names them


@dataclass(frozen=True)
class Joint:
    name: str
    index: int  # pybullet's joint index
    kind: str  # revolute, continuous, prismatic


@dataclass
class Model:
    name: str
    kind: str  # ROBOT, MODEL or GROUND_KIND
    links: Tuple[Link, ...]  # the canonical (base) link first
    joints: Tuple[Joint, ...] = ()
    static: bool = False
    workers: Tuple[int, ...] = (0,)  # the physics workers holding it (a static model: every one)
    spawn_pose: tuple = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))  # world pose of its frame at spawn

    @property
    def canonical(self) -> Link:
        return self.links[0]

    def link(self, name: str) -> Optional[Link]:
        for link in self.links:
            if link.name == name:
                return link
        return None

    def joint(self, name: str) -> Optional[Joint]:
        """A joint by its own name or its scoped name (``model::joint``), as ``Model::GetJoint`` finds it."""
        for joint in self.joints:
            if name in (joint.name, f"{self.name}::{joint.name}"):
                return joint
        return None


@dataclass(frozen=True)
class Entity:
    """What a name resolved to: the world, a model, a link of a model, or a collision of a link."""

    kind: str  # "world", "model", "link", "collision"
    model: Optional[Model] = None
    link: Optional[Link] = None
    collision: str = ""

    @property
    def scoped(self) -> str:
        if self.kind == "world":
            return "world"
        if self.kind == "model":
            return self.model.name
        name = f"{self.model.name}::{self.link.name}"
        return name if self.kind == "link" else f"{name}::{self.collision}"


WORLD = Entity("world")


@dataclass
class Entities:
    """The world's models in the order they came, and name resolution over them."""

    models: Dict[str, Model] = field(default_factory=dict)

    def add(self, model: Model) -> None:
        if model.name in self.models:
            raise KeyError(f"a model named {model.name!r} exists already")
        self.models[model.name] = model

    def remove(self, name: str) -> Model:
        return self.models.pop(name)

    def names(self) -> List[str]:
        return list(self.models)

    def model(self, name: str) -> Optional[Model]:
        return self.models.get(name)

    def find(self, name: str) -> Optional[Entity]:
        """The first entity called name (its scoped or its own name), models in order, each model's
        links and collisions after it; None when there is none."""
        for model in self.models.values():
            if name == model.name:
                return Entity("model", model)
            for link in model.links:
                if name in (link.name, f"{model.name}::{link.name}"):
                    return Entity("link", model, link)
                for collision in link.collisions:
                    if name in (collision, f"{model.name}::{link.name}::{collision}"):
                        return Entity("collision", model, link, collision)
        return None

    def frame(self, name: str) -> Optional[Entity]:
        """A reference frame: an entity, or the world for "", world, map and /map (an entity of
        that name comes first, as in Gazebo); None when neither."""
        found = self.find(name)
        if found is not None:
            return found
        return WORLD if name in WORLD_NAMES else None

    def link(self, name: str) -> Optional[Entity]:
        """A link (a body): as find, and only a link."""
        found = self.find(name)
        return found if found is not None and found.kind == "link" else None

    def joint(self, name: str) -> Optional[Tuple[Model, Joint]]:
        """The first model's joint of that name (own or scoped)."""
        for model in self.models.values():
            joint = model.joint(name)
            if joint is not None:
                return model, joint
        return None

    def __iter__(self) -> Iterator[Model]:
        return iter(self.models.values())

    def __len__(self) -> int:
        return len(self.models)
