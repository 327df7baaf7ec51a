"""The standard calculator, ``pltf_clc_std::PltfClcStd`` (paper 3.2, notes 3.1)."""

from typing import Sequence

from thorvald_model.constants import DRIVE_DIFF

from ..errors import KinematicsError
from .calculator import BaseCalculator


class PltfClcStd(BaseCalculator):
    """Any number of steered drives, mixed with type-1 drives and fixed passive wheels.

    Each steered wheel points along the velocity of its contact point, so the robot rotates about
    the instantaneous centre of rotation (-vy/wz, vx/wz), translates (wz = 0) or spins in place
    (vx = vy = 0) with one formula: steering atan2(vy + wz x, vx - wz y), speed the norm.

    Wheels that cannot steer confine the centre of rotation to their common axle line (the 4WD2WS
    robot of the paper's Figure 10 b); a twist that would make them slide is replaced by the
    closest realisable twist, and the result says so.
    """

    def _check_layout(self, drives: Sequence, passive_wheels: Sequence) -> None:
        steered = [d for d in drives if d.type != DRIVE_DIFF]
        fixed = [w for w in passive_wheels if getattr(w, "fixed", False)]
        if len(steered) < 2 and len(steered) == len(drives) and not fixed:
            raise KinematicsError(
                "a single steered drive on casters cannot hold the robot's heading: the standard calculator "
                "needs two steered drives or wheels that cannot steer"
            )
