"""A recorded drive as numbers: the drive states base_driver read, and ground truth of two kinds.

* :class:`DriveRecording`: per sample time, each drive's steering angle [rad] and rim speed [m/s] as
  base_driver read them (``base_state``), with the configuration in effect at the time.
* :class:`PoseTruth`: the simulator's ground truth (``odometry/gazebo``): base_link's pose in a fixed
  frame and its body twist.
* :class:`GnssTruth`: what a real robot has instead: an antenna's positions (a GNSS fix, converted to
  local metres around the first one with :func:`local_metres`) and an IMU's yaw, whose constant
  bias against the positions' east/north frame is unknown (the calibration estimates it).

Pure: numpy arrays in SI units, no messages. Samples are sorted by time; non-finite ones dropped.
"""

from dataclasses import dataclass
from typing import Sequence, Tuple

import numpy as np

from thorvald_model.datum import WGS84_A, WGS84_E2, earth_radii  # noqa: F401  (the constants: for tests)

from ..errors import CalibrationError


def _sorted(t, *series):
    t = np.asarray(t, dtype=float)
    series = [np.asarray(s, dtype=float) for s in series]
    ok = np.isfinite(t)
    for s in series:
        ok &= np.all(np.isfinite(s.reshape(len(t), -1)), axis=1)
    order = np.argsort(t[ok], kind="stable")
    t, series = t[ok][order], [s[ok][order] for s in series]
    first = np.concatenate([[True], np.diff(t) > 0])  # a time recorded twice: the first sample of it
    return (t[first], *(s[first] for s in series))


@dataclass(frozen=True, eq=False)
class DriveRecording:
    """Drive states as base_driver read them: t (N,) [s], steering (N, D) [rad], speed (N, D) [m/s]."""

    t: np.ndarray
    steering: np.ndarray
    speed: np.ndarray

    @classmethod
    def from_samples(cls, samples: Sequence[Tuple[float, Sequence[float], Sequence[float]]], drives: int):
        """From (t, steering per drive, rim speed per drive) samples; CalibrationError if a sample
        does not hold one value per drive."""
        for t, steering, speed in samples:
            if len(steering) != drives or len(speed) != drives:
                raise CalibrationError(
                    f"a drive state at {t:.3f} s holds {len(steering)} steering angles and {len(speed)} rim speeds "
                    f"for a robot of {drives} drives: recorded with another robot file?"
                )
        t = [s[0] for s in samples]
        steering = np.reshape([s[1] for s in samples], (len(samples), drives))
        speed = np.reshape([s[2] for s in samples], (len(samples), drives))
        return cls(*_sorted(t, steering, speed))

    @property
    def drives(self) -> int:
        return self.steering.shape[1]

    def __len__(self) -> int:
        return len(self.t)


@dataclass(frozen=True, eq=False)
class PoseTruth:
    """base_link's pose (x, y [m], yaw [rad], fixed frame) and body twist (vx, vy [m/s], wz [rad/s])."""

    t: np.ndarray
    x: np.ndarray
    y: np.ndarray
    yaw: np.ndarray
    vx: np.ndarray
    vy: np.ndarray
    wz: np.ndarray

    @classmethod
    def from_samples(cls, samples: Sequence[Tuple[float, float, float, float, float, float, float]]):
        """From (t, x, y, yaw, vx, vy, wz) samples."""
        rows = np.reshape(np.asarray(samples, dtype=float), (len(samples), 7))
        t, rest = _sorted(rows[:, 0], rows[:, 1:])
        x, y, yaw, vx, vy, wz = rest.T
        return cls(t, x, y, np.unwrap(yaw), vx, vy, wz)

    def __len__(self) -> int:
        return len(self.t)


@dataclass(frozen=True, eq=False)
class GnssTruth:
    """An antenna's fixes and an IMU's yaw.

    t_fix (M,) [s], east and north (M,) [m] in a local frame (:func:`local_metres`); t_yaw (K,) [s] and
    yaw (K,) [rad] the IMU's, unwrapped, whose zero may differ from east by an unknown constant;
    antenna: the antenna's position in base_link [m] (its lever arm when the robot turns).
    """

    t_fix: np.ndarray
    east: np.ndarray
    north: np.ndarray
    t_yaw: np.ndarray
    yaw: np.ndarray
    antenna: Tuple[float, float] = (0.0, 0.0)

    @classmethod
    def from_samples(
        cls,
        fixes: Sequence[Tuple[float, float, float]],
        yaws: Sequence[Tuple[float, float]],
        antenna: Tuple[float, float] = (0.0, 0.0),
    ):
        """From (t, east, north) fixes [s, m, m] and (t, yaw) IMU samples [s, rad]."""
        f = np.reshape(np.asarray(fixes, dtype=float), (len(fixes), 3))
        y = np.reshape(np.asarray(yaws, dtype=float), (len(yaws), 2))
        t_fix, en = _sorted(f[:, 0], f[:, 1:])
        t_yaw, yaw = _sorted(y[:, 0], y[:, 1])
        return cls(t_fix, en[:, 0], en[:, 1], t_yaw, np.unwrap(yaw), (float(antenna[0]), float(antenna[1])))

    def yaw_at(self, t) -> np.ndarray:
        """The IMU's yaw [rad] at times t, linearly interpolated (unwrapped)."""
        return np.interp(t, self.t_yaw, self.yaw)

    def __len__(self) -> int:
        return len(self.t_fix)


def local_metres(latitude: Sequence[float], longitude: Sequence[float]) -> Tuple[np.ndarray, np.ndarray]:
    """(east, north) [m] of fixes [deg] around the first one, with the WGS84 radii of curvature at its
    latitude: exact to about 1e-6 relative over the few hundred metres of a calibration drive."""
    lat = np.asarray(latitude, dtype=float)
    lon = np.asarray(longitude, dtype=float)
    if not len(lat):
        return np.zeros(0), np.zeros(0)
    radius_north, radius_east = earth_radii(float(lat[0]))
    east = np.radians(lon - lon[0]) * radius_east
    north = np.radians(lat - lat[0]) * radius_north
    return east, north


__all__ = ["DriveRecording", "GnssTruth", "PoseTruth", "local_metres"]
