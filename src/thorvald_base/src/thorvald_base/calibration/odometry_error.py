"""Odometry against ground truth, before and after calibration, as the paper measured it (3.3.2).

The recorded drive states are replayed through the robot's own calculator (its ``base_calculator``,
loaded as base_driver loads it; the kinematics exist once, in :mod:`thorvald_base.kinematics`):
with the configuration in effect they give the odometry base_driver computed; rewritten as base_driver
would have read them with the calibrated configuration (:func:`as_read_with`: steering + the change
of offset, rim speed x the ratio of radii) they give the calibrated robot's odometry on the same drive.

Both paths are compared with ground truth at its sample times, each in the frame of its own pose at
the first of them (as the paper's Figure 8 starts both at one point). The distance error is that of
the path lengths [%], taken at ground truth's instants for both paths: every sample of the
simulator's (as odometry_report takes them), and fixes at least STEP apart along the path for GNSS,
so that 2 cm of noise between fixes 10 cm apart does not add itself to the true distance (it would,
by about 4 %). The end-point difference is the distance between the two paths' last points [m].

Pure: no rospy, no messages.
"""

import math
from dataclasses import dataclass
from typing import Callable, Tuple, Union

import numpy as np

from thorvald_model.values import RobotConfig

from ..errors import CalibrationError
from ..kinematics import DriveState
from ..kinematics.calculator import NO_CORRECTION, OdometryCorrection
from ..plugins import load_calculator
from .recording import DriveRecording, GnssTruth, PoseTruth

STEP = 1.0  # [m] along GNSS ground truth between the fixes path lengths are taken at
BIAS_WINDOW = 2.0  # [s] between the fixes imu_bias compares (the drive fit's windows)


@dataclass(frozen=True)
class OdometryError:
    distance_error_percent: float  # [%] of ground truth's distance
    end_point_m: float  # [m] between the end points
    distance_m: float  # [m] odometry's
    truth_distance_m: float  # [m] ground truth's


Path = Tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]  # t [s], x, y [m], yaw [rad]


def as_read_with(recording: DriveRecording, in_effect: RobotConfig, calibrated: RobotConfig) -> DriveRecording:
    """The drive states base_driver would have read with the calibrated configuration: it reads
    steering + steering_offset and rim speeds from wheel turns x r_wheel."""
    offset = np.array([c.steering_offset - e.steering_offset for e, c in zip(in_effect.drives, calibrated.drives)])
    ratio = np.array([c.r_wheel / e.r_wheel for e, c in zip(in_effect.drives, calibrated.drives)])
    return DriveRecording(recording.t, recording.steering + offset, recording.speed * ratio)


def replay(
    config: RobotConfig,
    recording: DriveRecording,
    calculator_for: Callable = load_calculator,
    *,
    correction: OdometryCorrection = NO_CORRECTION,
) -> Path:
    """base_driver's odometry of the recorded states with this configuration (and the calibration's
    odometry correction): its pose at each."""
    calc = calculator_for(config)
    calc.odometry_correction = correction
    poses = np.zeros((len(recording), 3))
    for n, (t, steering, speed) in enumerate(zip(recording.t, recording.steering, recording.speed)):
        pose = calc.calculate_odometry([DriveState(a, v) for a, v in zip(steering, speed)], float(t)).pose
        poses[n] = pose.x, pose.y, pose.yaw
    return recording.t, poses[:, 0], poses[:, 1], np.unwrap(poses[:, 2])


def truth_path(truth: Union[PoseTruth, GnssTruth], heading_bias: float = 0.0) -> Path:
    """base_link's path in ground truth; from GNSS, the antenna's fixes less its lever arm turned by
    the heading (the IMU's yaw + heading_bias [rad])."""
    if isinstance(truth, PoseTruth):
        return truth.t, truth.x, truth.y, truth.yaw
    heading = truth.yaw_at(truth.t_fix) + heading_bias
    ax, ay = truth.antenna
    x = truth.east - (np.cos(heading) * ax - np.sin(heading) * ay)
    y = truth.north - (np.sin(heading) * ax + np.cos(heading) * ay)
    return truth.t_fix, x, y, heading


