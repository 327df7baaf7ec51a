"""Height fields (``height_field:``, one mapping): uneven ground on a regular grid in place of the
ground plane, from a grey-scale image, random bumps and ruts (the maths: :mod:`thorvald_sim.world.terrain`).

Rules beyond each key's own: a height field with an image takes no ``resolution``, one without takes
no ``min_height`` or ``max_height``, its ``max_height`` is above its ``min_height`` and its
``rut_width`` at most its ``rut_spacing``; the ground is not soft in a world with one (bullet
touches a wheel at one to four of its triangles, so the sinkage would wander). Its grid points (or
its image's pixels, read from the image's header), its image file's bytes and its noise lattice are
held to the world's limits (:class:`~thorvald_sim.world.limits.Limits`) as it is made.

In pybullet: bullet's height field, static, of the ground's friction and colour, with checks of 1 m
drawn for it as the plane's; the scene's body ``ground``.
"""

import functools
import math
import os
import tempfile
from dataclasses import dataclass
from typing import List, Optional, Tuple

from thorvald_model.errors import Problem
from thorvald_model.schema import Key

from ..bodies import np, p, set_surface
from ..geometry import Point, rectangle
from ..kind import Context, ElementKind, Entry
from ..limits import count_text, rounded
from ..rules import COORDINATE, HEIGHT, LENGTH, LENGTH_OR_ZERO, OPTIONAL_LENGTH, broken, file_path
from ..surfaces import ZERO_HINT
from ..terrain import check_image_budget, field_heights, image_levels, noise_lattice, points

CHECK = 1.0  # [m]: the side of a height field's checks, as the plane's
TEXTURE_PIXELS_PER_CHECK = 4  # so the renderer's sampling keeps the checks' edges
MAX_TEXTURE_PIXELS = 2048  # along a side of a height field's texture; a bigger field has bigger checks


@dataclass(frozen=True)
class HeightField:
    """Uneven ground on a regular grid in place of the ground plane (beyond its edges there is no
    ground; its friction and colour are the ground's): an image's grey levels, bumps and ruts
    (:meth:`heights`).

    Either a grey-scale ``image`` (a PNG, 8 or 16 bits; colours by luminance; its first row is the
    +y edge, as a map, and its pixels are the grid's points), black at ``min_height`` and white at
    ``max_height``; or a grid every ``resolution``. Either way, added: random bumps up to
    ``amplitude`` high and deep, ``feature_length`` apart (value noise from ``seed``), and ruts along
    the field's x axis ``rut_depth`` deep, ``rut_width`` wide, every ``rut_spacing`` across (the
    field's centre line half-way between two ruts). Within ``flat_radius`` of the origin, where robots
    spawn at z = 0 by default, the field is 0 (its grid points out to one cell's diagonal more),
    rising to full height over the next FLAT_BLEND. Patches, hills and rails stay at z = 0.
    """

    x: float  # [m] centre
    y: float  # [m]
    size_x: float  # [m]
    size_y: float  # [m]
    resolution: float  # [m] asked for between grid points (0 with an image: its pixels are the grid)
    image: str  # absolute path, or ""
    min_height: float  # [m] of black
    max_height: float  # [m] of white
    amplitude: float  # [m] of the bumps, up and down
    feature_length: float  # [m] between the bumps' random heights
    seed: int
    rut_depth: float  # [m]
    rut_width: float  # [m]
    rut_spacing: float  # [m] between neighbouring ruts' centre lines
    flat_radius: float  # [m] around the world's origin where the field is 0

    def grid_shape(self) -> Tuple[int, int]:
        """(nx, ny): grid points along x and along y."""
        if self.image:
            ny, nx = self._levels.shape
            return nx, ny
        return points(self.size_x, self.resolution), points(self.size_y, self.resolution)

    def grid_step(self) -> Tuple[float, float]:
        """[m] between grid points along x and along y (the resolution, shrunk to fit the size)."""
        nx, ny = self.grid_shape()
        return self.size_x / (nx - 1), self.size_y / (ny - 1)

    def heights(self):
        """The grid's heights [m] (a read-only numpy array ny x nx; row 0 is the -y edge, column 0 the -x edge)."""
        return self._heights

    # Made once per field (a frozen dataclass keeps a cached_property in its __dict__, outside its
    # fields): the image is read again by the next load of the world, so an edited image counts.
    @functools.cached_property
    def _levels(self):
        return image_levels(self.image)

    @functools.cached_property
    def _heights(self):
        return field_heights(self)

    def height_at(self, px: float, py: float) -> Optional[float]:
        """[m] of the surface at (px, py), as bullet draws it between the grid points; None off the field.

        bullet's height field splits each cell into two triangles along the diagonal from its
        (+x, -y) corner to its (-x, +y) corner, and is flat on each.
        """
        nx, ny = self.grid_shape()
        dx, dy = self.grid_step()
        u = (px - (self.x - self.size_x / 2)) / dx
        v = (py - (self.y - self.size_y / 2)) / dy
        if not (-1e-9 <= u <= nx - 1 + 1e-9 and -1e-9 <= v <= ny - 1 + 1e-9):
            return None
        i, j = min(max(math.floor(u), 0), nx - 2), min(max(math.floor(v), 0), ny - 2)
        fu, fv = u - i, v - j
        h = self.heights()
        h00, h10, h01, h11 = h[j, i], h[j, i + 1], h[j + 1, i], h[j + 1, i + 1]
        if fu + fv <= 1.0:
            return float(h00 + fu * (h10 - h00) + fv * (h01 - h00))
        return float(h11 + (1.0 - fu) * (h01 - h11) + (1.0 - fv) * (h10 - h11))


