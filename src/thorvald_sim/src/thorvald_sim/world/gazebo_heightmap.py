"""Gazebo Classic 11's heightmap as its physics collides with it: the grid of heights that a world
file's ``<collision><geometry><heightmap>`` makes from its image (:func:`gazebo_heights`), the
surface between the grid's points (:func:`height_at`), and the keys of our height field
(:class:`~thorvald_sim.world.kinds.height_field.HeightField`) that make the same grid, with what
they cannot make (:func:`as_height_field`).

Pure: numpy and PIL, imported when called (as in :mod:`~thorvald_sim.world.terrain`); no pybullet.

The convention
--------------
Read in the source of Gazebo 11.10 (the gazebo11 branch of gazebosim/gazebo-classic) and of what it
builds with: FreeImage 3.18 (which decodes the image), ignition-math 6 and its own copy of ODE
(``deps/opende``); a file named below without a project is gazebo-classic's. ``W`` is the image's
side in pixels, ``s`` the sampling, ``n = (W - 1) s + 1`` the grid's points a side; ``size`` and
``pos`` are the heightmap's ``<size>`` and ``<pos>`` (sdformat ``sdf/1.6/heightmap_shape.sdf``:
``size`` 1 1 1, ``pos`` 0 0 0 and ``sampling`` 2 by default; ``use_terrain_paging`` is the
renderer's only).

1. Files (``gazebo/common/HeightmapData.cc`` ``LoadTerrainFile``, ``gazebo/common/Image.cc``
   ``Load``): GDAL sniffs the file's content and only a PNG or a JPEG is read as an image (anything
   else goes to the DEM reader: not taken here); FreeImage then picks its decoder by the file's
   extension (``.png``; ``.jpg``, ``.jpeg``, ``.jpe``, ``.jif``), so both must agree. A PNG's gAMA
   chunk is applied against a screen gamma of 2.2 (FreeImage ``PluginPNG.cpp``; libpng skips it
   when their product is within 0.05 of 1, as for the usual 1/2.2); a JPEG is decoded with
   libjpeg's fast integer IDCT and without fancy upsampling (``PluginJPEG.cpp``, ``JPEG_DEFAULT``).
   Refused here: other formats, a mismatched extension, a gamma that would be applied, bit depths
   under 8 (FreeImage keeps 1- and 4-bit rows packed, which Gazebo's byte-per-pixel read garbles),
   16-bit images other than grey without transparency, CMYK. A JPEG's levels are PIL's decoding
   (accurate IDCT, fancy upsampling): they may differ from Gazebo's by a few levels.
2. The image's size (``gazebo/physics/HeightmapShape.cc`` ``Load``): square with ``W = 2^k + 1``
   (2, 3, 5, 9, ..., 513, ...), else Gazebo logs "Heightmap data size must be square, with a size of
   2^n+1" and the load fails (the renderer throws and gzserver/gzclient abort: gazebo-classic
   issues #2199, #1653). Nothing is resampled. Refused here.
3. The sampling (``HeightmapShape.cc`` ``Load`` and ``Init``): a power of two (1, 2, 4, ...); 0 or
   another number logs an error and 2 is used (so here too). The grid is ``n x n`` points:
   ``vertSize = W s - s + 1``.
4. A pixel's value (``gazebo/common/ImageHeightmap.cc`` ``FillHeightMap``; ``Image.cc`` ``GetData``,
   a raw copy of FreeImage's bytes, top row first): the pixel's *first byte* over 255. So: 8-bit
   grey, its level; a palette image, its palette *index*; RGB or RGBA, its *blue* (FreeImage holds
   pixels BGR(A) on little-endian machines: ``PluginPNG.cpp`` ``png_set_bgr``); grey with alpha, its
   grey (expanded to RGBA). 16-bit grey (FreeImage's FIT_UINT16, swapped to little-endian): the *low
   byte* over 255, and the height scale below is 1 whatever ``size.z`` (item 6): Gazebo Classic has
   no 16-bit heightmaps (ignition-common added them for Gazebo Sim: gazebosim/gz-common#266). This
   is ``sixteen_bit="classic"``, the default; ``"full"`` reads all 16 bits instead, the brightest
   pixel at ``size.z`` as with 8 bits (not Gazebo Classic's: for a world written for Gazebo Sim).
5. Between pixels (``FillHeightMap``): grid point (r, c), r counted from the image's *top* row and c
   from its left column, is the bilinear interpolation of the pixels' values at (r / s, c / s), then
   times the scale: ``h1 = p(r1, c1) - (p(r1, c1) - p(r1, c2)) dc`` (as a float32), likewise ``h2`` on
   row r2, ``h = (h1 - (h1 - h2) dr) scale`` (``h1 - h2`` in float32, ``h`` a float32), reproduced here
   step for step. With s = 1 the grid's points are the pixels.
6. The height scale (``HeightmapShape.cc`` ``Init``; ``Image.cc`` ``MaxColor``, ``Pixel``; ign-math6
   ``Color::Set``, ``Clamp``): ``scale = |size.z| / m``, ``m`` the image's "max colour": each pixel's
   value v taken as 0 if 0, as **1.0 if 1** (``Clamp`` divides only values over 1 by 255) and as
   float32 v / 255 otherwise; ``m`` is the first pixel, scanning from the *bottom* row, with the
   largest float32 sum of its three channels (for grey, the largest value); ``m`` is its *blue* as
   above. If ``m`` is 0 (a black image; a 16-bit one, whose pixels FreeImage will not read one by
   one), ``scale = 1`` (not ``size.z``). So with 8 bits a height is ``v / 255 * size.z / m``: the
   brightest pixel at ``size.z``, black at 0: the image's minimum is not subtracted. A negative
   ``size.z`` stores ``1 - h`` ("for backward compatibility"); refused here.
7. Where it is (ODE, Gazebo's default engine: ``gazebo/physics/ode/ODEHeightmapShape.cc`` ``Init``;
   ``deps/opende/src/heightfield.cpp``): ODE's height field is ``size.x`` by ``size.y``, centred on
   its origin, points ``size / (n - 1)`` apart (``m_fSampleWidth = width / (widthSamples - 1)``);
   each height is the stored float32 ``h + pos.z`` (ODE's offset). The geom is rotated by the
   collision's world rotation at load times a roll of +90 deg (ODE's height fields are y-up), which
   takes ODE's depth axis to world -y: grid row r (the image's row r from the top) is at
   ``y = size.y / 2 - r dy``: **the image's first row is the +y edge and its first column the -x
   edge**, as a map seen from above. Its *position* is never set (Gazebo marks the geom not
   placeable), so it stays at the world's origin: **``pos.x`` and ``pos.y`` and the translation of
   the model's, link's and collision's poses are ignored by the physics** (the renderer does shift
   the visual by them: gazebo-classic issues #868, #2996, "collision and visual offset"); only
   ``pos.z`` moves it, up. A rotation in those poses does turn (or tilt) the grid about the world's
   origin; the grid returned here is in the collision's rotated axes (a yaw of 0: world axes).
8. Between points (``heightfield.cpp``: cells of triangles ABC and DBC, A = (x, z), B = (x + 1, z),
   C = (x, z + 1), D = (x + 1, z + 1); ``dxHeightfieldData::GetHeight``): each cell is split along
   the diagonal from its (-x, -y) corner to its (+x, +y) corner, flat on each triangle
   (:func:`height_at`). Our pybullet height field splits it along the other diagonal, from (+x, -y)
   to (-x, +y) (``HeightField.height_at``).
9. Not modelled: Gazebo run with bullet (``gazebo/physics/bullet/BulletHeightmapShape.cc``) spaces
   the points ``size / n`` (not ``n - 1``), centres the heights' range on the collision's z (its
   correcting transform is a known no-op; ``pos.z`` unused), and alternates the diagonal by row
   (zigzag subdivision); DART builds its own. ODE also closes the field with a 1 m thick skirt
   below it (``thickness``), and beyond its edges there is no ground. The renderer draws the
   visual ``size.x`` square (``gazebo/rendering/Heightmap.cc`` uses ``size.x`` for both sides).
"""

