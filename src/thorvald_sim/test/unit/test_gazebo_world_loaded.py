"""A Gazebo world file where a world is named (load_world, so the simulator node, run_robot and
RobotSession): its ground plane our ground, its walls, poles and a crop mesh from GAZEBO_MODEL_PATH
built as the Gazebo API's models, what it leaves out said once each; a robot driven in it is stopped
by the wall it was written with."""

import math
import os

import numpy as np
import pytest

from thorvald_sim.tools.runner import RobotSession, RunOptions
from thorvald_sim.world import load_world, resolve_world

CONFIGS = os.path.join(os.path.dirname(os.path.abspath(__file__)), *[".."] * 3, "thorvald_model", "config")
STD = os.path.join(CONFIGS, "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")

FIELD = """<?xml version="1.0"?>
<sdf version="1.6">
  <world name="field">
    <include><uri>model://sun</uri></include>
    <include><uri>model://ground_plane</uri></include>
    <physics type="ode">
      <max_step_size>0.001</max_step_size><real_time_update_rate>1000</real_time_update_rate>
    </physics>
    <gravity>0 0 -9.8</gravity>
    <scene><ambient>0.4 0.4 0.4 1</ambient></scene>
    <model name="wall">
      <static>true</static>
      <pose>4 0 0.5 0 0 0</pose>
      <link name="link">
        <collision name="collision"><geometry><box><size>0.2 6 1</size></box></geometry></collision>
        <visual name="visual"><geometry><box><size>0.2 6 1</size></box></geometry></visual>
      </link>
    </model>
    <model name="pole">
      <static>true</static>
      <pose>-3 2 1 0 0 0</pose>
      <link name="link">
        <collision name="collision">
          <geometry><cylinder><radius>0.05</radius><length>2</length></cylinder></geometry>
        </collision>
      </link>
    </model>
    <include><uri>model://crop</uri><name>crop_1</name><pose>-2 -2 0 0 0 0.3</pose></include>
  </world>
</sdf>
"""

CROP_CONFIG = """<?xml version="1.0"?>
<model><name>crop</name><version>1.0</version><sdf version="1.6">model.sdf</sdf></model>
"""
CROP_SDF = """<?xml version="1.0"?>
<sdf version="1.6"><model name="crop"><static>true</static><link name="link">
  <collision name="collision"><geometry><mesh><uri>model://crop/meshes/crop.obj</uri><scale>1 1 2</scale></mesh>
  </geometry></collision></link></model></sdf>
"""
# a pyramid 0.4 m wide and 0.25 m tall (0.5 m with the model's scale)
CROP_OBJ = (
    "v -0.2 -0.2 0\nv 0.2 -0.2 0\nv 0.2 0.2 0\nv -0.2 0.2 0\nv 0 0 0.25\n"
    "f 1 3 2\nf 1 4 3\nf 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n"
)


@pytest.fixture
def field(tmp_path, monkeypatch):
    crop = tmp_path / "models" / "crop"
    (crop / "meshes").mkdir(parents=True)
    (crop / "model.config").write_text(CROP_CONFIG)
    (crop / "model.sdf").write_text(CROP_SDF)
    (crop / "meshes" / "crop.obj").write_text(CROP_OBJ)
    monkeypatch.setenv("GAZEBO_MODEL_PATH", str(tmp_path / "models"))
    monkeypatch.setenv("HOME", str(tmp_path))  # no ~/.gazebo/models of this machine's
    world = tmp_path / "field.world"
    world.write_text(FIELD)
    return str(world)


def test_a_gazebo_world_loads_where_a_world_is_named(field):
    world = load_world(field)
    assert world.gravity == pytest.approx(9.8)
    assert [m.name for m in world.models] == ["wall", "pole", "crop_1"]  # the ground plane is our ground
    crop = world.models[2]
    assert crop.static and crop.pose[0] == pytest.approx((-2.0, -2.0, 0.0))
    mesh = crop.spec.links[0].collisions[0].geometry
    assert mesh.path == os.path.join(os.path.dirname(field), "models", "crop", "meshes", "crop.obj")
    assert tuple(mesh.scale) == (1.0, 1.0, 2.0)
    said = "\n".join(world.notes)
    assert "ground_plane" in said and "taken as the ground" in said
    assert "scene" in said  # left out, and said
    assert "sun" not in said  # a light Gazebo's worlds all include: nothing to say
    assert "physics: Gazebo's steps of 0.001 s, 1000 a second: the simulator runs 1 x real time" in said
    assert world.real_time_factor == pytest.approx(1.0)


