"""Which wheel layouts each built-in kinematics calculator can serve.

A wheel that cannot steer (a type-1 drive, which rolls along base_link x, or a fixed passive wheel)
cannot slide sideways, so the robot's centre of rotation must lie on that wheel's axle line. Two
such wheels on different axle lines leave the robot able to turn only by sliding, which no
calculator can command; that is a layout error, not a calculator choice.

Calculators from other packages are only known to base_driver's plugin loader, so their names pass
here unchecked and base_driver checks them when it loads them.
"""

import math
from dataclasses import dataclass
from typing import List, Optional, Tuple

from .constants import DIFF_CALCULATOR, DRIVE_DIFF, ONE_WHEEL_CALCULATOR, STD_CALCULATOR
from .errors import Problem

LINE_TOLERANCE = 1e-3  # [m] and [rad]: how far two axle lines may differ and still be one line


@dataclass(frozen=True)
class AxleLine:
    """The line a non-steering wheel's centre of rotation must lie on: through (x, y), along (dx, dy)."""

    path: str
    x: float
    y: float
    dx: float
    dy: float

    def distance(self, x: float, y: float) -> float:
        return abs((x - self.x) * self.dy - (y - self.y) * self.dx)

    def same_line(self, other: "AxleLine") -> bool:
        parallel = abs(self.dx * other.dy - self.dy * other.dx) < LINE_TOLERANCE
        return parallel and self.distance(other.x, other.y) < LINE_TOLERANCE


def axle_lines(config) -> List[AxleLine]:
    """Axle lines of every wheel that cannot steer: type-1 drives and fixed passive wheels."""
    lines = []
    for d in config.drives:
        if d.type == DRIVE_DIFF:
            lines.append(AxleLine("motor_drives." + d.name, d.x, d.y, 0.0, 1.0))
    for w in config.passive_wheels:
        if w.fixed:
            lines.append(AxleLine("passive_wheels." + w.name, w.x, w.y, -math.sin(w.yaw), math.cos(w.yaw)))
    return lines


def common_axle(config) -> Tuple[Optional[AxleLine], List[Problem]]:
    """The one axle line all non-steering wheels share (None if there are none), and the problems."""
    lines = axle_lines(config)
    problems = []
    for line in lines[1:]:
        if not lines[0].same_line(line):
            problems.append(
                Problem(
                    line.path,
                    {"x": line.x, "y": line.y},
                    "wheels that cannot steer must share one axle line, or the robot cannot turn without "
                    f"sliding; this one's axle differs from {lines[0].path}'s",
                )
            )
    return (lines[0] if lines else None), problems


def layout_problems(config) -> List[Problem]:
    axle, problems = common_axle(config)
    if problems:
        return problems
    calc = config.base_calculator
    steered = config.steered_drives
    path = "base_calculator"
    if calc == STD_CALCULATOR:
        if axle is None and len(steered) < 2:
            problems.append(
                Problem(
                    path,
                    calc,
                    "a single steered drive on casters cannot hold the robot's heading: the standard calculator "
                    "needs two steered drives or a fixed axle (for one drive with fixed support wheels use "
                    f"'{ONE_WHEEL_CALCULATOR}')",
                )
            )
    elif calc == DIFF_CALCULATOR:
        diff = [d for d in config.drives if d.type == DRIVE_DIFF]
        if len(config.drives) != 2 or len(diff) != 2:
            problems.append(
                Problem(
                    path,
                    calc,
                    "the differential calculator serves exactly two type-1 drives; this robot has "
                    f"{len(config.drives)} drives, {len(diff)} of type 1",
                )
            )
        elif abs(diff[0].y - diff[1].y) < LINE_TOLERANCE:
            problems.append(
                Problem(path, calc, "the differential calculator needs its two wheels on either side (different y)")
            )
    elif calc == ONE_WHEEL_CALCULATOR:
        if len(config.drives) != 1 or not config.drives[0].steerable:
            problems.append(
                Problem(path, calc, "the one-wheel-drive calculator serves exactly one type-0 (steered) drive")
            )
        elif axle is None:
            problems.append(
                Problem(
                    path,
                    calc,
                    "the one-wheel-drive calculator needs fixed passive wheels: their axle line is where the "
                    "centre of rotation can lie",
                )
            )
        elif axle.distance(config.drives[0].x, config.drives[0].y) < LINE_TOLERANCE:
            problems.append(
                Problem(
                    "motor_drives." + config.drives[0].name,
                    {"x": config.drives[0].x, "y": config.drives[0].y},
                    "the single drive must not stand on the fixed wheels' axle line, or it cannot steer the robot",
                )
            )
    return problems
