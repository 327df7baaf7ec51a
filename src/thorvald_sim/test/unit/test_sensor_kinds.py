"""Sensor kinds (thorvald_sim.sensors.kinds): one registry entry a kind, holding its block reader, its
model, its messages and its RViz displays; a new kind is one module and one registry line.

Every registered kind is checked whole, on its own example block: the block reader gives a sensor of
that kind, the model measures it on a robot in pybullet, the publishers send a message of the
declared type on each of its topics, and the displays subscribe to topics it publishes. A kind
missing a part, or claiming a block another kind reads, is refused. docs/sensors.md holds the table
the registry renders.

The last part of this file is such a new kind's module: a range finder (gazebo_ros_range, a ``ray``
sensor publishing sensor_msgs/Range, shown by RViz's Range display). The registry line is
``registered(RANGE)``: the simulator then reads its block, measures the distance to a wall and
publishes it, and the RViz configuration shows it.
"""

import math
import os
from dataclasses import dataclass, replace

import numpy as np
import pybullet as p
import pytest
from sim_test_helpers import Recorder

from thorvald_sim.doc_tables import markers
from thorvald_sim.node.sensor_io import SensorIO, message_class
from thorvald_sim.physics.robot import Pose2D
from thorvald_sim.physics.simulation import Simulation
from thorvald_sim.sensors.blocks import read_sensor_blocks
from thorvald_sim.sensors.kinds import (
    BUILT_IN,
    KINDS_TABLE,
    SensorKind,
    SensorKindError,
    kind_named,
    kinds_markdown,
    registered,
    sensor_kinds,
)
from thorvald_sim.sensors.kinds.block import (
    FRAME_TF_RESOLVE,
    NON_NEGATIVE,
    Found,
    SensorSpec,
    read_namespace,
    read_pose,
    unpack,
)
from thorvald_sim.sensors.kinds.lidar import LASER
from thorvald_sim.sensors.kinds.model import Sensor
from thorvald_sim.sensors.rviz import sensor_displays
from thorvald_sim.world import parse_world

HERE = os.path.dirname(os.path.abspath(__file__))
SENSORS_MD = os.path.join(HERE, *[".."] * 4, "docs", "sensors.md")
INERTIAL = '<inertial><mass value="{m}"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
WALL_X = 3.0  # [m] the face of a wall ahead of the sensor, at x = 0


def robot_urdf(*blocks: str) -> str:
    """A 0.4 m box with sensor_link 1 m above the ground (fixed: pybullet merges it into the base)."""
    return f"""<robot name="probe">
  <link name="base_link">{INERTIAL.format(m=20)}
    <collision><origin xyz="0 0 0.1"/><geometry><box size="0.4 0.4 0.2"/></geometry></collision></link>
  <link name="sensor_link">{INERTIAL.format(m=0.2)}</link>
  <joint name="sensor_joint" type="fixed"><origin xyz="0 0 1.0"/><parent link="base_link"/>
    <child link="sensor_link"/></joint>
  {"".join(blocks)}
</robot>"""


@pytest.fixture
def sim():
    client = p.connect(p.DIRECT)
    simulation = Simulation(client, parse_world({}))
    half = (0.1, 2.0, 1.5)
    shape = p.createCollisionShape(p.GEOM_BOX, halfExtents=half, physicsClientId=client)
    p.createMultiBody(0, shape, -1, (WALL_X + half[0], 0.0, half[2]), physicsClientId=client)
    yield simulation
    p.disconnect(client)


def measured(sim, kind: SensorKind):
    """(spec, sensor, {role: [messages]}, displays) of the kind's example block on the probe robot,
    read for a simulated second with every topic subscribed."""
    urdf = robot_urdf(kind.example)
    blocks = read_sensor_blocks(urdf)
    assert not blocks.refused and not blocks.unsupported, (blocks.refused, blocks.unsupported)
    (spec,) = blocks.sensors
    robot = sim.spawn("probe", urdf, Pose2D())
    assert not robot.sensor_problems
    (sensor,) = robot.sensors
    io = SensorIO(sensor, "/probe", "", publisher=Recorder)
    for _ in range(round(1.0 / sim.dt)):
        sim.step()
        io.step(sim.time, dict.fromkeys(io.pubs, True))
    assert io.failure is None, io.failure
    return spec, sensor, {role: pub.messages for role, pub in io.pubs.items()}, sensor_displays([spec], "/probe")