@pytest.mark.parametrize(("physics", "pace"), [("", 1.0), ("<real_time_update_rate>0</real_time_update_rate>", 0.0),
    ("<max_step_size>0.004</max_step_size><real_time_update_rate>500</real_time_update_rate>", 2.0)])  # fmt: skip
def test_a_gazebo_worlds_pace_is_its_steps_a_second_times_their_size(tmp_path, physics, pace):
    """Gazebo paces its steps at real_time_update_rate a wall second (0: flat out); the simulator takes
    that pace unless its ~real_time_factor is set (SimulatorParams.paced_by)."""
    from thorvald_sim.node.params import SimulatorParams  # noqa: PLC0415

    path = tmp_path / "paced.world"
    path.write_text(f"<sdf version='1.6'><world name='w'><physics type='ode'>{physics}</physics></world></sdf>")
    world = load_world(str(path))
    assert world.real_time_factor == pytest.approx(pace)
    assert SimulatorParams().paced_by(world, given=False).real_time_factor == pytest.approx(pace)
    assert SimulatorParams(real_time_factor=3.0).paced_by(world, given=True).real_time_factor == 3.0
    assert SimulatorParams().paced_by(load_world(resolve_world("flat")), given=False) == SimulatorParams()


@pytest.mark.slow  # a drive of 6 simulated seconds
def test_a_robot_driven_at_the_worlds_wall_is_stopped_by_it(field):
    with RobotSession(STD, RunOptions(world=field)) as session:
        gazebo = session.engine.gazebo
        assert set(gazebo.models) == {"wall", "pole", "crop_1"}
        (position, _), _, _ = gazebo.state("pole")
        assert position == pytest.approx((-3.0, 2.0, 1.0), abs=1e-9)
        session.run(6.0, lambda t: (0.8, 0.0, 0.0))  # 4.8 m ahead if nothing were in the way
        x = session.pose()[0]
    # the wall's face at x = 3.9; the standard robot's front reaches about 0.8 m ahead of base_link
    assert 2.5 < x < 3.5, x


HILL = """<?xml version="1.0"?>
<sdf version="1.6">
  <world name="hill">
    <include><uri>model://sun</uri></include>
    <model name="hill">
      <static>true</static>
      <link name="link">
        <collision name="collision">
          <geometry><heightmap><uri>file://hill.png</uri><size>8 8 2</size><pos>0 0 0</pos>
            <sampling>1</sampling></heightmap></geometry>
        </collision>
      </link>
    </model>
  </world>
</sdf>
"""


def test_a_heightmap_world_is_the_ground_gazebo_makes_of_its_image(tmp_path):
    """An image that is not symmetric: its first row is the +y edge and its first column the -x edge,
    a pixel's height its level over the brightest times size z, the grid centred on the origin and
    size / (pixels - 1) apart (Gazebo's ODE heightmap)."""
    from PIL import Image  # noqa: PLC0415

    levels = [0] * 25
    levels[0] = 255  # row 0, column 0: the (-x, +y) corner
    levels[4 * 5 + 1] = 51  # row 4 (the -y edge), column 1
    levels[2 * 5 + 3] = 102  # row 2 (y = 0), column 3
    Image.frombytes("L", (5, 5), bytes(levels)).save(str(tmp_path / "hill.png"))
    (tmp_path / "hill.world").write_text(HILL)
    world = load_world(str(tmp_path / "hill.world"))
    assert world.models == ()  # the model held the heightmap only
    step = 8.0 / 4
    assert world.ground_height(-4.0, 4.0) == pytest.approx(2.0, abs=1e-6)
    assert world.ground_height(-4.0 + step, -4.0) == pytest.approx(51 / 255 * 2.0, abs=1e-6)
    assert world.ground_height(-4.0 + 3 * step, 0.0) == pytest.approx(102 / 255 * 2.0, abs=1e-6)
    assert world.ground_height(4.0, -4.0) == pytest.approx(0.0, abs=1e-6)
    assert world.ground_height(4.0, 4.0) == pytest.approx(0.0, abs=1e-6)  # the mirror corner is black


