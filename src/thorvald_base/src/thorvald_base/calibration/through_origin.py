"""A straight line through the origin, y = s x, by least squares, and its slope's standard uncertainty
from the points' scatter about it (nan from a single point): the turns' gain, the straight legs'
factor and heading. Pure: numpy."""

import math
from typing import Tuple

import numpy as np


def slope_sd(x, y, slope: float) -> float:
    """The standard uncertainty of slope as a regression of y on x through the origin."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if len(x) < 2:
        return math.nan
    rest = y - slope * x
    return float(math.sqrt(rest @ rest / (len(x) - 1) / (x @ x)))


def through_origin(x, y) -> Tuple[float, float]:
    """(slope, its standard uncertainty) of y = slope x by least squares."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    slope = float(x @ y / (x @ x))
    return slope, slope_sd(x, y, slope)


__all__ = ["slope_sd", "through_origin"]
