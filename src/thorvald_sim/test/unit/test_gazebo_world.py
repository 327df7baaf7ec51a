"""Gazebo Classic world files read as Gazebo 11 reads them (thorvald_sim.world.gazebo_world): physics,
gravity and the datum of SDF 1.4 and 1.6, models and includes, populations, actors' scripts,
heightmaps, what is left out (noted once a kind) and every problem of a file at once, with its line.

No ROS, no pybullet: Gazebo's folders come from a fake environment (GazeboPaths of the test's own
folders, no package exports, no Gazebo installed), every file is written into tmp_path. Every expected
value is worked out here from Gazebo's rules (Population.cc, Actor.cc and ignition-math's splines,
SphericalCoordinates.cc), never taken from the code under test.
"""

import math
import os
import struct
import time
import tracemalloc
import zlib

import pytest
from models_fixtures import write_obj

from thorvald_model.errors import ConfigError
from thorvald_sim.models.gazebo_paths import GazeboPaths
from thorvald_sim.models.spec import Box, Cylinder, Mesh, Plane
from thorvald_sim.world.gazebo_actors import PERSON
from thorvald_sim.world.gazebo_world import is_gazebo_world, read_gazebo_world
from thorvald_sim.world.limits import Limits

IDENTITY_Q = (0.0, 0.0, 0.0, 1.0)


# ---------------------------------------------------------------------------------------------
# Files
# ---------------------------------------------------------------------------------------------
def write(path, text):
    os.makedirs(os.path.dirname(str(path)), exist_ok=True)
    with open(str(path), "w") as f:
        f.write(text)
    return str(path)


def gazebo(*model_path, resource_path=()):
    """Gazebo's folders of a fake environment: GAZEBO_MODEL_PATH and GAZEBO_RESOURCE_PATH only."""
    env = {
        "GAZEBO_MODEL_PATH": ":".join(str(p) for p in model_path),
        "GAZEBO_RESOURCE_PATH": ":".join(str(p) for p in resource_path),
    }
    return GazeboPaths(env, exports=lambda: [], gazebo_share=None, package_folder={}.get)


def add_model(folder, name, body):
    """A model NAME in folder (model.config naming model.sdf, SDF 1.6) of the given <model> body."""
    write(
        os.path.join(str(folder), name, "model.config"),
        f'<?xml version="1.0"?><model><name>{name}</name><sdf version="1.6">model.sdf</sdf></model>',
    )
    write(
        os.path.join(str(folder), name, "model.sdf"),
        f'<?xml version="1.0"?>\n<sdf version="1.6">\n<model name="{name}">\n{body}\n</model>\n</sdf>\n',
    )
    return os.path.join(str(folder), name)


def world_file(tmp_path, body, version="1.6", name="field.world"):
    text = f'<?xml version="1.0"?>\n<sdf version="{version}">\n<world name="default">\n{body}\n</world>\n</sdf>\n'
    return write(tmp_path / name, text)


def line_of(path, marker):
    """The line (from 1) of the file where marker is: where the message must point."""
    with open(path) as f:
        for number, line in enumerate(f, 1):
            if marker in line:
                return number
    raise AssertionError(marker)


def box_model(name, size="1 1 1", pose="0 0 0 0 0 0", static=True):
    return f"""<model name="{name}"><static>{str(static).lower()}</static><pose>{pose}</pose>
  <link name="link"><collision name="c"><geometry><box><size>{size}</size></box></geometry></collision></link>
</model>"""


def pole_link(radius=0.05, length=2.0):
    return f"""<link name="link"><collision name="c"><geometry>
  <cylinder><radius>{radius}</radius><length>{length}</length></cylinder></geometry></collision></link>"""


def png_header(path, width, height):
    """A PNG of only its signature and IHDR chunk (8-bit grey): its size can be read, no pixel can."""
    ihdr = struct.pack(">IIBBBBB", width, height, 8, 0, 0, 0, 0)
    chunk = struct.pack(">I", 13) + b"IHDR" + ihdr + struct.pack(">I", zlib.crc32(b"IHDR" + ihdr))
    with open(str(path), "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk)
    return str(path)


def close(a, b, tol=1e-9):
    return all(abs(x - y) <= tol for x, y in zip(a, b))


def yaw_of(q):
    x, y, z, w = q
    return math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))


