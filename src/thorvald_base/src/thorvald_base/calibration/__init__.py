"""Odometry calibration: each drive's effective rolling radius and steering offset from a recorded drive.

A built robot rolls on tyres of slightly different radii and its steering modules are homed a little
off (the paper, 3.3.2); its odometry drifts accordingly. From a drive recorded with ground truth, the
simulator's body twist or a GNSS fix with an IMU's yaw, :func:`calibrate` estimates by least squares
what base_driver should use instead (``r_wheel``, ``steering_offset`` per drive), with each value's
standard uncertainty, and says which parameters the drive did not excite (a straight line cannot
tell a steering offset from a heading). :func:`odometry_error` replays the drive through the robot's
own calculator to give the odometry error before and after; :mod:`.calibration_file` writes the
result as a file base_driver loads at start (``~calibration``) and reads it back, checked.

* :mod:`.recording`: the recorded drive and ground truth as numbers;
* :mod:`.estimate`: the model, the least squares, uncertainties and excitation;
* :mod:`.observable`: which combinations a drive determines through the odometry, and a fit of
  those alone, the rest kept at the values in effect;
* :mod:`.scale`: the radii's common factor alone, from straight legs between standstills;
* :mod:`.torque_balance`: each tyre's radius against the others', from the wheels' torques;
* :mod:`.odometry_error`: odometry against ground truth, before and after;
* :mod:`.calibration_file`: the file base_driver loads, and the set_drive_params call.

``rosrun thorvald_base calibrate_odometry BAG --robot-model FILE`` (thorvald_base.calibration_cli)
reads a bag into these and prints them. Pure: numpy, no rospy, no messages.
"""

from .calibration_file import (
    calibration_dict,
    calibration_yaml,
    load_calibration,
    parse_calibration,
    set_drive_params_command,
)
from .estimate import (
    GNSS,
    MAX_OFFSET_SD,
    MAX_RADIUS_SD,
    SIMULATOR,
    WINDOW,
    Calibration,
    ParameterEstimate,
    calibrate,
)
from .observable import Combination, ObservableFit, observable_fit
from .odometry_error import OdometryError, as_read_with, odometry_error, replay, truth_path
from .recording import DriveRecording, GnssTruth, PoseTruth, local_metres
from .scale import ScaleFit, common_scale

__all__ = [
    "GNSS",
    "MAX_OFFSET_SD",
    "MAX_RADIUS_SD",
    "SIMULATOR",
    "WINDOW",
    "Calibration",
    "Combination",
    "DriveRecording",
    "GnssTruth",
    "ObservableFit",
    "OdometryError",
    "ParameterEstimate",
    "PoseTruth",
    "ScaleFit",
    "as_read_with",
    "calibrate",
    "calibration_dict",
    "calibration_yaml",
    "common_scale",
    "load_calibration",
    "local_metres",
    "observable_fit",
    "odometry_error",
    "parse_calibration",
    "replay",
    "set_drive_params_command",
    "truth_path",
]
