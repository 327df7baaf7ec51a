"""The budgets of a world (the package's "Limits"), counted from the parsed numbers before anything
they count is made, so that a typing mistake or a hostile file is refused at once with the key to
change, not by exhausting the memory or hanging the loader.

Each element kind says what its entries take of each budget (its ``budget`` function: shares, each
at the key a user would change); :func:`budget_problems` adds them up over the world and names,
for a budget it breaks, the entry that takes the most. The limits are read when a world is checked,
so a test can lower one (on :mod:`thorvald_sim.world`). The figures in brackets were measured with
pybullet 3.2.7 on one core.
"""

import math
import os
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

from thorvald_model.errors import Problem

from .keys import SURFACE_DEFAULTS, _surface_of
from .terrain import _image_size

MAX_PLANTS = 50_000  # over every rows and polytunnels entry (sphere plants: 2.6 GB, 14 s to build)
MAX_HOOPS = 2_000  # over every polytunnel (432 mesh vertices a hoop: 0.7 GB, 2.8 s)
MAX_TABLE_LEGS = 10_000  # pairs of table legs over every polytunnel (48 mesh vertices a pair)
MAX_BODIES = 2_000  # pybullet bodies (10 000 static boxes: 6.5 s to build, 17 ms a step)
MAX_HOLES = 50  # patches in a world with a soft one (50 overlapping: 7000 ground pieces, 2.6 s)
MAX_GROUND_LOOKUPS = 2_000_000  # points looking for the ground times what they search (1.6 to 5.5 s)
MAX_FIELD_POINTS = 1_000_000  # of a height field's grid, or pixels of its image (2 GB, 5 s)
MAX_NOISE_POINTS = 1_000_000  # of a height field's noise lattice (80 MB, 0.2 s)
MAX_IMAGE_BYTES = 32_000_000  # of a height field's image file (a 1000 x 1000 16-bit PNG is at most 2 MB)
MAX_MESH_BYTES = 32_000_000  # of the mesh files over every object (3 s to check; 0.6 to 1.4 GB in pybullet)
WALL_STEP = 0.5  # [m] between the points where a wall looks for the ground under it

Share = Tuple[str, Any, float]  # (key path, its value, how much of a budget its entry takes)
Shares = Dict[str, List[Share]]  # by budget (BUDGETS)

# The budgets an element kind's entries take shares of, checked in this order
BUDGETS = ("plants", "hoops", "table_legs", "bodies", "holes", "ground_lookups")


def budget_problems(kinds: Sequence, entries: Mapping[str, Sequence], problems: List[Problem]) -> bool:
    """Adds a problem for each budget the world's entries (by section) break; whether any is broken.

    kinds: the element kinds (:class:`~thorvald_sim.world.kind.ElementKind`), in order; each with a
    budget function gives its shares.
    """
    # Each plant, point along a wall, object and tunnel looks for the ground under it: the height
    # field (or the plane), every hill and every patch (what shapes the ground: geometry.py).
    searched = 1 + len(entries.get("slopes", ())) + len(entries.get("patches", ()))
    shares: Shares = {name: [] for name in BUDGETS}
    for kind in kinds:
        if kind.budget is None:
            continue
        for name, taken in kind.budget(kind.section, entries[kind.section], searched).items():
            if name not in shares:
                raise ValueError(f"element kind {kind.section!r} takes from no budget {name!r}: one of {BUDGETS}")
            shares[name].extend(taken)

    found = [
        _over(shares["plants"], MAX_PLANTS, "plants over the world's rows and polytunnels"),
        _over(shares["hoops"], MAX_HOOPS, "hoops over the world's polytunnels"),
        _over(shares["table_legs"], MAX_TABLE_LEGS, "pairs of table legs over the world's polytunnels"),
        _over(shares["bodies"], MAX_BODIES, "pybullet bodies over the world's entries and the ground", extra=1),
        _over(shares["holes"], MAX_HOLES, "holes in the ground (one under every patch, as one is soft)"),
    ]
    what = f"ground look-ups (plants, points every {WALL_STEP:g} m along walls, objects and tunnels, each over"
    what += f" the ground, {searched - 1} hills and patches)"
    lookups = _over(shares["ground_lookups"], MAX_GROUND_LOOKUPS, what)
    # said once a key: too many plants (the first budget) are too many look-ups too
    if lookups is not None and all(pr is None or pr.path != lookups.path for pr in found):
        found.append(lookups)

    found = [pr for pr in found if pr is not None]
    problems.extend(found)
    return bool(found)


def _over(shares: Sequence[Share], limit: int, what: str, extra: float = 0.0) -> Optional[Problem]:
    """The problem of a budget the shares (and extra, at no key) break, at the largest share's key; None within it."""
    total = sum(amount for _, _, amount in shares) + extra
    if total <= limit:
        return None
    path, value, amount = max(shares, key=lambda share: share[2])
    here = f", {_n(amount)} of them here" if amount < total else ""
    return Problem(path, value, f"makes {_n(total)} {what}{here}; at most {limit}")


# ---------------------------------------------------------------------------------------------
# The built-in kinds' shares
# ---------------------------------------------------------------------------------------------
def _at(entries: Sequence, key: str) -> List[Tuple[str, Any, dict]]:
    """(key path, the file's value or else the default, values) of the key of each entry."""
    return [(f"{e.path}.{key}", e.raw.get(key, e.values[key]), e.values) for e in entries]


