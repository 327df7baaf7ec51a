"""``rosrun thorvald_base kinematics CONFIG --twist VX VY WZ``: what each drive is told for a twist.

For a person designing a robot: loads the robot file, runs its base_calculator and the drive layer
(inversion from straight-ahead steering, wheel speed limits), and shows per drive the steering
angle and wheel speed, whether the twist had to be changed, and the twist that odometry recovers
from those drive states (as if the drives had reached their commands).
"""

import argparse
import json
import math
import sys
from typing import List, Optional

from thorvald_model import ConfigError, load_robot_config
from thorvald_model.errors import UnknownRobotError
from thorvald_model.examples import robot_file

from .errors import ThorvaldBaseError
from .kinematics import DriveLayer, DriveState, Twist
from .plugins import load_calculator


def compute(config, twist: Twist, estimator: str = "lsq", seed: Optional[int] = 0, projection: str = "axle") -> dict:
    """The report as plain data (pure: no printing)."""
    calc = load_calculator(config, estimator=estimator, seed=seed, projection=projection)
    result = calc.calculate_command(twist)
    layer = DriveLayer(config.drives)
    out = layer.apply(result.commands, [0.0] * len(config.drives))
    states = [DriveState(c.steering, c.speed) for c in out.commands]
    odom = calc.calculate_odometry(states, 0.0)
    drives = []
    for d, c in zip(config.drives, out.commands):
        drives.append(
            {
                "drive": d.name,
                "type": d.type,
                "x": d.x,
                "y": d.y,
                "steering_rad": c.steering,
                "steering_deg": math.degrees(c.steering),
                "speed_mps": c.speed,
                "max_speed_mps": d.max_wheel_speed,
            }
        )

    def tw(t):
        return {"vx": t.vx, "vy": t.vy, "wz": t.wz}

    return {
        "config": config.source,
        "base_calculator": config.base_calculator,
        "estimator": estimator,
        "projection": projection,
        "requested": tw(result.requested),
        "commanded": tw(result.twist),
        "changed": result.changed,
        "speed_scale": out.speed_scale,
        "drives": drives,
        "odometry": tw(odom.twist),
        "residual_mps": odom.residual,
    }


def format_table(report: dict) -> str:
    def tw(t):
        return "vx {:+.4f} m/s  vy {:+.4f} m/s  wz {:+.4f} rad/s".format(t["vx"], t["vy"], t["wz"])

    lines = [
        "{}  ({}, odometry: {})".format(report["config"], report["base_calculator"], report["estimator"]),
        "requested twist:  " + tw(report["requested"]),
    ]
    if report["changed"]:
        lines.append(
            "commanded twist:  " + tw(report["commanded"]) + "  (CHANGED: the requested twist is not realisable)"
        )
    else:
        lines.append("commanded twist:  as requested (realisable)")
    if report["speed_scale"] < 1.0:
        lines.append(
            "wheel speed limit: all wheel speeds scaled by {:.4f} (direction kept)".format(report["speed_scale"])
        )
    lines.append("")
    lines.append(
        "{:<8} {:>4} {:>8} {:>8} {:>12} {:>10} {:>12} {:>10}".format(
            "drive", "type", "x [m]", "y [m]", "steer [rad]", "[deg]", "speed [m/s]", "max [m/s]"
        )
    )
    for d in report["drives"]:
        lines.append(
            "{:<8} {:>4} {:>8.3f} {:>8.3f} {:>12.4f} {:>10.2f} {:>12.4f} {:>10.3f}".format(
                d["drive"],
                d["type"],
                d["x"],
                d["y"],
                d["steering_rad"],
                d["steering_deg"],
                d["speed_mps"],
                d["max_speed_mps"],
            )
        )
    lines.append("")
    lines.append(
        "odometry twist:   " + tw(report["odometry"]) + "  (residual {:.2e} m/s)".format(report["residual_mps"])
    )
    return "\n".join(lines)


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(
        prog="kinematics",
        description="Show the joint commands a robot configuration gives for a body twist, and the twist odometry "
        "recovers from them.",
    )
    parser.add_argument("config", metavar="ROBOT", help="an example robot's name or a robot configuration file (YAML)")
    parser.add_argument(
        "--twist", nargs=3, type=float, metavar=("VX", "VY", "WZ"), required=True, help="body twist [m/s m/s rad/s]"
    )
    parser.add_argument("--json", action="store_true", help="print JSON instead of a table")
    parser.add_argument("--estimator", choices=("lsq", "paper"), default="lsq", help="odometry estimator (default lsq)")
    parser.add_argument(
        "--projection",
        choices=("axle", "lsq"),
        default="axle",
        help="how a twist the wheels cannot realise is changed: keep wz and the speed along a fixed axle "
        "(axle, default) or the closest wheel velocities (lsq)",
    )
    args = parser.parse_args(argv)
    try:
        config = load_robot_config(robot_file(args.config))
        report = compute(config, Twist(*args.twist), args.estimator, projection=args.projection)
    except ConfigError as e:
        print(f"kinematics: {e}", file=sys.stderr)
        return 2
    except UnknownRobotError as e:
        print(f"kinematics: {e}", file=sys.stderr)
        return 2
    except ThorvaldBaseError as e:
        print(f"kinematics: {args.config}: {e}", file=sys.stderr)
        return 2
    print(json.dumps(report, indent=2) if args.json else format_table(report))
    return 0
