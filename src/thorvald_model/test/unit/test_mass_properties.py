"""A description's mass and centre of mass (thorvald_model.mass_properties), against figures worked
out by hand from small descriptions, and on the example robots against their own inertial blocks
summed without the joint tree (the simulator's tests compare the centre of mass with pybullet's)."""

import math
import xml.etree.ElementTree as ET

import pytest
from urdf_helpers import EXAMPLE_ROBOTS, robot_id, urdf_text

from thorvald_model.errors import UrdfError
from thorvald_model.mass_properties import mass_properties

INERTIA = '<inertia ixx="1" iyy="1" izz="1" ixy="0" ixz="0" iyz="0"/>'


def link(name, mass=None, xyz="0 0 0"):
    inertial = "" if mass is None else f'<inertial><origin xyz="{xyz}"/><mass value="{mass}"/>{INERTIA}</inertial>'
    return f'<link name="{name}">{inertial}</link>'


def joint(name, parent, child, *, kind="fixed", xyz="0 0 0", rpy="0 0 0", axis="0 0 1"):
    return (
        f'<joint name="{name}" type="{kind}"><origin xyz="{xyz}" rpy="{rpy}"/><parent link="{parent}"/>'
        f'<child link="{child}"/><axis xyz="{axis}"/></joint>'
    )


def robot(*parts):
    return '<robot name="r">' + "".join(parts) + "</robot>"


def test_two_bodies_on_a_fixed_joint():
    # 10 kg with its centre 0.5 m up; 5 kg 1 m ahead, its centre 0.2 m up: x = 5 / 15, z = (5 + 1) / 15
    props = mass_properties(
        robot(link("base", 10, "0 0 0.5"), link("arm", 5, "0 0 0.2"), joint("j", "base", "arm", xyz="1 0 0"))
    )
    assert props.mass == 15.0 and props.root == "base"
    assert props.com == pytest.approx((1 / 3, 0.0, 0.4))


def test_a_turned_joint_carries_its_childs_centre_round_and_a_position_turns_it_further():
    urdf = robot(
        link("base", 1),
        link("wheel", 1, "1 0 0"),
        joint("steer", "base", "wheel", kind="revolute", xyz="0 0 1", rpy="0 0 1.5707963267948966"),
    )
    # the joint's origin turns the child 90 degrees about z: its centre, 1 m along its x, is at (0, 1, 1)
    assert mass_properties(urdf).com == pytest.approx((0.0, 0.5, 0.5))
    # 90 degrees more about the joint's axis (z): at (-1, 0, 1)
    assert mass_properties(urdf, {"steer": math.pi / 2}).com == pytest.approx((-0.5, 0.0, 0.5))


def test_a_chain_composes_down_the_tree_and_massless_links_count_nothing():
    urdf = robot(
        link("base", 2),
        link("mid"),  # no inertial
        link("tip", 2, "0 0 -0.5"),
        joint("a", "base", "mid", xyz="0 2 0", rpy="1.5707963267948966 0 0"),
        joint("b", "mid", "tip", xyz="0 0 1"),
    )
    # roll 90 degrees at (0, 2, 0): mid's z is the base's -y; tip at mid's z = 1 is (0, 1, 0), its
    # centre 0.5 back along that z: (0, 1.5, 0); with the base's 2 kg at the origin: (0, 0.75, 0)
    props = mass_properties(urdf)
    assert props.com == pytest.approx((0.0, 0.75, 0.0), abs=1e-12)
    assert [name for name, _, _ in props.links] == ["base", "tip"]


@pytest.mark.parametrize(
    ("urdf", "says"),
    [
        (robot(link("base")), "no mass"),
        (robot(link("a", 1), link("b", 1)), "2 root links"),
        (robot('<link name="base"><inertial><mass value="heavy"/></inertial></link>'), "not a number"),
    ],
)
def test_a_description_without_a_mass_or_one_root_is_refused(urdf, says):
    with pytest.raises(UrdfError, match=says):
        mass_properties(urdf)


@pytest.mark.slow  # a description generated through xacro for every example robot
@pytest.mark.parametrize("path", EXAMPLE_ROBOTS, ids=robot_id)
def test_every_example_robot_has_the_mass_of_its_inertial_blocks_centred_between_its_wheels(path):
    text = urdf_text(path)
    masses = [float(m.get("value")) for m in ET.fromstring(text).iter("mass")]
    props = mass_properties(text)
    assert props.mass == pytest.approx(sum(masses)) and props.root == "base_link"
    # base_link is on the ground between the wheels: the centre of mass is above it, inside the wheels' box
    wheels = [c for name, _, c in props.links if name.startswith("wheel")]
    xs, ys = [c[0] for c in wheels], [c[1] for c in wheels]
    assert min(xs) - 0.5 < props.com[0] < max(xs) + 0.5 and min(ys) - 0.5 < props.com[1] < max(ys) + 0.5
    assert 0.0 < props.com[2] < 2.0