import math
import os
from typing import Any, Dict, NamedTuple, Optional, Sequence, Tuple

from .terrain import PNG_SIGNATURE, image_size

SAMPLING = 2  # the SDF's default <sampling>
SIXTEEN_BIT = ("classic", "full")
TRIANGLES = ("gazebo", "bullet")
DEFAULT_MAX_POINTS = 1_000_000  # as the world's budget of a height field's grid points (Limits.field_points)
GAMMA_SCREEN = 2.2  # FreeImage's screen gamma for a PNG's gAMA chunk
GAMMA_THRESHOLD = 0.05  # libpng applies a gamma only if screen * file gamma is this far from 1
# FreeImage's decoders by extension (FreeImage_GetFIFFromFilename), for the two formats GDAL hands over
EXTENSIONS = {"PNG": (".png",), "JPEG": (".jpg", ".jpeg", ".jpe", ".jif")}


class GazeboGrid(NamedTuple):
    """Gazebo's heights on its grid, and where the grid's points are (in the collision's axes)."""

    heights: Any  # [m] numpy array n x n, read-only: [row along y from -y to +y, column along x from -x to +x]
    x0: float  # [m] x of column 0 (the -x edge)
    y0: float  # [m] y of row 0 (the -y edge)
    dx: float  # [m] between columns
    dy: float  # [m] between rows


