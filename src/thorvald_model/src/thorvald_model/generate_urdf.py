"""``rosrun thorvald_model generate_urdf CONFIG [--tf-prefix P] [--extras X] [--robot-name N]``.

Prints the URDF of the robot a configuration file describes (or writes it with ``-o``). A broken
configuration prints the shared loader's problems, one per line, and exits 2; so does a robot whose
tree check_urdf would refuse (e.g. an extras joint naming a link that does not exist: the joint, the
link and the closest existing names), and nothing is written. Link references written with a
leading slash (``/base_link``) are the robot's links (:mod:`thorvald_model.urdf_check`).
"""

import argparse
import sys
from typing import List, Optional

from .description import generate_urdf
from .errors import ConfigError, XacroError


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(
        prog="generate_urdf", description="Print the URDF robot description generated from a robot configuration."
    )
    parser.add_argument("config", metavar="CONFIG", help="robot configuration YAML file")
    parser.add_argument("--tf-prefix", default="", help='prefix of every link and joint name, e.g. "robot_1/"')
    parser.add_argument("--extras", default="", metavar="XACRO", help="extra xacro file to include (model_extras)")
    parser.add_argument("--robot-name", default=None, help="robot name (default: the file's base name)")
    parser.add_argument("-o", "--output", default=None, help="write the URDF to this file instead of stdout")
    args = parser.parse_args(argv)
    try:
        urdf = generate_urdf(
            args.config, tf_prefix=args.tf_prefix, model_extras=args.extras, robot_name=args.robot_name
        )
    except ConfigError as e:
        print(e, file=sys.stderr)
        return 2
    except XacroError as e:
        print(f"generate_urdf: error: {e}", file=sys.stderr)
        return 2
    if args.output:
        with open(args.output, "w") as f:
            f.write(urdf)
    else:
        sys.stdout.write(urdf)
    return 0


if __name__ == "__main__":
    sys.exit(main())
