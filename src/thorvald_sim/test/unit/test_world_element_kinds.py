"""A new kind of world element is one module and one registry line.

The module is :mod:`sim_posts_kind`, outside the simulator's package: fence posts (``posts:``,
entries ``post0``, ...), its value type, keys, maker (with a rule between two keys), budget,
footprint and scene builder. The registry line is ``registered(POSTS)``: the tests load world files
with posts, read their values and problems, hold them to the budgets, build them in pybullet, and
check_world counts them and their extent. The built-in kinds are made the same way: each is whole in
its own module of :mod:`thorvald_sim.world.kinds`, which nothing else of the world's loading or the
scene imports, and one line of the registry.
"""

import importlib
import inspect
import math
import os
import pkgutil
from dataclasses import replace

import numpy as np
import pytest
import yaml
from PIL import Image
from sim_posts_kind import POST_KEYS, POSTS, Post
from sim_test_helpers import ray_down

import thorvald_sim.world
from thorvald_model.schema import Key
from thorvald_sim.physics.scene import build_scene
from thorvald_sim.tools.check_world import format_elements, summary
from thorvald_sim.world import (
    BUILT_IN,
    LIMITS,
    ConfigError,
    Limits,
    element_kinds,
    kinds,
    load_world,
    parse_world,
    registered,
    top_level_keys,
)
from thorvald_sim.world.keys_table import keys_markdown
from thorvald_testing.sources import imported_names

# ---------------------------------------------------------------------------------------------
# The tests
# ---------------------------------------------------------------------------------------------
# A hill 1 m high along x at x = 10 with ramps of slope 1/2: its footprint is 2 + 2 * 1 / 0.5 = 6 m
# long, from x = 7 to 13; its top from x = 9 to 11.
HILL = {"x": 10.0, "y": 0.0, "width": 4.0, "angle": math.atan(0.5), "height": 1.0, "top_length": 2.0}
WORLD = {
    "slopes": {"slope0": HILL},
    "walls": {"wall0": {"x": 0.0, "y": -5.0, "length": 4.0}},
    "posts": {
        "post0": {"x": 2.0, "y": 1.0, "height": 1.2},
        "post1": {"x": 10.0, "y": 0.5, "radius": 0.1, "height": 0.8},  # on the hill's top
        "post2": {"x": 12.0, "y": -1.0, "height": 0.5},  # on its far ramp, 1 m from its foot
    },
}


def write(tmp_path, data) -> str:
    path = tmp_path / "posts.yaml"
    path.write_text(yaml.safe_dump(data))
    return str(path)


def test_a_world_file_with_posts_loads_their_values(tmp_path):
    with registered(POSTS):
        world = load_world(write(tmp_path, WORLD))
    # post0 on the plane; post1 on the top (1 m); post2 1 m up the ramp from its foot at x = 13: 0.5 m
    assert world.posts == (
        Post("post0", 0, 2.0, 1.0, 0.0, 0.05, 1.2),
        Post("post1", 1, 10.0, 0.5, 1.0, 0.1, 0.8),
        Post("post2", 2, 12.0, -1.0, pytest.approx(0.5), 0.05, 0.5),
    )
    assert world.elements("posts") == world.posts
    # the registry's order: the built-in kinds', then the posts
    assert world.sections[-1] == ("posts", world.posts)
    assert [section for section, _ in world.sections] == [*(kind.section for kind in BUILT_IN), "posts"]
    # the rest of the world as without posts
    without = parse_world({key: value for key, value in WORLD.items() if key != "posts"})
    assert (world.slopes, world.walls) == (without.slopes, without.walls)


def test_a_broken_posts_entry_names_each_problem(tmp_path):
    data = {
        "posts": {
            "post0": {"y": 1.0, "height": 1.0},  # no x
            "post1": {"x": 1.0, "y": 1.0, "radius": -0.1, "height": 1.0},
            "post2": {"x": 1.0, "y": 1.0, "radius": 0.3, "height": 0.5},  # a disc: 0.5 < 2 * 0.3
            "post3": {"x": 1.0, "y": 1.0, "hieght": 1.0},
            "post5": {"x": 1.0, "y": 1.0, "height": 1.0},  # after a gap
        }
    }
    path = write(tmp_path, data)
    with registered(POSTS), pytest.raises(ConfigError) as e:
        load_world(path)
    assert e.value.source == path
    found = {pr.path: pr for pr in e.value.problems}
    assert set(found) == {
        "posts.post0.x", "posts.post1.radius", "posts.post2.height", "posts.post3.hieght", "posts.post3.height",
        "posts.post4",
    }  # fmt: skip
    assert found["posts.post0.x"].rule == "is required"
    assert (found["posts.post1.radius"].value, found["posts.post1.radius"].rule) == (-0.1, "must be in (0, 10000] [m]")
    assert found["posts.post2.height"].rule == "must be >= 2 * radius (0.6 m): a post, not a disc"
    assert found["posts.post3.hieght"].rule == "unknown key (did you mean 'height'?)"
    assert found["posts.post4"].rule.startswith("entries must be numbered from post0 without gaps")
    # one line of the message a problem, each with the file, the key path, the value and the rule
    assert f"{path}: posts.post1.radius: -0.1: must be in (0, 10000] [m]" in str(e.value).splitlines()[2]