# ---------------------------------------------------------------------------------------------
# A field
# ---------------------------------------------------------------------------------------------
def test_a_field_of_walls_poles_a_crop_mesh_the_ground_plane_and_the_sun(tmp_path):
    models = tmp_path / "models"
    crop = add_model(
        models,
        "crop",
        """<static>true</static><pose>0 0 0.1 0 0 0</pose><link name="link"><collision name="c"><geometry>
  <mesh><uri>model://crop/meshes/crop.obj</uri><scale>0.5 0.5 0.5</scale></mesh></geometry></collision></link>""",
    )
    os.makedirs(os.path.join(crop, "meshes"))
    write_obj(os.path.join(crop, "meshes", "crop.obj"))
    add_model(models, "pole", f"<static>true</static>{pole_link()}")
    path = world_file(
        tmp_path,
        f"""<include><uri>model://sun</uri></include>
<include><uri>model://ground_plane</uri></include>
{box_model("north_wall", "20 0.2 1", "0 10 0.5 0 0 0")}
{box_model("east_wall", "0.2 20 1", "10 0 0.5 0 0 1.5707963267948966")}
<include><uri>model://pole</uri><name>pole_a</name><pose>2 3 1 0 0 0</pose></include>
<include><uri>model://pole</uri><name>pole_b</name><pose>-2 3 1 0 0 0</pose><static>false</static></include>
<include><uri>model://crop</uri></include>
<include><uri>model://crop</uri><name>crop_2</name><pose>1 1 0 0 0 0</pose></include>""",
    )
    world = read_gazebo_world(path, gazebo(models))

    # file order; the sun (a light) is no model and is not noted
    assert [m.name for m in world.models] == [
        "ground_plane", "north_wall", "east_wall", "pole_a", "pole_b", "crop", "crop_2",
    ]  # fmt: skip
    assert not any("sun" in note for note in world.notes)
    plane = world.model("ground_plane")
    assert plane.static and isinstance(plane.spec.links[0].collisions[0].geometry, Plane)

    north = world.model("north_wall")
    assert north.static and north.pose == ((0.0, 10.0, 0.5), IDENTITY_Q)
    assert north.spec.links[0].collisions[0].geometry == Box((20.0, 0.2, 1.0))
    east = world.model("east_wall")
    assert east.pose[0] == (10.0, 0.0, 0.5) and close(
        east.pose[1], (0, 0, math.sin(math.pi / 4), math.cos(math.pi / 4))
    )

    # an include's <name>, <pose> and <static> replace the model's own
    a, b = world.model("pole_a"), world.model("pole_b")
    assert a.pose == ((2.0, 3.0, 1.0), IDENTITY_Q) and b.pose == ((-2.0, 3.0, 1.0), IDENTITY_Q)
    assert a.static and not b.static and not b.spec.static
    assert a.spec.links[0].collisions[0].geometry == Cylinder(0.05, 2.0)

    # without a <pose> in the include, the model file's own pose is the model's place
    crop_1, crop_2 = world.model("crop"), world.model("crop_2")
    assert crop_1.pose == ((0.0, 0.0, 0.1), IDENTITY_Q) and crop_2.pose == ((1.0, 1.0, 0.0), IDENTITY_Q)
    mesh = crop_1.spec.links[0].collisions[0].geometry
    assert isinstance(mesh, Mesh) and mesh.path == os.path.join(crop, "meshes", "crop.obj")
    assert mesh.scale == (0.5, 0.5, 0.5) and crop_2.spec.links == crop_1.spec.links
    assert world.actors == () and world.height_field is None and world.spherical_coordinates is None


# ---------------------------------------------------------------------------------------------
# Physics, gravity and the datum
# ---------------------------------------------------------------------------------------------
def test_sdf_1_4_has_gravity_in_physics(tmp_path):
    path = world_file(
        tmp_path,
        """<physics type="ode"><max_step_size>0.002</max_step_size><real_time_factor>0.5</real_time_factor>
  <real_time_update_rate>250</real_time_update_rate><gravity>0 0 -9.81</gravity></physics>
<gravity>0 0 -1</gravity>""",
        version="1.4",
    )
    world = read_gazebo_world(path, gazebo())
    assert (world.max_step_size, world.real_time_update_rate, world.real_time_factor) == (0.002, 250.0, 0.5)
    assert world.gravity == (0.0, 0.0, -9.81) and world.version == "1.4"
    # SDF 1.4 has no world <gravity>: sdformat 1.4 does not know it, so Gazebo does not read it
    assert any(n.startswith("world 'default' > gravity: SDF 1.4 has gravity in <physics>") for n in world.notes)


