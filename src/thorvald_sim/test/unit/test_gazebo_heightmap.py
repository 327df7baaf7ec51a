"""Gazebo Classic's heightmap (:mod:`thorvald_sim.world.gazebo_heightmap`): each pixel checked where the
convention puts it, by arithmetic written out here: image row r (from the top) is grid row n - 1 - r
(rows from -y), column c is column c (from -x); a height is value / 255 * size z / m + pos z, m the
brightest value over 255 (a 1 counting as 1.0, 0 as a scale of 1); points size / (n - 1) apart about
the origin; ODE's triangles on the (-x, -y) to (+x, +y) diagonal."""

import math

import numpy as np
import pytest
from PIL import Image
from PIL.PngImagePlugin import PngInfo

from thorvald_sim.world.gazebo_heightmap import as_height_field, gazebo_heights, height_at
from thorvald_sim.world.kinds.height_field import HeightField
from thorvald_sim.world.terrain import PNG_SIGNATURE

REL = 1e-6  # Gazebo stores its heights as float32

# 5 x 5: one white pixel in the first row's first column, a ramp along the columns elsewhere
RAMP = [[255, 40, 80, 120, 160]] + [[0, 40, 80, 120, 160]] * 4


def save(tmp_path, rows, name="h.png", mode=None, **options):
    array = np.asarray(rows)
    image = Image.fromarray(array.astype(np.uint16 if array.max() > 255 else np.uint8))
    if mode:
        image = image.convert(mode)
    path = tmp_path / name
    image.save(path, **options)
    return str(path)


def expected_grid(rows, size_z, pos_z=0.0, white=None):
    """The convention, pixel by pixel (sampling 1): grid row j (from -y) is image row n - 1 - j."""
    n = len(rows)
    m = (white if white is not None else max(max(r) for r in rows)) / 255
    return [[rows[n - 1 - j][i] / 255 * size_z / m + pos_z for i in range(n)] for j in range(n)]


# ---------------------------------------------------------------------------------------------
# Where each pixel goes, and how high
# ---------------------------------------------------------------------------------------------
def test_each_pixel_of_an_8_bit_image_is_where_the_convention_puts_it(tmp_path):
    grid = gazebo_heights(save(tmp_path, RAMP), (8.0, 4.0, 2.0), (0.0, 0.0, 0.0), sampling=1)
    assert grid.heights.shape == (5, 5)
    assert (grid.x0, grid.y0, grid.dx, grid.dy) == (-4.0, -2.0, 2.0, 1.0)
    want = expected_grid(RAMP, 2.0)
    for j in range(5):
        for i in range(5):
            assert grid.heights[j, i] == pytest.approx(want[j][i], rel=REL, abs=1e-12), (j, i)
    # the white pixel (the image's first row and column) is the (-x, +y) corner, at size z
    assert grid.heights[4, 0] == pytest.approx(2.0, rel=REL)
    assert height_at(grid, -4.0, 2.0) == pytest.approx(2.0, rel=REL)
    assert height_at(grid, -4.0, -2.0) == 0.0  # the last row's first pixel is black
    assert height_at(grid, 4.0, 0.0) == pytest.approx(160 / 255 * 2.0, rel=REL)  # the ramp's end, at +x
    assert not grid.heights.flags.writeable


def test_the_brightest_pixel_is_at_size_z_and_black_at_0_whatever_the_images_range(tmp_path):
    rows = [[10, 20, 30], [40, 128, 60], [70, 80, 90]]
    grid = gazebo_heights(save(tmp_path, rows), (2.0, 2.0, 3.0), sampling=1)
    want = expected_grid(rows, 3.0)  # scale 3 / (128 / 255): the minimum (10) is not subtracted
    assert grid.heights[1, 1] == pytest.approx(3.0, rel=REL)
    assert grid.heights[2, 0] == pytest.approx(10 / 128 * 3.0, rel=REL)
    assert grid.heights == pytest.approx(np.array(want), rel=REL)


