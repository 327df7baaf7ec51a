"""The budgets of a world, one value (:class:`Limits`; :data:`LIMITS` the defaults), checked at load
from the parsed numbers, before anything they count is made (an image's size is read from its
header, a mesh file's from the file system), so that a typing mistake or a hostile file is refused
at once with the key to change, not by exhausting the memory or hanging the loader.

The loader takes the limits as a value (``load_world(path, limits=Limits(bodies=100))``): a test
or a program that wants other budgets passes its own. Each element kind says what its entries take
of each budget (its ``budget`` function: shares, each at the key a user would change);
:func:`budget_problems` adds them up over the world and names, for a budget it breaks, the entry
that takes the most. The figures were measured with pybullet 3.2.7, one core:

- positions: ``x``, ``y`` (and an object's ``z``) in [-10 000, 10 000] m: a farm is at most 20 km
  across, and pybullet draws and its cameras see in single precision, 1 mm steps out there;
- lengths: every length, size, width, height, radius, spacing, thickness, gap, depth, jitter,
  amplitude and resolution at most 10 000 m (``min_height`` and ``max_height`` in [-10 000,
  10 000]); a mesh's ``scale`` at most 1000. So every count made from them is a finite number
  (these two are rules of each key: :mod:`thorvald_sim.world.rules`);
- plants: 50 000 over every rows entry (places, gaps included: each draws its random numbers) and
  every polytunnel (strawberries): a plant is a part of a triangle mesh of 32 to 42 vertices,
  50 000 sphere plants take pybullet 2.6 GB and 14 s to build, cylinders 1.5 GB and 6 s (a
  hectare of lettuce, rows 0.75 m apart and a plant every 0.35 m, is 38 000);
- hoops: 2000 over every polytunnel (432 mesh vertices a hoop: 0.7 GB, 2.8 s; 4 km of tunnel);
- pairs of table legs: 10 000 over every polytunnel (48 mesh vertices a pair);
- pybullet bodies: 2000 (one a patch, hill, object, wall and row, two a rail, three a polytunnel
  and three each of its tables, and the ground): pybullet loops over its bodies every step
  (10 000 static boxes took 6.5 s to build and 17 ms a step, slower than real time);
- holes: 50 patches in a world with a soft patch (each patch is a hole in the ground; overlapping
  holes cut it into pieces that grow as the cube of their number: 50 into 7000 pieces, 2.6 s to
  build; 100 into 21 000, 10 s);
- ground look-ups: 2 000 000; every plant of a row, every point along a wall (every 0.5 m),
  every object and every polytunnel looks for the ground under it among the height field (or the
  plane), every hill and every patch: points times (1 + hills + patches); at the limit 1.6 s of
  loading on the plane, 5.5 s on a height field (99 walls of 10 km);
- a height field's grid points, or its image's pixels: 1 000 000 (2 GB and 5 s in pybullet), its
  image file 32 MB (a 1000 x 1000 16-bit grey PNG is at most 2 MB); its noise lattice
  (``size / feature_length`` along each side, with an ``amplitude``): 1 000 000 points;
- mesh files: 32 MB over every object (each object counts its file: pybullet loads it for each);
  checking them takes up to 3 s, loading them 3 to 6 s and 0.6 to 1.4 GB.

A world at every limit at once would need them together, about 7 GB and a minute to build; each
limit alone leaves room for the largest fields and greenhouses a robot drives in. The shipped
worlds use 5 % of a budget at most (crop_rows' 2471 plants), but for farm_track's 6 holes of 50.

Pure: no pybullet.
"""

import math
from dataclasses import dataclass
from typing import Any, Callable, Dict, List, Mapping, Optional, Sequence, Tuple

from thorvald_model.errors import Problem


@dataclass(frozen=True)
class Limits:
    """The budgets of one world (the module's figures); each a count, or bytes."""

    plants: int = 50_000  # over every rows and polytunnels entry (sphere plants: 2.6 GB, 14 s to build)
    hoops: int = 2_000  # over every polytunnel (432 mesh vertices a hoop: 0.7 GB, 2.8 s)
    table_legs: int = 10_000  # pairs of table legs over every polytunnel (48 mesh vertices a pair)
    bodies: int = 2_000  # pybullet bodies (10 000 static boxes: 6.5 s to build, 17 ms a step)
    holes: int = 50  # patches in a world with a soft one (50 overlapping: 7000 ground pieces, 2.6 s)
    ground_lookups: int = 2_000_000  # points looking for the ground times what they search (1.6 to 5.5 s)
    field_points: int = 1_000_000  # of a height field's grid, or pixels of its image (2 GB, 5 s)
    noise_points: int = 1_000_000  # of a height field's noise lattice (80 MB, 0.2 s)
    image_bytes: int = 32_000_000  # of a height field's image file (a 1000 x 1000 16-bit PNG is at most 2 MB)
    mesh_bytes: int = 32_000_000  # of the mesh files over every object (3 s to check; 0.6 to 1.4 GB in pybullet)
    # a Gazebo world's models, actors and population instances (a static one of one link is a static rigid
    # body, which costs bullet nothing a step: 10 000 plants of one mesh build in 1.7 s, and a lidar robot
    # drives among them at 1.1 x real time: bench/gazebo_world.py)
    models: int = 20_000