def imu_bias(
    config: RobotConfig,
    recording: DriveRecording,
    truth: GnssTruth,
    calculator_for: Callable = load_calculator,
    *,
    correction: OdometryCorrection = NO_CORRECTION,
    window: float = BIAS_WINDOW,
) -> float:
    """[rad] the IMU yaw's bias against the fixes' east/north frame, from the fixes and odometry's
    translation: over windows between fixes, the fixes' displacement against odometry's, turned into
    east/north by the IMU's yaw (less odometry's own at the window's start), by least squares on the
    angle alone. What an end-point figure against GNSS needs when no drive fit estimated the bias (a
    hector GNSS with reference heading 0 puts the simulator's x north, so the IMU's yaw reads 90 degrees
    off east: taken as 0, the turns drive's end point read 6 m off where it was 0.6 m)."""
    t_odo, x_odo, y_odo, yaw_odo = replay(config, recording, calculator_for, correction=correction)
    inside = (truth.t_fix >= t_odo[0]) & (truth.t_fix <= t_odo[-1])
    t, east, north = truth.t_fix[inside], truth.east[inside], truth.north[inside]
    if len(t) < 2:
        raise CalibrationError("the ground truth and the drive states do not overlap in time")
    ends = np.searchsorted(t, t + window)
    a = np.flatnonzero(ends < len(t))
    b = ends[a]
    fixes = (east[b] - east[a]) + 1j * (north[b] - north[a])
    ox, oy, oyaw = (np.interp(t, t_odo, v) for v in (x_odo, y_odo, yaw_odo))
    odometry = ((ox[b] - ox[a]) + 1j * (oy[b] - oy[a])) * np.exp(1j * (truth.yaw_at(t[a]) - oyaw[a]))
    total = np.sum(fixes * np.conj(odometry))
    return float(np.angle(total)) if abs(total) > 0.0 else 0.0


def odometry_error(
    config: RobotConfig,
    recording: DriveRecording,
    truth: Union[PoseTruth, GnssTruth],
    heading_bias: float = 0.0,
    calculator_for: Callable = load_calculator,
    *,
    correction: OdometryCorrection = NO_CORRECTION,
) -> OdometryError:
    """The replayed odometry's distance error and end-point difference against ground truth."""
    t_odo, x_odo, y_odo, yaw_odo = replay(config, recording, calculator_for, correction=correction)
    t, x, y, yaw = truth_path(truth, heading_bias)
    inside = (t >= t_odo[0]) & (t <= t_odo[-1])
    if np.count_nonzero(inside) < 2:
        raise CalibrationError("the ground truth and the drive states do not overlap in time")
    t, x, y, yaw = t[inside], x[inside], y[inside], yaw[inside]
    odo = [np.interp(t, t_odo, v) for v in (x_odo, y_odo, yaw_odo)]
    truth_xy = _from_start(x, y, yaw[0])
    odo_xy = _from_start(odo[0], odo[1], odo[2][0])
    along = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(x), np.diff(y)))])
    points = _points_apart(along) if isinstance(truth, GnssTruth) else np.arange(len(t))
    d_truth = _length(truth_xy[:, points])
    d_odo = _length(odo_xy[:, points])
    error = (d_odo - d_truth) / d_truth * 100.0 if d_truth > 0 else math.nan
    end = float(np.hypot(*(odo_xy[:, -1] - truth_xy[:, -1])))
    return OdometryError(float(error), end, d_odo, d_truth)


def _from_start(x, y, yaw0) -> np.ndarray:
    """Points (2, N) in the frame of the first one, turned by yaw0 [rad]."""
    dx, dy = x - x[0], y - y[0]
    c, s = math.cos(yaw0), math.sin(yaw0)
    return np.vstack([c * dx + s * dy, -s * dx + c * dy])


def _points_apart(along: np.ndarray) -> np.ndarray:
    """Indices of the first point, each first point STEP further along, and the last point."""
    steps = np.floor(along / STEP)
    first = np.concatenate([[True], np.diff(steps) > 0])
    first[-1] = True
    return np.flatnonzero(first)


def _length(points: np.ndarray) -> float:
    return float(np.sum(np.hypot(*np.diff(points, axis=1))))


__all__ = ["BIAS_WINDOW", "STEP", "OdometryError", "as_read_with", "imu_bias", "odometry_error", "replay", "truth_path"]
