"""``rosrun thorvald_base calibrate_odometry BAG --robot-model FILE``: odometry calibration from a bag.

The bag holds what base_driver read (``.../base_state``) and ground truth: the simulator's
(``.../odometry/gazebo``) or a real robot's GNSS fix and IMU (``.../gps/fix``, ``.../imu/data``).
Topics are found by their ending, so a robot in any namespace works; messages are decoded with the
definitions stored in the bag. By default the simulator's ground truth is used when the bag has it,
else GNSS and IMU; ``--ground-truth gnss`` asks for GNSS and IMU, as on a real robot.

Prints each drive's calibrated ``r_wheel`` and ``steering_offset`` with their standard uncertainties,
the parameters the drive did not excite and why, and the odometry error before and after (``--json``:
the same as one JSON document); writes the calibration file base_driver loads at start
(``~calibration``, base_bringup.launch's ``calibration:=``), by default ``calibration.yaml`` beside
the bag, and prints the ``set_drive_params`` call that applies it to the running robot.

The work is thorvald_base.calibration's; this module reads the bag and prints. A bad bag, missing
topics, a bad robot file or a drive that excites nothing: one line on stderr, exit status 2.
"""

import argparse
import json
import math
import os
import sys
from dataclasses import dataclass, replace
from typing import Dict, List, Optional, Tuple

import numpy as np
import rosbag

from thorvald_model import ConfigError, load_robot_config, with_drive_params

from .bag_topics import lost_messages, lost_sentence, topics_by_ending
from .calibration import (
    GNSS,
    WINDOW,
    Calibration,
    DriveRecording,
    GnssTruth,
    ObservableFit,
    OdometryError,
    PoseTruth,
    ScaleFit,
    as_read_with,
    calibrate,
    calibration_yaml,
    common_scale,
    local_metres,
    observable_fit,
    odometry_error,
    set_drive_params_command,
)
from .calibration.calibration_file import changes_yaml, read_calibration
from .calibration.heading import WINDOW as HEADING_WINDOW
from .calibration.heading import HeadingFit, describe, heading_fit
from .calibration.observable import FAR, along_undetermined
from .calibration.odometry_error import imu_bias
from .calibration.turns import TurnFit, turn_fit
from .conversions import quaternion_yaw
from .errors import BagError, CalibrationError, ThorvaldBaseError
from .kinematics.calculator import NO_CORRECTION

ENDINGS = {"states": "base_state", "truth": "odometry/gazebo", "fix": "gps/fix", "imu": "imu/data"}
EXIT_ERROR = 2
NO_FIX = -1  # sensor_msgs/NavSatStatus STATUS_NO_FIX


def find_topics(bag, path: str) -> Dict[str, str]:
    """Each wanted topic by its ending; BagError if several topics end alike."""
    return topics_by_ending(bag.get_type_and_topic_info().topics, ENDINGS, path, BagError)


