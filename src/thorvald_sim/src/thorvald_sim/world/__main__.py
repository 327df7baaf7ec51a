"""``python -m thorvald_sim.world [--update FILE]``: prints the world file's keys as a markdown table
(:func:`thorvald_sim.world.keys_markdown`), or writes it into FILE between its ``world-keys`` marker
lines (``docs/worlds.md``). Exit status 2, one line on stderr, for a file without the markers."""

import argparse
import sys
from typing import List, Optional

from .registry import keys_markdown, with_keys_table


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m thorvald_sim.world", description=__doc__.split("\n")[0])
    parser.add_argument("--update", metavar="FILE", help="write the table into FILE between its marker lines")
    args = parser.parse_args(argv)
    table = keys_markdown()
    if args.update is None:
        sys.stdout.write(table)
        return 0
    try:
        with open(args.update) as f:
            text = f.read()
        updated = with_keys_table(text, table)
    except (OSError, ValueError) as e:
        print(f"{args.update}: {e}", file=sys.stderr)
        return 2
    if updated != text:
        with open(args.update, "w") as f:
            f.write(updated)
    return 0


if __name__ == "__main__":
    sys.exit(main())