def test_sdf_1_6_has_gravity_in_the_world_and_gazebos_defaults_fill_what_is_missing(tmp_path):
    path = world_file(
        tmp_path,
        """<gravity>0 0 -3.71</gravity>
<physics name="fast" type="ode"><real_time_update_rate>0</real_time_update_rate></physics>
<physics name="chosen" type="ode" default="true"><max_step_size>0.004</max_step_size></physics>""",
    )
    world = read_gazebo_world(path, gazebo())
    assert world.gravity == (0.0, 0.0, -3.71)
    # the physics marked default is used; what it leaves out is sdformat's default
    assert (world.max_step_size, world.real_time_update_rate, world.real_time_factor) == (0.004, 1000.0, 1.0)
    assert any("physics 'fast'" in n and "default one" in n for n in world.notes)

    bare = read_gazebo_world(world_file(tmp_path, "", name="bare.world"), gazebo())
    assert (bare.max_step_size, bare.real_time_update_rate, bare.real_time_factor) == (0.001, 1000.0, 1.0)
    assert bare.gravity == (0.0, 0.0, -9.8) and bare.datum is None


@pytest.mark.parametrize("heading", [0.0, 90.0, 180.0, -30.0])
def test_spherical_coordinates_give_the_datum_gazebo_11s_gps_uses(tmp_path, heading):
    path = world_file(
        tmp_path,
        f"""<spherical_coordinates><surface_model>EARTH_WGS84</surface_model><latitude_deg>53.268642</latitude_deg>
  <longitude_deg>-0.524509</longitude_deg><elevation>12.5</elevation><heading_deg>{heading}</heading_deg>
</spherical_coordinates>""",
    )
    world = read_gazebo_world(path, gazebo())
    sc = world.spherical_coordinates
    assert (sc.latitude_deg, sc.longitude_deg, sc.elevation, sc.heading_deg) == (53.268642, -0.524509, 12.5, heading)
    # SphericalCoordinates.cc, LOCAL to ENU with the heading negated: east = -x cos h - y sin h,
    # north = x sin h - y cos h; the world's x axis (1, 0) is at this ENU yaw
    h = math.radians(heading)
    east, north = -math.cos(h), math.sin(h)
    datum = world.datum
    assert (datum.latitude, datum.longitude, datum.altitude) == (53.268642, -0.524509, 12.5)
    assert abs(math.remainder(datum.yaw - math.atan2(north, east), 2 * math.pi)) < 1e-12


# ---------------------------------------------------------------------------------------------
# Populations
# ---------------------------------------------------------------------------------------------
def test_a_grid_population_is_named_and_placed_as_gazebo_places_it(tmp_path):
    path = world_file(
        tmp_path,
        f"""<population name="poles">
  <model name="pole"><static>true</static>{pole_link()}</model>
  <pose>10 20 0.5 0 0 0</pose>
  <distribution><type>grid</type><rows>2</rows><cols>3</cols><step>1 2 0</step></distribution>
</population>""",
    )
    world = read_gazebo_world(path, gazebo())
    # 3 columns (odd): x from 10 - 1 * (3 - 1) / 2 = 9; 2 rows (even): y from 20 - (2 * 0 / 2 + 2 / 2) = 19;
    # row i, column j is clone i * 3 + j, at (9 + j, 19 + 2 i)
    expected = [(f"pole_clone_{i * 3 + j}", (9.0 + j, 19.0 + 2 * i, 0.5)) for i in range(2) for j in range(3)]
    assert [(m.name, m.pose[0]) for m in world.models] == expected
    assert all(m.pose[1] == IDENTITY_Q and m.static for m in world.models)
    assert all(m.spec is world.models[0].spec for m in world.models)  # read once


def test_a_linear_population_steps_from_the_boxs_corner_and_stops_short_of_its_far_side(tmp_path):
    path = world_file(
        tmp_path,
        f"""<population name="row"><model name="pole">{pole_link()}</model>
  <pose>0 0 1 0 0 0</pose><box><size>8 2 2</size></box><model_count>4</model_count>
  <distribution><type>linear-x</type></distribution></population>""",
    )
    world = read_gazebo_world(path, gazebo())
    # the pose moved by -size/2 to (-4, -1, 0); x = 8 i / 4, y and z at half the box
    assert [m.pose[0] for m in world.models] == [(-4.0, 0.0, 1.0), (-2.0, 0.0, 1.0), (0.0, 0.0, 1.0), (2.0, 0.0, 1.0)]