WALKER = """<?xml version="1.0"?>
<sdf version="1.6">
  <world name="crossing">
    <include><uri>model://ground_plane</uri></include>
    <actor name="walker">
      <pose>-3 2.5 0.9 0 0 0</pose>
      <script>
        <loop>false</loop>
        <delay_start>1</delay_start>
        <trajectory id="0" type="walking">
          <waypoint><time>0</time><pose>-3 2.5 0.9 0 0 0</pose></waypoint>
          <waypoint><time>6</time><pose>3 2.5 0.9 0 0 0</pose></waypoint>
        </trajectory>
      </script>
    </actor>
  </world>
</sdf>
"""


@pytest.mark.slow  # 8 simulated seconds
def test_an_actor_walks_its_script_and_the_world_sees_it_there(tmp_path):
    """A person crossing in front of the robot: where its script has it, a body a ray (a lidar's
    beam) meets there and nowhere else, standing where its script ends."""
    from thorvald_sim.bullet import pybullet as p  # noqa: PLC0415

    (tmp_path / "crossing.world").write_text(WALKER)
    options = RunOptions(world=str(tmp_path / "crossing.world"), model_extras=ROW_LIDAR, record_sensors=True)
    with RobotSession(STD, options) as session:
        gazebo = session.engine.gazebo

        def scan():  # the lidar 0.9 m ahead, 0.375 m left of base_link, 0.13 m up (it sees a wheel too)
            return session.recordings["row_lidar"][-1][1].ranges

        def nearest_new(before):  # the nearest of the returns that are not in the scan before
            now = scan()
            seen = np.isfinite(before)
            new = np.isfinite(now) & ~seen  # where nothing was, or much nearer than what was
            new[seen] |= np.isfinite(now[seen]) & (now[seen] < before[seen] - 0.1)
            return float(now[new].min()) if new.any() else None

        def beam():  # from beside the robot across the actor's path at x = 0, at chest height
            hit = p.rayTest((0.0, 1.5, 1.2), (0.0, 4.0, 1.2), physicsClientId=session.client)[0]
            return None if hit[0] < 0 else 2.5 * hit[2]

        def x():
            return gazebo.state("walker")[0][0][0]

        session.run(0.5, lambda t: None)
        assert x() == pytest.approx(-3.0, abs=1e-9) and beam() is None  # waiting out its delay_start
        behind = scan()  # the actor behind the lidar's 270 degrees: the robot's own wheel only
        session.run(4.0, lambda t: None)  # 3 s into its 6 s walk: at x = 0
        assert x() == pytest.approx(0.0, abs=0.02)
        assert beam() == pytest.approx(2.5 - 1.5 - 0.25, abs=0.02)  # its near side, 0.25 m before its axis
        # in the lidar's view: its axis math.hypot(0.9, 2.125) m from the lidar, less its radius
        assert nearest_new(behind) == pytest.approx(math.hypot(0.9, 2.5 - 0.375) - 0.25, abs=0.05)
        session.run(8.0, lambda t: None)
        assert x() == pytest.approx(3.0, abs=1e-9) and beam() is None  # at the end of its walk, staying
        assert nearest_new(behind) == pytest.approx(math.hypot(3.0 - 0.9, 2.5 - 0.375) - 0.25, abs=0.05)


@pytest.mark.slow  # 8 simulated seconds
def test_an_actor_walking_into_a_standing_robot_pushes_it_along(tmp_path):
    """An actor is moved, not pushed: a robot standing in its path is shoved ahead of it."""
    path = tmp_path / "through.world"
    path.write_text(WALKER.replace("-3 2.5 0.9", "-3 0 0.9").replace("3 2.5 0.9", "3 0 0.9"))
    with RobotSession(STD, RunOptions(world=str(path))) as session:
        session.run(1.0, lambda t: None)
        assert abs(session.pose()[0]) < 0.01
        session.run(8.0, lambda t: None)
        # the walker ends at x = 3; the robot, its back against the walker's front, is beyond it
        assert session.pose()[0] > 3.0, session.pose()


