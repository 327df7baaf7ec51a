"""A new kind of world element is one module and one registry line.

The first part of this file is such a module: fence posts (``posts:``, entries ``post0``, ...), a
cylinder standing on the ground at ``x``, ``y``, of a ``radius`` and ``height``: its value type, its
keys, its maker (with a rule between two keys), its budget and its scene builder. The registry line
is ``registered(POSTS)``: the tests load world files with posts, read their values and problems,
hold them to the budgets, build them in pybullet, and check_world counts them and their extent.
"""

import math
from dataclasses import dataclass, replace

import pybullet as p
import pytest
import yaml
from sim_test_helpers import ray_down

from thorvald_model.errors import Problem
from thorvald_model.schema import Key
from thorvald_sim import world as world_module
from thorvald_sim.check_world import format_elements, summary
from thorvald_sim.scene import build_scene, builder_of
from thorvald_sim.world import (
    BUILT_IN,
    COORDINATE,
    LENGTH,
    ConfigError,
    Context,
    ElementKind,
    Entry,
    bodies_each,
    budgets,
    element_kinds,
    elements,
    keys_markdown,
    load_world,
    parse_world,
    registered,
    top_level_keys,
)


# ---------------------------------------------------------------------------------------------
# The kind's module
# ---------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Post:
    """A fence post: a cylinder standing on the ground."""

    name: str
    index: int
    x: float  # [m] of its axis
    y: float  # [m]
    z: float  # [m] of its foot: the ground under its axis
    radius: float  # [m]
    height: float  # [m]


POST_KEYS = (
    Key("x", float, **COORDINATE),
    Key("y", float, **COORDINATE),
    Key("radius", float, 0.05, **LENGTH),
    Key("height", float, **LENGTH),
)


def make_post(entry: Entry, context: Context) -> Post:
    v = entry.values
    broken = {pr.path for pr in context.problems}
    if v["height"] < 2 * v["radius"] and f"{entry.path}.radius" not in broken:
        rule = f"must be >= 2 * radius ({2 * v['radius']} m): a post, not a disc"
        context.problems.append(Problem(f"{entry.path}.height", v["height"], rule))
    z = context.ground_at(v["x"], v["y"])
    return Post(entry.name, entry.index, v["x"], v["y"], z, v["radius"], v["height"])


def build_post(client: int, world, post: Post, name: str, bodies: dict) -> None:
    shape = p.createCollisionShape(p.GEOM_CYLINDER, radius=post.radius, height=post.height, physicsClientId=client)
    centre = (post.x, post.y, post.z + post.height / 2)
    bodies[name] = p.createMultiBody(0, shape, -1, basePosition=centre, physicsClientId=client)


def post_footprint(post: Post):
    return [(post.x - post.radius, post.y - post.radius), (post.x + post.radius, post.y + post.radius)]


POSTS = ElementKind(
    "posts", "post", POST_KEYS, make_post, build_post, budget=bodies_each(looks=True), doc="fence posts",
    footprint=post_footprint,
)  # fmt: skip

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
    assert world.extra == (("posts", world.posts),)
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


def test_posts_take_their_share_of_the_budgets(monkeypatch):
    # three posts, a hill and a wall, and the ground: 6 bodies
    monkeypatch.setattr(world_module, "MAX_BODIES", 5)
    with registered(POSTS), pytest.raises(ConfigError) as e:
        parse_world(WORLD)
    rule = "makes 6 pybullet bodies over the world's entries and the ground, 3 of them here; at most 5"
    assert [(pr.path, pr.value, pr.rule) for pr in e.value.problems] == [("posts", 3, rule)]
    monkeypatch.setattr(world_module, "MAX_BODIES", 6)
    # each of the 3 posts looks for the ground once, over the plane and the hill: 6 look-ups; the
    # wall's 4 m every 0.5 m: 9 points, 18 look-ups; 24 in all
    monkeypatch.setattr(world_module, "MAX_GROUND_LOOKUPS", 23)
    with registered(POSTS), pytest.raises(ConfigError) as e:
        parse_world(WORLD)
    assert [pr.path for pr in e.value.problems] == ["walls.wall0.length"]
    assert e.value.problems[0].rule.startswith("makes 24 ground look-ups")
    monkeypatch.setattr(world_module, "MAX_GROUND_LOOKUPS", 24)
    with registered(POSTS):
        assert len(parse_world(WORLD).posts) == 3


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
        ({"section": "extra"}, "WorldConfig has an attribute of that name"),
        ({"section": "Posts"}, "its section must be a lowercase name"),
        ({"prefix": "post1"}, "its entries' prefix 'post1' must be lowercase letters"),
        ({"keys": (*POST_KEYS, Key("h", float, 1.0, aliases=("height",)))}, "its keys name height more than once"),
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


def test_every_built_in_kind_has_a_builder_in_the_scene():
    for kind in BUILT_IN:
        assert callable(builder_of(kind)), kind.section
    lost = replace(POSTS, builder="build_post")
    with pytest.raises(LookupError, match=r"thorvald_sim\.scene has no builder 'build_post'"):
        builder_of(lost)


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


def test_a_limit_set_on_the_package_reaches_every_module_that_reads_it(monkeypatch):
    # the grid budget is read by the height field's maker and by the image check
    monkeypatch.setattr(world_module, "MAX_FIELD_POINTS", 10)
    assert budgets.MAX_FIELD_POINTS == elements.MAX_FIELD_POINTS == 10
    with pytest.raises(ConfigError) as e:
        parse_world({"height_field": {"size_x": 1, "size_y": 1, "resolution": 0.25}})
    assert e.value.problems[0].rule == "makes 5 x 5 grid points; at most 10"
    monkeypatch.undo()
    assert budgets.MAX_FIELD_POINTS == elements.MAX_FIELD_POINTS == world_module.MAX_FIELD_POINTS == 1_000_000


def test_check_world_counts_posts_and_takes_their_footprints_into_the_extent(tmp_path):
    with registered(POSTS):
        s = summary(load_world(write(tmp_path, {"posts": WORLD["posts"]})))
        assert format_elements(s) == "3 posts"
    assert s["elements"]["posts"] == 3
    # post0 at (2, 1) and post2 at (12, -1), 5 cm in radius, bound it
    assert s["extent"] == [1.95, -1.05, 12.05, 1.05]
