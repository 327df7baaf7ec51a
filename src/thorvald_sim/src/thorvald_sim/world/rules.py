"""What the element kinds' keys and makers share: the bounds of every position and length (the
"Limits" of :mod:`thorvald_sim.world.limits` that are rules of one key), the colour key, and the
helpers a maker reports a problem with (a key already broken, a file the world names).

Each problem is reported with its key path, the value and the rule, beside every other; a key that
already broke its own rule is not compared again (its value is the default, not the file's).
"""

import os
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

from thorvald_model.errors import Problem
from thorvald_model.schema import Key, in_range

WHAT = "world"  # what a ConfigError says the file is

# Bounds of every position and length: a farm is at most 20 km across, and pybullet draws and its
# cameras see in single precision, 1 mm steps out there
MAX_REACH = 10_000.0  # [m] |x|, |y| of anything, and an object's |z|
MAX_LENGTH = 10_000.0  # [m] of any length, size, height or spacing

UNIT_RANGE = dict(check=in_range(0.0, 1.0), rule="must be in [0, 1]")

# Every length and position is bounded (MAX_LENGTH, MAX_REACH): the numbers made from them (plants,
# hoops, grid points) are then finite floats, and a count is checked before anything is made.
LENGTH = dict(check=lambda v: 0.0 < v <= MAX_LENGTH, rule=f"must be in (0, {MAX_LENGTH:g}] [m]")
LENGTH_OR_ZERO = dict(check=in_range(0.0, MAX_LENGTH), rule=f"must be in [0, {MAX_LENGTH:g}] [m]")
HEIGHT = dict(check=in_range(-MAX_LENGTH, MAX_LENGTH), rule=f"must be in [-{MAX_LENGTH:g}, {MAX_LENGTH:g}] [m]")
COORDINATE = dict(check=in_range(-MAX_REACH, MAX_REACH), rule=f"must be in [-{MAX_REACH:g}, {MAX_REACH:g}] [m]")
OPTIONAL_LENGTH = dict(default=None, **LENGTH)  # a key a cross-field rule requires or refuses

# rgba is a list, which the schema's keys do not take: it is checked apart (take_colours) and stands
# in the entry as an empty string, so that its key is known (for "did you mean") and given once.
RGBA_KEY = Key("rgba", str, "")
RGBA_RULE = "must be a list of 3 or 4 numbers in [0, 1] (red, green, blue, alpha)"

Rgba = Tuple[float, float, float, float]


def broken(problems: Sequence[Problem], path: str, *keys: str) -> bool:
    """Whether one of the entry's keys has a problem already (its value was replaced by the default)."""
    paths = {f"{path}.{k}" for k in keys}
    return any(p.path in paths for p in problems)


def file_path(value: str, base_dir: str, path: str, problems: List[Problem], extensions: Sequence[str] = ()) -> str:
    """The absolute path of a file the world names (relative to base_dir); a problem if it is not there."""
    full = os.path.normpath(os.path.join(base_dir, os.path.expanduser(value)))
    if extensions and not full.lower().endswith(tuple(extensions)):
        names = " or ".join(e[1:].upper() for e in extensions)
        problems.append(Problem(path, value, f"must be an {names} file ({', '.join(extensions)})"))
    elif not os.path.isfile(full):
        problems.append(Problem(path, value, f"no such file: {full} (a relative path is from the world file's folder)"))
    return full


# ---------------------------------------------------------------------------------------------
# Colours (rgba is a list, which the schema's keys do not take: checked here, and "" in the entry)
# ---------------------------------------------------------------------------------------------
def colour(value: Any) -> Optional[Rgba]:
    """The colour a list of 3 or 4 numbers in [0, 1] gives (alpha 1 if left out); None if it is not one."""
    if not isinstance(value, (list, tuple)) or len(value) not in (3, 4):
        return None
    numbers = []
    for v in value:
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not 0.0 <= v <= 1.0:
            return None
        numbers.append(float(v))
    return (*numbers, 1.0) if len(numbers) == 3 else tuple(numbers)


def take_colour(entry: Any, path: str, default: Optional[Rgba], problems: List[Problem]) -> Tuple[Any, Optional[Rgba]]:
    """The entry with its rgba, checked here, replaced by "" for parse_entry, and the colour."""
    if not isinstance(entry, Mapping) or "rgba" not in entry:
        return entry, default
    found = colour(entry["rgba"])
    if found is None:
        problems.append(Problem(f"{path}.rgba", entry["rgba"], RGBA_RULE))
    return {**entry, "rgba": ""}, found or default


def take_colours(section: Any, key: str, problems: List[Problem]) -> Tuple[Any, Dict[str, Optional[Rgba]]]:
    """The section with each entry's rgba taken out (as :func:`take_colour`), and the colours by entry."""
    if not isinstance(section, Mapping):
        return section, {}
    clean, colours = {}, {}
    for name, entry in section.items():
        clean[name], colours[str(name)] = take_colour(entry, f"{key}.{name}", None, problems)
    return clean, colours