HEIGHT_FIELD_KEYS = (
    Key("x", float, 0.0, **COORDINATE),
    Key("y", float, 0.0, **COORDINATE),
    Key("size_x", float, **LENGTH),
    Key("size_y", float, **LENGTH),
    Key("resolution", float, **OPTIONAL_LENGTH),
    Key("image", str, None, check=bool, rule="must not be empty"),
    Key("min_height", float, None, **HEIGHT),
    Key("max_height", float, None, **HEIGHT),
    Key("amplitude", float, 0.0, **LENGTH_OR_ZERO),
    Key("feature_length", float, 1.0, **LENGTH),
    Key("seed", int, 0),
    Key("rut_depth", float, 0.0, **LENGTH_OR_ZERO),
    Key("rut_width", float, 0.3, **LENGTH),
    Key("rut_spacing", float, 1.5, **LENGTH),
    Key("flat_radius", float, 2.0, **LENGTH_OR_ZERO),
)


def make(entry: Entry, context: Context) -> Optional[HeightField]:
    v, raw, path, problems = entry.values, entry.raw, entry.path, context.problems
    limits = context.limits
    image, levels = "", None
    if v["image"]:
        image = file_path(v["image"], context.base_dir, f"{path}.image", problems)
        if os.path.isfile(image):
            try:
                # its size from its header first: a huge image is refused before it is decoded
                check_image_budget(image, limits)
                levels = image_levels(image)
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
    if v["rut_width"] > v["rut_spacing"] and not broken(problems, path, "rut_width", "rut_spacing"):
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
        nx, ny = (max(2.0, rounded(size / hf.resolution) + 1) for size in (hf.size_x, hf.size_y))
        if nx * ny > limits.field_points:
            rule = f"makes {count_text(nx)} x {count_text(ny)} grid points; at most {limits.field_points}"
            problems.append(Problem(f"{path}.resolution", raw.get("resolution", hf.resolution), rule))
            return None
    if hf.amplitude > 0:
        ni, nj = noise_lattice(hf.size_x, hf.feature_length), noise_lattice(hf.size_y, hf.feature_length)
        if ni * nj > limits.noise_points:
            rule = (
                f"makes {count_text(ni)} x {count_text(nj)} noise lattice points (size / feature_length); "
                f"at most {limits.noise_points}"
            )
            problems.append(Problem(f"{path}.feature_length", hf.feature_length, rule))
            return None
    return hf