class HeightFieldKeys(NamedTuple):
    """Our height field's keys for a Gazebo heightmap (``HeightField(**keywords)``), and how the
    heights of its grid's points would differ from Gazebo's (none: the same, to float32 rounding).
    Between the points they always differ, on the other diagonal (the convention, item 8)."""

    keywords: Dict[str, Any]
    differences: Tuple[str, ...]
    kind: str = "grey"  # of the image, as read: "grey", "palette", "colour" or "16-bit"


class _Read(NamedTuple):
    """An image as Gazebo reads it."""

    values: Any  # numpy float64 W x W: each pixel's value in [0, 1] as FillHeightMap takes it, top row first
    scale: float  # FillHeightMap's scale.z
    sampling: int  # as used
    kind: str  # "grey", "palette", "colour" or "16-bit"
    image: Any  # the PIL image (loaded)


# ---------------------------------------------------------------------------------------------
# The grid
# ---------------------------------------------------------------------------------------------
def gazebo_heights(
    image_path: str,
    size: Sequence[float],
    pos: Sequence[float] = (0.0, 0.0, 0.0),
    sampling: int = SAMPLING,
    *,
    sixteen_bit: str = "classic",
    shift_xy: bool = False,
    max_points: int = DEFAULT_MAX_POINTS,
) -> GazeboGrid:
    """The heights Gazebo Classic 11's physics (ODE) collides with, for a ``<heightmap>`` of this
    image, ``<size>``, ``<pos>`` and ``<sampling>``, exactly (float32 steps included; the convention
    in this module's docstring): a :class:`GazeboGrid` ``(heights, x0, y0, dx, dy)``.

    ``shift_xy`` moves the grid by ``pos.x``, ``pos.y``, where Gazebo draws it; its physics does not
    (the default). ``max_points`` bounds the grid's points (``n * n``, at least the image's pixels),
    counted from the image's header before its pixels are decoded. ValueError, with the reason, for
    an image Gazebo does not read as a heightmap (or that is refused here: the convention, item 1),
    one that cannot be read, non-finite sizes or positions, a negative or zero ``size`` x or y, a
    negative ``size.z``, or a grid over ``max_points``.
    """
    import numpy as np  # noqa: PLC0415

    size, pos = _vector(size, "size"), _vector(pos, "pos")
    read = _read(image_path, size, sampling, sixteen_bit, max_points)
    n = (read.values.shape[0] - 1) * read.sampling + 1
    grid = _fill(read.values, read.sampling, read.scale)  # float32, rows from the image's top
    heights = np.flipud(grid).astype(np.float64) + pos[2]  # ODE: stored height * 1.0 + offset
    heights.setflags(write=False)
    x0 = -size[0] / 2 + (pos[0] if shift_xy else 0.0)
    y0 = -size[1] / 2 + (pos[1] if shift_xy else 0.0)
    return GazeboGrid(heights, x0, y0, size[0] / (n - 1), size[1] / (n - 1))


