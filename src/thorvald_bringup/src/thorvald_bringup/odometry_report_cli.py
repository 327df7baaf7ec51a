"""``rosrun thorvald_bringup odometry_report``: the paper's odometry experiment, driven and reported.

Without ``--bag`` it drives the robot (default: the paper's Figure 7 robot) through the verification
manoeuvre in the simulator on the tarmac_gravel world, faster than real time, with base_driver's
drive states measured from the simulated joints: odometry_report.launch on a ROS master of its
own, so a running roscore is left alone. rosbag records the drive; then the bag is read and the
report printed: distance by ground truth and by odometry, the distance error, the end-point
difference, for both estimators (lsq live from base_driver, paper replayed from the same drive
states), next to the paper's figures; Figures 8 and 9 are written as PNG.

``--bag FILE`` makes the report from an existing bag (pass ``--robot`` if it is another robot).

Exit status 0 with the report; 2 with the reason on stderr (a robot file's problems, one per line;
otherwise one line: an unknown robot, a drive that did not finish, with the end of its launch's
log, or a recording that makes no report) and no traceback.
"""

import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import textwrap
import time
from typing import List, Tuple

from thorvald_base.stamped_commands import LOCKSTEP_BROKEN
from thorvald_base.verification import MANOEUVRES, SIDE
from thorvald_model import ConfigError, examples, load_robot_config
from thorvald_model.errors import UnknownRobotError
from thorvald_model.ports import free_port
from thorvald_sim.physics.as_built import PROFILES, as_built_for, describe_as_built
from thorvald_sim.physics.presets import MAX_WORKERS

from .errors import DriveError, ReportError, ThorvaldBringupError, UnknownRobot

TARGET_DISTANCE_ERROR = 0.5  # [%] for lsq (the paper: 1.0 %)
TARGET_END_POINT = 1.0  # [m] for lsq (the paper: 2.2 m)
ANSI = re.compile(r"\x1b\[[0-9;]*m")  # the colours of rosconsole's lines


def parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="odometry_report",
        description="Drive the paper's odometry verification manoeuvre in the simulator (or read a bag of it) "
        "and report odometry against ground truth, with Figures 8 and 9 as PNG.",
    )
    robot = p.add_mutually_exclusive_group()
    robot.add_argument(
        "--robot",
        default="thorvald_ii_6wd6ws_asym",
        help="an example robot's name or a robot file (default: the paper's Figure 7 robot)",
    )
    robot.add_argument("--robot-model", metavar="FILE", help="a robot configuration file instead of an example robot")
    p.add_argument("--bag", metavar="FILE", help="report from this bag instead of driving")
    p.add_argument("--plan", action="store_true", help="with --bag: the bag is of --manoeuvre's plan")
    p.add_argument("--world", default="tarmac_gravel", help="the simulator's world (default tarmac_gravel)")
    p.add_argument(
        "--manoeuvre",
        choices=MANOEUVRES,
        default="verification",
        help="the paper's verification manoeuvre (default), a field route of rows and headland turns (a drive "
        "unlike the calibration drive, to validate a calibration on), or the calibration drive",
    )
    p.add_argument(
        "--as-built",
        metavar="FILE|PROFILE:SEED",
        default="",
        help="drive the robot as built: an as-built file or a profile drawn with a seed (field:3); base_driver "
        "runs on the configuration, as on a real robot (default: built as configured)",
    )
    p.add_argument(
        "--out",
        metavar="DIR",
        help="where the bag and the figures go (default ./odometry_report; with --bag, the bag's folder)",
    )
    p.add_argument(
        "--calibration",
        metavar="FILE",
        default="",
        help="base_driver's calibration file (rosrun thorvald_base calibrate_odometry writes it)",
    )
    p.add_argument("--json", metavar="FILE", help="also write the figures as JSON to FILE")
    p.add_argument("--real-time-factor", type=float, default=0.0, help="0: as fast as the machine can (default)")
    p.add_argument("--gui", action="store_true", help="open pybullet's window")
    p.add_argument(
        "--physics-workers",
        type=int,
        default=1,
        metavar="N",
        help="step the physics in N worker processes (the simulator's ~physics_workers; default 1: in the "
        "simulator node). In lockstep the figures are the same to the bit",
    )
    p.add_argument("--timeout", type=float, default=600.0, help="wall seconds the drive may take (default 600)")
    return p


def robot_file(args) -> str:
    """The robot file of --robot-model, else of --robot: an example robot's name or a file, as every
    tool takes it (thorvald_model.examples); UnknownRobot with "did you mean" for a name that is none."""
    if args.robot_model:
        return os.path.abspath(args.robot_model)
    try:
        return os.path.abspath(examples.robot_file(args.robot))
    except UnknownRobotError as e:
        raise UnknownRobot(f"--robot {e}") from None