# ---------------------------------------------------------------------------------------------
# Every kind, whole
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("kind", BUILT_IN, ids=lambda k: k.name)
def test_a_registered_kind_reads_measures_publishes_and_shows_its_example(sim, kind):
    spec, sensor, published, displays = measured(sim, kind)
    assert spec.kind == kind.name and spec.link == "sensor_link"
    assert set(spec.topics) <= set(kind.roles), "a topic role the kind declares no message type for"
    assert type(sensor) is kind.model
    # a message of the declared type on every topic the block has, stamped and framed
    assert set(published) == set(spec.topics)
    for role, messages in published.items():
        assert messages, f"nothing published on {role}"
        assert {m._type for m in messages} == {kind.roles[role]}
        assert 0.0 < messages[-1].header.stamp.to_sec() <= sim.time + 1e-9
    # its displays show topics it publishes
    topics = {f"/probe/{topic.lstrip('/')}" for topic in spec.topics.values()}
    for display in displays:
        assert (display.get("Topic") or display.get("Image Topic")) in topics, display


def test_every_message_type_a_kind_declares_exists():
    for kind in sensor_kinds():
        for role, message_type in kind.roles.items():
            assert message_class(message_type)._type == message_type, (kind.name, role)


def test_the_kinds_read_every_block_the_old_tables_named():
    claimed = {(t, plugin): kind.name for kind in BUILT_IN for t, plugins in kind.sensors for plugin in plugins}
    assert claimed[("ray", "libgazebo_ros_laser.so")] == claimed[("gpu_ray", "libgazebo_ros_gpu_laser.so")] == "laser"
    assert claimed[("ray", "libgazebo_ros_velodyne_laser.so")] == "multilayer"
    assert claimed[("depth", "libgazebo_ros_openni_kinect.so")] == claimed[("camera", "libgazebo_ros_openni_kinect.so")]
    model = {plugin: kind.name for kind in BUILT_IN for plugin in kind.model_plugins}
    assert model == {"libgazebo_ros_imu.so": "imu", "libhector_gazebo_ros_gps.so": "gps", "libgazebo_ros_p3d.so": "p3d"}


# ---------------------------------------------------------------------------------------------
# A kind missing a part is refused
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("change", "says"),
    [
        ({"read_sensor": None}, "no read_sensor"),
        ({"sensors": (), "model_plugins": ()}, "reads no block"),
        ({"model_plugins": ("libx.so",)}, "no read_model_plugin"),
        ({"roles": {}}, "publishes nothing"),
        ({"roles": {"scan": "LaserScan"}}, "must be a message type"),
        ({"model": object}, "must be a Sensor class"),
        ({"messages": None}, "messages must be a function"),
        ({"displays": "laser"}, "displays must be a function"),
        ({"example": ""}, "needs an example block"),
        ({"name": "Laser 2"}, "must be a lower-case identifier"),
    ],
)
def test_a_kind_missing_a_part_is_refused_when_it_is_made(change, says):
    with pytest.raises(SensorKindError, match=says):
        replace(LASER, **change)


def test_a_kind_claiming_a_block_another_reads_or_a_taken_name_is_refused_when_registered():
    with pytest.raises(SensorKindError, match=r"'laser' and 'laser2' both read ray \+ libgazebo_ros_laser.so"):
        with registered(replace(LASER, name="laser2")):
            pass
    with pytest.raises(SensorKindError, match="registered twice"):
        with registered(replace(LASER, sensors=(("ray", ("libmine.so",)),))):
            pass
    assert sensor_kinds() == BUILT_IN


def test_docs_sensors_md_holds_the_table_the_registry_renders():
    begin, end = markers(KINDS_TABLE)
    with open(SENSORS_MD) as f:
        text = f.read()
    assert text.count(begin) == 1 and text.count(end) == 1, "docs/sensors.md needs the sensor-kinds markers"
    held = text.split(begin + "\n")[1].split(end)[0]
    assert held == kinds_markdown(), "run: python -m thorvald_sim.sensors.kinds --update docs/sensors.md"
    assert [row.split("`")[1] for row in held.splitlines()[2:]] == [kind.name for kind in BUILT_IN]


# ---------------------------------------------------------------------------------------------
# A new kind: one module ...
# ---------------------------------------------------------------------------------------------
RANGE_PLUGINS = ("libgazebo_ros_range.so",)
ULTRASOUND, INFRARED = 0, 1  # sensor_msgs/Range radiation types


@dataclass(frozen=True)
class RangeConfig:
    min_range: float  # [m]
    max_range: float
    field_of_view: float  # [rad]: the cone's full angle
    radiation: int  # sensor_msgs/Range radiation_type