def check(fields: Tuple[HeightField, ...], context: Context) -> None:
    if fields and context.ground.soft:
        rule = f"must be 0 with a height_field ({ZERO_HINT}): bullet touches a wheel at 1 to 4 of its triangles"
        context.problems.append(Problem("ground.sinkage", context.ground.sinkage, rule))


def ground(hf: HeightField, px: float, py: float) -> float:
    """The field's height at (px, py), 0 off it."""
    return hf.height_at(px, py) or 0.0


def footprint(hf: HeightField) -> List[Point]:
    return rectangle(hf.x, hf.y, 0.0, (-hf.size_x / 2, hf.size_x / 2), (-hf.size_y / 2, hf.size_y / 2))


# ---------------------------------------------------------------------------------------------
# In pybullet
# ---------------------------------------------------------------------------------------------
def build(client: int, world, field: HeightField, name: str, bodies: dict) -> None:
    heights = field.heights()
    nx, ny = field.grid_shape()
    dx, dy = field.grid_step()
    # pybullet's "rows" run along x: numHeightfieldRows is the number of points along x, and the
    # data goes row of constant y after row, from -y. bullet centres the grid on the body and its
    # heights between their lowest and highest, so the body sits at the middle of that range.
    shape = p.createCollisionShape(
        p.GEOM_HEIGHTFIELD,
        meshScale=(dx, dy, 1.0),
        heightfieldData=heights.ravel().tolist(),
        numHeightfieldRows=nx,
        numHeightfieldColumns=ny,
        physicsClientId=client,
    )
    middle = (float(heights.min()) + float(heights.max())) / 2
    body = p.createMultiBody(0, shape, -1, basePosition=(field.x, field.y, middle), physicsClientId=client)
    texture = _checker_texture(client, field.size_x, field.size_y)
    p.changeVisualShape(body, -1, rgbaColor=world.ground_rgba, textureUniqueId=texture, physicsClientId=client)
    set_surface(client, body, world.ground)
    bodies[name] = body


def _checker_texture(client: int, size_x: float, size_y: float) -> int:
    """A texture of checks CHECK apart (more on a field over 512 m) over size_x by size_y [m], as the plane's.

    pybullet stretches a height field's texture over the whole field once (its own checker texture
    would be four squares of half the field each), so the checks are drawn into it at the field's
    size. pybullet loads textures from files only: this one goes through a temporary file.
    """
    from PIL import Image  # noqa: PLC0415  (only for height fields)

    check = max(CHECK, max(size_x, size_y) * TEXTURE_PIXELS_PER_CHECK / MAX_TEXTURE_PIXELS)
    ix = (np.arange(max(1, round(size_x / check)) * TEXTURE_PIXELS_PER_CHECK) // TEXTURE_PIXELS_PER_CHECK)[None, :]
    iy = (np.arange(max(1, round(size_y / check)) * TEXTURE_PIXELS_PER_CHECK) // TEXTURE_PIXELS_PER_CHECK)[:, None]
    levels = np.where((ix + iy) % 2 == 0, 255, 205).astype(np.uint8)
    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "checks.png")
        Image.fromarray(levels).convert("RGB").save(path)
        return p.loadTexture(path, physicsClientId=client)


HEIGHT_FIELD = ElementKind(
    "height_field", None, HEIGHT_FIELD_KEYS, make=make, builder=build, footprint=footprint, check=check,
    on_ground=False, body="ground", ground=ground, replaces_ground=True,
    doc="uneven ground in place of the ground plane (beyond its edges there is no ground), of the ground's "
    "friction and colour",
    defaults={
        "resolution": "0.2; none with an image", "image": "none: a grid", "min_height": "0, with an image only",
        "max_height": "1, with an image only",
    },
)  # fmt: skip
