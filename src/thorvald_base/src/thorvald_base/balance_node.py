"""The ``balance_wheels`` node: each tyre's rolling radius against the others', from the motors' currents.

On a rigid frame of speed-controlled wheels a tyre larger than base_driver thinks pushes and the others
brake it (:mod:`thorvald_base.calibration.torque_balance`). This node drives the ``balance`` manoeuvre
(:func:`thorvald_base.verification.plan_named`: straight legs back and forth at 0.2 m/s, a pause after
each) as ``verification_drive`` drives its manoeuvres, and in each pause reads the wheels' torques over
the leg from their motor currents (``motor_controller_data``, through each drive's motor and gear:
:mod:`thorvald_model.motors`), and sets the radii for the next leg through base_driver's
``set_drive_params``: first a probe along the fight, then the fit of every leg so far.

On a robot whose steered wheels have a toe ground truth cannot see (every steered robot of more than
one steered drive, :mod:`thorvald_base.calibration.toe_balance`), shorter legs follow with the radii
at that fit: the toe search, which changes one drive's steering offset at a time in the pauses and
keeps the offsets at which the frame's resistance (the wheels' mean torque against the travel) is
least; then four legs of the radii again with those offsets (the first at the first legs' fit, the
next at the radii the first legs' stiffness gives, then at the fit of these legs), whose fit is the
balance. A wheel homed off scrubs, and the radii at which no wheel fights are then
off by tenths of a percent.

At the end it prints each leg's fight (the rms of the wheels' torques beyond their mean, and the
electrical power the motors spent on it), the balanced radii and the offsets found, and writes them
(``~out``): the calibration base_driver started with (``~calibration``), each r_wheel replaced by its
balanced value and each searched steering_offset by the one found. The radii keep their geometric
mean, the offsets the patterns the frame follows (a crab and an arc): those are ground truth's to tell
(``calibrate_odometry``).

Drive it on level, even ground, with the calibration from the calibration drive in effect.

Parameters: verification_drive's (but ``~manoeuvre``: always ``balance``; ``~side`` [m]: each leg's
length, default 4), ``~calibration`` (the calibration file base_driver runs with, if any),
``~out`` (the file to write; default none), ``~json`` (a file for the report's figures; default
none), ``~drive_params_service`` (default ``base_driver/set_drive_params``) and ``~controllers_topic``
(default ``motor_controller_data``).
Exit status 0 with the report; 1 when the motors report no current (a base that does not measure
it) or the wheels' torques do not grow with their slip; 2 for a bad robot or calibration file.
"""

import json
import math
import os
import sys
from typing import List, Optional, Sequence, Tuple

import numpy as np
import rospy

from thorvald_model import ConfigError, with_drive_params
from thorvald_model.motors import Motor, output_torque, propulsion_motor
from thorvald_msgs.msg import ControllerArray, DriveParam
from thorvald_msgs.srv import DriveParams

from .calibration.balancer import Balancer
from .calibration.calibration_file import CalibrationValues, changes_yaml, read_calibration
from .calibration.toe_balance import ToeSearch
from .calibration.torque_balance import Leg, fight_power
from .errors import CalibrationError
from .verification import BALANCE_SPEED, BalanceWindow, balance_legs
from .verification_node import VerificationDrive

NO_BALANCE = 3  # the exit status when the legs could not support a balance (the report says why)
DECIDE_AFTER = 1.5  # [s] after a leg's end: its last motor_controller_data has arrived (1 Hz)
MIN_SAMPLES = 3  # motor_controller_data messages a leg must hold