def height_at(grid: GazeboGrid, x: float, y: float, triangles: str = "gazebo") -> Optional[float]:
    """[m] of the surface at (x, y), flat on each cell's two triangles; None off the grid.

    ``triangles``: ``"gazebo"``, ODE's (each cell split from its (-x, -y) corner to its (+x, +y)
    corner, the convention, item 8), or ``"bullet"``, our pybullet height field's (from (+x, -y) to
    (-x, +y), as ``HeightField.height_at``).
    """
    if triangles not in TRIANGLES:
        raise ValueError(f"triangles must be one of {TRIANGLES}, not {triangles!r}")
    h = grid.heights
    ny, nx = h.shape
    u, v = (x - grid.x0) / grid.dx, (y - grid.y0) / grid.dy
    if not (-1e-9 <= u <= nx - 1 + 1e-9 and -1e-9 <= v <= ny - 1 + 1e-9):
        return None
    i, j = min(max(math.floor(u), 0), nx - 2), min(max(math.floor(v), 0), ny - 2)
    fu, fv = u - i, v - j
    h00, h10, h01, h11 = float(h[j, i]), float(h[j, i + 1]), float(h[j + 1, i]), float(h[j + 1, i + 1])
    if triangles == "gazebo":
        if fu >= fv:  # the (+x, -y) triangle: corners 00, 10, 11
            return h00 + fu * (h10 - h00) + fv * (h11 - h10)
        return h00 + fv * (h01 - h00) + fu * (h11 - h01)  # the (-x, +y) one: 00, 01, 11
    if fu + fv <= 1.0:
        return h00 + fu * (h10 - h00) + fv * (h01 - h00)
    return h11 + (1.0 - fu) * (h01 - h11) + (1.0 - fv) * (h10 - h11)


# ---------------------------------------------------------------------------------------------
# Our height field
# ---------------------------------------------------------------------------------------------
def as_height_field(
    image_path: str,
    size: Sequence[float],
    pos: Sequence[float] = (0.0, 0.0, 0.0),
    sampling: int = SAMPLING,
    *,
    sixteen_bit: str = "classic",
    shift_xy: bool = False,
    max_points: int = DEFAULT_MAX_POINTS,
) -> HeightFieldKeys:
    """The keys of our height field for this heightmap (arguments and errors as :func:`gazebo_heights`).

    Our field's grid is the image's pixels, its first row the +y edge, centred on (``x``, ``y``),
    ``size / (pixels - 1)`` apart, black at ``min_height`` and white at ``max_height`` (8 bits by
    luminance, 16 bits over 65535): so ``x = y = 0`` (``pos.x``, ``pos.y`` with ``shift_xy``),
    ``min_height = pos.z``, ``max_height = pos.z + scale`` (the convention, item 6), the image itself,
    no bumps, ruts or flat disc. That is Gazebo's grid, to float32 rounding, for an 8-bit grey (or
    grey-valued) image with ``sampling`` 1. Otherwise ``differences`` says what differs:

    - a sampling over 1: Gazebo's ``s - 1`` interpolated points between pixels (ours has the pixels'
      points only; they are at the same heights);
    - 16 bits in Gazebo Classic (low bytes, scale 1); a colour image (Gazebo reads blue, ours the
      luminance); a palette image whose palette is not a grey ramp (Gazebo reads the indices);
    - a flat ``size.z`` of 0 over a non-black image (our field needs ``max_height > min_height``).

    Between the points they differ always: ODE's diagonal is the other one (the convention, item 8).
    """
    import numpy as np  # noqa: PLC0415

    size, pos = _vector(size, "size"), _vector(pos, "pos")
    read = _read(image_path, size, sampling, sixteen_bit, max_points)
    differences = []
    if read.sampling > 1:
        n = (read.values.shape[0] - 1) * read.sampling + 1
        differences.append(
            f"sampling {read.sampling}: Gazebo's grid is {n} x {n} points, {read.sampling - 1} interpolated between "
            "neighbouring pixels; our field's is the image's pixels (at the same heights as Gazebo's there)"
        )
    image = read.image
    if read.kind == "16-bit" and sixteen_bit == "classic":
        differences.append(
            "16 bits: Gazebo Classic takes each pixel's low byte over 255, at a scale of 1 whatever size z; "
            "our field reads all 16 bits"
        )
    elif read.kind == "colour":
        rgb = np.asarray(image.convert("RGB"), dtype=np.int32)
        if not ((rgb[..., 0] == rgb[..., 1]).all() and (rgb[..., 1] == rgb[..., 2]).all()):
            differences.append("a colour image: Gazebo reads each pixel's blue, our field its luminance")
    elif read.kind == "palette":
        if not (np.asarray(image) == np.asarray(image.convert("L"))).all():
            differences.append("a palette image: Gazebo reads the palette's indices, our field the colours' luminance")
    scale = read.scale
    if scale <= 0.0:
        if read.values.any():
            differences.append("size z is 0: Gazebo's field is flat at pos z; ours needs max_height > min_height")
        scale = 1.0  # a black image stays at min_height whatever the span
    keywords = {
        "x": pos[0] if shift_xy else 0.0,
        "y": pos[1] if shift_xy else 0.0,
        "size_x": size[0],
        "size_y": size[1],
        "resolution": 0.0,
        "image": os.path.abspath(image_path),
        "min_height": pos[2],
        "max_height": pos[2] + scale,
        "amplitude": 0.0,
        "feature_length": 1.0,
        "seed": 0,
        "rut_depth": 0.0,
        "rut_width": 0.3,
        "rut_spacing": 1.5,
        "flat_radius": 0.0,
    }
    return HeightFieldKeys(keywords, tuple(differences), read.kind)


