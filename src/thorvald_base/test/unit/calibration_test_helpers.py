"""Synthetic recorded drives with known as-built parameters, made with the workspace's own kinematics.

A drive is a list of (duration [s], Twist) segments. At every sample the robot's calculator gives the
true steering angle φ and rim speed v of each wheel for the twist (every contact point moves as the
rigid body says); what base_driver, running on the configuration in effect (r_eff, δ_eff), reads of
a wheel that really rolls with r_true and stands δ_true to the left of its reading is then::

    θ = φ − (δ_true − δ_eff),    s = v · r_eff / r_true

Ground truth integrates the same twists (those the calculator realises) with
thorvald_base.kinematics.integrate_se2, each held over the interval before its sample (as
base_driver's odometry integrates measured states), so a replay of the calibrated drive must give
ground truth back exactly. GNSS ground truth is the antenna's
position (base_link + the heading turned lever arm) every ``fix_every`` samples, and the IMU's yaw
is the heading less its bias ψ.
"""

import math
from dataclasses import dataclass
from typing import List, Optional, Sequence, Tuple

import numpy as np

from thorvald_base.calibration import DriveRecording, GnssTruth, PoseTruth
from thorvald_base.kinematics import Pose, Twist, integrate_se2
from thorvald_base.plugins import load_calculator

RATE = 50.0  # [Hz] base_driver's cycle


@dataclass
class Synthetic:
    recording: DriveRecording
    pose_truth: PoseTruth
    gnss_truth: GnssTruth
    twists: List[Twist]


def synthetic_drive(
    config,
    segments: Sequence[Tuple[float, Twist]],
    radii: Sequence[float],
    offsets: Sequence[float],
    *,
    heading_bias: float = 0.0,
    antenna: Tuple[float, float] = (0.0, 0.0),
    fix_every: int = 5,
    start: Optional[Pose] = None,
    noise: Optional[dict] = None,
    seed: int = 0,
) -> Synthetic:
    """noise: standard deviations of what is added, any of ``twist`` [m/s, rad/s] (the simulator's
    twist), ``fix`` [m] (each GNSS coordinate), ``yaw`` [rad] (the IMU's), ``speed`` [m/s] and
    ``steering`` [rad] (the drive states read)."""
    noise = noise or {}
    start = start or Pose(1.5, -2.0, 0.4)
    rng = np.random.default_rng(seed)
    calc = load_calculator(config)
    twists = [twist for duration, twist in segments for _ in range(round(duration * RATE))]
    twists = [Twist(), *twists, Twist()]
    n = len(twists)
    t = 100.0 + np.arange(n) / RATE
    eff_r = np.array([d.r_wheel for d in config.drives])
    eff_offset = np.array([d.steering_offset for d in config.drives])
    steering = np.zeros((n, len(config.drives)))
    speed = np.zeros_like(steering)
    poses = [start]
    for j, asked in enumerate(twists):
        # a robot with a fixed axle realises a twist of its own (the calculator's projection)
        result = calc.calculate_command(asked)
        commands, twist = result.commands, result.twist
        twists[j] = twist
        phi = np.array([c.steering for c in commands])
        v = np.array([c.speed for c in commands])
        steering[j] = phi - (np.asarray(offsets) - eff_offset)
        speed[j] = v * eff_r / np.asarray(radii)
        if j:
            poses.append(integrate_se2(poses[-1], twist, 1.0 / RATE))
    x = np.array([p.x for p in poses])
    y = np.array([p.y for p in poses])
    yaw = np.unwrap([p.yaw for p in poses])
    vx, vy, wz = (np.array([getattr(tw, name) for tw in twists]) for name in ("vx", "vy", "wz"))
    steered = np.array([d.steerable for d in config.drives])
    steering += steered * rng.normal(0.0, noise.get("steering", 0.0), steering.shape)
    speed += rng.normal(0.0, noise.get("speed", 0.0), speed.shape)
    tw = noise.get("twist", 0.0)
    pose_truth = PoseTruth(
        t, x, y, yaw, vx + rng.normal(0, tw, n), vy + rng.normal(0, tw, n), wz + rng.normal(0, tw, n)
    )
    fixes = np.arange(0, n, fix_every)
    east = x + np.cos(yaw) * antenna[0] - np.sin(yaw) * antenna[1]
    north = y + np.sin(yaw) * antenna[0] + np.cos(yaw) * antenna[1]
    sd_fix = noise.get("fix", 0.0)
    gnss = GnssTruth(
        t[fixes],
        east[fixes] + rng.normal(0, sd_fix, len(fixes)),
        north[fixes] + rng.normal(0, sd_fix, len(fixes)),
        t,
        yaw - heading_bias + rng.normal(0, noise.get("yaw", 0.0), n),
        antenna,
    )
    return Synthetic(DriveRecording(t, steering, speed), pose_truth, gnss, twists)


# A drive that turns both ways, crabs and spins: every parameter is excited.
MIXED = (
    (4.0, Twist(1.0, 0.0, 0.0)),
    (6.0, Twist(0.8, 0.0, 0.35)),
    (5.0, Twist(0.6, 0.3, -0.2)),
    (3.0, Twist(0.0, 0.0, 0.6)),
    (6.0, Twist(0.9, -0.2, -0.3)),
    (4.0, Twist(0.5, 0.4, 0.0)),
)
# Differential robots do only vx and wz.
DIFF_DRIVE = (
    (4.0, Twist(0.8, 0.0, 0.0)),
    (6.0, Twist(0.6, 0.0, 0.5)),
    (5.0, Twist(0.7, 0.0, -0.4)),
    (3.0, Twist(0.0, 0.0, 0.8)),
)
STRAIGHT = ((30.0, Twist(1.0, 0.0, 0.0)),)

DEG = math.pi / 180.0


def with_turn_slip(drive: Synthetic, left: float, right: float, start: Optional[Pose] = None) -> Synthetic:
    """The drive's ground truth as if the body turned left turns ``left`` times and right turns ``right``
    times as fast as the wheels say (tyres that slip in a turn), the translation in base_link kept; the
    drive states are the same. The IMU reads that heading (no bias)."""
    start = start or Pose(drive.pose_truth.x[0], drive.pose_truth.y[0], float(drive.pose_truth.yaw[0]))
    poses = [start]
    for twist in drive.twists[1:]:
        gain = left if twist.wz > 0 else right
        poses.append(integrate_se2(poses[-1], Twist(twist.vx, twist.vy, twist.wz * gain), 1.0 / RATE))
    t = drive.pose_truth.t
    x = np.array([p.x for p in poses])
    y = np.array([p.y for p in poses])
    yaw = np.unwrap([p.yaw for p in poses])
    wz = np.array([tw.wz * (left if tw.wz > 0 else right) for tw in drive.twists])
    truth = PoseTruth(t, x, y, yaw, drive.pose_truth.vx, drive.pose_truth.vy, wz)
    gnss = GnssTruth(t[::5], x[::5], y[::5], t, yaw)
    return Synthetic(drive.recording, truth, gnss, drive.twists)
