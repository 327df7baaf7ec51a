"""The built-in element kinds' makers (an entry's checked values -> the element's value) and their
rules: the rules between an entry's keys, between a section's entries and with the rest of the
world (the ``make`` and ``check`` functions of :mod:`thorvald_sim.world.registry`'s entries).

Each problem is reported with its key path, the value and the rule, beside every other; a key that
already broke its own rule is not compared again (its value is the default, not the file's).
"""

import os
from dataclasses import replace
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

from thorvald_model.errors import MISSING, Problem

from ..mesh_check import mesh_problem
from .budgets import (
    MAX_FIELD_POINTS,
    MAX_MESH_BYTES,
    MAX_NOISE_POINTS,
    _check_image_budget,
    _n,
    _over,
    _rounded,
    _wall_steps,
)
from .geometry import SOFT_PATCH_REACH, _along
from .keys import (
    MESH_EXTENSIONS,
    SHAPE_KEYS,
    SLOPE_DEFAULTS,
    SURFACE_DEFAULTS,
    ZERO_HINT,
    _kind_colour,
    _surface,
    _surface_of,
)
from .kind import Context, Entry
from .terrain import _image_levels, _noise_lattice
from .values import (
    RGBA_CONCRETE,
    RGBA_LEAF,
    RGBA_WOOD,
    HeightField,
    Patch,
    Polytunnel,
    Rail,
    Rows,
    Slope,
    Wall,
    WorldObject,
)


# ---------------------------------------------------------------------------------------------
# Patches, hills, rails: what the others stand on (or beside)
# ---------------------------------------------------------------------------------------------
def _patch(entry: Entry, context: Context) -> Patch:
    v = entry.values
    surface = _surface_of(v, SURFACE_DEFAULTS)
    colour = v["rgba"] or _kind_colour(surface)
    return Patch(entry.name, entry.index, v["x"], v["y"], v["size_x"], v["size_y"], v["yaw"], surface, colour)


def _patches_check(patches: Tuple[Patch, ...], context: Context) -> None:
    context.problems.extend(_missing_lateral_friction(context.data.get("patches")))
    context.problems.extend(_soft_patch_problems(patches, context.single("height_field") is not None))


def _missing_lateral_friction(section: Any) -> List[Problem]:
    """A patch's lateral friction is required unless it names a surface kind (reported as parse_entry
    reports a required key: beside the entry's other problems, even when they drop the entry)."""
    if not isinstance(section, Mapping):
        return []
    return [
        Problem(f"patches.{name}.lateral_friction", MISSING, "is required")
        for name, entry in section.items()
        if isinstance(entry, Mapping) and "lateral_friction" not in entry and "surface" not in entry
    ]


def _soft_patch_problems(patches: Sequence[Patch], height_field: bool) -> List[Problem]:
    problems = []
    for patch in patches:
        if not patch.surface.soft:
            continue
        path = f"patches.{patch.name}.sinkage"
        if height_field:
            rule = f"must be 0 with a height_field ({ZERO_HINT}): a soft patch needs a hole in the ground"
            problems.append(Problem(path, patch.surface.sinkage, rule))
        elif max(max(abs(x), abs(y)) for x, y in patch.corners()) > SOFT_PATCH_REACH:
            rule = f"needs the patch within {SOFT_PATCH_REACH:g} m of the origin in x and y (the ground ends there)"
            problems.append(Problem(path, patch.surface.sinkage, rule))
    return problems


def _slope(entry: Entry, context: Context) -> Slope:
    v = entry.values
    return Slope(
        entry.name, entry.index, v["x"], v["y"], v["yaw"], v["width"], v["angle"], v["height"], v["top_length"],
        _surface_of(v, SLOPE_DEFAULTS),
    )  # fmt: skip


def _rail(entry: Entry, context: Context) -> Rail:
    v = entry.values
    return Rail(
        entry.name, entry.index, v["x"], v["y"], v["yaw"], v["length"], v["gauge"], v["height"], v["radius"],
        _surface(v),
    )  # fmt: skip


def _rails_check(rails: Tuple[Rail, ...], context: Context) -> None:
    context.problems.extend(_rail_problems(rails, context.problems))


