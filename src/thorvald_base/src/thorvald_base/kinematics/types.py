"""Value types of the kinematics core, in SI units and the base_link frame (REP 103).

A steering angle is the direction a wheel rolls in, measured from base_link x towards y [rad]; a
wheel speed is the signed rim speed along that direction [m/s]. A type-1 (propulsion-only) drive
always has steering 0 and a signed speed.
"""

from dataclasses import dataclass
from typing import Optional, Tuple


@dataclass(frozen=True)
class Twist:
    """A body velocity in base_link: vx, vy [m/s], wz [rad/s]."""

    vx: float = 0.0
    vy: float = 0.0
    wz: float = 0.0

    def is_close(self, other: "Twist", tol: float = 1e-9) -> bool:
        return abs(self.vx - other.vx) <= tol and abs(self.vy - other.vy) <= tol and abs(self.wz - other.wz) <= tol


@dataclass(frozen=True)
class Pose:
    """A pose of base_link in the odom frame: x, y [m], yaw [rad] in (-pi, pi]."""

    x: float = 0.0
    y: float = 0.0
    yaw: float = 0.0


@dataclass(frozen=True)
class DriveCommand:
    """What one drive is told: steering angle [rad] and wheel rim speed [m/s]."""

    steering: float
    speed: float


@dataclass(frozen=True)
class DriveState:
    """What one drive measures (or the simulated drive reports).

    steering: steering angle [rad]; speed: wheel rim speed [m/s]; wheel_angle: integrated wheel
    rotation [rad] (joint position of the wheel, not used by odometry); heard: False when the drive's
    reports stopped (its values are the last ones heard, or none): odometry leaves it out.
    """

    steering: float
    speed: float
    wheel_angle: float = 0.0
    heard: bool = True


@dataclass(frozen=True)
class CommandResult:
    """Joint commands for a twist.

    requested: the twist asked for; twist: the twist the commands realise. changed is True when
    the robot cannot realise the requested twist (a wheel that cannot steer would have to slide)
    and the closest realisable one was commanded instead, so a node can warn.
    """

    commands: Tuple[DriveCommand, ...]
    twist: Twist
    requested: Twist
    changed: bool


@dataclass(frozen=True)
class OdometryResult:
    """Velocity estimate and integrated pose from one set of measured drive states.

    twist: estimated body velocity; pose: pose after integrating over dt [s]; residual: RMS over
    the drives of the difference between each measured wheel velocity vector and the one the
    estimated twist implies [m/s] (0 for wheels that agree; grows with slip and disagreement);
    valid: False when the calculator gave a non-finite twist, in which case the pose was not changed.

    unheard: the drives (indices) whose reports stopped or held no number: left out of the estimate.
    blind: the drives heard cannot determine the motion by themselves (none heard, or the
    differential robot's one wheel); the twist is then the heard drives' speed along the last
    commanded motion, or zero with none heard (see BaseCalculator.calculate_odometry).
    """

    twist: Twist
    pose: Pose
    residual: float
    dt: float
    valid: bool = True
    translating: Optional[bool] = None  # the paper estimator's translation test; None for least squares
    unheard: Tuple[int, ...] = ()
    blind: bool = False

    @property
    def degraded(self) -> bool:
        """Some drive is unheard: the estimate rests on fewer wheels than the robot has."""
        return bool(self.unheard)
