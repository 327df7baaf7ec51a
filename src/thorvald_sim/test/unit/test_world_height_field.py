"""Height fields: keys and rules, the heights an image or a seed gives (pure), and the ground pybullet
builds at exactly those heights."""

import math
import random

import numpy as np
import pybullet as p
import pytest
import sim_test_helpers
from PIL import Image

from thorvald_sim.physics.scene import build_scene
from thorvald_sim.world import load_world, parse_world, resolve_world
from thorvald_sim.world.kinds.height_field import HeightField
from thorvald_sim.world.kinds.rows import plant_positions

FIELD = {"size_x": 10.0, "size_y": 6.0}


def field_of(**keys):
    return parse_world({"height_field": {**FIELD, **keys}}).height_field


def problems_of(data, base_dir=None):
    return sim_test_helpers.world_problems(data, base_dir=base_dir)


def write_png(path, levels, mode):
    """A grey image of levels in [0, 1] (rows from the top: the +y edge), 8 or 16 bits."""
    levels = np.asarray(levels, dtype=float)
    if mode == "I;16":
        Image.fromarray(np.round(levels * 65535).astype(np.uint16)).save(path)
    else:
        Image.fromarray(np.round(levels * 255).astype(np.uint8)).convert(mode).save(path)
    return str(path)


def ray_down(client, x, y, top=10.0):
    return sim_test_helpers.ray_down(client, x, y, top=top, bottom=-10.0)


# ---------------------------------------------------------------------------------------------
# Keys
# ---------------------------------------------------------------------------------------------
def test_defaults():
    hf = field_of()
    assert hf == HeightField(0.0, 0.0, 10.0, 6.0, 0.2, "", 0.0, 1.0, 0.0, 1.0, 0, 0.0, 0.3, 1.5, 2.0)
    assert hf.grid_shape() == (51, 31) and hf.grid_step() == pytest.approx((0.2, 0.2))
    # without bumps, ruts or an image: flat at 0
    assert not hf.heights().any()


def test_the_resolution_is_shrunk_to_fit_the_size():
    hf = field_of(resolution=0.3)  # 10 / 0.3 = 33.3 cells: 33 of 0.303 m; 6 / 0.3 = 20 cells
    assert hf.grid_shape() == (34, 21) and hf.grid_step() == pytest.approx((10 / 33, 0.3))


def test_each_rule():
    found = problems_of(
        {
            "height_field": {
                **FIELD,
                "min_height": 1,
                "amplitude": -0.1,
                "rut_width": 2,
                "rut_spacing": 1.5,
                "flat_radius": -1,
                "seed": 0.5,
            }
        }
    )
    assert {k: pr.rule for k, pr in found.items()} == {
        "height_field.amplitude": "must be in [0, 10000] [m]",
        "height_field.flat_radius": "must be in [0, 10000] [m]",
        "height_field.seed": "must be an integer",
        "height_field.min_height": "is used with an image only",
        "height_field.max_height": "must be > min_height (1.0 m)",
        "height_field.rut_width": "must be <= rut_spacing (1.5 m)",
    }
    found = problems_of({"height_field": {"size_x": -1, "size_y": 6}})
    assert {k: pr.rule for k, pr in found.items()} == {"height_field.size_x": "must be in (0, 10000] [m]"}
    found = problems_of({"height_field": {"size_x": 1000, "size_y": 1000, "resolution": 0.5}})
    assert found["height_field.resolution"].rule == "makes 2001 x 2001 grid points; at most 1000000"
    found = problems_of({"height_field": {"size_x": 10}, "heightfield": {}})
    assert found["heightfield"].rule == "unknown key (did you mean 'height_field'?)"
    assert found["height_field.size_y"].rule == "is required"


