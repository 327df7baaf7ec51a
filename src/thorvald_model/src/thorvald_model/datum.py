"""A robot_localization datum file: where the world's origin is on the Earth, for simulated GNSS.

The original's launch files pass ``datum_file`` (robot_localization's format) to the model::

    datum: [53.268642, -0.524509, 0.0]   # latitude [deg], longitude [deg], heading [rad]

The heading is robot_localization's: the ENU yaw of the world's x axis (0 = east, counter-clockwise).
Further entries (robot_localization allows the world and base_link frame names after the three
numbers) are ignored; ``altitude`` [m] may be given as a key of its own. Pure: no ROS.
"""

import math
from dataclasses import dataclass
from typing import Any, Tuple

from .errors import MISSING, ConfigError, Problem
from .schema import read_yaml_file

WHAT = "datum file"
# WGS84, as GNSS receivers give latitude and longitude
WGS84_A = 6378137.0  # [m] equatorial radius
WGS84_F = 1.0 / 298.257223563  # flattening
WGS84_E2 = 2 * WGS84_F - WGS84_F * WGS84_F  # first eccentricity squared


def earth_radii(latitude: float) -> Tuple[float, float]:
    """(north, east) [m per radian] of latitude and of longitude at a latitude [deg]: WGS84's
    meridional radius of curvature, and the prime vertical's times cos(latitude). The simulated GNSS,
    the odometry report and the calibration convert between metres and degrees with these."""
    phi = math.radians(latitude)
    temp = 1.0 / (1.0 - WGS84_E2 * math.sin(phi) ** 2)
    prime_vertical = WGS84_A * math.sqrt(temp)
    return prime_vertical * (1.0 - WGS84_E2) * temp, prime_vertical * math.cos(phi)


@dataclass(frozen=True)
class Datum:
    latitude: float  # [deg]
    longitude: float  # [deg]
    yaw: float = 0.0  # [rad] ENU yaw of the world's x axis
    altitude: float = 0.0  # [m]

    @property
    def compass_heading(self) -> float:
        """[deg] the compass heading of the world's x axis (0 = north, clockwise), as hector's
        ``referenceHeading``: 90 - degrees(yaw)."""
        return 90.0 - math.degrees(self.yaw)

    @property
    def reference(self) -> Tuple[float, float, float, float]:
        """hector_gazebo_ros_gps's reference: (latitude, longitude, heading [deg], altitude)."""
        return (self.latitude, self.longitude, self.compass_heading, self.altitude)


def load_datum(path: str) -> Datum:
    """Reads and checks a datum file; ConfigError naming the file, the key, the value and the rule."""
    return parse_datum(read_yaml_file(path, WHAT), path)


def parse_datum(data: Any, source: str = "<datum>") -> Datum:
    if not isinstance(data, dict) or "datum" not in data:
        raise ConfigError(source, [Problem("datum", MISSING, "must be [latitude, longitude, heading]")], WHAT)
    raw = data["datum"]
    if not isinstance(raw, (list, tuple)) or len(raw) < 3:
        raise ConfigError(source, [Problem("datum", raw, "must be [latitude, longitude, heading]")], WHAT)
    problems = []
    values = []
    rules = (
        ("latitude", lambda v: -90.0 <= v <= 90.0, "must be in [-90, 90] [deg]"),
        ("longitude", lambda v: -180.0 <= v <= 180.0, "must be in [-180, 180] [deg]"),
        ("heading", math.isfinite, "must be a finite angle [rad]"),
    )
    for k, (name, check, rule) in enumerate(rules):
        value = raw[k]
        ok = isinstance(value, (int, float)) and not isinstance(value, bool) and math.isfinite(value)
        if not ok or not check(float(value)):
            problems.append(Problem(f"datum[{k}] ({name})", value, rule if ok else "must be a number; " + rule))
        values.append(float(value) if ok else 0.0)
    altitude = data.get("altitude", 0.0)
    if not isinstance(altitude, (int, float)) or isinstance(altitude, bool) or not math.isfinite(altitude):
        problems.append(Problem("altitude", altitude, "must be a finite number [m]"))
        altitude = 0.0
    if problems:
        raise ConfigError(source, problems, WHAT)
    return Datum(values[0], values[1], values[2], float(altitude))
