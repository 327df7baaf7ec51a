"""One robot's DBC file from ``thorvald.dbc``: every frame of every device at its own identifier.

``thorvald.dbc`` describes each frame once, for device 0; a log of a robot's bus has frames of
motor controller nodes 1..n, batteries 1..k and IO boards. ``robot_dbc`` copies each message per
device of the robot (``Roboteq_TxPDO1_node3`` at 0x183, ``Battery_TPDO1_bat1`` at 0x3C1, ...)
with its comments and value tables, so cantools, SavvyCAN or any DBC tool decodes the log. Plain
text work on the file's lines (no DBC library on the robot).
"""

import re
from typing import Dict, List, Tuple

_MESSAGE = re.compile(r"^BO_ (\d+) (\w+):(.*)$")
_COMMENT = re.compile(r"^CM_ BO_ (\d+) (.*)$")
_VALUES = re.compile(r"^VAL_ (\d+) (.*)$")


def devices_of(config) -> Dict[str, List[Tuple[int, str]]]:
    """Message name prefix -> (id offset, name suffix) per device of the robot. ``RoboteqDiff_``
    messages are the prop/prop controllers' variants of ``Roboteq_`` ones at the same identifier."""
    controllers = sorted(config.motor_controllers, key=lambda c: c.node)
    return {
        "Roboteq_": [(c.node, f"node{c.node}") for c in controllers],
        "RoboteqDiff_": [(c.node, f"node{c.node}") for c in controllers if not c.steered],
        "Battery_": [(b.id, f"bat{b.id}") for b in config.present_batteries],
        "IO_": [(b.id, f"io{b.id}") for b in config.io_boards_on_bus],
    }


def robot_dbc(template: str, config) -> str:
    """The DBC text for one robot configuration (thorvald_model RobotConfig)."""
    devices = devices_of(config)
    header, blocks, comments, values, general = [], [], {}, {}, []
    lines = template.splitlines()
    k = 0
    while k < len(lines):
        line = lines[k]
        m = _MESSAGE.match(line)
        if m:
            block = [line]
            k += 1
            while k < len(lines) and lines[k].startswith(" SG_"):
                block.append(lines[k])
                k += 1
            blocks.append((int(m.group(1)), m.group(2), m.group(3), block[1:]))
            continue
        c, v = _COMMENT.match(line), _VALUES.match(line)
        if c:
            comments[int(c.group(1))] = c.group(2)
        elif v:
            values[int(v.group(1))] = v.group(2)
        elif blocks:
            general.append(line)
        else:
            header.append(line)
        k += 1
    out = list(header)
    copies = []  # (new id, base id)
    # a prop/prop controller sends its own variant of these (same identifier, other signals)
    variants = {base for base, name, _, _ in blocks if name.startswith("RoboteqDiff_")}
    prop_prop = {offset for offset, _ in devices.get("RoboteqDiff_", [])}
    for base, name, rest, signals in blocks:
        prefix = next((p for p in devices if name.startswith(p)), None)
        for offset, suffix in devices.get(prefix, []):
            if prefix == "Roboteq_" and base in variants and offset in prop_prop:
                continue
            copies.append((base + offset, base))
            out.append(f"BO_ {base + offset} {name}_{suffix}:{rest}")
            out.extend(signals)
            out.append("")
    out.extend(line for line in general if line.strip())
    for new, base in copies:
        if base in comments:
            out.append(f"CM_ BO_ {new} {comments[base]}")
    for new, base in copies:
        if base in values:
            out.append(f"VAL_ {new} {values[base]}")
    return "\n".join(out).rstrip() + "\n"


def main(argv=None) -> int:
    """``rosrun thorvald_base can_dbc ROBOT.yaml [-o FILE]``: the robot's DBC file."""
    import argparse  # noqa: PLC0415
    import sys  # noqa: PLC0415

    from thorvald_model import ConfigError, load_robot_config  # noqa: PLC0415

    from .protocol import dbc_path  # noqa: PLC0415

    parser = argparse.ArgumentParser(prog="can_dbc", description="The DBC file of one robot's CAN devices.")
    parser.add_argument("robot", help="the robot configuration file (YAML)")
    parser.add_argument("-o", "--output", help="write here (default: standard output)")
    args = parser.parse_args(argv)
    try:
        config = load_robot_config(args.robot)
    except ConfigError as e:
        print(f"can_dbc: {e}", file=sys.stderr)
        return 2
    with open(dbc_path()) as f:
        text = robot_dbc(f.read(), config)
    if args.output:
        with open(args.output, "w") as f:
            f.write(text)
    else:
        sys.stdout.write(text)
    return 0
