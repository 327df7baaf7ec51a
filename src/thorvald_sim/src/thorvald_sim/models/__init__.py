"""Models that are not Thorvald robots (an SDF ``<model>``, a generic URDF), read into values and built
in pybullet: :mod:`.spec` (the values), :mod:`.sdf` and :mod:`.urdf_model` (the readers, pure),
:mod:`.build` (pybullet), :mod:`.reading` (their limits), :mod:`.meshes` (COLLADA and ASCII STL).

Importing this package imports no pybullet: ``from thorvald_sim.models.build import SimModel``.
"""

from .reading import MAX_COLLISIONS, MAX_JOINTS, MAX_LINKS, MAX_VISUALS
from .sdf import default_finder, parse_sdf_model
from .spec import ModelSpec
from .urdf_model import GazeboCollision, gazebo_collision_names, parse_urdf_model

__all__ = [
    "MAX_COLLISIONS",
    "MAX_JOINTS",
    "MAX_LINKS",
    "MAX_VISUALS",
    "GazeboCollision",
    "ModelSpec",
    "default_finder",
    "gazebo_collision_names",
    "parse_sdf_model",
    "parse_urdf_model",
]