def test_a_level_of_1_counts_as_white_in_gazebos_scale(tmp_path):
    # ign-math's Color::Clamp divides only values over 1 by 255: a 1 is taken as 1.0, the image's "max"
    rows = [[0, 1, 0], [0, 100, 0], [0, 0, 0]]
    grid = gazebo_heights(save(tmp_path, rows), (2.0, 2.0, 5.0), sampling=1)
    assert grid.heights[1, 1] == pytest.approx(100 / 255 * 5.0, rel=REL)  # not 5 m
    assert grid.heights[2, 1] == pytest.approx(1 / 255 * 5.0, rel=REL)


def test_a_black_image_is_flat_at_pos_z(tmp_path):
    grid = gazebo_heights(save(tmp_path, [[0] * 3] * 3), (2.0, 2.0, 5.0), (0.0, 0.0, -1.5), sampling=1)
    assert grid.heights.tolist() == [[-1.5] * 3] * 3


def test_sampling_puts_bilinear_points_between_the_pixels(tmp_path):
    rows = [[0, 40, 80], [120, 160, 200], [240, 30, 60]]
    grid = gazebo_heights(save(tmp_path, rows), (4.0, 4.0, 1.0), sampling=2)
    assert grid.heights.shape == (5, 5) and (grid.dx, grid.dy) == (1.0, 1.0)

    def h(level):
        return level / 240  # the brightest level (240) at size z = 1

    top = 4  # the grid's row of the image's first row
    # image point (r, c) at r / 2, c / 2 from the top left: the pixels at even points
    assert grid.heights[top, 0] == pytest.approx(h(0), abs=1e-7)
    assert grid.heights[top - 2, 2] == pytest.approx(h(160), rel=REL)
    assert grid.heights[0, 4] == pytest.approx(h(60), rel=REL)  # the last row's last pixel: (+x, -y)
    # between two pixels of a row, of a column, and amid four
    assert grid.heights[top, 1] == pytest.approx(h((0 + 40) / 2), rel=REL)
    assert grid.heights[top - 1, 0] == pytest.approx(h((0 + 120) / 2), rel=REL)
    assert grid.heights[top - 1, 3] == pytest.approx(h((40 + 80 + 160 + 200) / 4), rel=REL)
    assert grid.heights[top - 3, 1] == pytest.approx(h((120 + 160 + 240 + 30) / 4), rel=REL)


@pytest.mark.parametrize(("sampling", "points"), [(1, 5), (2, 9), (4, 17), (3, 9), (0, 9)])
def test_a_sampling_of_a_power_of_two_makes_that_many_cells_a_pixel_else_2(tmp_path, sampling, points):
    grid = gazebo_heights(save(tmp_path, RAMP), (8.0, 8.0, 1.0), sampling=sampling)
    assert grid.heights.shape == (points, points)
    assert grid.dx == grid.dy == 8.0 / (points - 1)
    step = (points - 1) // 4
    # every step-th point is a pixel, at the pixel's height
    assert grid.heights[::step, ::step] == pytest.approx(np.array(expected_grid(RAMP, 1.0)), rel=REL, abs=1e-12)


def test_size_scales_the_grid_and_the_heights(tmp_path):
    path = save(tmp_path, RAMP)
    small = gazebo_heights(path, (1.0, 1.0, 1.0), sampling=1)
    big = gazebo_heights(path, (10.0, 6.0, 4.0), sampling=1)
    assert (big.x0, big.y0, big.dx, big.dy) == (-5.0, -3.0, 2.5, 1.5)
    assert big.heights == pytest.approx(4.0 * small.heights, rel=REL)
    assert height_at(big, -5.0, 3.0) == pytest.approx(4.0, rel=REL)


