"""The two-wheel differential calculator, ``pltf_clc_2wdiff::PltfClc2WDiff`` (notes 3.3)."""

from typing import List

from thorvald_model.constants import DIFF_CALCULATOR

from .calculator import BaseCalculator
from .types import DriveCommand, Twist


class PltfClc2WDiff(BaseCalculator):
    """Two type-1 (propulsion-only) drives on one axle, optionally on casters.

    Wheel speed v_i = vx - wz y_i (vx -+ wz |y| for the right/left wheel), steering always 0 and the
    speed signed, which the type-1 device layer maps to its direction factor +1. The wheels cannot
    slide, so vy must be -wz x_axle (0 for an axle on base_link's y axis): a sideways command keeps
    vx and wz and drops vy, reported as changed.
    """

    name = DIFF_CALCULATOR

    def _commands(self, twist: Twist) -> List[DriveCommand]:
        return [DriveCommand(0.0, twist.vx - twist.wz * y) for y in self.layout.y]