def read_bag(
    path: str, drives: int, ground_truth: str = "auto", antenna: Tuple[float, float] = (0.0, 0.0)
) -> Tuple[DriveRecording, object, str, str]:
    """(drive states, ground truth, a sentence saying which ground truth, the robot's namespace)."""
    try:
        bag = rosbag.Bag(path)
    except (OSError, rosbag.ROSBagException) as e:
        raise BagError(f"{path}: cannot read the bag: {e}") from None
    with bag:
        topics = find_topics(bag, path)
        names = ", ".join(sorted(bag.get_type_and_topic_info().topics)) or "no topics"
        has_sim = "truth" in topics
        has_gnss = "fix" in topics and "imu" in topics
        if "states" not in topics:
            raise BagError(f"{path}: no topic ending in {ENDINGS['states']} (the bag has: {names})")
        use_gnss = ground_truth == "gnss" or (ground_truth == "auto" and not has_sim and has_gnss)
        if use_gnss and not has_gnss:
            missing = " and ".join(ENDINGS[k] for k in ("fix", "imu") if k not in topics)
            raise BagError(f"{path}: no topic ending in {missing} for GNSS ground truth (the bag has: {names})")
        if not use_gnss and not has_sim:
            wanted = f"{ENDINGS['truth']} (or {ENDINGS['fix']} and {ENDINGS['imu']})"
            raise BagError(f"{path}: no ground truth: no topic ending in {wanted} (the bag has: {names})")
        wanted = [topics["states"]] + ([topics["fix"], topics["imu"]] if use_gnss else [topics["truth"]])
        states, poses, fixes, yaws = [], [], [], []
        sequences: Dict[str, List[int]] = {}
        for topic, msg, _ in bag.read_messages(topics=wanted):
            stamp = msg.header.stamp.to_sec()
            sequences.setdefault(topic, []).append(msg.header.seq)
            if topic == topics["states"]:
                states.append((stamp, tuple(msg.steer_pos), tuple(msg.prop_speed)))
            elif topic == topics.get("truth"):
                p, v = msg.pose.pose, msg.twist.twist
                poses.append(
                    (
                        stamp,
                        p.position.x,
                        p.position.y,
                        quaternion_yaw(p.orientation),
                        v.linear.x,
                        v.linear.y,
                        v.angular.z,
                    )
                )
            elif topic == topics.get("fix"):
                if msg.status.status > NO_FIX:
                    fixes.append((stamp, msg.latitude, msg.longitude))
            else:
                yaws.append((stamp, quaternion_yaw(msg.orientation)))
    lost = lost_messages(sequences)
    if lost:
        raise BagError(
            f"{path}: the recording is incomplete ({lost_sentence(lost)}): a reader fell behind and dropped "
            "messages; record again"
        )
    namespace = topics["states"][: -len(ENDINGS["states"])].rstrip("/")
    recording = DriveRecording.from_samples(states, drives)
    if use_gnss:
        if len(fixes) < 2 or len(yaws) < 2:
            raise BagError(f"{path}: {len(fixes)} GNSS fixes and {len(yaws)} IMU messages: too few for ground truth")
        east, north = local_metres([f[1] for f in fixes], [f[2] for f in fixes])
        truth = GnssTruth.from_samples(list(zip([f[0] for f in fixes], east, north)), yaws, antenna)
        said = (
            f"GNSS {topics['fix']} ({len(fixes)} fixes) and the IMU's yaw {topics['imu']} "
            "(its bias against east estimated)"
        )
    else:
        if len(poses) < 2:
            raise BagError(f"{path}: {len(poses)} messages on {topics['truth']}: too few for ground truth")
        truth = PoseTruth.from_samples(poses)
        said = f"the simulator's {topics['truth']}"
    return recording, truth, said, namespace


def parse_args(argv: Optional[List[str]]):
    parser = argparse.ArgumentParser(
        prog="calibrate_odometry",
        description="Each drive's rolling radius and steering offset from a recorded drive with ground truth.",
    )
    parser.add_argument(
        "bags",
        nargs="+",
        metavar="BAG",
        help="the recorded drive: base_state and ground truth (--fit heading: one or more, each recorded with "
        "--calibration in effect)",
    )
    parser.add_argument("--robot-model", required=True, help="the robot file base_driver ran on")
    parser.add_argument("--calibration", default="", help="the calibration file base_driver ran with, if any")
    parser.add_argument(
        "--ground-truth",
        choices=("auto", "sim", "gnss"),
        default="auto",
        help="the simulator's odometry/gazebo, or GNSS (gps/fix) and IMU yaw (imu/data); auto: the simulator's "
        "when the bag has it",
    )
    parser.add_argument(
        "--antenna", nargs=2, type=float, default=(0.0, 0.0), metavar=("X", "Y"), help="GNSS antenna in base_link [m]"
    )
    parser.add_argument(
        "--window", type=float, default=WINDOW, help=f"[s] between GNSS fixes compared (default {WINDOW:g})"
    )
    parser.add_argument(
        "--out", default="", help="the calibration file to write (default: calibration.yaml beside the bag)"
    )
    parser.add_argument(
        "--fit",
        choices=("drives", "odometry", "scale", "straight", "turns", "heading"),
        default="drives",
        help="drives: each drive's radius and offset from its own wheel's motion (the default); odometry: only "
        "the combinations the drive determines through the odometry, the rest kept at the values in effect "
        "(the simulator's ground truth); scale: only the radii's common factor, from straight legs between "
        "standstills (the straight manoeuvre, driven with the calibration in effect); straight: the same legs' "
        "common factor and odometry's yaw per metre, from the legs' heading; turns: only odometry's "
        "yaw-rate multiplier, from U turns of the working radius (the turns manoeuvre, driven with the "
        "calibration in effect); heading: odometry's heading model (yaw-rate multiplier, yaw per metre along x "
        "and y, each wheel's weight in the yaw rate) from drives of every motion (the heading manoeuvre, driven "
        "with the calibration in effect)",
    )
    parser.add_argument(
        "--balance",
        metavar="FILE",
        default="",
        help="balance_wheels' calibration file (each tyre's radius against the others', from the motors' "
        "currents): the radii move to it along the combinations the drive does not determine (the simulator's "
        "ground truth), or take it with ground truth's common factor (GNSS)",
    )
    parser.add_argument(
        "--keep-yaw-per-metre",
        action="store_true",
        help="--fit heading: keep the calibration in effect's yaw per metre along x (straight legs at working "
        "speed told it, --fit straight) and fit the rest",
    )
    parser.add_argument("--json", action="store_true", help="print the results as one JSON document")
    return parser.parse_args(argv)


