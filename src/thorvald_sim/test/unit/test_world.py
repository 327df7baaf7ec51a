"""The world files: schema, defaults, error reports, the shipped worlds and how a world is named."""

import math
import os

import pytest
import yaml

import thorvald_sim.world as world_module
from thorvald_sim.world import ConfigError, load_world, parse_world, resolve_world, shipped_worlds, worlds_dir
from thorvald_sim.world.kinds.patches import Patch
from thorvald_sim.world.kinds.rows import plant_positions
from thorvald_sim.world.surfaces import Surface

SHIPPED = ["crop_rows", "farm_track", "flat", "greenhouse", "polytunnel", "slope", "tarmac_gravel", "vineyard"]


def write(tmp_path, data, name="world.yaml"):
    path = tmp_path / name
    path.write_text(data if isinstance(data, str) else yaml.safe_dump(data))
    return str(path)


def problems_of(data):
    with pytest.raises(ConfigError) as e:
        parse_world(data, "test-world")
    return {p.path: p for p in e.value.problems}, str(e.value)


def shipped(name):
    return load_world(resolve_world(name))


# ---------------------------------------------------------------------------------------------
# The shipped worlds
# ---------------------------------------------------------------------------------------------
def test_the_shipped_worlds_are_listed():
    assert shipped_worlds() == SHIPPED


@pytest.mark.parametrize("name", SHIPPED)
def test_every_shipped_world_loads_and_says_what_it_is(name):
    path = resolve_world(name)
    assert path == os.path.join(worlds_dir(), name + ".yaml")
    world = load_world(path)
    assert world.source == path
    assert world.description
    with open(path) as f:
        assert f.readline().startswith(f"# {name}: "), "a comment header naming the world"


def test_flat_is_ground_only():
    world = shipped("flat")
    assert world.ground == Surface(0.9, 0.0, 0.0, 0.0)
    assert (world.patches, world.slopes, world.rails) == ((), (), ())
    assert (world.objects, world.rows, world.polytunnels, world.walls, world.height_field) == ((), (), (), (), None)
    assert world.gravity == 9.81
    assert world.ground_rgba == (0.35, 0.35, 0.37, 1.0)


def test_tarmac_gravel_has_the_slip_tests_ice_patch():
    world = shipped("tarmac_gravel")
    ice = [pa for pa in world.patches if pa.surface.lateral_friction < 0.3]
    assert len(ice) == 1
    # x from 4 to 8 m, y from -16 to -12 m: off the manoeuvre's 20 x 20 m area
    assert (ice[0].x - ice[0].size_x / 2, ice[0].x + ice[0].size_x / 2) == (4.0, 8.0)
    assert (ice[0].y - ice[0].size_y / 2, ice[0].y + ice[0].size_y / 2) == (-16.0, -12.0)
    assert ice[0].yaw == 0.0
    assert ice[0].surface.lateral_friction == 0.1


def test_tarmac_gravel_has_gravel_on_tarmac_around_the_origin_but_not_at_it():
    world = shipped("tarmac_gravel")
    assert world.ground.lateral_friction == 0.9
    gravel = [pa for pa in world.patches if pa.surface.lateral_friction >= 0.3]
    assert len(gravel) >= 4
    for pa in (pa for pa in gravel if pa.surface.kind == "gravel"):
        assert 0.55 <= pa.surface.lateral_friction <= 0.6, pa.name
        assert 0.01 <= pa.surface.rolling_friction <= 0.02, pa.name
    for pa in gravel:
        # every corner inside the 20 x 20 m area around the origin
        c, s = math.cos(pa.yaw), math.sin(pa.yaw)
        for u in (-pa.size_x / 2, pa.size_x / 2):
            for v in (-pa.size_y / 2, pa.size_y / 2):
                assert abs(pa.x + c * u - s * v) <= 10.0 + 1e-9, pa.name
                assert abs(pa.y + s * u + c * v) <= 10.0 + 1e-9, pa.name
    # robots spawn at the origin: nothing within 2 m of it (a grid of 0.05 m over the disc)
    for i in range(-40, 41):
        for j in range(-40, 41):
            x, y = i * 0.05, j * 0.05
            if math.hypot(x, y) <= 2.0:
                assert not any(pa.contains(x, y) for pa in world.patches), (x, y)


@pytest.mark.slow  # pybullet: a simulation, or worlds and robots built in it
def test_tarmac_gravel_patches_do_not_overlap():
    world = shipped("tarmac_gravel")
    for i in range(-220, 221):
        for j in range(-220, 221):
            x, y = i * 0.05, j * 0.05
            on = [pa.name for pa in world.patches if pa.contains(x, y)]
            assert len(on) <= 1, (x, y, on)


