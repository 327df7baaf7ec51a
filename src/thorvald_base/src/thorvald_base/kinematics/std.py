"""The standard calculator, ``pltf_clc_std::PltfClcStd`` (paper 3.2, notes 3.1)."""

from thorvald_model.constants import ONE_WHEEL_CALCULATOR, STD_CALCULATOR
from thorvald_model.errors import Problem

from .calculator import BaseCalculator


class PltfClcStd(BaseCalculator):
    """Any number of steered drives, mixed with type-1 drives and fixed passive wheels.

    Each steered wheel points along the velocity of its contact point, so the robot rotates about
    the instantaneous centre of rotation (-vy/wz, vx/wz), translates (wz = 0) or spins in place
    (vx = vy = 0) with one formula: steering atan2(vy + wz x, vx - wz y), speed the norm.

    Wheels that cannot steer confine the centre of rotation to their common axle line (the 4WD2WS
    robot of the paper's Figure 10 b); a twist that would make them slide is made realisable by the
    calculator's projection (by default: wz and the speed along the fixed wheels kept), and the
    result says so.
    """

    name = STD_CALCULATOR

    @classmethod
    def layout_rules(cls, drives, passive_wheels, axle):
        if axle is None and sum(1 for d in drives if d.steerable) < 2:
            return [
                Problem(
                    "base_calculator",
                    cls.name,
                    "a single steered drive on casters cannot hold the robot's heading: the standard calculator "
                    "needs two steered drives or a fixed axle (for one drive with fixed support wheels use "
                    f"'{ONE_WHEEL_CALCULATOR}')",
                )
            ]
        return []
