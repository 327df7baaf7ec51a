"""``rosrun thorvald_sim run_robot ROBOT --commands CMDS.csv --out DIR``: drive a robot in the
simulator without ROS (:mod:`thorvald_sim.tools.runner`).

ROBOT is an example robot's name or a robot file, as the other tools take a robot (one rule,
:mod:`thorvald_model.examples`); ``--help`` gives every option and the commands file. Prints the
summary. A broken file prints its problems (file, place, value, rule) and an unknown robot name the
closest example and the list, both with exit status 2; a robot the simulator refuses exits 1.
"""

import argparse
import json
import sys
from typing import List, Optional

from thorvald_model.errors import ConfigError, UnknownRobotError
from thorvald_model.examples import robot_file

from ..errors import ThorvaldSimError
from ..physics.presets import PRESETS
from .runner import COLUMNS, MAX_COMMANDS, MAX_DURATION, RunOptions, read_commands, run_robot

DESCRIPTION = """\
Drive one robot in the simulator without ROS: the robot's own base_driver core (calculator, drive
layer, calibration, limits) in the same process as a pybullet simulation, in lockstep, so two runs
write the same files. ROBOT is an example robot's name (thorvald_ii_4wd4ws_std, ...: a misspelt one
gets "did you mean" and the list) or a robot file (a path ending in .yaml)."""

EPILOG = f"""\
the commands file (--commands):
  CSV text, a header naming the columns {", ".join(COLUMNS)} (in any order), then one command a row:
    t   [s]     simulated time from the start of the run at which the row begins to hold
    vx  [m/s]   forward speed     }}
    vy  [m/s]   sideways speed    }} in base_link (REP 103: x forward, y left, z up),
    wz  [rad/s] turning rate      }} the twist base_driver follows
  Each row holds from its t until the next row's t (rows in increasing t), and the last one for
  --hold seconds more; before the first row's t there is no command and the wheels stand.
  At most {MAX_COMMANDS} rows; t within [0, {MAX_DURATION:g}] s. A broken row is named by its line.

  example: 0.5 m/s ahead from 0.5 s (2 m), on the spot at 0.3927 rad/s from 4.5 s (a quarter turn
  in 4 s, less the wheels' re-steering first: the standard robot ends 83 degrees round), stopped from
  8.5 s (for --hold, 1 s):
    t,vx,vy,wz
    0.5,0.5,0,0
    4.5,0,0,0.3927
    8.5,0,0,0

outputs (DIR):
  ground_truth.csv, odometry.csv  t,x,y,yaw [s, m, m, rad] at every control cycle: the simulator's
                                  true pose relative to the spawn pose, and base_driver's odometry
  summary.json                    simulated_s, wall_s, drive_wall_s, distance_truth_m,
                                  distance_odometry_m, end_point_difference_m and what was run
  sensors/NAME.npz                with --record-sensors: each sensor's readings (t and its fields)

exit status: 0 done; 2 a broken argument or file (every problem with its file, place, value and
rule), or an unknown robot name; 1 the simulator refused the robot.

example:
  rosrun thorvald_sim run_robot thorvald_ii_4wd4ws_std --commands cmds.csv --out /tmp/run --world tarmac_gravel
"""


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="run_robot",
        description=DESCRIPTION,
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("robot", metavar="ROBOT", help="an example robot's name, or a robot file (.yaml)")
    parser.add_argument(
        "--commands",
        required=True,
        metavar="CMDS.csv",
        help="the commands: t,vx,vy,wz rows in base_link (below)",
    )
    parser.add_argument(
        "--out", required=True, metavar="DIR", help="where ground_truth.csv, odometry.csv, summary.json go (below)"
    )
    parser.add_argument(
        "--world",
        default="flat",
        metavar="W",
        help="a shipped world's name (flat, tarmac_gravel, crop_rows, slope, ...) or a world file (default: flat)",
    )
    parser.add_argument(
        "--as-built",
        default="",
        metavar="FILE|PROFILE:SEED",
        help="simulate the robot as built: an as-built file, or a profile and seed (field:7) drawing a "
        "builder's imperfections; base_driver still drives from the robot file (default: as configured)",
    )
    parser.add_argument(
        "--calibration",
        default="",
        metavar="FILE",
        help="base_driver's calibration file (calibrate_odometry writes it): the drive keys it sets "
        "(radii, steering offsets) and the odometry's correction (default: none)",
    )
    parser.add_argument(
        "--model-extras",
        default="",
        metavar="XACRO",
        help="an extra xacro fitted to the robot's description (sensors, frame parts), as model.launch's "
        "model_extras; its sensors are simulated, and recorded with --record-sensors (default: none)",
    )
    parser.add_argument(
        "--seed",
        type=int,
        default=0,
        metavar="N",
        help="seed of every sensor's noise (the simulator's ~seed; default 0)",
    )
    parser.add_argument(
        "--hold", type=float, default=1.0, metavar="S", help="[s] how long the last command holds (default 1)"
    )
    parser.add_argument(
        "--record-sensors",
        action="store_true",
        help="measure every sensor of the description at its rate and save its readings to DIR/sensors/NAME.npz",
    )
    parser.add_argument(
        "--physics",
        choices=tuple(PRESETS),
        default="default",
        help="the physics preset: default (240 Hz) or fleet (120 Hz, about half the CPU)",
    )
    return parser


def parse_args(argv: Optional[List[str]] = None) -> argparse.Namespace:
    return build_parser().parse_args(argv)


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
        robot = robot_file(args.robot)
    except UnknownRobotError as e:
        print(f"run_robot: ROBOT {e}", file=sys.stderr)
        return 2
    try:
        commands = read_commands(args.commands)
        run = run_robot(robot, commands, options, out_dir=args.out)
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
