"""``python -m thorvald_sim.sensors.kinds [--update FILE]``: prints the table of sensor kinds
(:func:`thorvald_sim.sensors.kinds.kinds_markdown`), or writes it into FILE between its
``sensor-kinds`` marker lines (``docs/sensors.md``). Exit status 2, one line on stderr, for a file
without the markers."""

import sys
from typing import List, Optional

from ...doc_tables import table_main
from . import KINDS_TABLE, kinds_markdown


def main(argv: Optional[List[str]] = None) -> int:
    return table_main("python -m thorvald_sim.sensors.kinds", KINDS_TABLE, kinds_markdown, argv)


if __name__ == "__main__":
    sys.exit(main())
