"""The two-wheel differential calculator, ``pltf_clc_2wdiff::PltfClc2WDiff`` (notes 3.3)."""

from typing import List

from thorvald_model.constants import DIFF_CALCULATOR
from thorvald_model.errors import Problem
from thorvald_model.layout import LINE_TOLERANCE

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

    @classmethod
    def layout_rules(cls, drives, passive_wheels, axle):
        diff = [d for d in drives if not d.steerable]
        if len(drives) != 2 or len(diff) != 2:
            rule = (
                "the differential calculator serves exactly two type-1 drives; this robot has "
                f"{len(drives)} drives, {len(diff)} of type 1"
            )
            return [Problem("base_calculator", cls.name, rule)]
        if abs(diff[0].y - diff[1].y) < LINE_TOLERANCE:
            rule = "the differential calculator needs its two wheels on either side (different y)"
            return [Problem("base_calculator", cls.name, rule)]
        return []

    def _commands(self, twist: Twist) -> List[DriveCommand]:
        return [DriveCommand(0.0, twist.vx - twist.wz * y) for y in self.layout.y]