def read_range(found: Found) -> SensorSpec:
    """gazebo_ros_range: a ray sensor's range and horizontal fan, the plugin's topicName, frameName,
    radiation ("ultrasound" or "infrared") and fov (the plugin's cone, else the fan's width)."""
    sensor, plugin, link, name, filename, rate = unpack(found)
    ray = sensor.required("ray", "a range sensor needs <ray>")
    rng = ray.required("range", "a range sensor needs <range> (min, max)")
    low = rng.number("min", rule=NON_NEGATIVE[0], check=NON_NEGATIVE[1])
    high = rng.number("max", rule=f"must be > min ({low!r})", check=lambda v: v > low)
    horizontal = ray.required("scan", "a range sensor needs <scan>").required("horizontal", "needs <horizontal>")
    fan = horizontal.number("max_angle", 0.0) - horizontal.number("min_angle", 0.0)
    fov = plugin.number("fov", fan, rule="must be in [0, pi)", check=lambda v: 0 <= v < math.pi)
    radiation = INFRARED if (plugin.text("radiation", "ultrasound") or "").lower() == "infrared" else ULTRASOUND
    return SensorSpec(
        "range", name, link, read_pose(sensor), rate, filename, {"range": plugin.text("topicName", "sonar")},
        plugin.text("frameName", link), FRAME_TF_RESOLVE, read_namespace(plugin),
        RangeConfig(low, high, fov, radiation),
    )  # fmt: skip


class RangeFinder(Sensor):
    """The nearest return of a ray along the sensor's +x within its range (inf: none)."""

    def read(self, now: float) -> float:
        c: RangeConfig = self.spec.config
        origin, quat = self.pose()
        axis = np.asarray(p.getMatrixFromQuaternion(quat)).reshape(3, 3)[:, 0]
        start, end = np.asarray(origin) + c.min_range * axis, np.asarray(origin) + c.max_range * axis
        ((_, _, fraction, _, _),) = p.rayTestBatch([start.tolist()], [end.tolist()], physicsClientId=self.client)
        return math.inf if fraction >= 1.0 else c.min_range + fraction * (c.max_range - c.min_range)


def range_messages(out, distance: float, wanted):
    c: RangeConfig = out.spec.config
    msg = out.message("range")
    msg.radiation_type, msg.field_of_view = c.radiation, c.field_of_view
    msg.min_range, msg.max_range, msg.range = c.min_range, c.max_range, distance
    yield "range", msg


def range_displays(spec, topic, name, colour):
    return [{"Class": "rviz/Range", "Name": name, "Topic": topic("range"), "Enabled": True, "Color": colour}]


RANGE = SensorKind(
    "range",
    blocks="`ray` + `libgazebo_ros_range.so`",
    published="`sensor_msgs/Range` on `topicName`",
    model=RangeFinder,
    roles={"range": "sensor_msgs/Range"},
    messages=range_messages,
    displays=range_displays,
    sensors=(("ray", RANGE_PLUGINS),),
    read_sensor=read_range,
    example="""<gazebo reference="sensor_link"><sensor type="ray" name="sonar_front"><update_rate>20</update_rate>
<ray><scan><horizontal><samples>1</samples><min_angle>-0.13</min_angle><max_angle>0.13</max_angle></horizontal>
</scan><range><min>0.02</min><max>4</max></range></ray>
<plugin name="sonar_front" filename="libgazebo_ros_range.so"><topicName>sonar_front</topicName>
<frameName>sensor_link</frameName><radiation>ultrasound</radiation></plugin></sensor></gazebo>""",
)


# ---------------------------------------------------------------------------------------------
# ... and one registry line
# ---------------------------------------------------------------------------------------------
def test_a_new_kind_is_unsupported_until_registered_then_read_measured_published_and_shown(sim):
    before = read_sensor_blocks(robot_urdf(RANGE.example))
    assert not before.sensors and [u.what for u in before.unsupported] == [
        "sensor ray 'sonar_front' (libgazebo_ros_range.so)"
    ]
    with registered(RANGE):
        assert kind_named("range") is RANGE
        spec, _, published, displays = measured(sim, RANGE)
    assert sensor_kinds() == BUILT_IN  # taken out again
    assert spec.config == RangeConfig(0.02, 4.0, pytest.approx(0.26), ULTRASOUND) and spec.rate == 20.0
    # 20 readings a simulated second, each the distance to the wall's face: 3 m
    (messages,) = published.values()
    assert len(messages) == 20
    last = messages[-1]
    assert (last._type, last.header.frame_id, last.radiation_type) == ("sensor_msgs/Range", "probe/sensor_link", 0)
    assert last.range == pytest.approx(WALL_X, abs=1e-3) and (last.min_range, last.max_range) == pytest.approx(
        (0.02, 4.0)
    )  # float32
    assert displays == [
        {"Class": "rviz/Range", "Name": "sonar_front (range)", "Topic": "/probe/sonar_front", "Enabled": True,
         "Color": "255; 80; 80"}
    ]  # fmt: skip


def test_a_new_kind_appears_in_the_docs_table_while_registered():
    with registered(RANGE):
        assert kinds_markdown().splitlines()[-1] == (
            "| `range` | `ray` + `libgazebo_ros_range.so` | `sensor_msgs/Range` on `topicName` |"
        )