def main(argv: Optional[List[str]] = None) -> int:
    args = parse_args(argv)
    args.bag = args.bags[0]
    try:
        if len(args.bags) > 1 and args.fit != "heading":
            raise CalibrationError(f"--fit {args.fit} takes one bag, not {len(args.bags)} (--fit heading, several)")
        return run(args)
    except (ConfigError, ThorvaldBaseError) as e:
        print(f"calibrate_odometry: {e}", file=sys.stderr)
        return EXIT_ERROR


def run(args) -> int:
    if not args.window > 0:
        raise CalibrationError(f"--window: {args.window!r}: must be > 0 [s]")
    robot = load_robot_config(args.robot_model)
    in_effect, earlier, odometry = robot, [], None
    if args.calibration:
        values = read_calibration(args.calibration, robot)
        earlier, odometry = list(values.changes), values.odometry
        in_effect = with_drive_params(in_effect, earlier)
    if args.fit in ("scale", "straight", "turns", "heading") and args.balance:
        raise CalibrationError(
            f"--balance goes with --fit drives or odometry: --fit {args.fit} keeps every radius's share"
        )
    if args.fit == "heading":
        drives = [read_bag(bag, len(robot.drives), args.ground_truth, args.antenna) for bag in args.bags]
        return run_heading(args, in_effect, drives, earlier=earlier, odometry=odometry)
    recording, truth, said, namespace = read_bag(args.bag, len(robot.drives), args.ground_truth, args.antenna)
    if args.fit == "turns":
        return run_turns(args, in_effect, recording, truth, said=said, earlier=earlier, odometry=odometry)
    correction = odometry or NO_CORRECTION
    scale = None
    if args.fit in ("scale", "straight"):
        scale = common_scale(in_effect, recording, truth, heading=args.fit == "straight", in_effect=correction)
        if args.fit == "straight":
            odometry = scale.correction
        calibration, observable = scale.calibration(in_effect), None
    elif args.fit == "odometry":
        if not isinstance(truth, PoseTruth):
            raise CalibrationError(
                "--fit odometry: needs the simulator's ground truth (a body twist at every instant), not GNSS"
            )
        observable = observable_fit(in_effect, recording, truth)
        calibration = observable.calibration(float(np.sum(np.abs(np.diff(truth.yaw)))))
    else:
        calibration = calibrate(in_effect, recording, truth, window=args.window)
        observable = observable_fit(in_effect, recording, truth) if isinstance(truth, PoseTruth) else None
    if args.balance:
        calibration = with_balance(calibration, observable, list(read_calibration(args.balance, robot).changes), robot)
    calibrated = calibration.calibrated(in_effect)
    bias = calibration.heading_bias[0] if calibration.heading_bias else _bias(in_effect, recording, truth, correction)
    before = odometry_error(in_effect, recording, truth, bias, correction=correction)
    after = odometry_error(
        calibrated, as_read_with(recording, in_effect, calibrated), truth, bias, correction=odometry or NO_CORRECTION
    )
    out = args.out or default_out(args)
    kept = write_file(out, calibration, earlier, args, said, odometry=odometry)
    outcome = Outcome(
        calibration,
        said,
        before,
        after,
        out,
        set_drive_params_command(calibration.changes(), namespace),
        kept,
        observable,
        args.fit,
        scale,
    )
    if args.json:
        print(json.dumps(as_json(outcome), indent=2))
    else:
        print_text(outcome)
    return 0