def test_image_rules(tmp_path):
    (tmp_path / "text.png").write_text("not an image")
    write_png(tmp_path / "line.png", [[0.0, 0.5, 1.0]], "L")
    write_png(tmp_path / "ok.png", [[0.0, 1.0], [1.0, 0.0]], "L")
    cases = {
        "missing.png": f"no such file: {tmp_path / 'missing.png'} (a relative path is from the world file's folder)",
        "text.png": "cannot read the image: ",
        "line.png": "must be an image of at least 2 x 2 pixels, not (3, 1)",
    }
    for image, rule in cases.items():
        found = problems_of({"height_field": {**FIELD, "image": image}}, str(tmp_path))
        assert list(found) == ["height_field.image"], image
        assert found["height_field.image"].rule.startswith(rule), image
        assert found["height_field.image"].value == image
    found = problems_of({"height_field": {**FIELD, "image": "ok.png", "resolution": 0.1}}, str(tmp_path))
    assert found["height_field.resolution"].rule == "must not be given with an image: its pixels are the grid"


# ---------------------------------------------------------------------------------------------
# Heights (pure)
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("mode", ["L", "I;16", "RGB"])
def test_an_image_gives_black_at_min_height_and_white_at_max_with_its_first_row_at_plus_y(tmp_path, mode):
    levels = [[1.0, 0.0, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.2]]  # white top left, dark grey bottom right
    image = write_png(tmp_path / "f.png", levels, mode)
    hf = parse_world(
        {"height_field": {**FIELD, "image": "f.png", "min_height": -0.5, "max_height": 1.5, "flat_radius": 0}},
        base_dir=str(tmp_path),
    ).height_field
    assert hf.image == image and hf.grid_shape() == (3, 3) and hf.grid_step() == (5.0, 3.0)
    # top left of the image: the -x, +y corner of the field
    assert hf.height_at(-5.0, 3.0) == pytest.approx(1.5)
    assert hf.height_at(5.0, -3.0) == pytest.approx(-0.5 + 2.0 * 0.2, abs=2.0 / 255)
    assert hf.height_at(0.0, 0.0) == pytest.approx(-0.5)
    assert hf.height_at(5.1, 0.0) is None and hf.height_at(0.0, -3.1) is None


def test_random_bumps_stay_within_their_amplitude_and_a_seed_gives_the_same_field():
    keys = dict(size_x=30.0, size_y=20.0, amplitude=0.05, feature_length=1.5, flat_radius=0.0)
    h = field_of(seed=4, **keys).heights()
    assert np.abs(h).max() <= 0.05
    assert h.max() > 0.03 and h.min() < -0.03, "the bumps use their range"
    assert np.array_equal(field_of(seed=4, **keys).heights(), h)
    assert not np.array_equal(field_of(seed=5, **keys).heights(), h)
    # smooth: between neighbouring points 0.2 m apart it changes by far less than the amplitude
    # (value noise's steepest slope is 1.5 * 2 * amplitude / feature_length = 0.1 [m/m])
    assert np.abs(np.diff(h, axis=1)).max() <= 0.1 * 0.2 + 1e-9


def test_ruts_run_along_x_half_way_from_the_centre_line():
    hf = field_of(
        size_x=4.0, size_y=6.0, resolution=0.05, rut_depth=0.08, rut_width=0.4, rut_spacing=1.5, flat_radius=0
    )
    # ruts at y = +-0.75, +-2.25; their centre lines 8 cm deep, their edges 0.2 m out at 0
    for y, depth in ((0.75, -0.08), (-0.75, -0.08), (2.25, -0.08), (0.0, 0.0), (0.75 + 0.2, 0.0), (1.5, 0.0)):
        for x in (-1.0, 0.0, 1.95):
            assert hf.height_at(x, y) == pytest.approx(depth, abs=1e-9), (x, y)
    # half-way down the rut's side (0.1 m from its centre line): half its depth
    assert hf.height_at(0.5, 0.75 + 0.1) == pytest.approx(-0.04, abs=1e-9)