# ---------------------------------------------------------------------------------------------
# Reading the image as Gazebo does
# ---------------------------------------------------------------------------------------------
def _vector(value: Sequence[float], name: str) -> Tuple[float, float, float]:
    rule = f"{name} must be three numbers (x y z), not {value!r}"
    try:
        items = list(value)
    except TypeError:
        raise ValueError(rule) from None
    if len(items) != 3 or any(isinstance(v, bool) for v in items):
        raise ValueError(rule)
    try:
        x, y, z = (float(v) for v in items)
    except (TypeError, ValueError):
        raise ValueError(rule) from None
    if not all(math.isfinite(v) for v in (x, y, z)):
        raise ValueError(f"{name} must be finite, not {value!r}")
    if name == "size" and (x <= 0 or y <= 0 or z < 0):
        raise ValueError(
            f"size must be > 0 along x and y and >= 0 along z, not {value!r} "
            "(Gazebo's negative z inverts the heights as 1 - h: not taken)"
        )
    return x, y, z


def _sampling(sampling: int) -> int:
    if isinstance(sampling, bool) or not isinstance(sampling, int) or sampling < 0:
        raise ValueError(f"sampling must be an unsigned integer, not {sampling!r}")
    if sampling == 0 or sampling & (sampling - 1):
        return SAMPLING  # as Gazebo: "Heightmap sampling value must be a power of 2", and 2 is used
    return sampling


def _read(image_path: str, size, sampling: int, sixteen_bit: str, max_points: int) -> _Read:
    """The image's values and the height scale as Gazebo computes them; every refusal as a ValueError."""
    import numpy as np  # noqa: PLC0415
    from PIL import Image, UnidentifiedImageError  # noqa: PLC0415

    if sixteen_bit not in SIXTEEN_BIT:
        raise ValueError(f"sixteen_bit must be one of {SIXTEEN_BIT}, not {sixteen_bit!r}")
    s = _sampling(sampling)
    # the header first: the size and the budget before a pixel is decoded
    try:
        width, height = image_size(image_path)
        with open(image_path, "rb") as f:
            head = f.read(26)
    except OSError as e:
        raise ValueError(f"cannot read the image: {e}") from None
    if width != height or width < 2 or (width - 1) & (width - 2):
        raise ValueError(
            f"is {width} x {height} pixels: Gazebo takes square images of 2^k + 1 pixels a side (3, 5, 9, ..., 513)"
        )
    n = (width - 1) * s + 1
    if n * n > max_points:
        raise ValueError(
            f"makes a grid of {n} x {n} points ({width} x {height} pixels, sampling {s}); at most {max_points}"
        )
    png = head[:8] == PNG_SIGNATURE
    if png and len(head) < 26:
        raise ValueError("cannot read the image: a PNG file without its IHDR header")
    if png and (head[24] < 8 or (head[24] == 16 and head[25] != 0)):
        what = {0: "grey", 2: "RGB", 3: "palette", 4: "grey and alpha", 6: "RGBA"}.get(head[25], "unknown colour type")
        raise ValueError(
            f"is a {head[24]}-bit {what} PNG: Gazebo Classic reads 8-bit images (and 16-bit grey ones); save it as "
            "8-bit grey"
        )
    try:
        with Image.open(image_path) as image:
            image.load()
    except (OSError, UnidentifiedImageError, Image.DecompressionBombError) as e:
        raise ValueError(f"cannot read the image: {e}") from None
    if image.format not in EXTENSIONS:
        raise ValueError(f"is a {image.format} image: Gazebo reads PNG and JPEG images as heightmaps")
    extension = os.path.splitext(image_path)[1].lower()
    if extension not in EXTENSIONS[image.format]:
        raise ValueError(
            f"is a {image.format} file named {extension or 'without an extension'}: Gazebo picks its decoder by "
            f"the extension ({', '.join(EXTENSIONS[image.format])})"
        )
    gamma = image.info.get("gamma")
    if png and gamma is not None and abs(gamma * GAMMA_SCREEN - 1.0) >= GAMMA_THRESHOLD:
        raise ValueError(
            f"has a gamma of {gamma} (gAMA chunk), which Gazebo's FreeImage applies against a screen gamma of 2.2: "
            "remove the chunk (or make it 1/2.2)"
        )
    if png and head[24] == 16 and "transparency" in image.info:
        raise ValueError("is a 16-bit grey PNG with a transparent level (tRNS): FreeImage makes it RGBA")
    mode = image.mode
    if mode in ("I;16", "I;16L", "I;16B", "I"):
        raw = np.asarray(image).astype(np.int64)
        if raw.min() < 0 or raw.max() > 65535:
            raise ValueError(f"has levels outside 16 bits (PIL mode {mode})")
        if sixteen_bit == "classic":
            # FreeImage's FIT_UINT16, little-endian: Gazebo reads the low byte; MaxColor finds no
            # pixel it can read, so the scale is 1
            return _Read((raw & 0xFF) / 255.0, 1.0, s, "16-bit", image)
        top = int(raw.max())
        scale = 1.0 if top == 0 else abs(size[2]) / (top / 65535.0)
        return _Read(raw / 65535.0, scale, s, "16-bit", image)
    if mode in ("L", "P"):
        first = np.asarray(image).astype(np.int64)  # grey levels, or palette indices
        channels = np.stack([first] * 3, axis=-1)
        kind = "grey" if mode == "L" else "palette"
    elif mode == "LA":
        first = np.asarray(image)[..., 0].astype(np.int64)  # FreeImage: grey to RGBA, so the grey
        channels = np.stack([first] * 3, axis=-1)
        kind = "grey"
    elif mode in ("RGB", "RGBA"):
        rgb = np.asarray(image)[..., :3].astype(np.int64)
        first = rgb[..., 2]  # BGR(A) in memory: the blue
        channels = rgb[..., ::-1]  # as Pixel() sets a colour: (blue, green, red)
        kind = "colour"
    else:
        raise ValueError(f"is not an image Gazebo reads as grey levels (PIL mode {mode})")
    return _Read(first / 255.0, _scale(channels, size[2]), s, kind, image)