def with_balance(calibration: Calibration, observable: Optional[ObservableFit], balanced, robot) -> Calibration:
    """The calibration with each drive's radius, and its steering offset where the balance searched
    the toe, from the balanced calibration file's changes: along the combinations the drive did not
    determine (with the simulator's ground truth: observable given), or the balanced radii scaled to the
    calibration's geometric mean and the balance's offsets as they are (GNSS: the toe search kept the
    crab and arc it started with)."""
    config = with_drive_params(robot, balanced)
    radii = [d.r_wheel for d in config.drives]
    toe = {index for index, key, _ in balanced if key == "steering_offset"}
    offsets = [d.steering_offset for d in config.drives] if toe else None
    by_name = {f"{p.drive}.{p.key}": p for p in calibration.parameters}
    if observable is not None:
        values = along_undetermined(observable, [by_name[n].value for n in observable.names], radii, offsets)
        moved = dict(zip(observable.names, values))
    else:
        fitted = [by_name[f"drive{k}.r_wheel"].value for k in range(len(radii))]
        scale = math.exp(float(np.mean(np.log(fitted)) - np.mean(np.log(radii))))
        moved = {f"drive{k}.r_wheel": r * scale for k, r in enumerate(radii)}
        moved.update({f"drive{k}.steering_offset": offsets[k] for k in toe if f"drive{k}.steering_offset" in by_name})
    parameters = []
    for p in calibration.parameters:
        value = moved.get(f"{p.drive}.{p.key}", p.value)
        parameters.append(p if value == p.value else replace(p, value=value, excited=True, reason=""))
    return replace(calibration, parameters=tuple(parameters))


@dataclass(frozen=True)
class Outcome:
    calibration: Calibration
    ground_truth: str  # which, in words
    before: OdometryError
    after: OdometryError
    path: str  # the calibration file written
    command: str  # the set_drive_params call
    kept: bool  # the file keeps values of the calibration in effect that were not estimated again
    observable: Optional[ObservableFit] = None  # what the drive determines through the odometry (simulator)
    fit: str = "drives"
    scale: Optional[ScaleFit] = None  # --fit scale's legs


def default_out(args) -> str:
    return os.path.join(os.path.dirname(os.path.abspath(args.bag)), "calibration.yaml")


def run_turns(args, in_effect, recording, truth, *, said: str, earlier, odometry) -> int:
    """--fit turns: the yaw-rate multiplier from the drive's turns, every drive value kept."""
    fit = turn_fit(in_effect, recording, truth, odometry or NO_CORRECTION)
    bias = _bias(in_effect, recording, truth, fit.in_effect)
    before = odometry_error(in_effect, recording, truth, bias, correction=fit.in_effect)
    after = odometry_error(in_effect, recording, truth, bias, correction=fit.correction)
    out = args.out or default_out(args)
    header = header_lines(args, out, said)
    header += f"\nthe yaw-rate multiplier from {len(fit.turns)} turns"
    if earlier:
        header += f"; the drives' values kept from {args.calibration}"
    write_text(out, changes_yaml([], header, extra=earlier, odometry=fit.correction))
    if args.json:
        print(json.dumps(turns_json(fit, said, before, after, out), indent=2))
    else:
        print_turns(fit, said, (before, after), path=out, kept=bool(earlier))
    return 0


def _bias(config, recording, truth, correction) -> float:
    """[rad] the IMU's yaw bias an end-point figure against GNSS needs (0 with the simulator's ground
    truth): from the fixes and odometry's translation, for fits that do not estimate it."""
    return imu_bias(config, recording, truth, correction=correction) if isinstance(truth, GnssTruth) else 0.0


