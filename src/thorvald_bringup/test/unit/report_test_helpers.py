"""Synthetic drives for the odometry report's tests: a robot that follows twists exactly.

Ground truth integrates the twists; the drive states are what the robot's calculator commands for
them (scaled by ``wheel_scale``, as wheels of a wrong radius would measure), and base_driver's
odometry is the lsq replay of those states, so a test knows every expected figure in closed form.
"""

import math
import os

from thorvald_base.kinematics import Pose, Twist, integrate_se2
from thorvald_base.plugins import load_calculator
from thorvald_bringup.odometry_report import Path, Recording, replay
from thorvald_model import load_robot_config

CONFIG_DIR = os.path.join(os.path.dirname(__file__), "..", "..", "..", "thorvald_model", "config")
RATE = 50.0  # [Hz] of base_driver's cycle and the recorded odometry


def robot(name="thorvald_ii_6wd6ws_asym"):
    return load_robot_config(os.path.join(CONFIG_DIR, name, name + ".yaml"))


def calculators(config, names=("lsq", "paper")):
    return {n: load_calculator(config, estimator=n, seed=0) for n in names}


def moved(origin, pose):
    """pose (in a frame whose origin sits at `origin` of the world) in world coordinates."""
    c, s = math.cos(origin[2]), math.sin(origin[2])
    return (origin[0] + c * pose.x - s * pose.y, origin[1] + s * pose.x + c * pose.y, origin[2] + pose.yaw)


def synthetic(
    config, legs, *, wheel_scale=1.0, lead=1.0, tail=3.0, truth_origin=(0.0, 0.0, 0.0), odom_origin=(0.0, 0.0, 0.0)
):
    """A Recording of a robot driving legs [(Twist, seconds)], standing still lead s before and tail s after.

    The robot starts at truth_origin in the simulator's frame and odom_origin in base_driver's.
    """
    calc = load_calculator(config)
    dt = 1.0 / RATE
    commands, states = [], []
    truth, pose = Path(), Pose()
    t = 10.0
    truth.append(t, moved(truth_origin, pose), (0.0, 0.0, 0.0))
    states.append((t, tuple(0.0 for _ in config.drives), tuple(0.0 for _ in config.drives)))
    timeline = [(Twist(), lead), *legs, (Twist(), tail)]
    for twist, seconds in timeline:
        steps = round(seconds * RATE)
        result = calc.calculate_command(twist)
        for k in range(steps):
            # a command at t moves the robot over [t, t + dt]; base_driver measures that motion at t + dt
            if k % 2 == 0 and (twist.vx or twist.vy or twist.wz or commands):
                commands.append((t, twist.vx, twist.vy, twist.wz))
            pose = integrate_se2(pose, twist, dt)
            t += dt
            truth.append(t, moved(truth_origin, pose), (twist.vx, twist.vy, twist.wz))
            steering = tuple(c.steering for c in result.commands)
            speed = tuple(c.speed * wheel_scale for c in result.commands)
            states.append((t, steering, speed))
    live = replay(load_calculator(config), states)
    odometry = Path()
    for i in range(len(live)):
        pose = moved(odom_origin, Pose(live.x[i], live.y[i], live.yaw[i]))
        odometry.append(live.t[i], pose, (live.vx[i], live.vy[i], live.wz[i]))
    return Recording(commands, truth, odometry, states, robot="synthetic")