def test_the_field_is_flat_around_the_origin_where_robots_spawn():
    hf = field_of(x=2.0, size_x=20.0, size_y=20.0, amplitude=0.2, flat_radius=2.5, seed=1)
    # a 0.1 m grid over the disc of 2.5 m about the world's origin (not the field's centre)
    for i in range(-25, 26):
        for j in range(-25, 26):
            if math.hypot(i / 10, j / 10) <= 2.5:
                assert hf.height_at(i / 10, j / 10) == 0.0
    # beyond 2.5 + 1 m, the bumps at full height
    unflat = field_of(x=2.0, size_x=20.0, size_y=20.0, amplitude=0.2, flat_radius=0.0, seed=1)
    assert hf.height_at(6.0, 5.0) == unflat.height_at(6.0, 5.0) != 0.0


def test_between_grid_points_the_surface_is_bullets_two_triangles():
    hf = field_of(size_x=2.0, size_y=2.0, resolution=2.0, amplitude=1.0, flat_radius=0.0)
    (h00, h10), (h01, h11) = hf.heights()  # rows from -y
    # the cell's diagonal runs from its (+x, -y) corner to its (-x, +y) corner
    assert hf.height_at(0.0, 0.0) == pytest.approx((h10 + h01) / 2)
    assert hf.height_at(-0.5, -0.5) == pytest.approx(h00 + 0.25 * (h10 - h00) + 0.25 * (h01 - h00))
    assert hf.height_at(0.5, 0.5) == pytest.approx(h11 + 0.25 * (h01 - h11) + 0.25 * (h10 - h11))


def test_ground_height_is_the_field_the_hills_and_the_patches_whichever_is_highest():
    world = parse_world(
        {
            "height_field": {"size_x": 10.0, "size_y": 10.0, "amplitude": 0.05, "flat_radius": 0.0},
            "slopes": {"slope0": {"x": 3, "y": 3, "width": 2, "angle": 0.5, "height": 0.4, "top_length": 1}},
            "patches": {"patch0": {"x": -3, "y": -3, "size_x": 1, "size_y": 1, "lateral_friction": 0.5}},
        }
    )
    hf = world.height_field
    assert world.ground_height(3.0, 3.0) == pytest.approx(0.4)
    assert world.ground_height(0.0, 1.0) == hf.height_at(0.0, 1.0)
    assert world.ground_height(-3.0, -3.0) == max(0.001, hf.height_at(-3.0, -3.0))
    assert world.ground_height(20.0, 0.0) == 0.0, "beyond the field: 0"


# ---------------------------------------------------------------------------------------------
# In pybullet
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("kind", ["bumps and ruts", "image"])
def test_a_ray_down_hits_the_field_where_height_at_says(client, tmp_path, kind):
    if kind == "image":
        rng = np.random.RandomState(0)
        write_png(tmp_path / "f.png", rng.uniform(0, 1, (9, 13)), "I;16")
        keys = {"image": "f.png", "min_height": 0.2, "max_height": 1.0}
    else:
        keys = {"resolution": 0.25, "amplitude": 0.3, "feature_length": 1.0, "rut_depth": 0.1, "seed": 2}
    world = parse_world(
        {"height_field": {"x": 1.0, "y": -2.0, "size_x": 12.0, "size_y": 8.0, **keys}}, base_dir=str(tmp_path)
    )
    hf = world.height_field
    scene = build_scene(client, world)
    assert list(scene.bodies) == ["ground"]
    rng = random.Random(1)
    for _ in range(300):
        x, y = rng.uniform(-4.95, 6.95), rng.uniform(-5.95, 1.95)
        # bullet holds heights as 32-bit floats
        assert ray_down(client, x, y) == (scene.bodies["ground"], pytest.approx(hf.height_at(x, y), abs=2e-5))
    # the grid points inside the edges
    nx, ny = hf.grid_shape()
    dx, dy = hf.grid_step()
    h = hf.heights()
    for j in range(1, ny - 1, 2):  # the edges: a ray along them may slip by
        for i in range(1, nx - 1, 2):
            x, y = -5.0 + i * dx, -6.0 + j * dy
            assert ray_down(client, x, y)[1] == pytest.approx(h[j, i], abs=2e-5)
    # the plane is gone: beyond the field, nothing
    assert ray_down(client, 10.0, 0.0)[0] == -1