LIMITS = Limits()  # the defaults: what the simulator and check_world load every world with

WALL_STEP = 0.5  # [m] between the points where a wall looks for the ground under it (its look-ups)

Share = Tuple[str, Any, float]  # (key path, its value, how much of a budget its entry takes)
Shares = Dict[str, List[Share]]  # by budget (BUDGETS)
Budget = Callable[[str, Sequence[Any], int], Mapping[str, Sequence[Share]]]  # ElementKind.budget

# The budgets an element kind's entries take shares of (fields of Limits), checked in this order, and
# what each message says they count
BUDGETS = ("plants", "hoops", "table_legs", "bodies", "holes", "ground_lookups")
_COUNTED = {
    "plants": "plants over the world's rows and polytunnels",
    "hoops": "hoops over the world's polytunnels",
    "table_legs": "pairs of table legs over the world's polytunnels",
    "bodies": "pybullet bodies over the world's entries and the ground",
    "holes": "holes in the ground (one under every patch, as one is soft)",
}


def budget_problems(
    kinds: Sequence, entries: Mapping[str, Sequence], problems: List[Problem], limits: Limits = LIMITS
) -> bool:
    """Adds a problem for each budget the world's entries (by section) break; whether any is broken.

    kinds: the element kinds (:class:`~thorvald_sim.world.kind.ElementKind`), in order; each with a
    budget function gives its shares.
    """
    # Each plant, point along a wall, object and tunnel looks for the ground under it: the ground (the
    # plane, or the kind that takes its place) and every entry of the kinds that shape it (hills, patches)
    searched = 1 + sum(
        len(entries.get(kind.section, ())) for kind in kinds if kind.ground is not None and not kind.replaces_ground
    )
    shares: Shares = {name: [] for name in BUDGETS}
    for kind in kinds:
        if kind.budget is None:
            continue
        for name, taken in kind.budget(kind.section, entries[kind.section], searched).items():
            if name not in shares:
                raise ValueError(f"element kind {kind.section!r} takes from no budget {name!r}: one of {BUDGETS}")
            shares[name].extend(taken)

    # the ground is one body more
    found = [
        over(shares[name], getattr(limits, name), _COUNTED[name], extra=float(name == "bodies")) for name in _COUNTED
    ]
    what = f"ground look-ups (plants, points every {WALL_STEP:g} m along walls, objects and tunnels, each over"
    what += f" the ground, {searched - 1} hills and patches)"
    lookups = over(shares["ground_lookups"], limits.ground_lookups, what)
    # said once a key: too many plants (the first budget) are too many look-ups too
    if lookups is not None and all(pr is None or pr.path != lookups.path for pr in found):
        found.append(lookups)

    found = [pr for pr in found if pr is not None]
    problems.extend(found)
    return bool(found)


def over(shares: Sequence[Share], limit: int, what: str, extra: float = 0.0) -> Optional[Problem]:
    """The problem of a budget the shares (and extra, at no key) break, at the largest share's key; None within it."""
    total = sum(amount for _, _, amount in shares) + extra
    if total <= limit:
        return None
    path, value, amount = max(shares, key=lambda share: share[2])
    here = f", {count_text(amount)} of them here" if amount < total else ""
    return Problem(path, value, f"makes {count_text(total)} {what}{here}; at most {limit}")


# ---------------------------------------------------------------------------------------------
# What the kinds' budget functions share
# ---------------------------------------------------------------------------------------------
def at(entries: Sequence, key: str) -> List[Tuple[str, Any, dict]]:
    """(key path, the file's value or else the default, values) of the key of each entry."""
    return [(f"{e.path}.{key}", e.raw.get(key, e.values[key]), e.values) for e in entries]


def bodies_each(bodies: float = 1.0, looks: bool = False) -> Budget:
    """The budget of a kind whose entries are ``bodies`` pybullet bodies each (a share of the whole
    section, at its key) and, with ``looks``, look for the ground once each."""

    def budget(section: str, entries: Sequence, searched: int) -> Shares:
        shares = {"bodies": [(section, len(entries), bodies * len(entries))]}
        if looks:
            shares["ground_lookups"] = [(section, len(entries), len(entries) * searched)]
        return shares

    return budget


def rounded(ratio: float) -> float:
    """round(ratio), as a float; a ratio too big to be any count (inf for a tiny spacing) is itself."""
    return float(round(ratio)) if ratio < 1e15 else ratio


def floored(ratio: float) -> float:
    """math.floor(ratio + 1e-9) (a whole number of spacings, though floating point makes it 2.9999...)
    as a float; a ratio too big to be any count is itself."""
    return float(math.floor(ratio + 1e-9)) if ratio < 1e15 else ratio


def count_text(count: float) -> str:
    """A count (a float from :func:`rounded`) as the message says it."""
    if count < 1e15:
        return str(int(count))
    return f"{count:.3g}" if math.isfinite(count) else "more than 1e308"
