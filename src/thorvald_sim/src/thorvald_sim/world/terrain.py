"""Terrain: a height field's grid of heights from a grey-scale image, random bumps and ruts, flat
around the origin (:func:`field_heights`), and what its image and noise cost, counted before they
are made (:func:`check_image_budget`: an image's file and pixels, from its header, which our height
fields and Gazebo worlds' heightmaps are held to).

numpy and PIL are imported when a field is made, so that importing the world stays cheap. No pybullet.
"""

import math
import os
import random
import warnings
from typing import Tuple

from .limits import Limits

FLAT_BLEND = 1.0  # [m] over which a height field rises from its flat disc to full height
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def points(size: float, resolution: float) -> int:
    """Grid points along a side of size [m], as near resolution [m] apart as fits (at least 2)."""
    return max(2, round(size / resolution) + 1)


def image_levels(path: str):
    """The image's grey levels in [0, 1] (numpy, rows from the -y edge); ValueError if it cannot be read."""
    import numpy as np  # noqa: PLC0415
    from PIL import Image, UnidentifiedImageError  # noqa: PLC0415

    try:
        with Image.open(path) as image:
            image.load()
            if image.mode in ("I;16", "I;16L", "I;16B", "I"):
                levels = np.asarray(image, dtype=np.float64) / 65535.0
            else:
                levels = np.asarray(image.convert("L"), dtype=np.float64) / 255.0
    except (OSError, UnidentifiedImageError) as e:
        raise ValueError(f"cannot read the image: {e}") from None
    if levels.ndim != 2 or min(levels.shape) < 2:
        raise ValueError(f"must be an image of at least 2 x 2 pixels, not {levels.shape[::-1]}")
    levels = np.clip(np.flipud(levels), 0.0, 1.0)  # the image's first row is the +y edge
    levels.setflags(write=False)
    return levels


def field_heights(hf):
    """The heights [m] of a height field (a :class:`~thorvald_sim.world.kinds.height_field.HeightField`) on its grid."""
    import numpy as np  # noqa: PLC0415

    nx, ny = hf.grid_shape()
    xs = np.linspace(-hf.size_x / 2, hf.size_x / 2, nx)  # from the field's centre
    ys = np.linspace(-hf.size_y / 2, hf.size_y / 2, ny)
    gx, gy = np.meshgrid(xs, ys)
    h = np.zeros((ny, nx))
    if hf.image:
        h += hf.min_height + (hf.max_height - hf.min_height) * hf._levels
    if hf.amplitude > 0:
        h += hf.amplitude * _value_noise(gx / hf.feature_length, gy / hf.feature_length, hf.seed)
    if hf.rut_depth > 0:
        # distance from the nearest rut's centre line; ruts at (k + 1/2) rut_spacing across the field
        d = np.abs((gy / hf.rut_spacing) % 1.0 - 0.5) * hf.rut_spacing
        h -= np.where(d < hf.rut_width / 2, hf.rut_depth * 0.5 * (1 + np.cos(2 * np.pi * d / hf.rut_width)), 0.0)
    if hf.flat_radius > 0:
        # every grid point within a cell's diagonal beyond the radius is 0 too, so that each triangle
        # over the disc is flat at 0, not just its points
        r = np.hypot(gx + hf.x, gy + hf.y) - math.hypot(*hf.grid_step())
        h *= _smoothstep((r - hf.flat_radius) / FLAT_BLEND)
    h.setflags(write=False)
    return h


def _value_noise(u, v, seed: int):
    """Smooth noise in [-1, 1] at lattice coordinates (u, v) (numpy arrays): random values at the
    integer points, from one generator seeded by seed in row order over the lattice around (u, v),
    blended with the smoothstep (continuous slopes, flat at the lattice points)."""
    import numpy as np  # noqa: PLC0415

    i0, j0 = int(np.floor(u.min())), int(np.floor(v.min()))
    ni, nj = int(np.floor(u.max())) - i0 + 2, int(np.floor(v.max())) - j0 + 2
    rng = random.Random(seed)
    lattice = np.array([[rng.uniform(-1.0, 1.0) for _ in range(ni)] for _ in range(nj)])
    iu, jv = np.floor(u).astype(int) - i0, np.floor(v).astype(int) - j0
    iu, jv = np.minimum(iu, ni - 2), np.minimum(jv, nj - 2)
    su, sv = _smoothstep(u - i0 - iu), _smoothstep(v - j0 - jv)
    a = lattice[jv, iu] + su * (lattice[jv, iu + 1] - lattice[jv, iu])
    b = lattice[jv + 1, iu] + su * (lattice[jv + 1, iu + 1] - lattice[jv + 1, iu])
    return a + sv * (b - a)


def _smoothstep(t):
    import numpy as np  # noqa: PLC0415

    t = np.clip(t, 0.0, 1.0)
    return t * t * (3.0 - 2.0 * t)


def image_size(path: str) -> Tuple[int, int]:
    """(width, height) of the image from its header, without decoding it; ValueError if it cannot be read.

    A PNG's are read here (its IHDR chunk: PIL refuses a PNG of more than 179 million pixels with a
    DecompressionBombError that hides the size); another format's through PIL, which reads only the
    header until the image is loaded.
    """
    from PIL import Image, UnidentifiedImageError  # noqa: PLC0415

    with open(path, "rb") as f:
        head = f.read(24)
    if head[:8] == PNG_SIGNATURE:
        if len(head) < 24 or head[12:16] != b"IHDR":
            raise ValueError("cannot read the image: a PNG file without its IHDR header")
        return int.from_bytes(head[16:20], "big"), int.from_bytes(head[20:24], "big")
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", Image.DecompressionBombWarning)
            with Image.open(path) as image:
                return image.size
    except (OSError, UnidentifiedImageError, Image.DecompressionBombError) as e:
        raise ValueError(f"cannot read the image: {e}") from None


def noise_lattice(size: float, feature_length: float) -> float:
    """Lattice points along one side of a field's noise (as :func:`_value_noise` makes them)."""
    half = size / 2 / feature_length
    return half * 2 + 3 if half >= 1e15 else float(math.floor(half) - math.floor(-half) + 2)


def check_image_budget(path: str, limits: Limits) -> None:
    """ValueError (the rule) if the image's file or its pixels (from its header) are over the limits."""
    size = os.path.getsize(path)
    if size > limits.image_bytes:
        raise ValueError(f"is a file of {size} bytes; at most {limits.image_bytes}")
    width, height = image_size(path)
    if width * height > limits.field_points:
        raise ValueError(f"makes {width} x {height} grid points (its pixels); at most {limits.field_points}")
