"""What every ``check_*`` command prints once its files are read (``check_config``, thorvald_sim's
``check_world``): the summaries of the valid files, the count of the invalid ones, the exit status.

One valid file: its details; several: a table, one row each; ``--json``: the rows as JSON. The
problems of invalid files are printed by the caller as it meets them (stderr); this says how many
of how many, and gives exit status 2 when any was invalid.
"""

import json
import sys
from typing import Callable, List, Sequence, TypeVar

T = TypeVar("T")
EXIT_INVALID = 2


def report(
    valid: Sequence[T],
    failed: int,
    total: int,
    *,
    as_json: bool,
    row: Callable[[T], dict],
    details: Callable[[T], str],
    table: Callable[[List[dict]], str],
) -> int:
    """Prints the valid files' summaries; the exit status (0, or 2 when any of total failed)."""
    if as_json:
        print(json.dumps([row(v) for v in valid], indent=2))
    elif total == 1 and valid:
        print(details(valid[0]))
    elif valid:
        print(table([row(v) for v in valid]))
    if failed:
        if total > 1:
            print(f"{failed} of {total} file(s) invalid", file=sys.stderr)
        return EXIT_INVALID
    return 0