class BalanceDrive(VerificationDrive):
    def __init__(self):
        super().__init__("balance")
        self.motors: List[Motor] = [propulsion_motor(d) for d in self.config.drives]
        path = str(rospy.get_param("~calibration", "") or "")
        self.in_effect = read_calibration(path, self.config) if path else CalibrationValues()
        self.calibration = list(self.in_effect.changes)
        config = with_drive_params(self.config, self.calibration)
        self.out = str(rospy.get_param("~out", "") or "")
        self.json = str(rospy.get_param("~json", "") or "")
        self.windows: List[BalanceWindow] = balance_legs(self.plan)
        self.balancer = Balancer(config, [w.kind for w in self.windows])
        self.samples: List[Tuple[float, Tuple[float, ...]]] = []  # (stamp, propulsion amps per drive)
        self.service = rospy.resolve_name(str(rospy.get_param("~drive_params_service", "base_driver/set_drive_params")))
        rospy.Subscriber(
            str(rospy.get_param("~controllers_topic", "motor_controller_data")),
            ControllerArray,
            self.on_controllers,
            queue_size=100,
        )

    def on_controllers(self, msg):
        by_name = {c.name: c for c in msg.controllers}
        amps = [math.nan] * len(self.config.drives)
        for controller in self.config.motor_controllers:
            c = by_name.get(controller.name)
            if c is None:
                continue
            propulsion = [v for v in c.motor_vars if v.type == "propulsion"]
            for index, var in zip(controller.indices, propulsion):
                amps[index] = var.motor_amps
        self.samples.append((msg.header.stamp.to_sec(), tuple(amps)))

    def during(self, start: float, t: float) -> None:
        balancer = self.balancer
        while len(balancer.legs) < len(self.windows) and t >= self.windows[len(balancer.legs)].end + DECIDE_AFTER:
            window = self.windows[len(balancer.legs)]
            was = balancer.stopped
            balancer.record(self.measure(start, window.begin, window.end, window.speed))
            radii, offsets = balancer.next()
            if balancer.stopped is not None and was is None:
                rospy.logwarn("balance_wheels: %s; the rest of the drive with the radii and offsets it started with",
                              balancer.stopped)  # fmt: skip
            if radii is not None:
                self.set_params("r_wheel", radii, "radii")
            if offsets is not None:
                steered = [k for k, d in enumerate(self.config.drives) if d.steerable]
                self.set_params("steering_offset", [offsets[k] for k in steered], "steering offsets", steered)

    def measure(self, start: float, begin: float, end: float, speed: float) -> Leg:
        """The leg's mean wheel torques over its measured part, from the currents reported in it."""
        legs = len(self.balancer.legs)
        rows = [amps for stamp, amps in self.samples if start + begin <= stamp <= start + end]
        rows = [amps for amps in rows if all(math.isfinite(a) for a in amps)]
        if len(rows) < MIN_SAMPLES:
            raise RuntimeError(
                f"{len(rows)} motor_controller_data messages with every drive's current during balance leg "
                f"{legs + 1} ({begin:.0f} to {end:.0f} s): is base_driver publishing them?"
            )
        radii = self.balancer.radii
        rates = [speed / r for r in radii]
        torques = np.mean(
            [[output_torque(m, a, w) for m, a, w in zip(self.motors, amps, rates)] for amps in rows], axis=0
        )
        if not np.any(np.abs(np.mean(rows, axis=0)) > 0.0):
            raise RuntimeError("every motor current reads 0: this base does not measure its motors' currents")
        return Leg(radii, speed, tuple(float(t) for t in torques), tuple(rates), end - begin, len(rows))

    def set_params(self, key: str, values: Sequence[float], what: str, indices: Optional[Sequence[int]] = None) -> None:
        indices = list(range(len(values))) if indices is None else list(indices)
        try:
            rospy.wait_for_service(self.service, timeout=self.startup_timeout)
            params = [DriveParam(index=k, type=key, value=float(v)) for k, v in zip(indices, values)]
            answer = rospy.ServiceProxy(self.service, DriveParams)(params)
        except (rospy.ROSException, rospy.ServiceException) as e:
            raise RuntimeError(f"{self.service}: {e}") from None
        if answer.status < len(params):
            raise RuntimeError(f"{self.service} refused the {what}: {answer.message}")

    def balance(self) -> Tuple[str, bool]:
        """Drives the legs; (the report, whether a balance was found), having written ~out (when found)
        and ~json (the legs, and the balance or why there is none)."""
        self.run()
        balancer = self.balancer
        if len(balancer.legs) < len(self.windows):
            raise RuntimeError(f"the drive ended after {len(balancer.legs)} of {len(self.windows)} legs")
        try:
            fit = balancer.result()
        except CalibrationError as e:
            text = report(self.name, balancer.legs, None, balancer.start_radii, self.motors,
                          description=self.description)  # fmt: skip
            text += f"\n{e}: no balance; the calibration it started with stands"
            if self.json:
                with open(self.json, "w") as f:
                    json.dump(as_json(balancer.legs, None, balancer.start_radii, self.motors, stopped=str(e)), f,
                              indent=2)  # fmt: skip
            return text, False
        toe = balancer.toe
        text = report(self.name, balancer.legs, fit, balancer.start_radii, self.motors, description=self.description,
                      toe=toe)  # fmt: skip
        if self.out:
            changes = [(k, "r_wheel", r) for k, r in enumerate(fit.radii)]
            if toe is not None:
                changes += [(k, "steering_offset", toe.result[k]) for k in toe.drives]
            header = (
                f"balance_wheels: {self.name}, each tyre's radius against the others' from its motor's current"
                + (",\nthe steering offsets at which the frame's resistance is least" if toe is not None else "")
                + ";\nthe other values as the calibration it started with"
            )
            with open(self.out, "w") as f:
                f.write(changes_yaml(changes, header, self.calibration, self.in_effect.odometry))
            text += f"\nwrote {os.path.abspath(self.out)}"
        if self.json:
            with open(self.json, "w") as f:
                json.dump(as_json(balancer.legs, fit, balancer.start_radii, self.motors, toe=toe), f, indent=2)
        return text, True


