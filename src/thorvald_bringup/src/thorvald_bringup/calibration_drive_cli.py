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

A robot of more than two drives (whose wheels can fight on one rigid frame) goes on, unless
``--no-balance``: balance_wheels drives straight legs slowly with that calibration in effect and
sets each tyre's radius against the others' from the motors' currents, and on a steered robot the
steering offsets ground truth cannot see (the toe) from the frame's resistance (balanced.yaml); the
calibration drive's fit is taken again with it (``calibrate_odometry --balance``,
balanced_calibration.yaml); and the straight manoeuvre, driven at working speed with that in effect,
gives the radii's common factor and odometry's yaw per metre, the turn it reads on a straight line that
the frame does not make (``calibrate_odometry --fit straight``): scaled_calibration.yaml.

Last, unless ``--no-heading``, the heading manoeuvre (the calibration manoeuvre's straight runs, crab
legs, spins, squares and circles, the straight legs, and the field route's headland U turns) is driven
with all that in effect, and odometry's heading model fitted to it (``calibrate_odometry --fit
heading``: the yaw-rate multiplier, yaw per metre along x and y, and each wheel's weight in the yaw
rate): calibration.yaml, what base_driver loads. The tyres slip in a turn, a frame crabbing can turn
where its wheels say straight, and while the wheels re-steer they disagree and the frame turns as the
wheels that carry it say; no radius or offset makes the wheels' geometry read that.