@pytest.mark.slow  # 6 simulated seconds
def test_a_robot_on_a_heightmap_hill_stands_on_its_slope_and_climbs_it(tmp_path):
    """A ramp image (each column brighter to the east): the robot put down at the origin at the height
    the image gives there (as a users' spawn_model -z puts it: Gazebo does not lift a model out of a
    heightmap) stands on it, pitched as the slope (0.1: 2 m over 20 m), and drives up it."""
    import math  # noqa: PLC0415

    from PIL import Image  # noqa: PLC0415

    columns = [round(255 * c / 16) for c in range(17)]
    Image.frombytes("L", (17, 17), bytes(columns * 17)).save(str(tmp_path / "hill.png"))
    (tmp_path / "ramp.world").write_text(HILL.replace("<size>8 8 2</size>", "<size>20 20 2</size>"))
    ground = columns[8] / 255 * 2.0  # at the origin: the middle column's level, of the brightest's 2 m
    with RobotSession(STD, RunOptions(world=str(tmp_path / "ramp.world"), z=ground + 0.1)) as session:
        session.run(1.0, lambda t: None)
        x0, _, z0, _, pitch, _ = session.pose()
        assert pitch == pytest.approx(-math.atan(0.1), abs=0.01)  # nose up, facing uphill
        # base_link stands as high above the ground as on the flat, the ground 1 m up here (the middle)
        with RobotSession(STD, RunOptions()) as flat:
            flat.run(1.0, lambda t: None)
            above = flat.pose()[2]
        assert z0 == pytest.approx(ground + above, abs=0.05)
        session.run(6.0, lambda t: (0.5, 0.0, 0.0))
        x1, _, z1, _, _, _ = session.pose()
    assert x1 - x0 > 1.5 and z1 - z0 == pytest.approx(0.1 * (x1 - x0), abs=0.03)


PLANT_ROW = """<?xml version="1.0"?>
<sdf version="1.6">
  <world name="row">
    <include><uri>model://ground_plane</uri></include>
    <population name="lettuce">
      <model name="lettuce"><include><uri>model://crop</uri><static>true</static></include></model>
      <pose>4 0.375 0 0 0 0</pose>
      <box><size>2 0.01 0.01</size></box>
      <distribution><type>linear-x</type></distribution>
      <model_count>5</model_count>
    </population>
  </world>
</sdf>
"""
PRISM_OBJ = (
    "".join(  # a square prism 0.3 m wide and 0.25 m tall, its base on z = 0
        f"v {x} {y} {z}\n" for z in (0, 0.25) for x, y in ((-0.15, -0.15), (0.15, -0.15), (0.15, 0.15), (-0.15, 0.15))
    )
    + "f 1 2 3\nf 1 3 4\nf 5 7 6\nf 5 8 7\nf 1 5 6\nf 1 6 2\nf 2 6 7\nf 2 7 3\nf 3 7 8\nf 3 8 4\nf 4 8 5\nf 4 5 1\n"
)
ROW_LIDAR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data", "row_lidar.xacro")


