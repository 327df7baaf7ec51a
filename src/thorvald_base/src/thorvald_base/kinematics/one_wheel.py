"""The one-wheel-drive calculator, ``pltf_clc_1wd::PltfClc1WD`` (a design of ours: notes 3.3 found none)."""

from typing import Sequence

from thorvald_model.constants import DRIVE_DIFF

from ..errors import KinematicsError
from .calculator import BaseCalculator
from .geometry import Layout


class PltfClc1WD(BaseCalculator):
    """One steered drive supported by passive wheels, of which the fixed ones share one axle line.

    The fixed wheels cannot slide, so the centre of rotation lies on their axle line, and the one
    drive's steering angle picks where on it: the robot moves like a tricycle (or a forklift with
    the steered wheel behind). Realisable twists are those with no velocity across the axle at the
    fixed wheels; any other twist is replaced by the closest realisable one (compared by the
    velocities of the drive and the fixed wheels) and reported as changed.

    Odometry: the drive's velocity vector gives two equations and the axle one more, so both
    estimators are exact for one drive (the original left the pose unchanged with one drive).
    """

    def _check_layout(self, drives: Sequence, passive_wheels: Sequence) -> None:
        if len(drives) != 1 or drives[0].type == DRIVE_DIFF:
            raise KinematicsError("the one-wheel-drive calculator serves exactly one type-0 (steered) drive")
        if not any(getattr(w, "fixed", False) for w in passive_wheels):
            raise KinematicsError(
                "the one-wheel-drive calculator needs fixed passive wheels: their axle line is where the "
                "centre of rotation can lie"
            )
        layout = Layout(drives, passive_wheels)
        if len(layout.basis) != 2:
            raise KinematicsError("the fixed passive wheels of a one-wheel drive must share one axle line")
