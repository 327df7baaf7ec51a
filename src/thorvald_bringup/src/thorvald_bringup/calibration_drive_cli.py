"""``rosrun thorvald_bringup calibration_drive``: a robot driven through the calibration manoeuvre, and
its odometry calibrated from that drive.

The manoeuvre (:func:`thorvald_base.verification.plan_named`, ``calibration``) excites what a drive can
tell of the drives' radii and steering offsets: straight runs both ways, crab legs and spins both ways
where every wheel steers, UMBmark's squares both ways (corners spun on the spot, or turned about the
axle line on a fixed-axle robot) and circles both ways, within a square of twice ``--side`` around the
start. It is driven as the paper's experiment is (odometry_report.launch: the simulator on a ROS master
of its own, the robot on measured drives in lockstep, optionally as built), recorded by record_drive
with the simulator's ground truth and a simulated RTK-GNSS and IMU, and the bag given to
``calibrate_odometry`` (thorvald_base.calibration_cli), whose report this prints: each drive's radius
and offset, which combinations of them the drive determines, the odometry before and after, and the
calibration file written. A real robot drives the same manoeuvre with ``calibration_drive.launch`` on
its own master and records what ``calibrate_odometry --ground-truth gnss`` reads.

Exit status 0 with the calibration; 2 with the reason on stderr (a robot file's problems, one per
line; otherwise one line) and no traceback.
"""

import argparse
import os
import sys
import textwrap

from thorvald_base.verification import SIDE
from thorvald_model import ConfigError, load_robot_config
from thorvald_sim.as_built import PROFILES, as_built_for

from .errors import DriveError, ThorvaldBringupError
from .odometry_report_cli import drive, robot_file

BAG = "calibration_drive.bag"


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="calibration_drive",
        description="Drive the calibration manoeuvre in the simulator and calibrate odometry from it.",
    )
    robot = p.add_mutually_exclusive_group()
    robot.add_argument("--robot", default="thorvald_ii_6wd6ws_asym", help="an example robot (default: Figure 7's)")
    robot.add_argument("--robot-model", metavar="FILE", help="a robot configuration file instead of an example robot")
    p.add_argument("--as-built", metavar="FILE|PROFILE:SEED", default="", help="the simulated robot as built (field:3)")
    p.add_argument("--calibration", metavar="FILE", default="", help="the calibration base_driver runs with, if any")
    p.add_argument("--world", default="tarmac_gravel", help="the simulator's world (default tarmac_gravel)")
    p.add_argument("--side", type=float, default=SIDE, help=f"[m] of the manoeuvre's squares (default {SIDE:g})")
    p.add_argument(
        "--ground-truth",
        choices=("sim", "gnss"),
        default="sim",
        help="calibrate against the simulator's (default) or the simulated RTK-GNSS and IMU, as on a real robot",
    )
    p.add_argument("--fit", choices=("drives", "odometry"), default="drives", help="calibrate_odometry's --fit")
    p.add_argument("--out", metavar="DIR", default="calibration_drive", help="the bag's and the calibration's folder")
    p.add_argument("--json", action="store_true", help="print calibrate_odometry's results as JSON")
    p.add_argument("--real-time-factor", type=float, default=0.0, help="0: as fast as the machine can (default)")
    p.add_argument("--gui", action="store_true", help="open pybullet's window")
    p.add_argument("--timeout", type=float, default=600.0, help="wall seconds the drive may take (default 600)")
    return p


def main(argv=None) -> int:
    args = parser().parse_args(argv)
    try:
        return run(args)
    except ConfigError as e:
        print(e, file=sys.stderr)
        return 2
    except ThorvaldBringupError as e:
        print(f"calibration_drive: {e}", file=sys.stderr)
        if isinstance(e, DriveError) and e.log_tail:
            print(textwrap.indent(e.log_tail, "  | "), file=sys.stderr)
        return 2


def run(args) -> int:
    if not (args.side > 0.0 and args.side < 1000.0):
        raise ThorvaldBringupError(f"--side: {args.side!r}: must be in (0, 1000) [m]")
    model = robot_file(args)
    config = load_robot_config(model)
    as_built_for(args.as_built, config)  # refused here, before anything starts
    if args.as_built and args.as_built.partition(":")[0] not in PROFILES:
        args.as_built = os.path.abspath(args.as_built)
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    bag = os.path.join(out, BAG)
    wall = drive(args, model, bag, "calibration", args.side)
    print(f"  drive: {wall:.1f} s wall; bag {bag}", flush=True)
    # ROS's Python (rosbag) only now: --help and bad robots stay fast
    from thorvald_base.calibration_cli import main as calibrate_odometry  # noqa: PLC0415

    command = [bag, "--robot-model", model, "--out", os.path.join(out, "calibration.yaml")]
    command += ["--ground-truth", args.ground_truth, "--fit", args.fit]
    if args.calibration:
        command += ["--calibration", os.path.abspath(args.calibration)]
    if args.json:
        command.append("--json")
    return calibrate_odometry(command)


__all__ = ["main", "parser", "run"]
