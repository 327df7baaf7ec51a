"""The kinematics core (paper sections 3.1 to 3.3): calculators, odometry and the drive layer.

Pure Python: no rospy, no messages, no pybullet. SI units throughout, base_link frame (REP 103).
"""

from .calculator import BaseCalculator, OdometryCorrection
from .diff import PltfClc2WDiff
from .drive import DriveLayer, DriveLayerOutput, SimulatedDrive, SteeringInverter, limit_wheel_speeds
from .odometry import LeastSquaresEstimator, PaperEstimator, integrate_se2, normalize_angle
from .one_wheel import PltfClc1WD
from .std import PltfClcStd
from .types import CommandResult, DriveCommand, DriveState, OdometryResult, Pose, Twist

__all__ = [
    "BaseCalculator",
    "CommandResult",
    "DriveCommand",
    "DriveLayer",
    "DriveLayerOutput",
    "DriveState",
    "LeastSquaresEstimator",
    "OdometryCorrection",
    "OdometryResult",
    "PaperEstimator",
    "PltfClc1WD",
    "PltfClc2WDiff",
    "PltfClcStd",
    "Pose",
    "SimulatedDrive",
    "SteeringInverter",
    "Twist",
    "integrate_se2",
    "limit_wheel_speeds",
    "normalize_angle",
]