def test_posts_take_their_share_of_the_budgets():
    # three posts, a hill and a wall, and the ground: 6 bodies
    with registered(POSTS), pytest.raises(ConfigError) as e:
        parse_world(WORLD, limits=Limits(bodies=5))
    rule = "makes 6 pybullet bodies over the world's entries and the ground, 3 of them here; at most 5"
    assert [(pr.path, pr.value, pr.rule) for pr in e.value.problems] == [("posts", 3, rule)]
    # each of the 3 posts looks for the ground once, over the plane and the hill: 6 look-ups; the
    # wall's 4 m every 0.5 m: 9 points, 18 look-ups; 24 in all
    with registered(POSTS), pytest.raises(ConfigError) as e:
        parse_world(WORLD, limits=Limits(bodies=6, ground_lookups=23))
    assert [pr.path for pr in e.value.problems] == ["walls.wall0.length"]
    assert e.value.problems[0].rule.startswith("makes 24 ground look-ups")
    with registered(POSTS):
        assert len(parse_world(WORLD, limits=Limits(bodies=6, ground_lookups=24)).posts) == 3


def test_the_scene_builds_the_posts_where_they_stand(client):
    with registered(POSTS):
        world = parse_world(WORLD)
        scene = build_scene(client, world)
    names = [name for name in scene.bodies if name.startswith("posts.")]
    assert names == ["posts.post0", "posts.post1", "posts.post2"]
    assert list(scene.bodies)[-3:] == names, "after the built-in kinds"
    for post in world.posts:
        # a ray down the post's axis meets its top; one beside it, the ground (or the hill) under it
        body, z = ray_down(client, post.x, post.y)
        assert (body, z) == (scene.bodies[f"posts.{post.name}"], pytest.approx(post.z + post.height, abs=1e-6))
        body, z = ray_down(client, post.x + post.radius + 0.01, post.y)
        assert body != scene.bodies[f"posts.{post.name}"]
    assert ray_down(client, 10.0, 0.5) == (scene.bodies["posts.post1"], pytest.approx(1.8, abs=1e-6))


def test_registered_leaves_the_registry_as_it_was():
    assert element_kinds() == BUILT_IN
    assert "posts" not in top_level_keys()
    with pytest.raises(RuntimeError), registered(POSTS):
        assert element_kinds() == (*BUILT_IN, POSTS)
        assert top_level_keys()[-2:] == ("posts", "description")
        raise RuntimeError("the block fails")
    assert element_kinds() == BUILT_IN
    # without the kind, a posts section is an unknown key again
    with pytest.raises(ConfigError) as e:
        parse_world(WORLD)
    assert [(pr.path, pr.rule[:11]) for pr in e.value.problems] == [("posts", "unknown key")]


@pytest.mark.parametrize(
    ("changes", "why"),
    [
        ({"section": "walls"}, "the world file has that top-level key already"),
        ({"section": "ground"}, "the world file has that top-level key already"),
        ({"section": "elements"}, "WorldConfig has an attribute of that name"),
        ({"section": "sections"}, "WorldConfig has an attribute of that name"),
        ({"section": "ground_height"}, "WorldConfig has an attribute of that name"),
        ({"section": "Posts"}, "its section must be a lowercase name"),
        ({"prefix": "post1"}, "its entries' prefix 'post1' must be lowercase letters"),
        ({"keys": (*POST_KEYS, Key("h", float, 1.0, aliases=("height",)))}, "its keys name height more than once"),
        ({"builder": "build_post"}, "make and builder must be functions"),
        ({"ground": lambda post, x, y: post.height}, r"a kind that shapes the ground \(ground\) is made before"),
    ],
)
def test_a_kind_that_cannot_be_one_is_refused(changes, why):
    kind = replace(POSTS, **changes)
    with pytest.raises(ValueError, match="cannot be registered: " + why), registered(kind):
        pass
    assert element_kinds() == BUILT_IN
    with registered(POSTS), pytest.raises(ValueError, match="the world file has that top-level key already"):
        with registered(POSTS):
            pass