A balance that the legs cannot support stops (balance_wheels says why: wheels whose torques do not
follow their radii, a radius beyond what a tyre's pressure and wear give, a fight that did not
shrink, a radius the robot file's rules refuse): the calibration from ground truth then stands, a
warning says so, and the straight legs and the heading drive follow with it; ``--require-balance``
exits 3 there instead.

Exit status 0 with the calibration; 2 with the reason on stderr (a robot file's problems, one per
line; otherwise one line) and no traceback; 3 (``--require-balance``) when the balance stopped.
"""

import argparse
import contextlib
import io
import json
import math
import os
import shutil
import sys
import textwrap
from typing import List, Sequence

import numpy as np

from thorvald_base.calibration.calibration_file import load_calibration
from thorvald_base.calibration.toe_balance import toe_gauge
from thorvald_base.calibration.torque_balance import relative_errors
from thorvald_base.verification import SIDE
from thorvald_model import ConfigError, load_robot_config, with_drive_params
from thorvald_sim.physics.as_built import PROFILES, as_built_for

from .errors import DriveError, ThorvaldBringupError
from .odometry_report_cli import drive, robot_file, run_launch

BAG = "calibration_drive.bag"
CALIBRATION = "calibration.yaml"  # what base_driver loads: the final calibration
ODOMETRY = "odometry_calibration.yaml"  # before the balance: calibrated from ground truth alone
BALANCED = "balanced.yaml"  # balance_wheels': the radii where the wheels do not fight
BALANCE_JSON = "balance.json"
BALANCED_FIT = "balanced_calibration.yaml"  # the calibration drive's fit with the balance, before the straight legs
STRAIGHT_BAG = "straight.bag"
SCALED = "scaled_calibration.yaml"  # the straight legs' common factor on the balanced fit, before the heading
HEADING_BAG = "heading.bag"
NO_BALANCE = 3  # the exit status with --require-balance when the balance stopped (balance_wheels' own)


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
    balance = p.add_mutually_exclusive_group()
    balance.add_argument(
        "--balance", action="store_true", default=None,
        help="then balance the wheels from their motor currents (default: a robot of more than two drives)",
    )  # fmt: skip
    balance.add_argument("--no-balance", dest="balance", action="store_false", help="calibrate from ground truth alone")
    p.add_argument(
        "--require-balance", action="store_true",
        help="exit 3 when the balance stops (the legs cannot support one): by default the calibration from ground "
        "truth stands, with a warning, and the drive goes on",
    )  # fmt: skip
    p.add_argument(
        "--no-heading", "--no-turns", dest="heading", action="store_false",
        help="leave out the last drive, the heading manoeuvre that fits odometry's heading model (the yaw-rate "
        "multiplier, yaw per metre along x and y, the wheels' weights)",
    )  # fmt: skip
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
    built = as_built_for(args.as_built, config)  # refused here, before anything starts
    if args.as_built and args.as_built.partition(":")[0] not in PROFILES:
        args.as_built = os.path.abspath(args.as_built)
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    bag = os.path.join(out, BAG)
    wall, _ = drive(args, model, bag, "calibration", args.side, log="calibration_drive")
    print(f"  drive: {wall:.1f} s wall; bag {bag}", flush=True)
    balance = args.balance if args.balance is not None else fights(config)
    # ROS's Python (rosbag) only now: --help and bad robots stay fast
    from thorvald_base.calibration_cli import main as calibrate_odometry  # noqa: PLC0415

    final = os.path.join(out, CALIBRATION)
    for stale in (os.path.join(out, name) for name in (CALIBRATION, ODOMETRY, SCALED)):
        if os.path.exists(stale):
            os.remove(stale)
    first = os.path.join(out, ODOMETRY if balance or args.heading else CALIBRATION)
    command = [bag, "--robot-model", model, "--out", first]
    command += ["--ground-truth", args.ground_truth, "--fit", args.fit]
    if args.calibration:
        command += ["--calibration", os.path.abspath(args.calibration)]
    if args.json:
        command.append("--json")
    if not balance:
        if not args.heading:
            return calibrate_odometry(command)
        captured = io.StringIO()
        with contextlib.redirect_stdout(captured):
            status = calibrate_odometry(command)
        text = captured.getvalue()
        if status != 0:
            print(text, end="")
            return status
        if not args.json:
            print(text, end="", flush=True)
        heading = heading_step(args, model, first, out, calibrate_odometry, straight=False)
        if args.json:
            result = json.loads(text[text.index("{") :])
            result["heading"] = heading
            print(json.dumps(result, indent=2))
        return 0
    captured = io.StringIO()
    with contextlib.redirect_stdout(captured):
        status = calibrate_odometry(command)
    text = captured.getvalue()
    if status != 0 or not os.path.isfile(first):
        print(text, end="")
        return status or 2
    if not args.json:
        print(text, end="", flush=True)
    balanced_file = os.path.join(out, BALANCED)
    figures = os.path.join(out, BALANCE_JSON)
    scaled = os.path.join(out, SCALED if args.heading else CALIBRATION)
    balanced_fit = os.path.join(out, BALANCED_FIT)
    for stale in (balanced_file, figures, balanced_fit):
        if os.path.exists(stale):
            os.remove(stale)
    launch_args = [f"robot_model:={model}", f"side:={args.side:g}", f"out:={balanced_file}", f"json:={figures}"]
    log = os.path.join(out, "balance_wheels_launch.log")
    wall, said = run_launch(
        argparse.Namespace(**{**vars(args), "calibration": first}), "balance_wheels.launch", launch_args, log,
        f"{os.path.basename(model)[:-5]} through the balance manoeuvre, its steering offsets calibrated",
    )  # fmt: skip
    balanced = None
    if os.path.isfile(figures):
        with open(figures) as f:
            balanced = json.load(f)
    stopped = (balanced or {}).get("stopped")
    if balanced is None or not (stopped or os.path.isfile(balanced_file)):
        tail = "\n".join(said.splitlines()[-25:])
        raise DriveError(f"the balancing drive did not finish (no balanced calibration); see {log}", tail)
    if not args.json:
        start = said.find("balance_wheels: ")
        print(f"  drive: {wall:.1f} s wall", flush=True)
        print(said[start:].split("\n[", 1)[0].rstrip() if start >= 0 else "", flush=True)
    if stopped:
        print(f"calibration_drive: warning: {stopped}; the calibration from ground truth stands", file=sys.stderr)
        if args.require_balance:
            return NO_BALANCE
        balanced_fit, fit_text = first, text  # the calibration drive's fit, as ground truth left it
    else:
        if not args.json:
            print(
                "\nthe calibration drive's fit, each radius moved to the balance's along what that drive did not "
                "determine:"
            )
        # the calibration drive's fit again, with the balance
        captured = io.StringIO()
        with contextlib.redirect_stdout(captured):
            status = calibrate_odometry([*command[:4], balanced_fit, *command[5:], "--balance", balanced_file])
        if status != 0:
            print(captured.getvalue(), end="")
            return status
        fit_text = captured.getvalue()
        if not args.json:
            print(fit_text, end="", flush=True)
    # the radii's common factor, from straight legs at working speed with all that in effect
    straight_bag = os.path.join(out, STRAIGHT_BAG)
    with_fit = argparse.Namespace(**{**vars(args), "calibration": balanced_fit})
    wall, _ = drive(with_fit, model, straight_bag, "straight", args.side, log="straight")
    scale = [straight_bag, "--robot-model", model, "--out", scaled, "--calibration", balanced_fit, "--fit", "straight"]
    scale += ["--ground-truth", args.ground_truth, *(["--json"] if args.json else [])]
    if not args.json:
        print(f"  drive: {wall:.1f} s wall; bag {straight_bag}", flush=True)
        print("\nthe radii's common factor and odometry's yaw per metre from the straight legs, that in effect:")
    captured = io.StringIO()
    with contextlib.redirect_stdout(captured):
        status = calibrate_odometry(scale)
    if status != 0:
        print(captured.getvalue(), end="")
        return status
    text = captured.getvalue()
    if not args.json:
        print(text, end="", flush=True)
    heading = None
    if args.heading:
        heading = heading_step(args, model, scaled, out, calibrate_odometry, straight=True)
    tyres = None
    if args.as_built and not stopped:
        tyres = tyre_errors(config, built, load_calibration(first, config), balanced, load_calibration(final, config))
    if args.json:  # the calibration drive's fit (with the balance), the balance, the straight legs' factor
        result = json.loads(fit_text[fit_text.index("{") :])
        result["balance"] = balanced
        result["straight"] = json.loads(text[text.index("{") :])
        if heading is not None:
            result["heading"] = heading
        if tyres is not None:
            result["tyres"] = tyres
        print(json.dumps(result, indent=2))
        return 0
    if tyres is not None:
        names = ("configured", "ground_truth", "tyres", "calibration")
        largest = [tyres[k]["largest_percent"] for k in names]
        relative = [tyres[k]["largest_relative_percent"] for k in names]
        print(
            "each tyre's radius against the as-built robot's, the largest error [%]: configured {:.2f}, from ground "
            "truth {:.2f}, the tyres (balanced, at the straight legs' common factor) {:.2f}, the calibration's "
            "radii {:.2f} (each against the others only: {:.2f}, {:.2f}, {:.2f}, {:.2f})".format(*largest, *relative)
        )
    return 0


def heading_step(args, model: str, in_effect: str, out: str, calibrate_odometry, *, straight: bool) -> dict:
    """The heading manoeuvre driven with the calibration file in_effect, and odometry's heading model
    fitted to it over that file into calibration.yaml (straight: in_effect's yaw per metre came from the
    straight legs and is kept); --fit heading's JSON with --json (else its text is printed and the dict is
    empty). When the drive gives none (a fit beyond what a calibration explains), calibration.yaml is the
    file in_effect, the reason is printed and returned as {"error": reason}."""
    bag = os.path.join(out, HEADING_BAG)
    with_fit = argparse.Namespace(**{**vars(args), "calibration": in_effect})
    wall, _ = drive(with_fit, model, bag, "heading", args.side, log="heading")
    command = [bag, "--robot-model", model, "--out", os.path.join(out, CALIBRATION), "--calibration", in_effect]
    command += ["--fit", "heading", "--ground-truth", args.ground_truth, *(["--json"] if args.json else [])]
    command += ["--keep-yaw-per-metre"] if straight else []
    if not args.json:
        print(f"  drive: {wall:.1f} s wall; bag {bag}", flush=True)
        print("\nodometry's heading model from a drive of every motion, all that in effect:", flush=True)
    captured, said = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(captured), contextlib.redirect_stderr(said):
        status = calibrate_odometry(command)
    text = captured.getvalue()
    if status != 0:  # the calibration stands without the heading model
        shutil.copyfile(in_effect, os.path.join(out, CALIBRATION))
        reason = said.getvalue().strip().replace("calibrate_odometry: ", "", 1)
        print(f"no heading model from the drive ({reason}); {CALIBRATION} is {os.path.basename(in_effect)}")
        return {"error": reason}
    if not args.json:
        print(text, end="", flush=True)
    return json.loads(text[text.index("{") :]) if args.json else {}


def fights(config) -> bool:
    """Whether the robot's wheels can fight: more than two driven wheels on one rigid frame (two on
    one axle roll as they must, and ground truth tells their radii apart by the heading)."""
    return len(config.drives) > 2


def tyre_radii(balanced: Sequence[float], calibration: Sequence[float]) -> List[float]:
    """[m] each tyre's rolling radius: the balance's radii (each against the others) at the calibration's
    geometric mean (the straight legs' common factor)."""
    factor = math.exp(float(np.mean(np.log(calibration)) - np.mean(np.log(balanced))))
    return [float(r * factor) for r in balanced]


def toe_errors(config, built, odometry_changes, balanced) -> dict:
    """The steering offsets' largest error off the patterns ground truth sees (the toe) [deg]: from ground
    truth, and as balance_wheels' toe search found them."""
    gauge = toe_gauge(config)
    truth = np.array([d.steering_offset for d in built.drives])

    def toe(offsets) -> float:
        e = np.asarray(offsets) - truth
        return float(np.degrees(np.max(np.abs(e - gauge @ (gauge.T @ e)))))

    start = [d.steering_offset for d in with_drive_params(config, odometry_changes).drives]
    found = list(start)
    for name, values in balanced["toe"]["drives"].items():
        found[int(name[len("drive") :])] = values["steering_offset"]
    return {"ground_truth_deg": toe(start), "balanced_deg": toe(found)}


def tyre_errors(config, built, odometry_changes, balanced, final_changes) -> dict:
    """Each tyre's radius against the as-built robot's [%]: configured, calibrated from ground truth,
    balanced (at the common factor of the calibration drive's fit), the tyres (the balance at the
    calibration's common factor, which the straight legs set: what the drives tell of each tyre), and the
    calibration (the odometry's radii, which take the tyres' slip on the drive too); absolute and with
    the common factor removed (what the balance alone can tell)."""
    truth = [d.r_wheel for d in built.drives]

    def radii(changes):
        return [d.r_wheel for d in with_drive_params(config, changes).drives]

    sets = {
        "configured": radii([]),
        "ground_truth": radii(odometry_changes),
        "balanced": [balanced["drives"][f"drive{k}"]["r_wheel"] for k in range(len(config.drives))],
        "calibration": radii(final_changes),
    }
    sets["tyres"] = tyre_radii(sets["balanced"], sets["calibration"])
    out = {"toe": toe_errors(config, built, odometry_changes, balanced)} if "toe" in balanced else {}
    for name, radii in sets.items():
        errors = [100.0 * (r / t - 1.0) for r, t in zip(radii, truth)]
        relative = 100.0 * relative_errors(radii, truth)
        out[name] = {
            "errors_percent": errors,
            "largest_percent": max(abs(e) for e in errors),
            "largest_relative_percent": float(max(abs(relative))),
        }
    return out


__all__ = ["main", "parser", "run"]