def test_a_random_population_is_in_its_region_and_the_same_at_every_load(tmp_path):
    body = f"""<population name="stones">
  <model name="stone"><static>true</static>{pole_link(0.1, 0.2)}<pose>5 5 5 0 0 0</pose></model>
  <pose>3 -4 0.1 0 0 0</pose><box><size>6 2 0.2</size></box><model_count>25</model_count>
  <distribution><type>random</type></distribution></population>"""
    path = world_file(tmp_path, body)
    first = read_gazebo_world(path, gazebo())
    assert [m.name for m in first.models] == [f"stone_clone_{i}" for i in range(25)]
    for m in first.models:  # in the box [pose - size / 2, pose + size / 2]
        (x, y, z), q = m.pose
        assert 0.0 <= x <= 6.0 and -5.0 <= y <= -3.0 and 0.0 <= z <= 0.2 and q == IDENTITY_Q
    assert len({m.pose for m in first.models}) == 25
    assert [m.pose for m in read_gazebo_world(path, gazebo()).models] == [m.pose for m in first.models]
    assert [m.pose for m in read_gazebo_world(path, gazebo(), seed=1).models] != [m.pose for m in first.models]
    assert any("the same places at every load" in n for n in first.notes)
    # the clone's place is Gazebo's inserted <pose>, before the model's own, which is not used
    assert any("stone' > pose:" in n and "not used" in n for n in first.notes)


def test_a_random_population_in_a_cylinder_stands_on_its_base(tmp_path):
    path = world_file(
        tmp_path,
        f"""<population name="p"><model name="m">{pole_link()}</model><pose>1 2 3 0 0 0</pose>
  <cylinder><radius>2</radius><length>0.5</length></cylinder><model_count>30</model_count>
  <distribution><type>random</type></distribution></population>""",
    )
    for m in read_gazebo_world(path, gazebo()).models:
        x, y, z = m.pose[0]
        assert math.hypot(x - 1, y - 2) <= 2.0 and 3.0 <= z <= 3.5


def test_a_population_of_ten_million_is_refused_fast_in_constant_memory(tmp_path):
    path = world_file(
        tmp_path,
        f"""<population name="weeds"><model name="weed">{pole_link()}</model><pose>0 0 0 0 0 0</pose>
  <box><size>100 100 1</size></box><model_count>10000000</model_count>
  <distribution><type>random</type></distribution></population>""",
    )
    paths = gazebo()
    tracemalloc.start()
    began = time.perf_counter()
    try:
        with pytest.raises(ConfigError) as error:
            read_gazebo_world(path, paths)
        took = time.perf_counter() - began
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    message = str(error.value)
    assert f"line {line_of(path, '<population')}: world 'default' > population 'weeds'" in message
    assert "makes 10000001 bodies" in message and "at most 20000 (Limits.models)" in message
    assert took < 0.5 and peak < 2_000_000  # no list of 10^7 places, nor of 10^7 models


def test_a_uniform_population_of_as_many_models_as_observations_is_the_observations(tmp_path):
    path = world_file(
        tmp_path,
        f"""<population name="p"><model name="m">{pole_link()}</model><pose>1 1 0 0 0 0</pose>
  <box><size>0.3 0.3 0.2</size></box><model_count>9</model_count>
  <distribution><type>uniform</type></distribution></population>""",
    )
    # observations every 0.1 m while below 0.3 (0.1 + 0.1 + 0.1 is just above it): x, y in 0, 0.1, 0.2,
    # y outer; k-means started from the first 9 of the 9 keeps each its own centroid; the box's corner
    # at the pose minus half the box
    places = [m.pose[0] for m in read_gazebo_world(path, gazebo()).models]
    expected = [(0.85 + x, 0.85 + y) for y in (0.0, 0.1, 0.2) for x in (0.0, 0.1, 0.2)]
    assert len(places) == 9 and all(close(p[:2], e, 1e-12) and -0.1 <= p[2] <= 0.1 for p, e in zip(places, expected))


def test_the_mesh_files_count_once_against_the_budget_whatever_the_instances(tmp_path):
    """Every instance of a mesh shares its shape (thorvald_sim.models.build.ShapeCache): each file
    counts once, so 4 crops of one mesh take its size, and a second mesh adds its own."""
    models = tmp_path / "models"
    crop = add_model(
        models,
        "crop",
        """<static>true</static><link name="link"><collision name="c"><geometry>
  <mesh><uri>model://crop/crop.obj</uri></mesh></geometry></collision></link>""",
    )
    size = os.path.getsize(write_obj(os.path.join(crop, "crop.obj")))
    path = world_file(
        tmp_path,
        """<population name="crops"><include><uri>model://crop</uri></include><pose>0 0 0 0 0 0</pose>
  <distribution><type>grid</type><rows>2</rows><cols>2</cols><step>1 1 0</step></distribution></population>""",
    )
    assert len(read_gazebo_world(path, gazebo(models), Limits(mesh_bytes=size)).models) == 4
    with pytest.raises(ConfigError) as error:
        read_gazebo_world(path, gazebo(models), Limits(mesh_bytes=size - 1))
    assert f"line {line_of(path, '<population')}: world 'default' > population 'crops'" in str(error.value)
    assert f"{size} bytes of mesh files" in str(error.value)


