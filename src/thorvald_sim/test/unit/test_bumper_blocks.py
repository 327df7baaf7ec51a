"""The bumper's block (thorvald_sim.sensors.kinds.bumper): a Gazebo contact sensor with gazebo_ros_bumper,
its collisions named as Gazebo's URDF conversion names them, and a block naming one that is not
there refused with the names there are.

The expected names come from SDFormat 9's parser_urdf.cc (CreateCollisions, CreateCollision,
ReduceCollisionsToParent) and its own test of them, test/integration/fixed_joint_reduction.cc: a
base_link with one collision and three links lumped into it (child_link_1 and child_link_1a fixed to
it, child_link_2 fixed to child_link_1) names them base_link_collision,
base_link_fixed_joint_lump__child_link_1_collision_1, ..._child_link_2_collision_2 and
..._child_link_1a_collision_3 (children in the order of their joints' names, each lumped with what
was lumped into it first).
"""

import xml.etree.ElementTree as ET

import pytest

from thorvald_sim.errors import BlockError
from thorvald_sim.sensors.blocks import read_sensor_blocks, resolve_frame, resolve_topic
from thorvald_sim.sensors.kinds.block import FRAME_TF_RESOLVE, Element, Found
from thorvald_sim.sensors.kinds.bumper import BumperConfig, Shape, gazebo_link, read_bumper

INERTIAL = '<inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>'
BOX = '<collision><origin xyz="0.1 0 0"/><geometry><box size="0.1 0.2 0.3"/></geometry></collision>'
CYLINDER = '<collision name="rim"><geometry><cylinder radius="0.2" length="0.05"/></geometry></collision>'
SPHERE = '<collision><geometry><sphere radius="0.05"/></geometry></collision>'
MESH = '<collision><geometry><mesh filename="package://nowhere/shell.stl"/></geometry></collision>'


def link(name, *collisions):
    return f'<link name="{name}">{INERTIAL}{"".join(collisions)}</link>'


def joint(name, parent, child, kind="fixed", xyz="0 0 0"):
    axis = "" if kind == "fixed" else '<axis xyz="0 1 0"/>'
    return (
        f'<joint name="{name}" type="{kind}"><origin xyz="{xyz}"/><parent link="{parent}"/>'
        f'<child link="{child}"/>{axis}</joint>'
    )


# sdformat's fixed_joint_reduction test model, its links' collisions as boxes
SDFORMAT_MODEL = "".join(
    [
        link("base_link", BOX),
        link("child_link_1", BOX),
        link("child_link_1a", BOX),
        link("child_link_2", BOX),
        joint("fixed_joint_1", "base_link", "child_link_1"),
        joint("fixed_joint_1a", "base_link", "child_link_1a"),
        joint("fixed_joint_2", "child_link_1", "child_link_2"),
    ]
)

# a small robot: a chassis with two collisions, a bumper and a plate lumped into it, a wheel on a moving joint
ROBOT = "".join(
    [
        link("chassis", BOX, BOX),
        link("bumper_link", BOX),
        link("plate", CYLINDER, SPHERE),
        link("wheel", CYLINDER),
        link("shell", MESH),
        joint("bumper_joint", "chassis", "bumper_link", xyz="0.5 0 0.2"),
        joint("plate_joint", "chassis", "plate"),
        joint("shell_joint", "chassis", "shell"),
        joint("wheel_joint", "chassis", "wheel", kind="continuous"),
    ]
)


def contact_block(link_name, *collisions, plugin="", sensor_name="bumper", extra=""):
    names = "".join(f"<collision>{c}</collision>" for c in collisions)
    return f"""<gazebo reference="{link_name}"><sensor type="contact" name="{sensor_name}">{extra}
  <contact>{names}</contact>
  <plugin name="bumper_plugin" filename="libgazebo_ros_bumper.so">{plugin}</plugin></sensor></gazebo>"""


def robot(*parts: str) -> ET.Element:
    return ET.fromstring(f'<robot name="r">{"".join(parts)}</robot>')


def found(root: ET.Element, link_name: str) -> Found:
    """The block as the block reader hands it to the kind."""
    sensor = root.find(f"gazebo[@reference='{link_name}']/sensor")
    path = f"sensor[@name='{sensor.get('name')}']"
    plugin = Element(sensor.find("plugin"), f"{path}/plugin[@filename='libgazebo_ros_bumper.so']")
    rate = float(sensor.findtext("update_rate") or 0.0)
    return Found(Element(sensor, path), plugin, link_name, sensor.get("name"), "libgazebo_ros_bumper.so", rate)