def _rail_problems(rails: Tuple[Rail, ...], found: List[Problem]) -> List[Problem]:
    problems = []
    for rail in rails:
        path = f"rails.{rail.name}"
        # A key that already broke its own rule was replaced by its default; comparing that default
        # would report a value the file does not hold.
        if _broken(found, path, "radius", "height", "gauge"):
            continue
        if rail.radius >= rail.height:
            problems.append(
                Problem(
                    f"{path}.radius",
                    rail.radius,
                    f"must be < height ({rail.height} m): a pipe cannot sink into the ground",
                )
            )
        if rail.gauge <= 2.0 * rail.radius:
            problems.append(
                Problem(
                    f"{path}.gauge",
                    rail.gauge,
                    f"must be > 2 * radius ({2.0 * rail.radius} m): the two pipes would overlap",
                )
            )
    return problems


def _broken(problems: Sequence[Problem], path: str, *keys: str) -> bool:
    """Whether one of the entry's keys has a problem already (its value was replaced by the default)."""
    paths = {f"{path}.{k}" for k in keys}
    return any(p.path in paths for p in problems)


def _file(value: str, base_dir: str, path: str, problems: List[Problem], extensions: Sequence[str] = ()) -> str:
    """The absolute path of a file the world names (relative to base_dir); a problem if it is not there."""
    full = os.path.normpath(os.path.join(base_dir, os.path.expanduser(value)))
    if extensions and not full.lower().endswith(tuple(extensions)):
        names = " or ".join(e[1:].upper() for e in extensions)
        problems.append(Problem(path, value, f"must be an {names} file ({', '.join(extensions)})"))
    elif not os.path.isfile(full):
        problems.append(Problem(path, value, f"no such file: {full} (a relative path is from the world file's folder)"))
    return full


# ---------------------------------------------------------------------------------------------
# Objects, rows, polytunnels, walls: on the ground
# ---------------------------------------------------------------------------------------------
def _object(entry: Entry, context: Context) -> WorldObject:
    """The object; a mesh's (key path, value, absolute file) goes to the context's meshes, read by
    :func:`_objects_check`."""
    name, index, v, raw = entry.name, entry.index, entry.values, entry.raw
    problems = context.problems
    path = f"objects.{name}"
    shape = v["shape"]
    others = {k for keys in SHAPE_KEYS.values() for k in keys} - set(SHAPE_KEYS[shape])
    for k in sorted(others & set(raw)):
        wanted = ", ".join(SHAPE_KEYS[shape])
        problems.append(Problem(f"{path}.{k}", raw[k], f"is not a key of a {shape} (it takes {wanted})"))
    for k in SHAPE_KEYS[shape]:
        if v[k] is None and k != "scale" and not _broken(problems, path, k):
            problems.append(Problem(f"{path}.{k}", MISSING, f"is required for a {shape}"))
    dims = {k: v[k] or 0.0 for k in ("size_x", "size_y", "size_z", "radius", "length")}
    file = ""
    if shape == "mesh" and v["file"]:
        found = len(problems)
        file = _file(v["file"], context.base_dir, f"{path}.file", problems, MESH_EXTENSIONS)
        if len(problems) == found:
            context.meshes.append((f"{path}.file", v["file"], file))
    colour = v["rgba"] or RGBA_WOOD
    thing = WorldObject(
        name, index, shape, v["x"], v["y"], 0.0, v["roll"], v["pitch"], v["yaw"], **dims, file=file,
        scale=v["scale"] or 1.0, mass=v["mass"], rgba=colour, surface=_surface(v),
    )  # fmt: skip
    above = thing.half_height if v["z"] is None else v["z"]
    return replace(thing, z=context.ground_at(v["x"], v["y"]) + above)


def _objects_check(objects: Tuple[WorldObject, ...], context: Context) -> None:
    _mesh_problems(context.meshes, context.problems)