def test_pos_raises_the_field_and_its_x_and_y_move_only_the_visual(tmp_path):
    path = save(tmp_path, RAMP)
    at_origin = gazebo_heights(path, (8.0, 4.0, 2.0), sampling=1)
    moved = gazebo_heights(path, (8.0, 4.0, 2.0), (3.0, -1.0, 0.5), sampling=1)
    assert moved.heights == pytest.approx(at_origin.heights + 0.5, rel=REL)
    assert (moved.x0, moved.y0) == (-4.0, -2.0), "ODE ignores pos x and y"
    shifted = gazebo_heights(path, (8.0, 4.0, 2.0), (3.0, -1.0, 0.5), sampling=1, shift_xy=True)
    assert (shifted.x0, shifted.y0) == (-1.0, -3.0)
    assert height_at(shifted, -1.0, 1.0) == pytest.approx(2.5, rel=REL)


def test_16_bits_gazebo_classic_reads_each_pixels_low_byte_at_a_scale_of_1(tmp_path):
    rows = [[0x0000, 0x0102, 0xFFFF], [0x8000, 0x80FF, 0x0010], [0x1234, 0x0001, 0x0300]]
    grid = gazebo_heights(save(tmp_path, rows), (2.0, 2.0, 7.0), (0.0, 0.0, 1.0), sampling=1)
    for r in range(3):
        for c in range(3):
            want = (rows[r][c] % 256) / 255 * 1.0 + 1.0  # size z does not count
            assert grid.heights[2 - r, c] == pytest.approx(want, rel=REL), (r, c)


def test_16_bits_in_full_reads_all_of_them_the_brightest_at_size_z(tmp_path):
    rows = [[0, 1000, 30000], [65535, 2, 40000], [12345, 0, 50000]]
    grid = gazebo_heights(save(tmp_path, rows), (2.0, 2.0, 7.0), sampling=1, sixteen_bit="full")
    for r in range(3):
        for c in range(3):
            assert grid.heights[2 - r, c] == pytest.approx(rows[r][c] / 65535 * 7.0, rel=REL, abs=1e-12), (r, c)


def test_a_colour_image_is_read_by_its_blue_and_a_palette_image_by_its_indices(tmp_path):
    rgb = np.zeros((3, 3, 3), dtype=np.uint8)
    rgb[0, 0] = (255, 255, 255)  # white: the brightest, so the scale is size z
    rgb[0, 1] = (255, 0, 0)  # red: no blue
    rgb[2, 2] = (0, 0, 51)  # dark blue
    path = tmp_path / "c.png"
    Image.fromarray(rgb).save(path)
    grid = gazebo_heights(str(path), (2.0, 2.0, 3.0), sampling=1)
    assert grid.heights[2, 0] == pytest.approx(3.0, rel=REL)
    assert grid.heights[2, 1] == 0.0
    assert grid.heights[0, 2] == pytest.approx(51 / 255 * 3.0, rel=REL)

    palette = Image.new("P", (3, 3))
    palette.putpalette([255, 0, 0] * 2 + [0, 0, 255] * 254)  # colours unrelated to the indices
    palette.putdata([0, 1, 2, 3, 4, 5, 6, 7, 200])
    palette.save(tmp_path / "p.png")
    grid = gazebo_heights(str(tmp_path / "p.png"), (2.0, 2.0, 2.0), sampling=1)
    assert grid.heights[2, 1] == pytest.approx(1 / 255 * 2.0, rel=REL)  # index 1: taken as white by the scale
    assert grid.heights[0, 2] == pytest.approx(200 / 255 * 2.0, rel=REL)