def test_a_population_gazebo_would_ignore_is_refused_with_why(tmp_path):
    path = world_file(
        tmp_path,
        f"""<population name="p"><model name="m">{pole_link()}</model>
  <distribution><type>grid</type><rows>0</rows><cols>2</cols></distribution></population>""",
    )
    with pytest.raises(ConfigError) as error:
        read_gazebo_world(path, gazebo())
    message = str(error.value)
    assert "needs a <pose>" in message and "a grid needs <step>" in message
    assert "population 'p' > distribution > rows: '0': must be > 0" in message


# ---------------------------------------------------------------------------------------------
# Actors
# ---------------------------------------------------------------------------------------------
def hermite(p0, p1, m0, m1, s):
    """ignition-math's Spline segment: the cubic Hermite basis."""
    return (
        (2 * s**3 - 3 * s**2 + 1) * p0 + (-2 * s**3 + 3 * s**2) * p1 + (s**3 - 2 * s**2 + s) * m0 + (s**3 - s**2) * m1
    )


def test_an_actor_follows_gazebos_spline_waits_its_delay_and_loops(tmp_path):
    path = world_file(
        tmp_path,
        """<actor name="walker"><pose>5 5 0 0 0 0</pose>
  <skin><filename>walk.dae</filename></skin>
  <script><loop>true</loop><delay_start>1</delay_start><auto_start>true</auto_start>
    <trajectory id="0" type="walking">
      <waypoint><time>0</time><pose>0 0 1 0 0 0</pose></waypoint>
      <waypoint><time>1</time><pose>1 0 1 0 0 0</pose></waypoint>
      <waypoint><time>2</time><pose>2 0 1 0 0 0</pose></waypoint>
    </trajectory></script></actor>""",
    )
    world = read_gazebo_world(path, gazebo())
    (actor,) = world.actors
    assert actor.name == "walker" and actor.body == PERSON and actor.skin == "walk.dae" and actor.skin_path is None
    assert any("skin 'walk.dae' not found" in n for n in world.notes)
    # Catmull-Rom tangents of x = 0, 1, 2: (1 - 0) / 2 at the first, (2 - 0) / 2, (2 - 1) / 2 at the last
    tangents = (0.5, 1.0, 0.5)
    mid_first = hermite(0, 1, tangents[0], tangents[1], 0.5)  # 0.4375: not the linear 0.5
    mid_second = hermite(1, 2, tangents[1], tangents[2], 0.5)  # 1.5625
    expected = {
        0.0: (5.0, 5.0, 0.0),  # before delay_start: the actor's own pose
        0.5: (5.0, 5.0, 0.0),
        1.0: (0.0, 0.0, 1.0),  # script time 0: the first waypoint
        1.5: (mid_first, 0.0, 1.0),
        2.0: (1.0, 0.0, 1.0),  # at a waypoint: its pose
        2.5: (mid_second, 0.0, 1.0),
        3.0: (0.0, 0.0, 1.0),  # the end: back to the start, which it holds while it waits the delay again
        3.5: (0.0, 0.0, 1.0),
        4.0: (0.0, 0.0, 1.0),  # a second cycle after 2 + 1 s
        4.5: (mid_first, 0.0, 1.0),
        7.5: (mid_first, 0.0, 1.0),  # and a third
    }
    for t, position in expected.items():
        assert close(actor.pose_at(t)[0], position, 1e-12), t
    assert mid_first == 0.4375 and mid_second == 1.5625


def test_an_actors_orientation_follows_squad_between_waypoints(tmp_path):
    path = world_file(
        tmp_path,
        """<actor name="turner"><script>
  <trajectory id="0" type="t">
    <waypoint><time>0</time><pose>0 0 0 0 0 0</pose></waypoint>
    <waypoint><time>4</time><pose>0 0 0 0 0 1.5707963267948966</pose></waypoint>
  </trajectory></script></actor>""",
    )
    (actor,) = read_gazebo_world(path, gazebo()).actors
    # Shoemake's tangents of yaw 0 and 90 deg are at -22.5 and 112.5 deg; all about z, so slerp is
    # linear in yaw: squad at s = 1/4 is slerp(2 s (1 - s) = 0.375, 22.5, slerp(s, -22.5, 112.5) = 11.25)
    quarter = 22.5 + 0.375 * (11.25 - 22.5)  # 18.28125 deg, not slerp's 22.5
    assert abs(math.degrees(yaw_of(actor.pose_at(1.0)[1])) - quarter) < 1e-9
    assert abs(math.degrees(yaw_of(actor.pose_at(2.0)[1])) - 45.0) < 1e-9
    assert abs(math.degrees(yaw_of(actor.pose_at(3.999999)[1])) - 90.0) < 1e-3
    assert yaw_of(actor.pose_at(4.0)[1]) == 0.0  # the end: it loops (by default) back to the start


