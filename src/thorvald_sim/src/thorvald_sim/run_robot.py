"""``rosrun thorvald_sim run_robot ROBOT.yaml --commands CMDS.csv --out DIR``: drive a robot in the
simulator without ROS (:mod:`thorvald_sim.runner`).

  --commands CMDS.csv     t,vx,vy,wz (base_link [s], [m/s], [m/s], [rad/s]); each row holds from its t
                          until the next, the last for --hold seconds (1)
  --world W               a shipped world's name or a world file (flat)
  --as-built SPEC         an as-built file or PROFILE:SEED (field:7): the simulated robot as built
  --calibration FILE      base_driver's calibration file (calibrate_odometry writes it)
  --model-extras X        an extra xacro fitted to the robot (sensors)
  --seed N                of every sensor's noise (0)
  --record-sensors        measure every sensor of the description and save its readings (DIR/sensors)
  --out DIR               ground_truth.csv, odometry.csv, summary.json (and sensors/)

Prints the summary. A broken file prints its problems (file, place, value, rule) and exits 2; a
robot the simulator refuses exits 1.
"""

import argparse
import json
import sys
from typing import List, Optional

from thorvald_model.errors import ConfigError

from .errors import ThorvaldSimError
from .physics import PRESETS
from .runner import RunOptions, read_commands, run_robot


def parse_args(argv: Optional[List[str]] = None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(prog="run_robot", description="Drive a robot in the simulator without ROS.")
    parser.add_argument("robot", metavar="ROBOT.yaml", help="the robot configuration file")
    parser.add_argument("--commands", required=True, metavar="CMDS.csv", help="t,vx,vy,wz")
    parser.add_argument("--out", required=True, metavar="DIR", help="where the outputs go")
    parser.add_argument("--world", default="flat")
    parser.add_argument("--as-built", default="", metavar="FILE|PROFILE:SEED")
    parser.add_argument("--calibration", default="", metavar="FILE")
    parser.add_argument("--model-extras", default="", metavar="XACRO")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--hold", type=float, default=1.0, help="[s] the last command holds (1)")
    parser.add_argument("--record-sensors", action="store_true")
    parser.add_argument(
        "--physics", choices=tuple(PRESETS), default="default", help="the physics preset (default; fleet: cheaper)"
    )
    return parser.parse_args(argv)


def main(argv: Optional[List[str]] = None) -> int:
    args = parse_args(argv)
    if not args.hold >= 0.0:
        print(f"run_robot: --hold {args.hold!r}: must be >= 0 [s]", file=sys.stderr)
        return 2
    options = RunOptions(
        world=args.world,
        as_built=args.as_built,
        calibration=args.calibration,
        model_extras=args.model_extras,
        seed=args.seed,
        record_sensors=args.record_sensors,
        hold=args.hold,
        physics=args.physics,
    )
    try:
        commands = read_commands(args.commands)
        run = run_robot(args.robot, commands, options, out_dir=args.out)
    except ConfigError as e:
        print(e, file=sys.stderr)
        return 2
    except ThorvaldSimError as e:
        print(f"run_robot: {e}", file=sys.stderr)
        return 1
    print(json.dumps(run.summary, indent=2, sort_keys=True))
    return 0


if __name__ == "__main__":
    sys.exit(main())
