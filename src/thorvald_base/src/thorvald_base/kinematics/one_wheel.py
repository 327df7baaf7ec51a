"""The one-wheel-drive calculator, ``pltf_clc_1wd::PltfClc1WD`` (a design of ours: notes 3.3 found none)."""

from thorvald_model.constants import ONE_WHEEL_CALCULATOR
from thorvald_model.errors import Problem
from thorvald_model.layout import LINE_TOLERANCE

from .calculator import BaseCalculator


class PltfClc1WD(BaseCalculator):
    """One steered drive supported by passive wheels, of which the fixed ones share one axle line.

    The fixed wheels cannot slide, so the centre of rotation lies on their axle line, and the one
    drive's steering angle picks where on it: the robot moves like a tricycle (or a forklift with
    the steered wheel behind). Realisable twists are those with no velocity across the axle at the
    fixed wheels; any other twist is made realisable by the calculator's projection (by default:
    wz and the speed along the fixed wheels kept, the centre of rotation on the axle at vx / wz)
    and reported as changed.

    Odometry: the drive's velocity vector gives two equations and the axle one more, so both
    estimators are exact for one drive (the original left the pose unchanged with one drive).
    """

    name = ONE_WHEEL_CALCULATOR

    @classmethod
    def layout_rules(cls, drives, passive_wheels, axle):
        if len(drives) != 1 or not drives[0].steerable:
            rule = "the one-wheel-drive calculator serves exactly one type-0 (steered) drive"
            return [Problem("base_calculator", cls.name, rule)]
        if axle is None:
            rule = (
                "the one-wheel-drive calculator needs fixed passive wheels: their axle line is where the "
                "centre of rotation can lie"
            )
            return [Problem("base_calculator", cls.name, rule)]
        drive = drives[0]
        if axle.distance(drive.x, drive.y) < LINE_TOLERANCE:
            rule = "the single drive must not stand on the fixed wheels' axle line, or it cannot steer the robot"
            return [Problem("motor_drives." + drive.name, {"x": drive.x, "y": drive.y}, rule)]
        return []