def test_tarmac_gravel_verification_drive_is_mostly_tarmac_with_some_gravel():
    # The omnidirectional plan of thorvald_base.verification: a 10 m square from the origin, a 20 m
    # circle left (centre (0, 20 / 2pi)) and a 20 m sideways circle (centre (20 / 2pi, 0)); 1 cm steps.
    r = 20.0 / (2 * math.pi)
    points = []
    for k in range(1000):
        d = k / 100.0
        points += [(d, 0.0), (10.0, d), (10.0 - d, 10.0), (0.0, 10.0 - d)]
    for k in range(2000):
        a = 2 * math.pi * k / 2000
        points += [(r * math.sin(a), r - r * math.cos(a)), (r - r * math.cos(a), -r * math.sin(a))]
    world = shipped("tarmac_gravel")
    gravel = [pa for pa in world.patches if pa.surface.lateral_friction >= 0.3]
    on_gravel = sum(any(pa.contains(x, y) for pa in gravel) for x, y in points) / len(points)
    assert 0.03 < on_gravel < 0.3, on_gravel


def test_slope_is_a_10_degree_hill_starting_3_m_ahead():
    world = shipped("slope")
    assert len(world.slopes) == 1
    s = world.slopes[0]
    assert s.angle == pytest.approx(math.radians(10), abs=1e-4)
    assert (s.height, s.top_length, s.yaw, s.y) == (0.4, 2.0, 0.0, 0.0)
    # footprint: 2 m of top and two ramps of 0.4 / tan(10 deg) = 2.269 m each
    assert s.footprint_length == pytest.approx(2.0 + 2 * 0.4 / math.tan(0.1745))
    assert s.x - s.footprint_length / 2 == pytest.approx(3.0, abs=1e-3)
    assert s.width >= 3.0, "wider than every example robot"
    assert world.ground.lateral_friction == 0.9


def test_greenhouse_has_three_rail_pairs_side_by_side_starting_2_m_ahead():
    world = shipped("greenhouse")
    assert world.ground.lateral_friction == 0.8
    assert [r.y for r in world.rails] == [0.0, 1.6, 3.2]
    for r in world.rails:
        assert (r.gauge, r.height, r.radius, r.length, r.yaw) == (0.55, 0.1, 0.0255, 20.0, 0.0)
        assert r.x - r.length / 2 == 2.0
        assert r.x == 12.0 and r.surface == Surface(0.8, 0.0, 0.0)


def test_greenhouse_plant_rows_lie_beside_the_pipes_and_walls_around_it_all():
    world = shipped("greenhouse")
    (rows,) = world.rows
    # a row half-way between neighbouring pairs and one beside each outer pair, 1.6 m apart
    assert [rows.row_start(k)[1] for k in range(rows.count)] == pytest.approx([-0.8, 0.8, 2.4, 4.0])
    pipes = [y + side * r.gauge / 2 for r in world.rails for y in [r.y] for side in (-1, 1)]
    for line in plant_positions(rows):
        for x, y in line:
            assert 2.0 - rows.jitter <= x <= 22.0 + rows.jitter
            # every plant (moved by up to 2 cm) clear of every pipe by 0.8 - 0.02 - 0.275 - 0.0255 - 0.15 m
            assert min(abs(y - pipe) for pipe in pipes) - 0.0255 - rows.plant_radius >= 0.3295 - 1e-9
    # the walls enclose the rows and the origin
    xs = [w.x + side * w.length / 2 for w in world.walls if w.yaw == 0 for side in (-1, 1)]
    assert min(xs) <= -4.0 and max(xs) >= 26.0
    assert sorted(w.y for w in world.walls if w.yaw == 0) == [-2.4, 5.6]
    assert sorted(w.x for w in world.walls if w.yaw != 0) == [-4.0, 26.0]


# ---------------------------------------------------------------------------------------------
# Defaults
# ---------------------------------------------------------------------------------------------
def test_an_empty_world_is_flat_tarmac_on_earth():
    for data in (None, {}, {"ground": None}):
        world = parse_world(data, "empty")
        assert world.gravity == 9.81
        assert world.ground == Surface(0.9, 0.0, 0.0, 0.0)
        assert (world.patches, world.slopes, world.rails, world.description) == ((), (), (), "")
        assert (world.objects, world.rows, world.polytunnels, world.walls, world.height_field) == ((), (), (), (), None)
        assert world.source == "empty"
        assert world.ground_height(3.0, -4.0) == 0.0