def bodies_each(bodies: float = 1.0, looks: bool = False):
    """The budget of a kind whose entries are ``bodies`` pybullet bodies each (a share of the whole
    section, at its key) and, with ``looks``, look for the ground once each."""

    def budget(section: str, entries: Sequence, searched: int) -> Shares:
        shares = {"bodies": [(section, len(entries), bodies * len(entries))]}
        if looks:
            shares["ground_lookups"] = [(section, len(entries), len(entries) * searched)]
        return shares

    return budget


def patches_budget(section: str, entries: Sequence, searched: int) -> Shares:
    """One body a patch; with a soft one, a hole in the ground under every patch."""
    shares = bodies_each()(section, entries, searched)
    if any(_surface_of(e.values, SURFACE_DEFAULTS).soft for e in entries):
        shares["holes"] = [(section, len(entries), float(len(entries)))]
    return shares


def rows_budget(section: str, entries: Sequence, searched: int) -> Shares:
    """Every place of a plant (gaps included: each draws its random numbers), one body a row, and a
    ground look-up a place."""
    plants = [(path, value, _row_plants(v)) for path, value, v in _at(entries, "plant_spacing")]
    return {
        "plants": plants,
        "bodies": [(path, value, float(v["count"])) for path, value, v in _at(entries, "count")],
        "ground_lookups": [(path, value, n * searched) for path, value, n in plants],
    }


def polytunnels_budget(section: str, entries: Sequence, searched: int) -> Shares:
    """Strawberries, hoops, pairs of table legs, three bodies a tunnel and three each of its tables,
    and one ground look-up a tunnel (its floor)."""
    return {
        "plants": [(path, value, _tunnel_counts(v)[2]) for path, value, v in _at(entries, "plant_spacing")],
        "hoops": [(path, value, _tunnel_counts(v)[0]) for path, value, v in _at(entries, "hoop_spacing")],
        "table_legs": [(path, value, _tunnel_counts(v)[1]) for path, value, v in _at(entries, "leg_spacing")],
        "bodies": [(path, value, _tunnel_counts(v)[3]) for path, value, v in _at(entries, "tables")],
        "ground_lookups": [(section, len(entries), len(entries) * searched)],
    }


def walls_budget(section: str, entries: Sequence, searched: int) -> Shares:
    """One body a wall, and a ground look-up every WALL_STEP along it."""
    return {
        "bodies": [(section, len(entries), float(len(entries)))],
        "ground_lookups": [
            (path, value, (_wall_steps(v["length"]) + 1.0) * searched) for path, value, v in _at(entries, "length")
        ],
    }


def _row_plants(v: Mapping) -> float:
    """Places for plants (gaps included: each draws its random numbers) of a rows entry's values."""
    return v["count"] * (_floored(v["length"] / v["plant_spacing"]) + 1)


def _tunnel_counts(v: Mapping) -> Tuple[float, float, float, float]:
    """(hoops, pairs of table legs, plants, bodies) of a polytunnels entry's values, as
    :class:`~thorvald_sim.world.values.Polytunnel` and the scene make them."""
    hoops = max(1.0, _rounded(v["length"] / v["hoop_spacing"])) + 1
    if v["crop"] == "none":
        return hoops, 0.0, 0.0, 3.0
    span = v["length"] - 2 * v["end_gap"]
    tables = v["tables"]
    legs = tables * (max(1.0, _rounded(span / v["leg_spacing"])) + 1) if v["crop"] == "table_tops" else 0.0
    plants = tables * max(0.0, _floored(span / v["plant_spacing"]))
    # the legs of each side and the roof; each table's table, plants and berries
    return hoops, legs, plants, 3.0 + 3.0 * tables


def _wall_steps(length: float) -> int:
    """Steps of WALL_STEP (at most) along a wall: its points are one more."""
    return max(1, math.ceil(length / WALL_STEP))


# ---------------------------------------------------------------------------------------------
# Files (their sizes from the file system and an image's header, before they are read)
# ---------------------------------------------------------------------------------------------
def _check_image_budget(path: str) -> None:
    """ValueError (the rule) if the image's file or its pixels (from its header) are over the budgets."""
    size = os.path.getsize(path)
    if size > MAX_IMAGE_BYTES:
        raise ValueError(f"is a file of {size} bytes; at most {MAX_IMAGE_BYTES}")
    width, height = _image_size(path)
    if width * height > MAX_FIELD_POINTS:
        raise ValueError(f"makes {width} x {height} grid points (its pixels); at most {MAX_FIELD_POINTS}")


# ---------------------------------------------------------------------------------------------
# Counts as the messages say them
# ---------------------------------------------------------------------------------------------
def _rounded(ratio: float) -> float:
    """round(ratio), as a float; a ratio too big to be any count (inf for a tiny spacing) is itself."""
    return float(round(ratio)) if ratio < 1e15 else ratio


def _floored(ratio: float) -> float:
    """math.floor(ratio + 1e-9) (a whole number of spacings, though floating point makes it 2.9999...)
    as a float; a ratio too big to be any count is itself."""
    return float(math.floor(ratio + 1e-9)) if ratio < 1e15 else ratio


def _n(count: float) -> str:
    """A count (a float from :func:`_rounded`) as the message says it."""
    if count < 1e15:
        return str(int(count))
    return f"{count:.3g}" if math.isfinite(count) else "more than 1e308"