def run_heading(args, in_effect, drives, *, earlier, odometry) -> int:
    """--fit heading: odometry's heading model from one or more drives, every drive value kept."""
    drives_ = [(recording, truth) for recording, truth, _, _ in drives]
    fit = heading_fit(in_effect, drives_, odometry or NO_CORRECTION, keep_yaw_per_metre=args.keep_yaw_per_metre)
    errors = []
    for bag, (recording, truth, _, _) in zip(args.bags, drives):
        bias = _bias(in_effect, recording, truth, fit.correction)
        before = odometry_error(in_effect, recording, truth, bias, correction=fit.in_effect)
        after = odometry_error(in_effect, recording, truth, bias, correction=fit.correction)
        errors.append((bag, before, after))
    said = drives[0][2]
    out = args.out or default_out(args)
    header = header_lines(args, out, said)
    header += f"\nodometry's heading model from {fit.windows} windows of {HEADING_WINDOW:g} s"
    if len(args.bags) > 1:
        header += " of " + ", ".join(os.path.abspath(bag) for bag in args.bags)
    if earlier:
        header += f"; the drives' values kept from {args.calibration}"
    write_text(out, changes_yaml([], header, extra=earlier, odometry=fit.correction))
    if args.json:
        print(json.dumps(heading_json(fit, said, errors, out), indent=2))
        return 0
    print(f"ground truth: {said}")
    for line in describe(fit):
        print(line)
    for bag, before, after in errors:
        print(
            f"odometry against ground truth on {os.path.basename(bag)}: before {before.distance_error_percent:+.3f} % "
            f"of {before.truth_distance_m:.2f} m, end point {before.end_point_m:.3f} m; after "
            f"{after.distance_error_percent:+.3f} %, end point {after.end_point_m:.3f} m"
        )
    print(f"wrote {out}" + (" (with the drives' values of the calibration in effect)" if earlier else ""))
    print("base_driver applies it at start (~calibration); set_drive_params does not change odometry's correction")
    return 0


def heading_json(fit: HeadingFit, said: str, errors, path: str) -> dict:
    c = fit.correction
    names = ("yaw_rate_multiplier", "yaw_per_metre", "yaw_per_metre_sideways")
    values = (c.yaw_rate_multiplier, c.yaw_per_metre, c.yaw_per_metre_sideways)
    in_effect = (fit.in_effect.yaw_rate_multiplier, fit.in_effect.yaw_per_metre, fit.in_effect.yaw_per_metre_sideways)
    out = {"fit": "heading", "ground_truth_source": said, "windows": fit.windows}
    for name, value, sd, excited, kept, was in zip(names, values, fit.sd, fit.excited, fit.undetermined, in_effect):
        # excited: used; undetermined: moved less than DETERMINED sd from the value in effect, which it keeps
        out[name] = {"value": value, "sd": _number(sd), "excited": excited, "undetermined": kept, "in_effect": was}
    out["wheel_weights"] = {
        "value": list(c.wheel_weights),
        "told": fit.weights_told,
        "said": fit.weights_said,
        "in_effect": list(fit.in_effect.wheel_weights),
    }
    out["yaw_per_metre"]["kept"] = fit.kept_yaw_per_metre
    out["yaw_rate_multiplier"]["whole_turns"] = len(fit.turns)  # 0: from the windows, or kept
    out["heading_rms_deg"] = {"before": math.degrees(fit.rms_before), "after": math.degrees(fit.rms_after)}
    out["motions"] = [
        {
            "motion": m.motion,
            "windows": m.windows,
            "seconds": m.seconds,
            "turned_deg": math.degrees(m.turned),
            "before_deg": math.degrees(m.before),
            "after_deg": math.degrees(m.after),
            "rms_before_deg": math.degrees(m.rms_before),
            "rms_after_deg": math.degrees(m.rms_after),
        }
        for m in fit.motions
    ]
    out["drives"] = [{"bag": os.path.abspath(bag), "before": _errors(b), "after": _errors(a)} for bag, b, a in errors]
    out["before"], out["after"] = _errors(errors[0][1]), _errors(errors[0][2])
    out["calibration_file"] = path
    return out


def header_lines(args, path: str, said: str) -> str:
    return (
        f"odometry calibration of {args.robot_model}\nfrom {os.path.abspath(args.bag)}, ground truth {said}\n"
        f"base_driver: ~calibration (base_bringup.launch calibration:={path})"
    )


def write_text(path: str, text: str) -> None:
    try:
        with open(path, "w") as f:
            f.write(text)
    except OSError as e:
        raise CalibrationError(f"{path}: cannot write the calibration file: {e.strerror}") from None


def turns_json(fit: TurnFit, said: str, before: OdometryError, after: OdometryError, path: str) -> dict:
    return {
        "fit": "turns",
        "ground_truth_source": said,
        "turns": [
            {"start": turn.start, "end": turn.end, "truth_rad": turn.truth, "odometry_rad": turn.odometry}
            for turn in fit.turns
        ],
        "yaw_rate_multiplier": {
            "value": fit.multiplier,
            "sd": _number(fit.multiplier_sd),
            "in_effect": fit.in_effect.yaw_rate_multiplier,
        },
        "yaw_per_metre": fit.in_effect.yaw_per_metre,
        "before": _errors(before),
        "after": _errors(after),
        "calibration_file": path,
    }


