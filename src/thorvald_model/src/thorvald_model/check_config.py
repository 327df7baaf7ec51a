"""``rosrun thorvald_model check_config FILE [FILE ...] [--model-extras XACRO] [--tf-prefix P]``.

Validates robot configuration files. One file: a summary of the robot and its drives. Several
files: one table row per robot. Invalid files: every problem, one per line, on stderr, and exit
status 2.

With ``--model-extras`` (a model_extras file, e.g. the user's sensors) or ``--tf-prefix``, the
robot's URDF is generated as model.launch generates it and checked as check_urdf would
(:mod:`thorvald_model.urdf_check`): a joint naming a link that does not exist is reported with
the joint, the link and the closest existing names, as it would stop the robot's launch.

Every file is also checked against its calculator's own layout rules: the ``base_calculator`` class
is loaded by name through the plugin mechanism base_driver uses (:mod:`thorvald_model.plugins`, a
dynamic load: this package never imports thorvald_base), and a calculator that cannot be loaded is
a problem of the file. So a file base_driver would refuse is refused here too, always.
"""

import argparse
import math
import os
import sys
import xml.etree.ElementTree as ET
from typing import Dict, List, Optional

from .check_report import report
from .config import RobotConfig, load_robot_config
from .description import generate_urdf
from .errors import ConfigError, UnknownRobotError, XacroError
from .examples import robot_file
from .plugins import calculator_loader, calculator_problems


def summary(config: RobotConfig) -> dict:
    """The figures a robot designer looks at first."""
    passive = config.passive_wheels
    return {
        "robot": os.path.splitext(os.path.basename(config.source))[0],
        "calculator": config.base_calculator,
        "drives": len(config.drives),
        "steered": len(config.steered_drives),
        "driven": len(config.drives),
        "passive": len(passive),
        "casters": sum(1 for w in passive if not w.fixed),
        "fixed": sum(1 for w in passive if w.fixed),
        "suspended": sum(1 for d in config.drives if d.suspension is not None),
        "track": round(config.track, 4),
        "wheelbase": round(config.wheelbase, 4),
        "batteries": len(config.present_batteries),  # a module with with_battery: 0 is an empty enclosure
        "battery_modules": len(config.batteries),
    }


TABLE_COLUMNS = (
    # name, header, width, number format
    ("robot", "robot", -28, ""),
    ("drives", "drives", 7, ""),
    ("steered", "steered", 8, ""),
    ("driven", "driven", 7, ""),
    ("passive", "passive", 8, ""),
    ("track", "track [m]", 10, ".3f"),
    ("wheelbase", "wheelbase [m]", 14, ".3f"),
    ("calculator", "calculator", -0, ""),
)


def format_table(rows: List[dict]) -> str:
    def cell(text, width):
        return "  " + text if width == 0 else (text.ljust(-width) if width < 0 else text.rjust(width))

    lines = ["".join(cell(head, width) for _, head, width, _ in TABLE_COLUMNS)]
    for row in rows:
        lines.append("".join(cell(format(row[name], fmt), width) for name, _, width, fmt in TABLE_COLUMNS))
    return "\n".join(lines)


def description_summary(urdf: str, extras: str = "") -> Dict[str, object]:
    """Links, joints and the root link of a generated (checked) robot description."""
    root = ET.fromstring(urdf)
    links = [link.get("name") for link in root.findall("link")]
    children = {c.get("link") for c in root.findall("joint/child")}
    return {
        "links": len(links),
        "joints": len(root.findall("joint")),
        "root": next((link for link in links if link not in children), ""),
        "extras": extras,
    }


def format_description(d: Dict[str, object]) -> str:
    extras = ", with {}".format(d["extras"]) if d["extras"] else ""
    return "  description {} links, {} joints, root {}{}".format(d["links"], d["joints"], d["root"], extras)


def format_details(config: RobotConfig) -> str:
    s = summary(config)
    lines = [
        f"{config.source}: valid robot configuration",
        "  calculator  {}".format(s["calculator"]),
        "  drives      {} ({} steered, {} driven, {} with suspension)".format(
            s["drives"], s["steered"], s["driven"], s["suspended"]
        ),
        "  passive     {} wheels ({} casters, {} fixed)".format(s["passive"], s["casters"], s["fixed"]),
        "  track       {:.3f} m, wheelbase {:.3f} m".format(s["track"], s["wheelbase"]),
        "  batteries   {} (in {} battery module{})".format(
            s["batteries"], s["battery_modules"], "" if s["battery_modules"] == 1 else "s"
        ),
        "",
        "  drive   node type   x [m]   y [m]  r [m]  str_lim [deg]  max speed [m/s]",
    ]
    for d in config.drives:
        lines.append(
            f"  {d.name:<7} {d.node:>4} {d.type:>4} {d.x:>7.3f} {d.y:>7.3f} {d.r_wheel:>6.3f}"
            f" {math.degrees(d.str_lim):>14.1f} {d.max_wheel_speed:>16.2f}"
        )
    for w in config.passive_wheels:
        lines.append(f"  {w.name:<7}    - {w.type[:4]:>4} {w.x:>7.3f} {w.y:>7.3f} {w.r_wheel:>6.3f}")
    return "\n".join(lines)


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(
        prog="check_config", description="Validate Thorvald robot configuration files and summarise the robots."
    )
    parser.add_argument(
        "files", nargs="+", metavar="ROBOT", help="robot configuration YAML file(s), or example robots' names"
    )
    parser.add_argument("--json", action="store_true", help="print the summaries as JSON")
    parser.add_argument(
        "--model-extras",
        default="",
        metavar="XACRO",
        help="generate each robot's URDF with this model_extras file and check it as check_urdf would",
    )
    parser.add_argument(
        "--tf-prefix", default=None, help='tf_prefix of the generated URDF, e.g. "robot_1/" (generates and checks it)'
    )
    args = parser.parse_args(argv)
    describe = bool(args.model_extras) or args.tf_prefix is not None

    configs, descriptions, failed = [], {}, 0
    calculators = calculator_loader()  # one search of the workspace's exports for every file
    for given in args.files:
        path = given
        try:
            path = robot_file(given)  # an example robot's name, or a file
            config = load_robot_config(path)
            problems = calculator_problems(config, calculators)
            if problems:
                raise ConfigError(path, problems)
            if describe:
                urdf = generate_urdf(path, tf_prefix=args.tf_prefix or "", model_extras=args.model_extras)
                descriptions[config.source] = description_summary(urdf, args.model_extras)
            configs.append(config)
        except ConfigError as e:  # the robot file's problems, or the generated description's (UrdfCheckError)
            failed += 1
            print(e, file=sys.stderr)
        except XacroError as e:  # e.g. an extras file that is missing or not XML
            failed += 1
            print(f"check_config: error: {path}: {e}", file=sys.stderr)
        except UnknownRobotError as e:
            failed += 1
            print(f"check_config: {e}", file=sys.stderr)

    def row(config: RobotConfig) -> dict:
        out = summary(config)
        if config.source in descriptions:
            out["description"] = descriptions[config.source]
        return out

    def details(config: RobotConfig) -> str:
        text = format_details(config)
        if config.source in descriptions:
            text += "\n" + format_description(descriptions[config.source])
        return text

    return report(configs, failed, len(args.files), as_json=args.json, row=row, details=details, table=format_table)


if __name__ == "__main__":
    sys.exit(main())