def test_defaults_fill_every_optional_key():
    world = parse_world(
        {
            "gravity": "3.71",  # numbers written as strings count, as in robot files
            "ground": {"lateral_friction": 0.5},
            "patches": {"patch0": {"x": 1, "y": 2, "size_x": 3, "size_y": 4, "lateral_friction": 0.6}},
            "slopes": {"slope0": {"x": 0, "y": 0, "width": 2, "angle": 0.2, "height": 0.3}},
            "rails": {"rail0": {"x": 0, "y": 0, "length": 5}},
            "description": "mars",
        }
    )
    assert world.gravity == 3.71
    assert world.ground == Surface(0.5, 0.0, 0.0, 0.0)
    assert world.patches == (Patch("patch0", 0, 1.0, 2.0, 3.0, 4.0, 0.0, Surface(0.6, 0.0, 0.0)),)
    s = world.slopes[0]
    assert (s.name, s.index, s.yaw, s.top_length, s.surface) == ("slope0", 0, 0.0, 0.0, Surface(0.9, 0.0, 0.0))
    r = world.rails[0]
    assert (r.yaw, r.gauge, r.height, r.radius, r.surface) == (0.0, 0.55, 0.1, 0.0255, Surface(0.8, 0.0, 0.0))
    assert world.description == "mars"


def test_footprint_of_a_hill():
    # tan(angle) = 0.5: each ramp runs 2 m per metre of height
    world = parse_world(
        {"slopes": {"slope0": {"x": 0, "y": 0, "width": 1, "angle": math.atan(0.5), "height": 0.5, "top_length": 1.5}}}
    )
    assert world.slopes[0].footprint_length == pytest.approx(1.5 + 2 * 1.0)


def test_a_patch_knows_which_ground_points_it_covers():
    # 4 x 2 m turned by 90 degrees: 2 m along x, 4 m along y
    patch = Patch("patch0", 0, 1.0, 1.0, 4.0, 2.0, math.pi / 2, Surface(0.5, 0.0, 0.0))
    assert patch.contains(1.0, 2.9) and patch.contains(1.9, 1.0)
    assert not patch.contains(2.5, 1.0) and not patch.contains(1.0, 3.1)


# ---------------------------------------------------------------------------------------------
# Problems
# ---------------------------------------------------------------------------------------------
def test_a_bad_world_file_names_file_key_value_and_rule_for_every_problem(tmp_path):
    path = write(
        tmp_path,
        """
gravity: 0
ground:
  restitution: 1.5
patches:
  patch0: {x: 1, y: 2, size_x: -1.5, size_y: 1, lateral_friction: 0.5}
slopes:
  slope0: {x: 0, y: 0, width: 2, angle: 1.3, height: 0.4}
rails:
  rail0: {x: 0, y: 0, length: 10, gauge: abc}
""",
    )
    with pytest.raises(ConfigError) as e:
        load_world(path)
    err = e.value
    assert err.source == path and err.what == "world"
    lines = str(err).splitlines()
    assert lines[0] == f"{path}: invalid world (5 problems):"
    assert f"  {path}: patches.patch0.size_x: -1.5: must be in (0, 10000] [m]" in lines
    assert f"  {path}: gravity: 0: must be > 0" in lines
    assert f"  {path}: ground.restitution: 1.5: must be in [0, 1]" in lines
    assert f"  {path}: slopes.slope0.angle: 1.3: must be in (0, 1.2] [rad]" in lines
    assert f"  {path}: rails.rail0.gauge: 'abc': must be a finite number" in lines


def test_missing_required_keys_are_named():
    found, _ = problems_of({"patches": {"patch0": {"x": 0, "size_x": 1, "size_y": 1}}, "rails": {"rail0": {}}})
    for path in ("patches.patch0.y", "patches.patch0.lateral_friction", "rails.rail0.x", "rails.rail0.length"):
        assert found[path].rule == "is required", path


def test_unknown_keys_get_a_did_you_mean():
    found, _ = problems_of(
        {
            "slope": {},
            "ground": {"lateral_fricton": 0.5},
            "patches": {"patch0": {"x": 0, "y": 0, "size_x": 1, "size_y": 1, "lateral_friction": 0.5, "sizex": 2}},
        }
    )
    assert found["slope"].rule == "unknown key (did you mean 'slopes'?)"
    assert found["ground.lateral_fricton"].rule == "unknown key (did you mean 'lateral_friction'?)"
    assert found["patches.patch0.sizex"].rule == "unknown key (did you mean 'size_x'?)"


def test_a_gap_in_the_numbering_is_a_problem():
    patch = {"x": 0, "y": 0, "size_x": 1, "size_y": 1, "lateral_friction": 0.5}
    found, _ = problems_of({"patches": {"patch0": patch, "patch2": patch}})
    assert "without gaps" in found["patches.patch1"].rule
    assert "at the missing patch1, and patch2 would be dropped" in found["patches.patch1"].rule
    found, _ = problems_of({"patches": {"gravel0": patch}})
    assert found["patches.gravel0"].rule == "entries must be named patch0, patch1, ..."