def test_an_actor_without_loop_stays_at_its_end_and_its_first_waypoint_is_moved_to_time_0(tmp_path):
    path = world_file(
        tmp_path,
        """<actor name="a"><pose>9 9 9 0 0 0</pose><script><loop>false</loop>
  <trajectory id="1" type="second"><waypoint><time>1</time><pose>10 0 0 0 0 0</pose></waypoint>
    <waypoint><time>2</time><pose>12 0 0 0 0 0</pose></waypoint></trajectory>
  <trajectory id="0" type="first"><waypoint><time>0.5</time><pose>0 0 0 0 0 0</pose></waypoint>
    <waypoint><time>1.5</time><pose>1 0 0 0 0 0</pose></waypoint></trajectory>
</script></actor>""",
    )
    (actor,) = read_gazebo_world(path, gazebo()).actors
    # by id: "first" (its 0.5 s waypoint moved to 0, lasting 1.5 s), then "second" (1 s moved to 0, 2 s)
    assert [t.type for t in actor.trajectories] == ["first", "second"]
    assert actor.script_length == 3.5
    assert close(actor.pose_at(0.0)[0], (0, 0, 0))  # no delay: the first waypoint at once
    # two waypoints 1 apart: both tangents 1/2; half-way in time, the Hermite curve is at the middle
    assert close(actor.pose_at(0.75)[0], (hermite(0, 1, 0.5, 0.5, 0.5), 0, 0)) and hermite(0, 1, 0.5, 0.5, 0.5) == 0.5
    assert close(actor.pose_at(0.375)[0], (hermite(0, 1, 0.5, 0.5, 0.25), 0, 0))
    # at 1.5 s both trajectories hold the time: Gazebo takes the first it finds, the first's end
    assert close(actor.pose_at(1.5)[0], (1, 0, 0)) and close(actor.pose_at(1.5 + 1e-9)[0], (10, 0, 0))
    assert close(actor.pose_at(3.5)[0], (12, 0, 0)) and close(actor.pose_at(60.0)[0], (12, 0, 0))


# ---------------------------------------------------------------------------------------------
# Heightmaps
# ---------------------------------------------------------------------------------------------
def test_a_heightmap_collision_is_the_height_field(tmp_path):
    from PIL import Image  # noqa: PLC0415

    Image.frombytes("L", (3, 3), bytes([0, 64, 128, 32, 255, 16, 0, 0, 8])).save(str(tmp_path / "terrain.png"))
    path = world_file(
        tmp_path,
        """<model name="terrain"><static>true</static><pose>4 0 0 0 0 0</pose><link name="link">
  <collision name="c"><geometry><heightmap><uri>file://terrain.png</uri><size>10 12 2</size><pos>0 0 0.5</pos>
    <sampling>1</sampling></heightmap></geometry></collision>
  <visual name="v"><geometry><heightmap><uri>file://terrain.png</uri></heightmap></geometry></visual>
</link></model>""",
    )
    world = read_gazebo_world(path, gazebo())
    hf = world.height_field
    # the brightest pixel at size z above pos z, black at pos z; centred on the origin whatever the
    # model's pose (ODE's field is not moved), the image itself
    assert (hf["x"], hf["y"], hf["size_x"], hf["size_y"]) == (0.0, 0.0, 10.0, 12.0)
    assert (hf["min_height"], hf["max_height"]) == (0.5, 2.5)
    assert hf["image"] == str(tmp_path / "terrain.png")
    assert world.models == ()  # the model held the heightmap only
    assert any("model 'terrain': holds the heightmap only" in n for n in world.notes)
    assert any("does not move a heightmap" in n for n in world.notes)