def print_turns(fit: TurnFit, said: str, errors: Tuple[OdometryError, OdometryError], *, path: str, kept: bool) -> None:
    before, after = errors
    print(f"ground truth: {said}; {len(fit.turns)} turns")
    for turn in fit.turns:
        print(
            f"  turn {turn.start:7.2f} to {turn.end:7.2f} s: ground truth {math.degrees(turn.truth):+8.2f} deg, "
            f"odometry {math.degrees(turn.odometry):+8.2f} deg ({turn.short_percent:+.2f} % short)"
        )
    print(
        f"odometry's yaw-rate multiplier: {fit.multiplier:.5f} ± {fit.multiplier_sd:.5f} "
        f"(was {fit.in_effect.yaw_rate_multiplier:g}; the turns read {100 * (fit.gain - 1):+.3f} % short with it)"
    )
    print(
        f"odometry against ground truth: before {before.distance_error_percent:+.3f} % of "
        f"{before.truth_distance_m:.2f} m, end point {before.end_point_m:.3f} m; after "
        f"{after.distance_error_percent:+.3f} %, end point {after.end_point_m:.3f} m"
    )
    print(f"wrote {path}" + (" (with the drives' values of the calibration in effect)" if kept else ""))
    print("base_driver applies it at start (~calibration); set_drive_params does not change the multiplier")


def write_file(path: str, calibration: Calibration, earlier, args, said: str, *, odometry=None) -> bool:
    """The estimates, over the calibration in effect (what was not estimated again is kept from it), and
    odometry's correction (kept, or with what was fitted)."""
    estimated = {(p.index, p.key) for p in calibration.estimated}
    kept = [(i, key, value) for i, key, value in earlier if (i, key) not in estimated]
    header = header_lines(args, path, said)
    if kept:
        header += f"\nkept from {args.calibration}: " + ", ".join(f"drive{i} {key}" for i, key, _ in kept)
    text = calibration_yaml(calibration, header, extra=kept, odometry=odometry)
    write_text(path, text)
    return bool(kept)


def as_json(outcome: Outcome) -> dict:
    calibration = outcome.calibration
    drives: Dict[str, Dict[str, Optional[float]]] = {}
    for p in calibration.parameters:
        entry = drives.setdefault(p.drive, {})
        entry[p.key] = float(p.value)
        entry[p.key + "_sd"] = _number(p.sd)
    out = {
        "drives": drives,
        "ground_truth": calibration.ground_truth,
        "ground_truth_source": outcome.ground_truth,
        "before": _errors(outcome.before),
        "after": _errors(outcome.after),
        "not_excited": [
            {"drive": p.drive, "key": p.key, "value_in_effect": p.in_effect, "reason": p.reason}
            for p in calibration.not_excited
        ],
        "calibration_file": outcome.path,
        "set_drive_params": outcome.command,
    }
    if calibration.heading_bias is not None:
        out["imu_yaw_bias"] = {"value": calibration.heading_bias[0], "sd": _number(calibration.heading_bias[1])}
    out["fit"] = outcome.fit
    if outcome.scale is not None:
        out["scale"] = {
            "factor": outcome.scale.factor,
            "sd": _number(outcome.scale.sd),
            "legs": [
                {
                    "truth_m": leg.truth_m,
                    "odometry_m": leg.odometry_m,
                    "path_m": leg.path_m,
                    "straight": leg.straight,
                    "truth_turn_rad": leg.truth_turn,
                    "odometry_turn_rad": leg.odometry_turn,
                }
                for leg in outcome.scale.legs
            ],
        }
        if outcome.scale.yaw_per_metre is not None:
            out["scale"]["yaw_per_metre"] = {
                "added": outcome.scale.yaw_per_metre,
                "sd": _number(outcome.scale.yaw_per_metre_sd),
                "value": outcome.scale.correction.yaw_per_metre,
                "odometry_turn_after_rad": list(outcome.scale.odometry_turns_after),
            }
    if outcome.observable is not None:
        out["combinations"] = [
            {
                "strength": c.strength,
                "uncertainty_left": c.sd,
                "determined": c.determined,
                "parts": {name: weight for name, weight in c.parts},
            }
            for c in outcome.observable.combinations
        ]
    return out