def read(root: ET.Element, link_name: str):
    return read_bumper(found(root, link_name), root)


# ---------------------------------------------------------------------------------------------
# Names, as Gazebo's conversion gives them
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    "name",
    [
        "base_link_collision",
        "base_link_fixed_joint_lump__child_link_1_collision_1",
        "base_link_fixed_joint_lump__child_link_2_collision_2",
        "base_link_fixed_joint_lump__child_link_1a_collision_3",
    ],
)
def test_sdformats_own_fixed_joint_reduction_names_are_read(name):
    root = robot(SDFORMAT_MODEL, contact_block("base_link", name))
    (collision,) = read(root, "base_link").config.collisions
    assert collision.name == name


def test_the_plain_names_of_a_links_collisions():
    root = robot(ROBOT, contact_block("chassis", "chassis_collision", "chassis_collision_1"))
    config = read(root, "chassis").config
    assert [(c.name, c.link) for c in config.collisions] == [
        ("chassis_collision", "chassis"),
        ("chassis_collision_1", "chassis"),
    ]
    assert config.link == "chassis"
    assert config.collisions[0].shape == Shape("box", (0.1, 0.2, 0.3))
    assert config.collisions[0].origin.xyz == (0.1, 0.0, 0.0)


def test_a_lumped_links_collisions_are_named_after_the_link_they_are_lumped_into():
    # chassis: its own two (0, 1), then bumper_joint's bumper_link (2), plate_joint's plate (3, 4),
    # shell_joint's shell (5); the plate's first is URDF-named "rim": rim_collision_3
    names = [
        "chassis_fixed_joint_lump__bumper_link_collision_2",
        "chassis_fixed_joint_lump__rim_collision_3",
        "chassis_fixed_joint_lump__plate_collision_4",
    ]
    root = robot(ROBOT, contact_block("bumper_link", *names))
    config = read(root, "bumper_link").config
    assert config.link == "chassis"
    assert [(c.name, c.link, c.shape.kind) for c in config.collisions] == [
        (names[0], "bumper_link", "box"),
        (names[1], "plate", "cylinder"),
        (names[2], "plate", "sphere"),
    ]


def test_a_lumped_links_name_without_the_lumping_means_its_collision():
    # Gazebo rewrites bumper_link_collision to chassis_collision_bumper_link, which no collision has
    root = robot(ROBOT, contact_block("bumper_link", "bumper_link_collision", "plate_fixed_joint_lump__rim_collision"))
    config = read(root, "bumper_link").config
    assert [(c.name, c.link) for c in config.collisions] == [
        ("bumper_link_collision", "bumper_link"),
        ("plate_fixed_joint_lump__rim_collision", "plate"),
    ]


def test_a_mesh_collision_has_no_shape_to_check_points_against():
    root = robot(ROBOT, contact_block("chassis", "chassis_fixed_joint_lump__shell_collision_5"))
    (collision,) = read(root, "chassis").config.collisions
    assert collision.link == "shell" and collision.shape is None


def test_a_link_on_a_moving_joint_keeps_its_own_names():
    root = robot(ROBOT, contact_block("wheel", "wheel_fixed_joint_lump__rim_collision"))
    config = read(root, "wheel").config
    assert config.link == "wheel" and config.collisions[0].shape == Shape("cylinder", (0.2, 0.05))


def test_a_preserved_fixed_joint_keeps_its_link_and_names():
    preserve = '<gazebo reference="bumper_joint"><preserveFixedJoint>true</preserveFixedJoint></gazebo>'
    root = robot(ROBOT, preserve, contact_block("bumper_link", "bumper_link_collision"))
    assert gazebo_link(root, "bumper_link") == "bumper_link"
    config = read(root, "bumper_link").config
    assert config.link == "bumper_link" and config.collisions[0].link == "bumper_link"


def test_a_link_fixed_to_the_world_is_not_lumped_into_it():
    root = robot(link("world"), joint("anchor", "world", "chassis"), ROBOT)
    assert gazebo_link(root, "chassis") == "chassis"
    assert gazebo_link(root, "bumper_link") == "chassis"


