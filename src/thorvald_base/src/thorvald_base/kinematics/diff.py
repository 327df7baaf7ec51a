"""The two-wheel differential calculator, ``pltf_clc_2wdiff::PltfClc2WDiff`` (notes 3.3)."""

from typing import List, Sequence

from thorvald_model.constants import DRIVE_DIFF

from ..errors import KinematicsError
from .calculator import BaseCalculator
from .types import DriveCommand, Twist


class PltfClc2WDiff(BaseCalculator):
    """Two type-1 (propulsion-only) drives on one axle, optionally on casters.

    Wheel speed v_i = vx - wz y_i (vx -+ wz |y| for the right/left wheel), steering always 0 and the
    speed signed, which the type-1 device layer maps to its direction factor +1. The wheels cannot
    slide, so vy must be -wz x_axle (0 for an axle on base_link's y axis): a sideways command gets
    the closest realisable twist, reported as changed.
    """

    def _check_layout(self, drives: Sequence, passive_wheels: Sequence) -> None:
        if len(drives) != 2 or any(d.type != DRIVE_DIFF for d in drives):
            raise KinematicsError(
                "the differential calculator serves exactly two type-1 drives; "
                f"got {len(drives)} drives of types {[d.type for d in drives]}"
            )
        if abs(drives[0].x - drives[1].x) > 1e-3 or abs(drives[0].y - drives[1].y) < 1e-3:
            raise KinematicsError(
                "the differential calculator needs its two wheels on one axle, either side (x equal, y different)"
            )

    def _commands(self, twist: Twist) -> List[DriveCommand]:
        return [DriveCommand(0.0, twist.vx - twist.wz * y) for y in self.layout.y]