def _scale(channels, size_z: float) -> float:
    """HeightmapShape::Init's scale.z: |size z| over Image::MaxColor().R() (1 if that is 0).

    channels: int array H x W x 3, top row first, as Image::Pixel sets a colour (its R first).
    """
    import numpy as np  # noqa: PLC0415

    c = channels.astype(np.float32)
    # ign-math's Color::Clamp: only values over 1 are divided by 255 (so a 1 stays 1.0)
    c = np.where(c > 1, c / np.float32(255.0), c).astype(np.float32)
    sums = (c[..., 0] + c[..., 1]) + c[..., 2]  # float32, left to right
    # MaxColor scans FreeImage's rows from the bottom, keeping the first strictly larger sum
    scan = np.flipud(sums).ravel()
    first = int(np.argmax(scan))
    if not scan[first] > 0:
        m = 0.0
    else:
        m = float(np.flipud(c[..., 0]).ravel()[first])
    if abs(m) <= 1e-6:  # ignition::math::equal(heightmapSizeZ, 0.0)
        return 1.0
    return abs(size_z) / m


def _fill(values, sampling: int, scale: float):
    """ImageHeightmap::FillHeightMap, float32 steps included: the grid n x n, rows from the image's top."""
    import numpy as np  # noqa: PLC0415

    w = values.shape[0]
    n = (w - 1) * sampling + 1
    f = np.arange(n) / float(sampling)
    k1 = np.floor(f).astype(np.int64)
    k2 = np.minimum(np.ceil(f).astype(np.int64), w - 1)
    d = f - k1
    r1, r2, dr = k1[:, None], k2[:, None], d[:, None]
    c1, c2, dc = k1[None, :], k2[None, :], d[None, :]
    p1, p2 = values[r1, c1], values[r1, c2]
    h1 = (p1 - (p1 - p2) * dc).astype(np.float32)
    p3, p4 = values[r2, c1], values[r2, c2]
    h2 = (p3 - (p3 - p4) * dc).astype(np.float32)
    between = (h1 - h2).astype(np.float64)  # float - float: a float32
    return ((h1.astype(np.float64) - between * dr) * scale).astype(np.float32)