def _mesh_problems(meshes: Sequence[Tuple[str, str, str]], problems: List[Problem]) -> None:
    """Problems of the mesh files (key path, value, absolute file) the objects name: their sizes over
    the budget first (nothing is read then), else each file that is not a mesh pybullet can load."""
    sized = []
    for path, value, file in meshes:
        try:
            sized.append((path, value, file, float(os.path.getsize(file))))
        except OSError as e:
            problems.append(Problem(path, value, f"cannot be read ({file}): {e.strerror}"))
    shares = [(path, value, size) for path, value, _, size in sized]
    # each object loads its file: pybullet makes a collision shape and a visual shape of each
    over = _over(shares, MAX_MESH_BYTES, "bytes of mesh files over the world's objects (each object's counted)")
    if over is not None:
        problems.append(over)
        return
    reasons: Dict[str, Optional[str]] = {}
    for path, value, file, _ in sized:
        if file not in reasons:
            reasons[file] = mesh_problem(file)
        if reasons[file]:
            problems.append(Problem(path, value, f"is not a mesh pybullet can load ({file}): {reasons[file]}"))


def _rows(entry: Entry, context: Context) -> Rows:
    name, index, v, problems = entry.name, entry.index, entry.values, context.problems
    path = f"rows.{name}"
    rows = Rows(
        name, index, v["x"], v["y"], v["yaw"], v["count"], v["spacing"], v["length"], v["plant"], v["plant_spacing"],
        v["plant_radius"], v["plant_height"], v["gap_probability"], v["jitter"], v["seed"], v["rgba"] or RGBA_LEAF,
        _surface(v),
    )  # fmt: skip
    if rows.plant == "sphere" and rows.plant_height < rows.plant_radius and not _broken(problems, path, "plant_height"):
        rule = f"must be >= plant_radius ({rows.plant_radius} m) for a sphere: its centre would be below the ground"
        problems.append(Problem(f"{path}.plant_height", rows.plant_height, rule))
    return rows


def _polytunnel(entry: Entry, context: Context) -> Polytunnel:
    name, index, v, problems = entry.name, entry.index, entry.values, context.problems
    path = f"polytunnels.{name}"
    z = context.ground_at(v["x"], v["y"])
    tunnel = Polytunnel(
        name, index, v["x"], v["y"], z, v["yaw"], v["length"], v["width"], v["height"], v["leg_height"],
        v["hoop_spacing"], v["tube"], v["crop"], v["tables"], v["table_height"], v["table_width"], v["leg_spacing"],
        v["bed_height"], v["end_gap"], v["plant_spacing"], _surface(v),
    )  # fmt: skip
    t = tunnel
    if not _broken(problems, path, "height", "leg_height") and t.height <= t.leg_height:
        problems.append(Problem(f"{path}.height", t.height, f"must be > leg_height ({t.leg_height} m)"))
        return tunnel
    if not _broken(problems, path, "end_gap", "length") and 2 * t.end_gap >= t.length:
        rule = f"must be < length / 2 ({t.length / 2} m): the tables would have no length"
        problems.append(Problem(f"{path}.end_gap", t.end_gap, rule))
    if t.crop == "none" or _broken(problems, path, "tables", "table_width", "width", "table_height", "crop"):
        return tunnel
    if t.tables * t.table_width >= t.width:
        rule = f"times tables ({t.tables}) must be < width ({t.width} m): an aisle between the tables"
        problems.append(Problem(f"{path}.table_width", t.table_width, rule))
        return tunnel
    outer = max(abs(t.table_offset(0)), abs(t.table_offset(t.tables - 1))) + t.table_width / 2
    roof = t.roof_height(outer) - t.tube / 2
    if t.crop_top + 1.5 * t.plant_radius >= roof:
        key = "table_height" if t.crop == "table_tops" else "bed_height"
        rule = (
            f"puts the plants ({1.5 * t.plant_radius:.3g} m above it) under the roof ({roof:.3g} m at the outer table)"
        )
        problems.append(Problem(f"{path}.{key}", t.crop_top, "is too high: " + rule))
    return tunnel