def drive(
    args, model: str, bag: str, manoeuvre: str = "verification", side: float = SIDE, *, log: str = "odometry_report"
) -> Tuple[float, List[str]]:
    """Runs odometry_report.launch until the drive ends; returns the wall time [s] and the log's warnings
    of a broken lockstep (:func:`lockstep_breaks`). args: world, real_time_factor, gui, as_built,
    calibration, timeout; its output in log_launch.log beside the bag."""
    for stale in (bag, bag + ".active"):
        if os.path.exists(stale):
            os.remove(stale)
    log = os.path.join(os.path.dirname(bag), f"{log}_launch.log")
    wall, text = run_launch(
        args, "odometry_report.launch", [f"robot_model:={model}", f"bag:={bag}", f"manoeuvre:={manoeuvre}",
        f"side:={side:g}", f"physics_workers:={getattr(args, 'physics_workers', 1)}"], log,
        f"{os.path.basename(model)[:-5]} through the {manoeuvre} manoeuvre",
    )  # fmt: skip
    if "Verification drive of" not in text or not os.path.isfile(bag):
        tail = "\n".join(text.splitlines()[-25:])
        raise DriveError(f"the drive did not finish (no report from verification_drive or no bag); see {log}", tail)
    return wall, lockstep_breaks(text)


def lockstep_breaks(text: str) -> List[str]:
    """The warnings in a launch's output of a node in lockstep that stopped waiting (the simulator for
    base_driver's answer, base_driver for its stamped commands, each after 2 s of wall time): from
    there on what the run commands depends on the machine's timing, so the run may not repeat."""
    return [ANSI.sub("", line).strip() for line in text.splitlines() if LOCKSTEP_BROKEN in line]


def warn_lockstep_breaks(breaks: List[str], log: str) -> None:
    if breaks:
        print(
            f"WARNING: the lockstep was broken, so this run may not repeat (see {log}):\n"
            + "".join(f"  | {line}\n" for line in breaks),
            end="",
            file=sys.stderr,
            flush=True,
        )


def run_launch(args, launch: str, launch_args, log: str, what: str):
    """Runs thorvald_bringup's launch file with launch_args and the simulated robot's (args: world,
    real_time_factor, gui, as_built, calibration, timeout) on a ROS master of its own until it ends;
    (wall time [s], what it printed). Its output goes to log."""
    port = free_port()
    env = dict(os.environ, ROS_MASTER_URI=f"http://localhost:{port}")
    cmd = [
        "roslaunch",
        "-p",
        str(port),
        "thorvald_bringup",
        launch,
        *launch_args,
        f"world:={args.world}",
        f"real_time_factor:={args.real_time_factor:g}",
        f"with_gui:={'true' if args.gui else 'false'}",
        f"as_built:={args.as_built}",
        f"calibration:={os.path.abspath(args.calibration) if args.calibration else ''}",
    ]
    print(
        f"Driving {what}{' as built ' + args.as_built if args.as_built else ''} on {args.world} "
        f"(simulator, measured drives, ROS master on port {port}; log {log})",
        flush=True,
    )
    start = time.time()
    with open(log, "w") as out:
        proc = subprocess.Popen(cmd, stdout=out, stderr=subprocess.STDOUT, env=env, start_new_session=True)
        try:
            proc.wait(timeout=args.timeout)
        except subprocess.TimeoutExpired:
            os.killpg(proc.pid, 2)  # SIGINT: roslaunch stops its nodes, rosbag closes the bag
            proc.wait(timeout=60)
            raise DriveError(f"the drive took longer than {args.timeout:g} s of wall time; see {log}") from None
        except KeyboardInterrupt:
            os.killpg(proc.pid, 2)
            proc.wait(timeout=60)
            raise
    wall = time.time() - start
    with open(log) as f:
        text = f.read()
    warn_lockstep_breaks(lockstep_breaks(text), log)
    return wall, text


def report_json(report, as_built: str, world: str) -> dict:
    """The report's figures: per path, against the simulator's true pose and against RTK-GNSS."""

    def figures(table):
        return {
            name: {
                "distance_m": f.distance,
                "distance_error_percent": None if f.distance_error != f.distance_error else f.distance_error,
                "end_point_m": f.end_point_difference,
                "heading_deg": math.degrees(f.heading_difference),
            }
            for name, f in table.items()
        }

    return {
        "robot": report.recording.robot,
        "as_built": as_built,
        "world": world,
        "against_truth": figures(report.figures),
        "against_rtk_gnss": figures(report.figures_gnss),
    }