def test_an_included_terrain_model_is_the_height_field_and_its_image_found_in_its_folder(tmp_path):
    from PIL import Image  # noqa: PLC0415

    models = tmp_path / "models"
    terrain = add_model(
        models,
        "terrain",
        """<static>true</static><link name="link"><collision name="c"><geometry><heightmap>
  <uri>model://terrain/h.png</uri><size>20 20 4</size><sampling>1</sampling></heightmap></geometry></collision>
  <collision name="post"><pose>1 1 0 0 0 0</pose><geometry><box><size>0.1 0.1 1</size></box></geometry></collision>
</link>""",
    )
    Image.frombytes("L", (3, 3), bytes([0, 0, 0, 0, 51, 0, 0, 0, 0])).save(os.path.join(terrain, "h.png"))
    path = world_file(tmp_path, "<include><uri>model://terrain</uri><pose>0 0 0 0 0 0.5</pose></include>")
    with pytest.raises(ConfigError) as error:  # turned about z: ODE turns the field, ours cannot
        read_gazebo_world(path, gazebo(models))
    assert "model 'terrain' > link 'link' > collision 'c'" in str(error.value) and "a rotated heightmap" in str(
        error.value
    )

    path = world_file(tmp_path, "<include><uri>model://terrain</uri><pose>5 0 0 0 0 0</pose></include>", name="b.world")
    world = read_gazebo_world(path, gazebo(models))
    assert world.height_field["image"] == os.path.join(terrain, "h.png")
    # the brightest pixel (51) at size z, 4 m over the black ones, whatever its level: so white at 4 / (51 / 255)
    hf = world.height_field
    assert hf["min_height"] == 0.0 and abs(hf["max_height"] - 4.0 / (51 / 255)) < 1e-5
    (model,) = world.models  # the rest of the model stays, where the include puts it
    assert model.pose[0] == (5.0, 0.0, 0.0) and [c.name for c in model.spec.links[0].collisions] == ["post"]


def test_a_heightmap_in_a_visual_only_is_noted_and_collides_with_nothing(tmp_path):
    path = world_file(
        tmp_path,
        f"""<model name="m"><static>true</static>{pole_link()[:-7]}
  <visual name="v"><geometry><heightmap><uri>file://none.png</uri></heightmap></geometry></visual></link></model>""",
    )
    world = read_gazebo_world(path, gazebo())
    assert world.height_field is None and [m.name for m in world.models] == ["m"]
    assert world.model("m").spec.links[0].visuals == ()
    assert any("visual 'v': a heightmap in a visual only" in n for n in world.notes)


def test_a_heightmap_image_too_big_is_refused_from_its_header(tmp_path):
    png_header(tmp_path / "huge.png", 4097, 4097)  # 16.8 million pixels, and no pixel data at all
    path = world_file(
        tmp_path,
        """<model name="t"><static>true</static><link name="l"><collision name="c"><geometry>
  <heightmap><uri>file://huge.png</uri><size>100 100 5</size></heightmap></geometry></collision></link></model>""",
    )
    with pytest.raises(ConfigError) as error:
        read_gazebo_world(path, gazebo())
    message = str(error.value)
    assert f"line {line_of(path, '<heightmap>')}: world 'default' > model 't' > link 'l' > collision 'c'" in message
    assert "makes 4097 x 4097 grid points (its pixels); at most 1000000" in message


# ---------------------------------------------------------------------------------------------
# What is left out
# ---------------------------------------------------------------------------------------------
def test_every_element_that_means_nothing_here_is_noted_once_a_kind(tmp_path):
    path = world_file(
        tmp_path,
        """<light name="sun" type="directional"/><light name="lamp" type="point"/>
<scene><ambient>0.4 0.4 0.4 1</ambient></scene><gui><camera name="c"/></gui>
<plugin name="a" filename="liba.so"/><plugin name="b" filename="libb.so"/>
<audio><device>default</device></audio><wind/><atmosphere type="adiabatic"/>
<magnetic_field>0 0 1</magnetic_field><state world_name="default"/><road name="r"/>
<mystery/><mystery/>""",
    )
    notes = read_gazebo_world(path, gazebo()).notes
    assert "world 'default' > light 'sun' (and 1 more): lights are not simulated (ignored)" in notes
    for kind in ("scene", "gui", "plugin 'a' (and 1 more)", "audio", "wind", "atmosphere", "magnetic_field", "state"):
        assert sum(n.startswith(f"world 'default' > {kind}:") for n in notes) == 1, kind
    assert sum(n.startswith("world 'default' > road 'r':") for n in notes) == 1
    assert (
        "world 'default' > mystery (and 1 more): not an element of an SDF world: Gazebo ignores it (ignored)" in notes
    )
    assert len(notes) == 11


def test_a_second_model_of_a_taken_name_is_left_out_as_gazebo_does(tmp_path):
    path = world_file(tmp_path, box_model("post", pose="1 0 0 0 0 0") + box_model("post", pose="2 0 0 0 0 0"))
    world = read_gazebo_world(path, gazebo())
    assert [(m.name, m.pose[0]) for m in world.models] == [("post", (1.0, 0.0, 0.0))]
    first = line_of(path, '<model name="post">')
    assert any(f"a second model named 'post' (the first: line {first}:" in n for n in world.notes)


