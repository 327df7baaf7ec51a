"""``python -m thorvald_sim.world [--update FILE]``: prints the world file's keys as a markdown table
(:func:`thorvald_sim.world.keys_table.keys_markdown`), or writes it into FILE between its
``world-keys`` marker lines (``docs/worlds.md``). Exit status 2, one line on stderr, for a file
without the markers."""

import sys
from typing import List, Optional

from ..doc_tables import table_main
from .keys_table import KEYS_TABLE, keys_markdown


def main(argv: Optional[List[str]] = None) -> int:
    return table_main("python -m thorvald_sim.world", KEYS_TABLE, keys_markdown, argv)


if __name__ == "__main__":
    sys.exit(main())
