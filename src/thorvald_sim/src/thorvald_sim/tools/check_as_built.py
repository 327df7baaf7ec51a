"""``rosrun thorvald_sim check_as_built FILE --robot-model ROBOT.yaml``: checks an as-built robot.

FILE is an as-built file or a profile and seed (``field:7``), as ``spawn_robot -as_built`` and
``as_built:=`` take them; ROBOT.yaml is the robot file it differs from. Nothing starts: the two are
read and checked as the spawn would read them. A valid one: a summary of the robot as built (per
drive the true rolling radius and its difference from the configured one, the steering offset and
what the encoders count; the measurement delay and the load). An invalid one (or robot file):
every problem, one per line, on stderr, and exit status 2.
"""

import argparse
import json
import math
import os
import sys
from typing import List, Optional

from thorvald_model import ConfigError, load_robot_config
from thorvald_model.errors import UnknownRobotError
from thorvald_model.examples import robot_file
from thorvald_model.values import RobotConfig

from ..physics.as_built import AsBuilt, SimAsBuilt, as_built_for, for_simulator


def summary(built: AsBuilt, sim: SimAsBuilt, config: RobotConfig) -> dict:
    """The as-built robot's figures, SI units ([m], [rad], [s], [kg]; a count's size at the joint)."""
    drives = []
    for d, b, configured, drive in zip(built.drives, sim.drives, built.configured, config.drives):
        drives.append(
            {
                "drive": d.name,
                "r_wheel": d.r_wheel,
                "configured_r_wheel": configured,
                "r_wheel_difference": d.r_wheel - configured,
                "r_wheel_ratio": d.r_wheel / configured - 1.0,
                "steerable": drive.steerable,
                "steering_offset": d.steering_offset,
                "steering_count": b.steering_count,  # [rad] 0: the angle reported exactly
                "wheel_count": b.wheel_count,  # [rad]
                "speed_step": b.speed_step,  # [m/s] of one motor rpm
            }
        )
    return {
        "as_built": built.source or "as configured",
        "robot_model": config.source,
        "encoders": built.encoders,
        "delay": built.delay,
        "mass_offset": built.mass_offset,
        "loaded": built.loaded,
        "tyre_deflection": built.tyre_deflection,
        "drives": drives,
    }


def format_details(s: dict) -> str:
    """The summary for a reader: one line each for the whole robot, then a table of the drives."""
    counting = "counting whole counts and whole motor rpm, as the controllers" if s["encoders"] else "exact"
    lines = [
        f"{s['as_built']}: valid as-built robot of {s['robot_model']}",
        f"  encoders  {counting}",
        f"  delay     {s['delay'] * 1000:g} ms",
        f"  load      {s['mass_offset']:g} kg",
    ]
    if s["loaded"]:
        lines.append(f"  tyres     loaded {-s['loaded'] * 100:+.2f} % (included in every r below)")
    if s["tyre_deflection"]:
        lines.append(f"  tyres     soft: {s['tyre_deflection'] * 1000:.1f} mm under their share of the weight")
    lines += [
        "",
        "  drive      r [m]  configured [m]  difference [mm]    [%]  steering offset [deg]"
        "  steering count [deg]  wheel count [deg]  speed step [mm/s]",
    ]
    for d in s["drives"]:
        offset = f"{math.degrees(d['steering_offset']):+.3f}" if d["steerable"] else "-"
        steering_count = f"{math.degrees(d['steering_count']):.4f}" if d["steering_count"] else "exact"
        wheel_count = f"{math.degrees(d['wheel_count']):.4f}" if d["wheel_count"] else "exact"
        speed_step = f"{d['speed_step'] * 1000:.3f}" if d["speed_step"] else "exact"
        if not d["steerable"]:
            steering_count = "-"
        lines.append(
            f"  {d['drive']:<7} {d['r_wheel']:>8.5f} {d['configured_r_wheel']:>15.5f}"
            f" {d['r_wheel_difference'] * 1000:>+16.2f} {d['r_wheel_ratio'] * 100:>+6.2f}"
            f" {offset:>22} {steering_count:>21} {wheel_count:>18} {speed_step:>18}"
        )
    return "\n".join(lines)


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(
        prog="check_as_built",
        description="Check an as-built file (or a profile and seed, e.g. field:7) against the robot file it "
        "differs from, without starting the simulator.",
    )
    parser.add_argument("as_built", metavar="FILE", help="as-built YAML file, or PROFILE:SEED (e.g. field:7)")
    parser.add_argument(
        "--robot-model", required=True, metavar="ROBOT", help="an example robot's name or a robot configuration file"
    )
    parser.add_argument("--json", action="store_true", help="print the summary as JSON")
    args = parser.parse_args(argv)
    try:
        config = load_robot_config(robot_file(args.robot_model))
        built = as_built_for(args.as_built, config)
        sim = for_simulator(built, config)
    except ConfigError as e:
        print(e, file=sys.stderr)  # FILE: key path: value: rule, as every command that reads these files
        return 2
    except UnknownRobotError as e:
        print(f"check_as_built: --robot-model {e}", file=sys.stderr)
        return 2
    s = summary(built, sim, config)
    if args.json:
        print(json.dumps(s, indent=2))
    else:
        s["robot_model"] = os.path.basename(s["robot_model"])
        print(format_details(s))
    return 0


if __name__ == "__main__":
    sys.exit(main())