# ---------------------------------------------------------------------------------------------
# Bad worlds
# ---------------------------------------------------------------------------------------------
def test_broken_xml_names_its_line(tmp_path):
    path = write(tmp_path / "broken.world", '<?xml version="1.0"?>\n<sdf version="1.6">\n<world name="w">\n</sdf>\n')
    with pytest.raises(ConfigError) as error:
        read_gazebo_world(path, gazebo())
    assert str(error.value).startswith(f"{path}: line 4, column 2: not well-formed XML")


def test_a_missing_model_names_its_uri_and_every_folder_searched(tmp_path):
    first, second = tmp_path / "models", tmp_path / "more"
    first.mkdir()
    second.mkdir()
    path = world_file(tmp_path, "<include><uri>model://weed</uri></include>")
    with pytest.raises(ConfigError) as error:
        read_gazebo_world(path, gazebo(first, second))
    message = str(error.value)
    assert f"line {line_of(path, 'model://weed')}: world 'default' > include" in message
    assert f"<include> of model://weed cannot be found: model://weed not found in: {first}, {second}" in message


def test_a_recursive_include_is_refused_with_its_chain(tmp_path):
    models = tmp_path / "models"
    add_model(models, "a", "<include><uri>model://b</uri></include><link name='la'/>")
    add_model(models, "b", "<include><uri>model://a</uri></include><link name='lb'/>")
    path = world_file(tmp_path, "<include><uri>model://a</uri></include>")
    with pytest.raises(ConfigError) as error:
        read_gazebo_world(path, gazebo(models))
    assert "recursive <include>: model://a -> model://b -> model://a" in str(error.value)
    assert len(error.value.problems) == 1


def test_two_errors_in_one_file_are_both_reported_with_their_lines(tmp_path):
    path = world_file(
        tmp_path,
        box_model("good", "1 1 1")
        + "\n"
        + box_model("bad", "-1 1 1")
        + "\n<include><uri>model://nowhere</uri></include>\n<physics><max_step_size>0</max_step_size></physics>",
    )
    with pytest.raises(ConfigError) as error:
        read_gazebo_world(path, gazebo())
    message = str(error.value)
    assert len(error.value.problems) == 3 and "(3 problems)" in message
    size = line_of(path, "<size>-1 1 1</size>")
    assert (
        f"line {size}: world 'default' > model 'bad' > link 'link' > collision 'c' > geometry > box > size" in message
    )
    assert "'-1 1 1': -1: a box's sizes must be > 0" in message
    assert f"line {line_of(path, 'model://nowhere')}: world 'default' > include" in message
    assert f"line {line_of(path, '<max_step_size>')}: world 'default' > physics > max_step_size: '0'" in message


@pytest.mark.parametrize(
    "text, rule",
    [
        ('<sdf version="1.6"><model name="m"><link name="l"/></model></sdf>', "no <world>: a world file here has one"),
        ('<sdf version="1.3"><world name="w"/></sdf>', "SDF 1.3: read here are 1.4 to 1.7"),
        ('<robot name="r"/>', "<robot> at the top: a Gazebo world is an <sdf> file with a <world>"),
    ],
)
def test_a_file_that_is_no_world_is_refused(tmp_path, text, rule):
    path = write(tmp_path / "x.world", text)
    with pytest.raises(ConfigError) as error:
        read_gazebo_world(path, gazebo())
    assert rule in str(error.value)


def test_a_gazebo_world_is_told_from_a_yaml_world_by_its_content(tmp_path):
    sdf = '<?xml version="1.0"?>\n<sdf version="1.6"><world name="w"/></sdf>\n'
    assert is_gazebo_world(write(tmp_path / "field.world", sdf))
    assert is_gazebo_world(write(tmp_path / "field.txt", "\n  " + sdf))  # by content, whatever its name
    assert is_gazebo_world(write(tmp_path / "bare.world", '<!-- a world -->\n<world name="w"/>'))
    assert not is_gazebo_world(write(tmp_path / "flat.yaml", "gravity: 9.81\nwalls: {}\n"))
    assert not is_gazebo_world(write(tmp_path / "yaml.world", "gravity: 9.81\n"))  # YAML, whatever its name
    assert not is_gazebo_world(write(tmp_path / "robot.urdf", '<robot name="r"/>'))
    assert not is_gazebo_world(str(tmp_path / "missing.world"))