def test_between_the_points_gazebos_triangles_are_on_the_other_diagonal_than_bullets(tmp_path):
    rows = [[100, 200], [0, 50]]  # image top row at +y: h01 = 100, h11 = 200, h00 = 0, h10 = 50
    grid = gazebo_heights(save(tmp_path, rows), (2.0, 2.0, 1.0), sampling=1)
    h00, h10, h01, h11 = 0.0, 50 / 200, 100 / 200, 1.0
    # ODE: the diagonal from (-x, -y) to (+x, +y)
    assert height_at(grid, 0.0, 0.0) == pytest.approx((h00 + h11) / 2, rel=REL)
    assert height_at(grid, 0.5, -0.5) == pytest.approx(h00 + 0.75 * (h10 - h00) + 0.25 * (h11 - h10), rel=REL)
    assert height_at(grid, -0.5, 0.5) == pytest.approx(h00 + 0.75 * (h01 - h00) + 0.25 * (h11 - h01), rel=REL)
    # pybullet's: from (+x, -y) to (-x, +y)
    assert height_at(grid, 0.0, 0.0, triangles="bullet") == pytest.approx((h10 + h01) / 2, rel=REL)
    assert height_at(grid, 1.0, 1.0) == pytest.approx(h11, rel=REL)
    assert height_at(grid, 1.01, 0.0) is None and height_at(grid, 0.0, -1.01) is None
    with pytest.raises(ValueError, match="triangles"):
        height_at(grid, 0.0, 0.0, triangles="diamond")


# ---------------------------------------------------------------------------------------------
# Our height field
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("bits", [8, 16])
def test_our_height_field_has_gazebos_points_for_a_grey_image_without_sampling(tmp_path, bits):
    rows = RAMP if bits == 8 else [[v * 257 for v in row] for row in RAMP]
    path = save(tmp_path, rows)
    args = (path, (8.0, 4.0, 2.0), (5.0, 6.0, -0.5), 1)
    keys = as_height_field(*args, sixteen_bit="full")
    assert keys.differences == ()
    assert keys.keywords["min_height"] == -0.5 and keys.keywords["max_height"] == pytest.approx(1.5)
    assert (keys.keywords["x"], keys.keywords["y"], keys.keywords["flat_radius"]) == (0.0, 0.0, 0.0)
    field = HeightField(**keys.keywords)
    grid = gazebo_heights(*args, sixteen_bit="full")
    assert field.heights() == pytest.approx(grid.heights, rel=REL)
    assert field.grid_step() == (grid.dx, grid.dy)
    assert as_height_field(*args, shift_xy=True).keywords["x"] == 5.0


def test_what_our_height_field_cannot_make_is_said(tmp_path):
    grey = save(tmp_path, RAMP)
    (sampled,) = as_height_field(grey, (8.0, 8.0, 1.0)).differences
    assert "sampling 2" in sampled and "9 x 9" in sampled
    wide = save(tmp_path, [[v * 257 for v in row] for row in RAMP], name="w.png")
    (low_bytes,) = as_height_field(wide, (8.0, 8.0, 1.0), sampling=1).differences
    assert "low byte" in low_bytes
    colour = np.zeros((3, 3, 3), dtype=np.uint8)
    colour[1, 1] = (0, 200, 10)
    Image.fromarray(colour).save(tmp_path / "c.png")
    (blue,) = as_height_field(str(tmp_path / "c.png"), (2.0, 2.0, 1.0), sampling=1).differences
    assert "blue" in blue
    grey_rgb = save(tmp_path, RAMP, name="g.png", mode="RGB")
    assert as_height_field(grey_rgb, (8.0, 8.0, 1.0), sampling=1).differences == ()
    (flat,) = as_height_field(grey, (8.0, 8.0, 0.0), sampling=1).differences
    assert "size z is 0" in flat


