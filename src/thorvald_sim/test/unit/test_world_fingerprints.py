"""Every shipped world loads to the same values as it did when the world module was one file.

The fingerprints in ``test/data/world_fingerprints.json`` were computed by :func:`fingerprint` from
the world module as a single file, before it became a package of value types, schema and parser,
ground geometry and terrain with a registry of element kinds. A fingerprint is the SHA-256 of a
canonical text of the parsed world: every field of every value (floats to the last bit, as
``repr`` writes them; files relative to the worlds folder), and what the values compute (each row's
plants, each tunnel's hoops, tables and plants, the height field's grid, the ground's height on a
grid of points), so a change of any number a world loads to changes it.

To compute them again (only after a change of a shipped world that is meant): ``python
test_world_fingerprints.py`` in this folder writes the file.
"""

import dataclasses
import hashlib
import json
import os
import sys

import pytest

from thorvald_sim.world import load_world, resolve_world, shipped_worlds, worlds_dir
from thorvald_sim.world.kinds.patches import soft_patches
from thorvald_sim.world.kinds.rows import plant_positions

DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "world_fingerprints.json")

# the fields of a world as the single-file module had them, its kinds' sections read as attributes
# (a field added since is left out, so that an empty one does not change the fingerprint)
WORLD_FIELDS = (
    "source", "gravity", "ground", "patches", "slopes", "rails", "description", "objects", "rows",
    "polytunnels", "walls", "height_field", "ground_rgba",
)  # fmt: skip
SECTIONS = ("patches", "slopes", "rails", "objects", "rows", "polytunnels", "walls")
GRID = [(0.5 * i - 20.25, 0.5 * j - 20.25) for i in range(-40, 122, 3) for j in range(-40, 122, 3)]  # [m]


def _text(value) -> str:
    """A canonical text of a value: dataclasses field by field, floats as repr, paths relative."""
    if dataclasses.is_dataclass(value):
        inner = ", ".join(f"{f.name}={_text(getattr(value, f.name))}" for f in dataclasses.fields(value))
        return f"{type(value).__name__}({inner})"
    if isinstance(value, (tuple, list)):
        return "(" + ", ".join(_text(v) for v in value) + ")"
    if isinstance(value, str) and os.path.isabs(value):
        return repr(os.path.relpath(value, worlds_dir()))
    return repr(value)


def fingerprint(world) -> dict:
    """The world's fingerprint (its SHA-256) and the counts of its entries (to read a difference by)."""
    lines = []
    for name in WORLD_FIELDS:
        value = getattr(world, name)
        if name == "source":
            value = os.path.relpath(os.path.abspath(value), worlds_dir())
        lines.append(f"{name}: {_text(value)}")
    for rows in world.rows:
        lines.append(f"plants of {rows.name}: {_text(plant_positions(rows))}")
    for t in world.polytunnels:
        computed = (t.hoop_stations(), t.arch(), t.table_offsets(), t.table_leg_stations(), t.plant_stations())
        lines.append(f"tunnel {t.name}: {_text(computed)} {t.crop_top!r} {t.plant_radius!r} {t.plant_top!r}")
    for o in world.objects:
        lines.append(f"object {o.name}: {o.half_height!r}")
    hf = world.height_field
    if hf is not None:
        heights = hf.heights()
        digest = hashlib.sha256(heights.astype("<f8").tobytes()).hexdigest()
        lines.append(f"height field: {hf.grid_shape()} {hf.grid_step()} {digest}")
    lines.append("ground: " + " ".join(repr(world.ground_height(x, y)) for x, y in GRID))
    lines.append(f"soft patches: {_text(soft_patches(world.patches))}")
    text = "\n".join(lines)
    counts = {key: len(getattr(world, key)) for key in SECTIONS}
    counts["height_field"] = int(hf is not None)
    return {"sha256": hashlib.sha256(text.encode()).hexdigest(), "elements": counts}


def _expected() -> dict:
    """The fingerprints by world; none while the file is missing (then every world's test is missing
    and the cover test fails)."""
    if not os.path.exists(DATA):
        return {}
    with open(DATA) as f:
        return json.load(f)


@pytest.mark.parametrize("name", sorted(_expected()))
def test_a_shipped_world_loads_to_the_values_it_always_did(name):
    assert fingerprint(load_world(resolve_world(name))) == _expected()[name]


def test_the_fingerprints_cover_every_shipped_world():
    assert sorted(_expected()) == shipped_worlds()


def test_the_fingerprint_sees_a_change_of_one_number():
    # the ground's height of one hill a micrometre higher changes it, and so does one plant's seed
    world = load_world(resolve_world("slope"))
    hill = dataclasses.replace(world.slopes[0], height=world.slopes[0].height + 1e-6)
    changed = world.with_section("slopes", (hill, *world.slopes[1:]))
    assert fingerprint(changed)["sha256"] != _expected()["slope"]["sha256"]
    world = load_world(resolve_world("crop_rows"))
    rows = dataclasses.replace(world.rows[0], seed=world.rows[0].seed + 1)
    changed = world.with_section("rows", (rows, *world.rows[1:]))
    assert fingerprint(changed)["sha256"] != _expected()["crop_rows"]["sha256"]


if __name__ == "__main__":
    found = {name: fingerprint(load_world(resolve_world(name))) for name in shipped_worlds()}
    with open(DATA, "w") as f:
        json.dump(found, f, indent=2, sort_keys=True)
        f.write("\n")
    sys.exit(0)