def _wall(entry: Entry, context: Context) -> Wall:
    name, index, v, ground_at = entry.name, entry.index, entry.values, context.ground_at
    # the foot follows the lowest ground along the wall's centre line (every WALL_STEP); in a world
    # over its budgets, the ground at its centre
    if not context.over_budget:
        n = _wall_steps(v["length"])
        along = (_along(v["x"], v["y"], v["yaw"], v["length"] * (k / n - 0.5), 0.0) for k in range(n + 1))
        foot = min(ground_at(*point) for point in along)
    else:
        foot = ground_at(v["x"], v["y"])
    return Wall(
        name, index, v["x"], v["y"], foot, v["yaw"], v["length"], v["height"], v["thickness"],
        v["rgba"] or RGBA_CONCRETE, _surface(v),
    )  # fmt: skip


# ---------------------------------------------------------------------------------------------
# The height field: the ground's shape
# ---------------------------------------------------------------------------------------------
def _height_field(entry: Entry, context: Context) -> Optional[HeightField]:
    v, raw, path, problems = entry.values, entry.raw, entry.path, context.problems
    image, levels = "", None
    if v["image"]:
        image = _file(v["image"], context.base_dir, f"{path}.image", problems)
        if os.path.isfile(image):
            try:
                # its size from its header first: a huge image is refused before it is decoded
                _check_image_budget(image)
                levels = _image_levels(image)
            except ValueError as e:
                problems.append(Problem(f"{path}.image", v["image"], str(e)))
                image = ""
        else:
            image = ""
        if v["resolution"] is not None:
            rule = "must not be given with an image: its pixels are the grid"
            problems.append(Problem(f"{path}.resolution", v["resolution"], rule))
    elif "image" not in raw:
        for k in ("min_height", "max_height"):
            if v[k] is not None:
                problems.append(Problem(f"{path}.{k}", v[k], "is used with an image only"))
    low = 0.0 if v["min_height"] is None else v["min_height"]
    high = 1.0 if v["max_height"] is None else v["max_height"]
    if high <= low:
        problems.append(Problem(f"{path}.max_height", high, f"must be > min_height ({low} m)"))
    if v["rut_width"] > v["rut_spacing"] and not _broken(problems, path, "rut_width", "rut_spacing"):
        problems.append(Problem(f"{path}.rut_width", v["rut_width"], f"must be <= rut_spacing ({v['rut_spacing']} m)"))
    hf = HeightField(
        v["x"], v["y"], v["size_x"], v["size_y"], 0.0 if image else (v["resolution"] or 0.2), image, low, high,
        v["amplitude"], v["feature_length"], v["seed"], v["rut_depth"], v["rut_width"], v["rut_spacing"],
        v["flat_radius"],
    )  # fmt: skip
    if "image" in raw and not image:
        return None  # the problem is reported; there is no grid to make
    if levels is not None:
        hf.__dict__["_levels"] = levels  # the image as read to check it (the cached property's place)
    else:
        # counted as floats: a tiny resolution makes a count beyond any budget, not an OverflowError
        nx, ny = (max(2.0, _rounded(size / hf.resolution) + 1) for size in (hf.size_x, hf.size_y))
        if nx * ny > MAX_FIELD_POINTS:
            rule = f"makes {_n(nx)} x {_n(ny)} grid points; at most {MAX_FIELD_POINTS}"
            problems.append(Problem(f"{path}.resolution", raw.get("resolution", hf.resolution), rule))
            return None
    if hf.amplitude > 0:
        ni, nj = _noise_lattice(hf.size_x, hf.feature_length), _noise_lattice(hf.size_y, hf.feature_length)
        if ni * nj > MAX_NOISE_POINTS:
            rule = f"makes {_n(ni)} x {_n(nj)} noise lattice points (size / feature_length); at most {MAX_NOISE_POINTS}"
            problems.append(Problem(f"{path}.feature_length", hf.feature_length, rule))
            return None
    return hf


def _height_field_check(fields: Tuple[HeightField, ...], context: Context) -> None:
    if fields and context.ground.soft:
        rule = f"must be 0 with a height_field ({ZERO_HINT}): bullet touches a wheel at 1 to 4 of its triangles"
        context.problems.append(Problem("ground.sinkage", context.ground.sinkage, rule))