@pytest.mark.slow  # a robot with a lidar, a fifth of a simulated second
def test_a_lidar_sees_a_populations_plant_meshes(field, tmp_path):
    """A row of 5 crops (a population along x through model://, the model's mesh a prism): the
    lidar's beam straight ahead meets the first plant's near face."""
    (tmp_path / "models" / "crop" / "meshes" / "crop.obj").write_text(PRISM_OBJ)
    (tmp_path / "models" / "crop" / "model.sdf").write_text(CROP_SDF.replace("<scale>1 1 2</scale>", ""))
    (tmp_path / "row.world").write_text(PLANT_ROW)
    world = load_world(str(tmp_path / "row.world"))
    places = sorted(m.pose[0][0] for m in world.models)
    assert len(places) == 5 and places[0] == pytest.approx(3.0)  # Gazebo's linear-x: from the box's -x side
    options = RunOptions(world=str(tmp_path / "row.world"), model_extras=ROW_LIDAR, record_sensors=True)
    with RobotSession(STD, options) as session:
        session.run(0.2, lambda t: None)
        scan = session.recordings["row_lidar"][-1][1]
    ahead = scan.ranges[0, scan.ranges.shape[1] // 2]  # 721 beams over 270 degrees: the middle one
    # the lidar 0.9 m ahead of base_link at y = 0.375, 0.13 m up: the first plant's face at x = 2.85
    assert ahead == pytest.approx(2.85 - 0.9, abs=0.05)


def polytunnel_world(hoops=12, spacing=2.0, half_width=1.6):
    """A polytunnel as users' generator scripts write one for Gazebo: a <model> per pole (two a hoop,
    static cylinders), a hoop above each pair (a static box bent over the aisle, 2.6 m up), and a
    table along each side (static boxes), every pose written out."""
    models = []
    for k in range(hoops):
        x = k * spacing
        for side, y in (("l", half_width), ("r", -half_width)):
            models.append(
                f"<model name='pole_{k}_{side}'><static>true</static><pose>{x} {y} 1.25 0 0 0</pose><link name='l'>"
                "<collision name='c'><geometry><cylinder><radius>0.04</radius><length>2.5</length></cylinder>"
                "</geometry></collision></link></model>"
            )
        models.append(
            f"<model name='hoop_{k}'><static>true</static><pose>{x} 0 2.6 0 0 0</pose><link name='l'><collision "
            f"name='c'><geometry><box><size>0.05 {2 * half_width} 0.05</size></box></geometry></collision></link>"
            "</model>"
        )
    length = (hoops - 1) * spacing
    for side, y in (("l", half_width - 0.35), ("r", -half_width + 0.35)):
        models.append(
            f"<model name='table_{side}'><static>true</static><pose>{length / 2} {y} 0.8 0 0 0</pose><link name='l'>"
            f"<collision name='c'><geometry><box><size>{length} 0.5 0.05</size></box></geometry></collision>"
            "</link></model>"
        )
    body = "\n    ".join(models)
    return f"""<?xml version="1.0"?>
<sdf version="1.6">
  <world name="tunnel">
    <include><uri>model://sun</uri></include>
    <include><uri>model://ground_plane</uri></include>
    {body}
  </world>
</sdf>
"""


@pytest.mark.slow  # a drive of 6 simulated seconds
def test_a_generated_polytunnel_is_driven_down_its_aisle_and_its_poles_are_where_written(tmp_path):
    path = tmp_path / "tunnel.world"
    path.write_text(polytunnel_world())
    world = load_world(str(path))
    assert len(world.models) == 12 * 3 + 2 and all(m.static for m in world.models)
    with RobotSession(STD, RunOptions(world=str(path), x=-2.0)) as session:
        (pole, _), _, _ = session.engine.gazebo.state("pole_5_r")
        assert pole == pytest.approx((10.0, -1.6, 1.25), abs=1e-9)
        session.run(6.0, lambda t: (0.8, 0.0, 0.0))
        x, y, _, _, _, yaw = session.pose()
    # down the aisle between the tables (their edges 1 m from the middle), unhindered
    assert x > 2.0 and abs(y) < 0.05 and abs(yaw) < 0.02, (x, y, yaw)


GNSS_EXTRAS = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="$(find thorvald_model)/urdf/sensor_modules/sensor_modules.xacro"/>
  <xacro:gnss_antenna parent="${tf_prefix}base_link" name="gnss" xyz="0 0 1.2" noise="0 0 0" velocity_noise="0 0 0"/>
</robot>
"""


@pytest.mark.slow  # a robot with a GNSS, 4 simulated seconds
def test_a_gazebo_worlds_spherical_coordinates_are_the_gnss_datum(tmp_path):
    """<spherical_coordinates> at 52 N 1 W: the antenna over the origin reads them; driving along the
    world's x axis goes west, as Gazebo 11's frame has it with a heading of 0 (its x axis at ENU 180 deg)."""
    (tmp_path / "gnss.xacro").write_text(GNSS_EXTRAS)
    (tmp_path / "geo.world").write_text(
        "<sdf version='1.6'><world name='w'><include><uri>model://ground_plane</uri></include>"
        "<spherical_coordinates><surface_model>EARTH_WGS84</surface_model><latitude_deg>52</latitude_deg>"
        "<longitude_deg>-1</longitude_deg><elevation>50</elevation><heading_deg>0</heading_deg>"
        "</spherical_coordinates></world></sdf>"
    )
    extras = str(tmp_path / "gnss.xacro")
    options = RunOptions(world=str(tmp_path / "geo.world"), model_extras=extras, record_sensors=True)
    with RobotSession(STD, options) as session:
        session.run(0.5, lambda t: None)
        start = session.recordings["gnss_plugin"][-1][1]
        session.run(4.5, lambda t: (0.5, 0.0, 0.0))
        moved = session.pose()[0]
        end = session.recordings["gnss_plugin"][-1][1]
    assert start.latitude == pytest.approx(52.0, abs=1e-7) and start.longitude == pytest.approx(-1.0, abs=1e-7)
    assert moved > 1.0
    assert end.latitude == pytest.approx(52.0, abs=1e-6)  # due west: the latitude stays
    metres_per_degree = 6378137.0 * math.cos(math.radians(52.0)) * math.pi / 180  # WGS84, east at 52 N, about
    assert (end.longitude - start.longitude) * metres_per_degree == pytest.approx(-moved, rel=0.01)


CAMERA_EXTRAS = """<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:include filename="$(find thorvald_model)/urdf/sensor_modules/sensor_modules.xacro"/>
  <xacro:rgbd_camera parent="${tf_prefix}base_link" name="front" xyz="1.0 0 0.8" width="64" height="48"/>
</robot>
"""


@pytest.mark.slow  # a robot with a camera, rendered in software
def test_a_camera_sees_a_world_models_material_colour(tmp_path):
    """A wall of the world file's own colour (<material><diffuse>) 3 m ahead fills the middle of the
    robot's camera image with it (lit: pybullet's renderer shades it, the hue stays)."""
    (tmp_path / "camera.xacro").write_text(CAMERA_EXTRAS)
    (tmp_path / "wall.world").write_text(
        "<sdf version='1.6'><world name='w'><include><uri>model://ground_plane</uri></include>"
        "<model name='wall'><static>true</static><pose>4 0 1 0 0 0</pose><link name='l'>"
        "<collision name='c'><geometry><box><size>0.2 8 2</size></box></geometry></collision>"
        "<visual name='v'><geometry><box><size>0.2 8 2</size></box></geometry>"
        "<material><diffuse>0.1 0.3 0.9 1</diffuse></material></visual></link></model></world></sdf>"
    )
    extras = str(tmp_path / "camera.xacro")
    options = RunOptions(world=str(tmp_path / "wall.world"), model_extras=extras, record_sensors=True)
    with RobotSession(STD, options) as session:
        session.run(0.3, lambda t: None)
        (name,) = [n for n in session.recordings if session.recordings[n]]
        image = session.recordings[name][-1][1].image
    r, g, b = (float(v) for v in image[20:28, 28:36, :3].reshape(-1, 3).mean(axis=0))
    assert b > 1.5 * g > 1.5 * 1.5 * r, (r, g, b)  # the wall's blue, its green a third, its red a ninth


def test_a_16_bit_heightmap_is_read_whole_as_gazebo_sim_reads_it(tmp_path):
    """A 16-bit image (Gazebo Classic reads only each pixel's low byte): every level, the brightest
    pixel at size z, and said."""
    import numpy as np  # noqa: PLC0415
    from PIL import Image  # noqa: PLC0415

    levels = np.zeros((5, 5), dtype=np.uint16)
    levels[0, 0] = 65535  # the (-x, +y) corner
    levels[4, 4] = 300  # the (+x, -y) corner: 300 / 65535 of the way up (a low byte of 44 in Classic)
    Image.fromarray(levels).save(str(tmp_path / "hill.png"))
    (tmp_path / "hill.world").write_text(HILL)
    world = load_world(str(tmp_path / "hill.world"))
    assert world.ground_height(-4.0, 4.0) == pytest.approx(2.0, abs=1e-6)
    assert world.ground_height(4.0, -4.0) == pytest.approx(300 / 65535 * 2.0, abs=1e-6)
    assert any("16-bit image: read whole" in note for note in world.notes)
