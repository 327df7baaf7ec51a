"""Tables the docs hold that are rendered from a registry (the world file's keys, the sensor kinds):
written into a markdown file between two marker lines, ``<!-- NAME:begin -->`` and ``<!-- NAME:end -->``,
by ``python -m thorvald_sim.world --update docs/worlds.md`` and ``python -m thorvald_sim.sensors.kinds
--update docs/sensors.md``; each registry's test checks the docs hold what it renders."""

import argparse
import sys
from typing import Callable, List, Optional, Tuple


def markers(name: str) -> Tuple[str, str]:
    """The lines around table NAME in a markdown file."""
    return f"<!-- {name}:begin -->", f"<!-- {name}:end -->"


def with_table(text: str, table: str, name: str) -> str:
    """The markdown text with the lines between its markers of NAME replaced by table; ValueError if it
    has not both, in that order, once each."""
    begin_mark, end_mark = markers(name)
    lines = text.splitlines(keepends=True)
    marks = [i for i, line in enumerate(lines) if line.strip() in (begin_mark, end_mark)]
    if [lines[i].strip() for i in marks] != [begin_mark, end_mark]:
        raise ValueError(f"needs the lines {begin_mark} and {end_mark}, once each and in that order")
    begin, end = marks
    return "".join(lines[: begin + 1]) + table + "".join(lines[end:])


def table_main(prog: str, name: str, render: Callable[[], str], argv: Optional[List[str]] = None) -> int:
    """``prog [--update FILE]``: prints the table, or writes it into FILE between its markers of NAME.
    Exit status 2, one line on stderr, for a file without the markers."""
    parser = argparse.ArgumentParser(prog=prog, description=f"prints the {name} table, or writes it into a file")
    parser.add_argument("--update", metavar="FILE", help="write the table into FILE between its marker lines")
    args = parser.parse_args(argv)
    table = render()
    if args.update is None:
        sys.stdout.write(table)
        return 0
    try:
        with open(args.update) as f:
            text = f.read()
        updated = with_table(text, table, name)
    except (OSError, ValueError) as e:
        print(f"{args.update}: {e}", file=sys.stderr)
        return 2
    if updated != text:
        with open(args.update, "w") as f:
            f.write(updated)
    return 0
