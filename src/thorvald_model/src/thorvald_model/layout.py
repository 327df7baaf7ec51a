"""The wheel layout rules every kinematics calculator shares, and the axle lines they rest on.

The one copy of these rules: the configuration loader reports them as problems of the file, and
base_driver's calculators (thorvald_base.kinematics) refuse a layout with the same words, take
their wheel constraints from :func:`axle_lines` too, and declare the rules of their own (which
layouts they can serve) on top (``BaseCalculator.layout_rules``).

A wheel that cannot steer (a type-1 drive, which rolls along base_link x, or a fixed passive wheel,
which rolls along its yaw) cannot slide sideways, so the robot's centre of rotation must lie on
that wheel's axle line. Two such wheels on different axle lines leave the robot able to turn only
by sliding, which no calculator can command; that is a layout error, not a calculator choice.

Functions take the drives (``Drive``: ``name``, ``steerable``, ``x``, ``y``) and passive wheels
(``PassiveWheel``: ``name``, ``fixed``, ``x``, ``y``, ``yaw``) of a configuration, so they serve a
whole file and a calculator handed its drives alike.
"""

import math
from dataclasses import dataclass
from typing import List, Optional, Sequence, Tuple

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


def shared_layout_problems(drives: Sequence, passive_wheels: Sequence = ()) -> List[Problem]:
    """The layout rules every calculator shares: wheels that cannot steer share one axle line.

    A calculator adds its own (``BaseCalculator.layout_rules`` in thorvald_base), checked after
    these, so a calculator of another package gets the same checks as the built-in ones.
    """
    return common_axle(drives, passive_wheels)[1]