# ---------------------------------------------------------------------------------------------
# The block
# ---------------------------------------------------------------------------------------------
def test_the_plugins_defaults():
    root = robot(ROBOT, contact_block("bumper_link", "chassis_fixed_joint_lump__bumper_link_collision_2"))
    spec = read(root, "bumper_link")
    assert (spec.kind, spec.name, spec.link, spec.plugin, spec.rate) == (
        "bumper",
        "bumper",
        "bumper_link",
        "libgazebo_ros_bumper.so",
        0.0,
    )
    assert spec.topics == {"bumper": "bumper_states"} and spec.namespace is None
    assert (spec.frame, spec.frame_rule) == ("world", FRAME_TF_RESOLVE)


def test_the_plugins_names_resolve_as_gazebo_ros_resolves_them():
    plugin = "<bumperTopicName>front_bumper</bumperTopicName><frameName>bumper_link</frameName>"
    rate = "<update_rate>50</update_rate>"
    root = robot(ROBOT, contact_block("bumper_link", "bumper_link_collision", plugin=plugin, extra=rate))
    spec = read(root, "bumper_link")
    assert spec.rate == 50.0
    assert resolve_topic(spec, "bumper", "/thorvald_001") == "/thorvald_001/front_bumper"
    assert resolve_frame(spec, "", "/thorvald_001") == "thorvald_001/bumper_link"
    plugin += "<robotNamespace>/elsewhere</robotNamespace>"
    root = robot(ROBOT, contact_block("bumper_link", "bumper_link_collision", plugin=plugin))
    assert resolve_topic(read(root, "bumper_link"), "bumper", "/thorvald_001") == "/elsewhere/front_bumper"


@pytest.mark.parametrize(
    ("collisions", "says"),
    [
        (("chassis_collision_7",), "'chassis_collision_7': link chassis (link bumper_link is lumped into it"),
        (("wheel_fixed_joint_lump__rim_collision",), "its collisions: chassis_collision, chassis_collision_1, "),
        (("bumper_collision",), "has no collision of that name in Gazebo"),
        (("",), "empty: it must name a collision"),
        ((), "missing: the contact sensor needs the collision it reports"),
    ],
)
def test_a_block_naming_no_collision_of_its_link_is_refused(collisions, says):
    root = robot(ROBOT, contact_block("bumper_link", *collisions))
    with pytest.raises(BlockError) as e:
        read(root, "bumper_link")
    assert e.value.path == "sensor[@name='bumper']/contact/collision"
    assert says in e.value.rule


def test_a_block_without_contact_is_refused():
    root = robot(ROBOT, contact_block("bumper_link", "bumper_link_collision"))
    root.find("gazebo/sensor").remove(root.find("gazebo/sensor/contact"))
    with pytest.raises(BlockError) as e:
        read(root, "bumper_link")
    assert e.value.path == "sensor[@name='bumper']/contact" and "missing" in e.value.rule


def test_a_link_without_collisions_says_so():
    root = robot(link("base"), link("arm"), joint("arm_joint", "base", "arm"), contact_block("arm", "arm_collision"))
    with pytest.raises(BlockError) as e:
        read(root, "arm")
    assert "link base (link arm is lumped into it by fixed joints) has no collision" in e.value.rule
    assert e.value.rule.endswith("it has none")


def test_without_the_description_the_names_are_taken_as_written():
    root = robot(ROBOT, contact_block("bumper_link", "anything_collision"))
    config = read_bumper(found(root, "bumper_link")).config
    assert config == BumperConfig(config.collisions, "")
    assert [(c.name, c.link, c.shape) for c in config.collisions] == [("anything_collision", "bumper_link", None)]


def test_the_block_reader_gives_a_bumper():
    text = f'<robot name="r">{ROBOT}{contact_block("bumper_link", "bumper_link_collision")}</robot>'
    blocks = read_sensor_blocks(text)
    assert not blocks.unsupported and not blocks.refused
    (spec,) = blocks.sensors
    assert spec.kind == "bumper" and [c.name for c in spec.config.collisions] == ["bumper_link_collision"]


def test_the_block_reader_refuses_a_bumper_naming_no_collision_of_its_link_and_keeps_the_others():
    good = contact_block("chassis", "chassis_collision", sensor_name="front")
    text = f'<robot name="r">{ROBOT}{contact_block("bumper_link", "bumper_collision")}{good}</robot>'
    blocks = read_sensor_blocks(text)
    assert [s.name for s in blocks.sensors] == ["front"]
    assert blocks.sensors[0].config.collisions[0].shape == Shape("box", (0.1, 0.2, 0.3))
    (refused,) = blocks.refused
    assert (refused.link, refused.path) == ("bumper_link", "sensor[@name='bumper']/contact/collision")
    assert "'bumper_collision': link chassis (link bumper_link is lumped into it by fixed joints)" in refused.rule