def report(
    name, legs: Sequence[Leg], fit, start: Sequence[float], motors: Sequence[Motor], *, description: str,
    toe: Optional[ToeSearch] = None,
) -> str:  # fmt: skip
    """The legs' fight, each drive's radius before and balanced, and the toe search's offsets."""
    lines = [f"balance_wheels: {name}: {description}", "", "leg  way        fight [N m]  fight [W]"]
    for k, leg in enumerate(legs):
        way = "forwards" if leg.speed > 0 else "back"
        lines.append(f"{k + 1:<4} {way:<10} {leg.fight:>11.2f}  {max(fight_power(leg, motors), 0.0):>9.1f}")
    if fit is None:  # the balance stopped: the legs only
        return "\n".join(lines)
    lines += ["", "drive    r_wheel [m]   balanced [m]   change [%]   +- [%]"]
    for k, (before, after, sd) in enumerate(zip(start, fit.radii, fit.sd)):
        change, spread = 100 * (after / before - 1), 100 * sd / after
        lines.append(f"drive{k:<3} {before:>11.5f}   {after:>12.5f}   {change:>+10.3f}   {spread:>6.2g}")
    if toe is not None:
        lines += ["", "drive    steering_offset [deg]   found [deg]   change [deg]"]
        for k in toe.drives:
            before, after = math.degrees(toe.start[k]), math.degrees(toe.result[k])
            lines.append(f"drive{k:<3} {before:>21.3f}   {after:>11.3f}   {after - before:>+12.3f}")
        at = [m.at for m in toe.moves]
        lines += [
            "",
            f"toe search: {toe.legs} legs; the frame's resistance {at[0]:.2f} N m at the start, "
            f"{min(at):.2f} N m at the least (the wheels' mean torque against the travel)",
        ]
    first, last = legs[0], legs[-1]
    lines += [
        "",
        f"slip stiffness {fit.stiffness:.0f} N m s/m (the wheels' mean), torques fitted to {fit.residual:.2f} N m rms",
        f"the wheels spent {max(fight_power(first, motors), 0.0):.1f} W against each other at {BALANCE_SPEED:g} m/s "
        f"on the first leg, {max(fight_power(last, motors), 0.0):.1f} W on the last",
    ]
    return "\n".join(lines)


def as_json(
    legs: Sequence[Leg], fit, start: Sequence[float], motors: Sequence[Motor], *, toe=None, stopped: str = ""
) -> dict:
    """The report's figures; with the balance stopped (fit None), the legs and why (``stopped``)."""
    out = {
        "legs": [
            {"speed": leg.speed, "fight_nm": leg.fight, "fight_w": max(fight_power(leg, motors), 0.0),
             "torques_nm": list(leg.torques), "samples": leg.samples}
            for leg in legs
        ],
    }  # fmt: skip
    if fit is None:
        out["stopped"] = stopped
        return out
    out["stiffness"] = fit.stiffness
    out["residual_nm"] = fit.residual
    out["drives"] = {
        f"drive{k}": {"r_wheel_before": before, "r_wheel": after, "sd": sd}
        for k, (before, after, sd) in enumerate(zip(start, fit.radii, fit.sd))
    }
    if toe is not None:
        out["toe"] = {
            "legs": toe.legs,
            "drives": {
                f"drive{k}": {"steering_offset_before": toe.start[k], "steering_offset": toe.result[k]}
                for k in toe.drives
            },
            "moves": [
                {"drive": m.drive, "round": m.round, "step": m.step, "resistance_nm": [m.minus, m.at, m.plus],
                 "move": m.move}
                for m in toe.moves
            ],
        }  # fmt: skip
    return out


def main():
    rospy.init_node("balance_wheels")
    try:
        text, found = BalanceDrive().balance()
    except ConfigError as e:
        rospy.logfatal("balance_wheels: %s", e)
        sys.exit(2)
    except (RuntimeError, KeyError, CalibrationError) as e:
        rospy.logfatal("balance_wheels: %s", e)
        sys.exit(1)
    print(text, flush=True)
    rospy.signal_shutdown("balance drive done")
    if not found:
        sys.exit(NO_BALANCE)