@pytest.mark.parametrize("radius", [0.1, 0.2])
def test_a_pipe_cannot_sink_into_the_ground(radius):
    found, text = problems_of({"rails": {"rail0": {"x": 0, "y": 0, "length": 5, "height": 0.1, "radius": radius}}})
    assert list(found) == ["rails.rail0.radius"]
    assert found["rails.rail0.radius"].value == radius
    assert "must be < height (0.1 m)" in found["rails.rail0.radius"].rule
    assert f"test-world: rails.rail0.radius: {radius}: must be < height" in text


def test_an_invalid_radius_is_reported_once_not_compared_as_its_default():
    # the default radius (0.0255) is above this height, but the file holds no such radius
    found, _ = problems_of({"rails": {"rail0": {"x": 0, "y": 0, "length": 5, "height": 0.02, "radius": -1}}})
    assert list(found) == ["rails.rail0.radius"]
    assert found["rails.rail0.radius"].rule == "must be in (0, 10000] [m]"


def test_pipes_cannot_overlap():
    found, _ = problems_of({"rails": {"rail0": {"x": 0, "y": 0, "length": 5, "gauge": 0.05}}})
    assert list(found) == ["rails.rail0.gauge"]
    assert "must be > 2 * radius" in found["rails.rail0.gauge"].rule


def test_wrong_shapes_of_the_document():
    found, _ = problems_of({"ground": 0.9, "patches": [1, 2], "description": 3})
    assert found["ground"].rule == "must be a mapping of keys"
    assert found["patches"].rule == "must be a mapping of patch0, patch1, ..."
    assert found["description"].rule == "must be a string"
    with pytest.raises(ConfigError) as e:
        parse_world([1, 2], "listed")
    assert str(e.value).splitlines() == [
        "listed: invalid world (1 problem):",
        "  listed: <top level>: [1, 2]: the file must hold a mapping of keys",
    ]


@pytest.mark.parametrize("kind", ["missing", "directory", "not yaml"])
def test_an_unreadable_file_is_one_line(tmp_path, kind):
    if kind == "missing":
        path, reason = str(tmp_path / "nope.yaml"), "cannot read the world: No such file or directory"
    elif kind == "directory":
        path, reason = str(tmp_path), "cannot read the world: Is a directory"
    else:
        path, reason = write(tmp_path, "patches: [1, 2\n"), "not valid YAML"
    with pytest.raises(ConfigError) as e:
        load_world(path)
    assert len(str(e.value).splitlines()) == 1
    assert str(e.value).startswith(f"{path}: {reason}")


# ---------------------------------------------------------------------------------------------
# Naming a world
# ---------------------------------------------------------------------------------------------
def test_resolve_a_shipped_name():
    path = resolve_world("greenhouse")
    assert os.path.isfile(path)
    assert load_world(path).rails


def test_resolve_a_path(tmp_path, monkeypatch):
    path = write(tmp_path, {"gravity": 1.62}, "moon.yaml")
    assert resolve_world(path) == path
    # a bare file name in the current folder is a path too
    monkeypatch.chdir(tmp_path)
    assert resolve_world("moon.yaml") == "moon.yaml"
    os.rename("moon.yaml", "moon")
    assert resolve_world("moon") == "moon"
    # a path to a missing file is still a path: loading it says why it cannot be read
    assert resolve_world("missing/world.yaml") == "missing/world.yaml"


def test_an_unknown_name_lists_the_shipped_worlds():
    with pytest.raises(ConfigError) as e:
        resolve_world("flatt")
    assert str(e.value) == (
        "flatt: no such world: give a file or one of crop_rows, farm_track, flat, greenhouse, polytunnel, slope, "
        "tarmac_gravel, vineyard"
    )


def test_the_worlds_folder_is_found_with_and_without_ros(monkeypatch):
    here = os.path.dirname(os.path.abspath(__file__))
    sources = os.path.abspath(os.path.join(here, "..", "..", "worlds"))
    assert os.path.realpath(world_module.WORLDS_DIR) == os.path.realpath(sources)
    # without a ROS package path, the folder next to the sources
    monkeypatch.setenv("ROS_PACKAGE_PATH", "")
    assert os.path.realpath(worlds_dir()) == os.path.realpath(sources)
    assert shipped_worlds() == SHIPPED
    with pytest.raises(AttributeError):
        world_module.NO_SUCH_THING  # noqa: B018