def test_the_field_has_the_grounds_friction_and_things_stand_on_it(client):
    world = parse_world(
        {
            "ground": {"lateral_friction": 0.6, "rolling_friction": 0.01},
            "height_field": {"size_x": 20.0, "size_y": 20.0, "amplitude": 0.3, "feature_length": 2.0},
            "rows": {"row0": {"x": 3, "y": -5, "yaw": 1.5708, "length": 10, "plant_spacing": 0.5, "plant_height": 0.4}},
            "walls": {"wall0": {"x": -6, "y": 0, "yaw": 1.5708, "length": 8, "height": 1.0}},
            "objects": {"object0": {"shape": "box", "x": -3, "y": 4, "size_x": 0.5, "size_y": 0.5, "size_z": 0.5}},
        }
    )
    scene = build_scene(client, world)
    info = p.getDynamicsInfo(scene.bodies["ground"], -1, physicsClientId=client)
    assert (info[1], info[6]) == pytest.approx((0.6, 0.01))
    for x, y in plant_positions(world.rows[0])[0]:
        assert ray_down(client, x, y) == (
            scene.bodies["rows.row0.0"],
            pytest.approx(world.ground_height(x, y) + 0.4, abs=1e-4),
        )
    wall = world.walls[0]
    # the lowest of the ground every 0.5 m along it (yaw 1.5708 is 3.7e-6 off 90 degrees)
    assert wall.z == pytest.approx(min(world.ground_height(-6, -4 + 0.5 * k) for k in range(17)), abs=1e-5)
    assert ray_down(client, -6.0, 0.0)[1] == pytest.approx(wall.z + 1.0, abs=1e-4)
    box = world.objects[0]
    assert box.z == pytest.approx(world.ground_height(-3, 4) + 0.25)


def test_the_shipped_vineyard_is_flat_at_the_origin_and_climbs_along_x(client):
    world = load_world(resolve_world("vineyard"))
    hf = world.height_field
    assert hf.image.endswith("vineyard_hill.png") and hf.grid_shape() == (71, 37)
    # flat at 0 over the headland, where the robot spawns (1.5 x 1.4 m and more)
    for x in np.arange(-3.0, 4.01, 0.25):
        for y in np.arange(-3.0, 3.01, 0.25):
            assert world.ground_height(x, y) == 0.0
    # 3.5 m up at the plateau (x 48 on), give or take the swell's 0.15 m
    assert world.ground_height(50.0, 0.0) == pytest.approx(3.5, abs=1e-3)
    assert 1.4 < world.ground_height(26.0, 0.0) < 2.1
    scene = build_scene(client, world)
    assert ray_down(client, 50.0, 0.0) == (scene.bodies["ground"], pytest.approx(3.5, abs=1e-3))
    # every post's top 2 m above the ground under it; every vine's 1.8 m (but where a post stands in it)
    posts, vines = world.rows
    for k, line in enumerate(plant_positions(posts)):
        for x, y in line:
            expected = (scene.bodies[f"rows.row0.{k}"], pytest.approx(world.ground_height(x, y) + 2.0, abs=1e-4))
            assert ray_down(client, x, y) == expected
    for k, line in enumerate(plant_positions(vines)):
        for x, y in line:
            if min(abs(x - (6.0 + 5.0 * i)) for i in range(9)) > 0.1:
                expected = (scene.bodies[f"rows.row1.{k}"], pytest.approx(world.ground_height(x, y) + 1.8, abs=1e-4))
                assert ray_down(client, x, y) == expected
    # the aisle the robot drives up from the origin: free 0.75 m either side of y = 0, 2 m high
    for x in np.arange(0.0, 47.0, 0.2):
        for y in (-0.75, 0.0, 0.75):
            z = world.ground_height(x, y)
            assert ray_down(client, x, y, top=z + 2.0) == (scene.bodies["ground"], pytest.approx(z, abs=1e-4))