def _errors(error: OdometryError) -> dict:
    return {
        "distance_error_percent": _number(error.distance_error_percent),
        "end_point_m": _number(error.end_point_m),
        "distance_m": _number(error.distance_m),
        "truth_distance_m": _number(error.truth_distance_m),
    }


def _number(value: float) -> Optional[float]:
    return None if value is None or not math.isfinite(value) else float(value)


def print_text(outcome: Outcome) -> None:
    calibration, before, after = outcome.calibration, outcome.before, outcome.after
    unit = "windows" if calibration.ground_truth == GNSS else "samples"
    scale = outcome.scale
    if scale is not None:
        unit = "straight legs between standstills"
    print(f"ground truth: {outcome.ground_truth}; {calibration.observations} {unit}")
    if scale is not None:
        used = scale.used
        left = len(scale.legs) - len(used)
        print(
            f"the radii's common factor: {scale.factor:.5f} ± {scale.sd:.2g} "
            f"({100 * (scale.factor - 1):+.3f} %), ground truth's {sum(leg.truth_m for leg in used):.2f} m against "
            f"odometry's {sum(leg.odometry_m for leg in used):.2f} m"
            + (f"; {left} legs left out (turned or short)" if left else "")
        )
        if scale.yaw_per_metre is not None:
            print(
                f"odometry's yaw per metre along x: {scale.correction.yaw_per_metre:+.6f} rad/m "
                f"({math.degrees(scale.yaw_per_metre):+.4f} ± {math.degrees(scale.yaw_per_metre_sd):.4f} deg/m added); "
                "each leg's heading change [deg], ground truth / odometry before / after: "
                + ", ".join(
                    f"{math.degrees(leg.truth_turn):+.2f} / {math.degrees(leg.odometry_turn):+.2f} / "
                    f"{math.degrees(after):+.2f}"
                    for leg, after in zip(used, scale.odometry_turns_after)
                )
            )
    print(f"{'drive':<8} {'r_wheel [m]':<34} steering_offset [rad]")
    rows: Dict[str, Dict[str, str]] = {}
    for p in calibration.parameters:
        if p.excited:
            text = f"{p.value:.5f} ± {p.sd:.5f}"
            if p.key == "steering_offset":
                text += f" ({math.degrees(p.value):+.3f} deg)"
            text += f" (was {p.in_effect:g})"
        else:
            text = f"{p.in_effect:g} ({'kept' if scale is not None else 'not excited'})"
        rows.setdefault(p.drive, {})[p.key] = text
    for drive, row in rows.items():
        print(f"{drive:<8} {row.get('r_wheel', ''):<34} {row.get('steering_offset', '-')}")
    if calibration.heading_bias is not None:
        value, sd = calibration.heading_bias
        print(f"IMU yaw bias against east: {value:+.5f} ± {sd:.5f} rad ({math.degrees(value):+.3f} deg)")
    for p in calibration.not_excited if scale is None else ():
        print(f"not excited: {p.drive} {p.key} (left at {p.in_effect:g}): {p.reason}")
    fit = outcome.observable
    if fit is not None:
        print(
            f"what the drive determines through the odometry: {len(fit.determined)} of {len(fit.combinations)} "
            "combinations (in units of each parameter's prior uncertainty, 1 % of a radius and 0.5 deg of an offset)"
        )
        for c in fit.combinations:
            print(f"  {c.describe()}")
        if outcome.fit == "odometry":
            print("fitted: the determined combinations; the others kept at the values in effect")
            far = fit.far()
            if far:
                moved = ", ".join(f"{name} {priors:+.0f}" for name, priors in far)
                print(
                    f"warning: the fit moved parameters beyond {FAR:g} of their priors ({moved}): the drive's errors "
                    "are not the odometry model's (slip, wheels fighting each other); prefer --fit drives"
                )
    print(
        f"odometry against ground truth: before {before.distance_error_percent:+.3f} % of "
        f"{before.truth_distance_m:.2f} m, end point {before.end_point_m:.3f} m; after "
        f"{after.distance_error_percent:+.3f} %, end point {after.end_point_m:.3f} m"
    )
    kept = " (with what the calibration in effect set and was not estimated again)" if outcome.kept else ""
    print(f"wrote {outcome.path}{kept}")
    print(f"apply it to the running robot: {outcome.command}")


__all__ = ["BagError", "find_topics", "main", "read_bag"]