def _world_modules():
    """(name, source file) of every module of the world package, and of the scene."""
    found = [("thorvald_sim.world", thorvald_sim.world.__file__)]
    for info in pkgutil.walk_packages(thorvald_sim.world.__path__, "thorvald_sim.world."):
        found.append((info.name, importlib.util.find_spec(info.name).origin))
    return [*found, ("thorvald_sim.physics.scene", importlib.util.find_spec("thorvald_sim.physics.scene").origin)]


def test_a_built_in_kind_is_its_module_and_its_registry_line():
    modules = [(kind, inspect.getmodule(kind.make)) for kind in BUILT_IN]
    for kind, module in modules:
        assert module.__name__ == f"thorvald_sim.world.kinds.{kind.section}", kind.section
        assert kind in vars(module).values(), "the kind is its module's own"
        # every function of the kind is its module's (a budget may be a shared one: bodies_each)
        parts = (kind.make, kind.builder, kind.footprint, kind.check, kind.ground, kind.holes)
        assert {f.__module__ for f in parts if f is not None} == {module.__name__}, kind.section
    # the registry holds one line a kind, and every kind's module in its folder is registered
    folder = os.path.dirname(kinds.__file__)
    found = sorted(name[:-3] for name in os.listdir(folder) if name.endswith(".py") and name != "__init__.py")
    assert found == sorted(kind.section for kind in BUILT_IN)
    # nothing that loads or builds a world imports a kind's module but the registry (the kinds'
    # package), nor one kind's module another's: a kind is not spread over the package's layers
    names = {module.__name__ for _, module in modules}

    def kind_modules(path, name):
        imported = imported_names(path, name)
        return {m for m in names if any(n == m or n.startswith(m + ".") for n in imported)}

    for name, path in _world_modules():
        if name != "thorvald_sim.world.kinds" and name not in names:
            assert kind_modules(path, name) == set(), name
    for _, module in modules:
        assert kind_modules(module.__file__, module.__name__) == set(), module.__name__


def test_the_keys_table_has_a_row_for_the_posts():
    with registered(POSTS):
        table = keys_markdown()
    row = table.splitlines()[-2]
    assert row == (
        "| `posts` | `post0`, `post1`, ...: fence posts | `x` (required): must be in [-10000, 10000] [m]<br>"
        "`y` (required): must be in [-10000, 10000] [m]<br>`radius` (0.05): must be in (0, 10000] [m]<br>"
        "`height` (required): must be in (0, 10000] [m] |"
    )
    assert "posts" not in keys_markdown()


def test_a_limit_passed_as_a_value_reaches_every_check_that_reads_it(tmp_path):
    # the grid budget is read by the height field's maker and by its image's check
    tight = Limits(field_points=10)
    field = {"height_field": {"size_x": 1, "size_y": 1, "resolution": 0.25}}
    with pytest.raises(ConfigError) as e:
        parse_world(field, limits=tight)
    assert e.value.problems[0].rule == "makes 5 x 5 grid points; at most 10"
    Image.fromarray(np.zeros((4, 4), dtype=np.uint8)).save(tmp_path / "small.png")
    image = {"height_field": {"size_x": 1, "size_y": 1, "image": "small.png"}}
    with pytest.raises(ConfigError) as e:
        parse_world(image, base_dir=str(tmp_path), limits=tight)
    assert e.value.problems[0].rule == "makes 4 x 4 grid points (its pixels); at most 10"
    # the defaults are left as they were: nothing was set on a module
    assert LIMITS.field_points == Limits().field_points == 1_000_000
    assert parse_world(field).height_field.grid_shape() == (5, 5)
    assert parse_world(image, base_dir=str(tmp_path)).height_field.grid_shape() == (4, 4)


def test_check_world_counts_posts_and_takes_their_footprints_into_the_extent(tmp_path):
    with registered(POSTS):
        s = summary(load_world(write(tmp_path, {"posts": WORLD["posts"]})))
        assert format_elements(s) == "3 posts"
    assert s["elements"]["posts"] == 3
    # post0 at (2, 1) and post2 at (12, -1), 5 cm in radius, bound it
    assert s["extent"] == [1.95, -1.05, 12.05, 1.05]