# ---------------------------------------------------------------------------------------------
# Refusals
# ---------------------------------------------------------------------------------------------
def test_sizes_and_positions_must_be_three_finite_numbers(tmp_path):
    path = save(tmp_path, RAMP)
    for size, rule in [
        ((math.inf, 1.0, 1.0), "finite"),
        ((1.0, math.nan, 1.0), "finite"),
        ((-1.0, 1.0, 1.0), "> 0"),
        ((1.0, 0.0, 1.0), "> 0"),
        ((1.0, 1.0, -1.0), "negative z"),
        ((1.0, 1.0), "three numbers"),
        ((1.0, True, 1.0), "three numbers"),
        (("a", 1.0, 1.0), "three numbers"),
    ]:
        with pytest.raises(ValueError, match=rule):
            gazebo_heights(path, size)
    with pytest.raises(ValueError, match="pos must be finite"):
        gazebo_heights(path, (1.0, 1.0, 1.0), (0.0, 0.0, math.inf))
    for sampling in (-1, 1.5, True):
        with pytest.raises(ValueError, match="sampling"):
            gazebo_heights(path, (1.0, 1.0, 1.0), sampling=sampling)
    with pytest.raises(ValueError, match="sixteen_bit"):
        gazebo_heights(path, (1.0, 1.0, 1.0), sixteen_bit="low")


def test_unreadable_files_and_images_gazebo_does_not_take_are_refused(tmp_path):
    (tmp_path / "junk.png").write_bytes(b"not an image at all, not even a header")
    jpeg_named_png = tmp_path / "j.png"
    Image.fromarray(np.zeros((5, 5), dtype=np.uint8)).save(jpeg_named_png, format="JPEG")
    Image.new("CMYK", (5, 5)).save(tmp_path / "k.jpg")
    Image.new("1", (5, 5)).save(tmp_path / "b.png")
    Image.fromarray(np.zeros((5, 5), dtype=np.uint8)).save(tmp_path / "g.gif")
    linear = PngInfo()
    linear.add(b"gAMA", (100000).to_bytes(4, "big"))  # a gamma of 1: FreeImage would brighten it
    cases = [
        (str(tmp_path / "missing.png"), "cannot read"),
        (str(tmp_path / "junk.png"), "cannot read"),
        (save(tmp_path, [[0] * 5] * 3, name="r.png"), "5 x 3 pixels"),
        (save(tmp_path, [[0] * 4] * 4, name="f.png"), "2\\^k \\+ 1"),
        (save(tmp_path, [[0] * 6] * 6, name="s.png"), "2\\^k \\+ 1"),
        (str(jpeg_named_png), "picks its decoder by"),
        (str(tmp_path / "k.jpg"), "CMYK"),
        (str(tmp_path / "b.png"), "1-bit grey PNG"),
        (str(tmp_path / "g.gif"), "GIF"),
        (save(tmp_path, RAMP, name="l.png", pnginfo=linear), "gamma"),
    ]
    for path, rule in cases:
        with pytest.raises(ValueError, match=rule):
            gazebo_heights(path, (1.0, 1.0, 1.0))
    usual = PngInfo()
    usual.add(b"gAMA", (45455).to_bytes(4, "big"))  # 1/2.2: libpng leaves it
    assert gazebo_heights(save(tmp_path, RAMP, name="u.png", pnginfo=usual), (1.0, 1.0, 1.0)).heights.shape == (9, 9)


def test_the_grids_points_are_counted_from_the_header_before_a_pixel_is_decoded(tmp_path):
    # a PNG header of 4097 x 4097 pixels and no pixels: the budget refuses it, decoding could not
    ihdr = (4097).to_bytes(4, "big") * 2 + bytes([8, 0, 0, 0, 0])
    (tmp_path / "huge.png").write_bytes(PNG_SIGNATURE + (13).to_bytes(4, "big") + b"IHDR" + ihdr + b"\0" * 4)
    with pytest.raises(ValueError, match=r"8193 x 8193 points .* at most 1000000"):
        gazebo_heights(str(tmp_path / "huge.png"), (1.0, 1.0, 1.0))
    path = save(tmp_path, RAMP)
    with pytest.raises(ValueError, match="9 x 9 points"):
        gazebo_heights(path, (1.0, 1.0, 1.0), max_points=80)
    assert gazebo_heights(path, (1.0, 1.0, 1.0), max_points=81).heights.shape == (9, 9)