def main(argv=None) -> int:
    args = parser().parse_args(argv)
    try:
        return run(args)
    except ConfigError as e:
        print(e, file=sys.stderr)  # FILE: key path: value: rule, as every command that reads a robot file
        return 2
    except ThorvaldBringupError as e:
        print(f"odometry_report: {e}", file=sys.stderr)
        if isinstance(e, DriveError) and e.log_tail:  # what the launch said last: why the drive stopped
            print(textwrap.indent(e.log_tail, "  | "), file=sys.stderr)
        return 2


def run(args) -> int:
    """The report the arguments ask for; ConfigError (a robot or as-built file) or ThorvaldBringupError
    (an unknown robot, a drive that did not finish, a recording that makes no report) if none."""
    model = robot_file(args)
    config = load_robot_config(model)
    built = as_built_for(args.as_built, config)  # refused here, before anything starts
    if args.as_built and args.as_built.partition(":")[0] not in PROFILES:
        args.as_built = os.path.abspath(args.as_built)  # the spawn runs elsewhere (in ~/.ros)
    correction = None
    if args.calibration:  # refused here too, as base_driver would refuse it
        from thorvald_base.calibration.calibration_file import read_calibration  # noqa: PLC0415

        correction = read_calibration(args.calibration, config).odometry
    if not 1 <= args.physics_workers <= MAX_WORKERS:
        raise ThorvaldBringupError(f"--physics-workers: {args.physics_workers}: must be in 1..{MAX_WORKERS}")
    out = os.path.abspath(args.out or (os.path.dirname(os.path.abspath(args.bag)) if args.bag else "odometry_report"))
    os.makedirs(out, exist_ok=True)
    name = os.path.splitext(os.path.basename(model))[0]
    breaks = []
    if args.bag:
        bag = os.path.abspath(args.bag)
        wall = None
    else:
        if shutil.which("roslaunch") is None:
            raise DriveError("roslaunch not found: source the workspace's devel/setup.bash")
        bag = os.path.join(out, "odometry_report.bag")
        wall, breaks = drive(args, model, bag, args.manoeuvre)
    # ROS's Python (rosbag, the calculators' plugin loader) only now: --help and bad robots stay fast
    from thorvald_base.plugins import load_calculator  # noqa: PLC0415
    from thorvald_base.verification import commanded_path, plan_named  # noqa: PLC0415

    from .odometry_report import PAPER_SEED, check_complete, format_report, make_report  # noqa: PLC0415
    from .report_bag import read_recording  # noqa: PLC0415
    from .report_plots import figure8, figure9  # noqa: PLC0415

    recording = read_recording(bag, robot=name)
    check_complete(recording)
    drives = {len(s[1]) for s in recording.states}
    if drives != {len(config.drives)}:
        raise ReportError(
            f"{bag}: base_state has {', '.join(map(str, sorted(drives)))} drives, {name} has {len(config.drives)}: "
            "pass the bag's robot with --robot or --robot-model"
        )
    calculators = {e: load_calculator(config, estimator=e, seed=PAPER_SEED) for e in ("lsq", "paper")}
    for calculator in calculators.values():  # base_state is what base_driver read with the calibration in effect;
        if correction is not None:  # its odometry had the calibration's correction too
            calculator.odometry_correction = correction
    report = make_report(recording, calculators)
    if wall is not None or args.plan:
        report.planned_distance = commanded_path(plan_named(args.manoeuvre, config)[1])[1]
    print()
    print(format_report(report, (TARGET_DISTANCE_ERROR, TARGET_END_POINT), paper=args.manoeuvre == "verification"))
    if args.as_built:
        print(f"  as built ({args.as_built}): {describe_as_built(built)}")
    if wall is not None:
        simulated = recording.states[-1][0] - recording.states[0][0]
        workers = f", physics in {args.physics_workers} worker processes" if args.physics_workers > 1 else ""
        print(f"  drive: {simulated:.1f} s simulated in {wall:.1f} s wall, world {args.world}{workers}")
        print(f"  lockstep: {'broken, this run may not repeat: ' + breaks[0] if breaks else 'kept throughout'}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump({**report_json(report, args.as_built, args.world), "lockstep_breaks": breaks}, f, indent=1)
        print(f"  figures:  {os.path.abspath(args.json)}")
    print(f"  bag:      {bag}")
    print(f"  Figure 8: {figure8(report, os.path.join(out, 'figure8_paths.png'))}")
    print(f"  Figure 9: {figure9(report, os.path.join(out, 'figure9_velocities.png'))}")
    return 0
