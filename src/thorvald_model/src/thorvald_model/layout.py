"""Which wheel layouts a robot may have, and which each built-in kinematics calculator can serve.

The one copy of these rules: the configuration loader reports them as problems of the file, and
base_driver's calculators (thorvald_base.kinematics) refuse a layout with the same words, and take
their wheel constraints from :func:`axle_lines` too.

A wheel that cannot steer (a type-1 drive, which rolls along base_link x, or a fixed passive wheel,
which rolls along its yaw) cannot slide sideways, so the robot's centre of rotation must lie on
that wheel's axle line. Two such wheels on different axle lines leave the robot able to turn only
by sliding, which no calculator can command; that is a layout error, not a calculator choice.

Functions take the drives (``Drive``: ``name``, ``steerable``, ``x``, ``y``) and passive wheels
(``PassiveWheel``: ``name``, ``fixed``, ``x``, ``y``, ``yaw``) of a configuration, so they serve a
whole file and a calculator handed its drives alike. Calculators from other packages are only
known to base_driver's plugin loader: their names get the common-axle rule alone here.
"""

import math
from dataclasses import dataclass
from typing import List, Optional, Sequence, Tuple

from .constants import DIFF_CALCULATOR, ONE_WHEEL_CALCULATOR, STD_CALCULATOR
from .errors import Problem

LINE_TOLERANCE = 1e-3  # [m] and [rad]: how far two axle lines may differ and still be one line


@dataclass(frozen=True)
class AxleLine:
    """The axle line of a wheel that cannot steer: through its contact (x, y), along (dx, dy).

    (dx, dy) is the unit axle direction, across the wheel; the wheel rolls along (dy, -dx). The
    centre of rotation of the robot lies on this line, which in terms of the body twist
    t = (vx, vy, wz) is the constraint ``constraint . t = 0``.
    """

    path: str  # dotted key path of the wheel, e.g. "passive_wheels.passive0"
    x: float  # [m]
    y: float  # [m]
    dx: float
    dy: float

    @property
    def rolling(self) -> Tuple[float, float]:
        """Unit direction in which the wheel rolls."""
        return self.dy, -self.dx

    @property
    def moment(self) -> float:
        """x dy - y dx [m]: the contact's velocity across the axle is (vx, vy) . (dx, dy) + wz moment."""
        return self.x * self.dy - self.y * self.dx

    @property
    def constraint(self) -> Tuple[float, float, float]:
        """Row a with a . (vx, vy, wz) = 0 for every twist that does not make the wheel slide."""
        return self.dx, self.dy, self.moment

    def distance(self, x: float, y: float) -> float:
        return abs((x - self.x) * self.dy - (y - self.y) * self.dx)

    def same_line(self, other: "AxleLine") -> bool:
        parallel = abs(self.dx * other.dy - self.dy * other.dx) < LINE_TOLERANCE
        return parallel and self.distance(other.x, other.y) < LINE_TOLERANCE


def axle_lines(drives: Sequence, passive_wheels: Sequence = ()) -> List[AxleLine]:
    """Axle lines of every wheel that cannot steer: type-1 drives, then fixed passive wheels."""
    lines = []
    for d in drives:
        if not d.steerable:
            lines.append(AxleLine("motor_drives." + d.name, d.x, d.y, 0.0, 1.0))
    for w in passive_wheels:
        if w.fixed:
            lines.append(AxleLine("passive_wheels." + w.name, w.x, w.y, -math.sin(w.yaw), math.cos(w.yaw)))
    return lines


def common_axle(drives: Sequence, passive_wheels: Sequence = ()) -> Tuple[Optional[AxleLine], List[Problem]]:
    """The one axle line all non-steering wheels share (None if there are none), and the problems."""
    lines = axle_lines(drives, passive_wheels)
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


def layout_problems(calculator: str, drives: Sequence, passive_wheels: Sequence = ()) -> List[Problem]:
    """Every rule of the layout the named calculator would serve that these wheels break."""
    axle, problems = common_axle(drives, passive_wheels)
    if problems:
        return problems
    steered = [d for d in drives if d.steerable]
    path = "base_calculator"
    if calculator == STD_CALCULATOR:
        if axle is None and len(steered) < 2:
            problems.append(
                Problem(
                    path,
                    calculator,
                    "a single steered drive on casters cannot hold the robot's heading: the standard calculator "
                    "needs two steered drives or a fixed axle (for one drive with fixed support wheels use "
                    f"'{ONE_WHEEL_CALCULATOR}')",
                )
            )
    elif calculator == DIFF_CALCULATOR:
        diff = [d for d in drives if not d.steerable]
        if len(drives) != 2 or len(diff) != 2:
            problems.append(
                Problem(
                    path,
                    calculator,
                    "the differential calculator serves exactly two type-1 drives; this robot has "
                    f"{len(drives)} drives, {len(diff)} of type 1",
                )
            )
        elif abs(diff[0].y - diff[1].y) < LINE_TOLERANCE:
            problems.append(
                Problem(
                    path, calculator, "the differential calculator needs its two wheels on either side (different y)"
                )
            )
    elif calculator == ONE_WHEEL_CALCULATOR:
        if len(drives) != 1 or not steered:
            problems.append(
                Problem(path, calculator, "the one-wheel-drive calculator serves exactly one type-0 (steered) drive")
            )
        elif axle is None:
            problems.append(
                Problem(
                    path,
                    calculator,
                    "the one-wheel-drive calculator needs fixed passive wheels: their axle line is where the "
                    "centre of rotation can lie",
                )
            )
        elif axle.distance(drives[0].x, drives[0].y) < LINE_TOLERANCE:
            problems.append(
                Problem(
                    "motor_drives." + drives[0].name,
                    {"x": drives[0].x, "y": drives[0].y},
                    "the single drive must not stand on the fixed wheels' axle line, or it cannot steer the robot",
                )
            )
    return problems
