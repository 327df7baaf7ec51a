"""``rosrun thorvald_sim check_world FILE [FILE ...]``: validates simulator world files.

A FILE is a path, a shipped world's name (``flat``, ``crop_rows``, ...: see
:func:`thorvald_sim.world.resolve_world`) or a Gazebo world (an SDF ``.world`` file, or a name on
Gazebo's resource path such as ``worlds/farm.world``). The world is loaded as the simulator loads it,
every rule and budget of :mod:`thorvald_sim.world` included, without starting the simulator (no
pybullet). One valid file: a summary of the world (its elements, plants and extent; a Gazebo world's
models and actors, and each kind of element it leaves out, with its element path). Several: one
table row per world. Invalid files: every problem, one per line, on stderr, and exit status 2.
"""

import argparse
import sys
from typing import List, Optional, Tuple

from thorvald_model.check_report import report

from ..world import ConfigError, WorldConfig, element_kinds, load_world, resolve_world
from ..world.kinds.rows import plant_positions

Box = Tuple[float, float, float, float]  # (x min, y min, x max, y max) [m]


def sections() -> List[Tuple[str, str, str]]:
    """(section, one, many) of every kind of numbered entries, in the registry's order."""
    return [(kind.section, *kind.count_names) for kind in element_kinds() if not kind.single]


def plant_count(world: WorldConfig) -> int:
    """The plants the simulator makes: each row's (gaps left out) and each tunnel's strawberries."""
    rows = sum(len(line) for entry in world.rows for line in plant_positions(entry))
    return rows + sum(len(t.plant_stations()) * len(t.table_offsets()) for t in world.polytunnels)


def extent(world: WorldConfig) -> Optional[Box]:
    """The box [m] around everything on the ground (None for the ground alone): each element's
    footprint, as its kind gives it (:attr:`thorvald_sim.world.kind.ElementKind.footprint`)."""
    points: List[Tuple[float, float]] = []
    for kind in element_kinds():
        if kind.footprint is not None:
            for element in world.elements(kind.section):
                points += kind.footprint(element)
    if not points:
        return None
    xs, ys = [x for x, _ in points], [y for _, y in points]
    return min(xs), min(ys), max(xs), max(ys)


def summary(world: WorldConfig) -> dict:
    """The figures of a world: its elements by section, its plants and its extent."""
    box = extent(world)
    hf = world.height_field
    return {
        "world": world.source,
        "description": world.description,
        "elements": {key: len(world.elements(key)) for key, _, _ in sections()},
        "rows": sum(r.count for r in world.rows),
        "height_field": list(hf.grid_shape()) if hf is not None else None,
        "plants": plant_count(world),
        "extent": [round(v, 3) for v in box] if box is not None else None,
        "models": len(world.models),  # a Gazebo world's
        "static_models": sum(1 for m in world.models if m.static),
        "actors": len(world.actors),
        "notes": list(world.notes),
    }


def format_elements(s: dict) -> str:
    parts = []
    for key, one, many in sections():
        n = s["elements"][key]
        if n:
            parts.append(f"{n} {one if n == 1 else many}" + (f" ({s['rows']} rows)" if key == "rows" else ""))
    if s["height_field"] is not None:
        parts.append("a height field of {} x {} points".format(*s["height_field"]))
    return ", ".join(parts) or "none (the ground alone)"


def format_extent(s: dict) -> str:
    if s["extent"] is None:
        return "the ground alone"
    x0, y0, x1, y1 = s["extent"]
    return f"x {x0:.2f} .. {x1:.2f} m, y {y0:.2f} .. {y1:.2f} m ({x1 - x0:.1f} x {y1 - y0:.1f} m)"


def format_details(world: WorldConfig) -> str:
    s = summary(world)
    lines = [f"{world.source}: valid world"]
    if world.description:
        lines.append(f"  {world.description}")
    lines += [
        f"  elements  {format_elements(s)}",
        f"  plants    {s['plants']}",
        f"  extent    {format_extent(s)}",
    ]
    if s["models"] or s["actors"]:
        dynamic = s["models"] - s["static_models"]
        models = f"{s['models']} ({s['static_models']} static, {dynamic} dynamic)"
        lines.append(f"  models    {models}, actors {s['actors']}")
    lines += [f"  left out  {note}" for note in s["notes"]]
    return "\n".join(lines)


def format_table(summaries: List[dict]) -> str:
    width = max(len("world"), *(len(s["world"]) for s in summaries))
    lines = [f"{'world':<{width}}  {'elements':>8}  {'plants':>7}  extent"]
    for s in summaries:
        elements = sum(s["elements"].values()) + (s["height_field"] is not None)
        lines.append(f"{s['world']:<{width}}  {elements:>8}  {s['plants']:>7}  {format_extent(s)}")
    return "\n".join(lines)


def main(argv: Optional[List[str]] = None) -> int:
    parser = argparse.ArgumentParser(
        prog="check_world", description="Validate simulator world files (paths or shipped world names)."
    )
    parser.add_argument("files", nargs="+", metavar="FILE", help="world YAML file(s) or shipped world name(s)")
    parser.add_argument("--json", action="store_true", help="print the summaries as JSON")
    args = parser.parse_args(argv)

    worlds, failed = [], 0
    for name in args.files:
        try:
            worlds.append(load_world(resolve_world(name)))
        except ConfigError as e:
            failed += 1
            print(e, file=sys.stderr)
    return report(
        worlds, failed, len(args.files), as_json=args.json, row=summary, details=format_details, table=format_table
    )


if __name__ == "__main__":
    sys.exit(main())
