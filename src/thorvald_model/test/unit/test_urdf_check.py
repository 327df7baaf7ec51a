"""Link names as tf2 reads them, and the check check_urdf makes (thorvald_model.urdf_check).

The check's verdicts are compared with the real check_urdf (liburdfdom-tools) on the same broken
and fixed descriptions.
"""

import shutil
import subprocess
import xml.dom.minidom
import xml.etree.ElementTree as ET

import pytest

from thorvald_model import ConfigError
from thorvald_model.errors import MISSING, UrdfCheckError
from thorvald_model.urdf_check import (
    checked_urdf,
    closest_names,
    normalize_document,
    normalize_frame,
    normalize_urdf,
    urdf_problems,
)

LINKS = '<link name="base_link"/><link name="bat0_link"/><link name="lidar"/>'


def robot(body: str, head: str = '<robot name="r">') -> str:
    return f"{head}{body}</robot>"


def fixed(name: str, parent: str, child: str, extra: str = "", kind: str = "fixed") -> str:
    return f'<joint name="{name}" type="{kind}"><parent link="{parent}"/><child link="{child}"/>{extra}</joint>'


GOOD = robot(LINKS + fixed("bat_joint", "base_link", "bat0_link") + fixed("lidar_joint", "base_link", "lidar"))


def problems_of(xml: str):
    return [(p.path, p.value, p.rule) for p in urdf_problems(xml)]


# ---- the normaliser ----------------------------------------------------------------------------
@pytest.mark.parametrize(
    "name, normal",
    [
        ("base_link", "base_link"),
        ("/base_link", "base_link"),
        ("//base_link", "base_link"),
        ("/thorvald_001/base_link", "thorvald_001/base_link"),
        ("thorvald_001//base_link", "thorvald_001/base_link"),
        ("/thorvald_001//base_link", "thorvald_001/base_link"),
        ("thorvald_001/base_link", "thorvald_001/base_link"),
    ],
)
def test_a_frame_as_tf2_reads_it(name, normal):
    assert normalize_frame(name) == normal


def test_every_link_reference_is_normalised_and_joint_names_are_left():
    xml = robot(
        '<link name="/base_link"/><link name="thorvald_001//lidar"/><link name="wheel"/>'
        + fixed("/lidar_joint", "/base_link", "thorvald_001//lidar")
        + fixed("/wheel_joint", "base_link", "/wheel", kind="continuous")
        + '<gazebo reference="/thorvald_001/lidar"><material>Gazebo/Black</material></gazebo>'
        # a joint's Gazebo block names the joint as written: a joint name is no frame
        + '<gazebo reference="/wheel_joint"><springStiffness>10</springStiffness></gazebo>'
    )
    root = ET.fromstring(normalize_urdf(xml))
    assert [link.get("name") for link in root.findall("link")] == ["base_link", "thorvald_001/lidar", "wheel"]
    assert [j.get("name") for j in root.findall("joint")] == ["/lidar_joint", "/wheel_joint"]
    assert [(j.find("parent").get("link"), j.find("child").get("link")) for j in root.findall("joint")] == [
        ("base_link", "thorvald_001/lidar"),
        ("base_link", "wheel"),
    ]
    assert [g.get("reference") for g in root.findall("gazebo")] == ["thorvald_001/lidar", "/wheel_joint"]


def test_a_description_without_slashes_is_returned_as_it_is():
    assert normalize_urdf(GOOD) is GOOD
    assert checked_urdf(GOOD, "r") is GOOD


def test_xacros_document_is_normalised_in_place_keeping_its_formatting():
    pretty = xml.dom.minidom.parseString(GOOD).toprettyxml(indent="  ")
    doc = xml.dom.minidom.parseString(pretty.replace('"base_link"', '"/base_link"'))
    # 1 link name + 2 joint parents
    assert normalize_document(doc) == 3
    assert doc.toxml() == xml.dom.minidom.parseString(pretty).toxml()


# ---- the check ---------------------------------------------------------------------------------
def test_a_good_description_has_no_problem():
    assert urdf_problems(GOOD) == []


def test_a_missing_link_names_the_joint_the_link_and_the_closest_links():
    xml = GOOD.replace(
        '<parent link="base_link"/><child link="lidar"/>', '<parent link="base_lnk"/><child link="lidar"/>'
    )
    ((path, value, rule),) = problems_of(xml)
    assert (path, value) == ("joint lidar_joint/parent", "base_lnk")
    # difflib's ratio: base_lnk / base_link 2*8/17 = 0.94, / bat0_link 2*6/17 = 0.71, / lidar below 0.6
    assert rule == "link does not exist (closest: base_link, bat0_link)"
    with pytest.raises(UrdfCheckError) as info:
        checked_urdf(xml, "extras.xacro")
    assert isinstance(info.value, ConfigError)
    assert (
        "extras.xacro: joint lidar_joint/parent: 'base_lnk': link does not exist (closest: base_link, bat0_link)"
        in str(info.value)
    )
    assert str(info.value).startswith("extras.xacro: invalid robot description (1 problem):")


def test_closest_names_compare_the_name_after_its_prefix_too():
    links = ["base_link", "bat0_link", "thorvald_001/base_link", "thorvald_001/top0"]
    # thorvald_002/base_link / thorvald_001/base_link: all but one of 22 characters agree
    assert closest_names("thorvald_002/base_link", links)[0] == "thorvald_001/base_link"
    # written for a robot with a prefix, generated without one: whole names agree 2*9/31 = 0.58 only,
    # the parts after the prefix entirely
    assert closest_names("thorvald_001/base_link", ["base_link", "bat0_link"]) == ["base_link", "bat0_link"]
    assert closest_names("camera_optical_frame", links) == []
    assert (
        "none of the 3 links has a close name"
        in urdf_problems(
            GOOD.replace('<parent link="base_link"/><child link="lidar"/>', '<parent link="xyz"/><child link="lidar"/>')
        )[0].rule
    )


@pytest.mark.parametrize(
    "xml, expected",
    [
        ("", ("", MISSING, "the robot description is empty")),
        ("<robot name='r'><link", ("", MISSING, "the robot description is not valid XML")),
        ("<sdf/>", ("", MISSING, "the robot description's root element is <sdf>, not <robot>")),
        (robot(""), ("robot", MISSING, "the robot description has no <link>")),
        (robot(LINKS, "<robot>"), ("robot/@name", MISSING, "a robot needs a name")),
        (robot(LINKS, '<robot name="r" version="2.0">'), ("robot/@version", "2.0", "only URDF version 1.0")),
        (robot(LINKS + '<link name="lidar"/>'), ("link lidar", "lidar", "another link has this name")),
        (robot(LINKS + "<link/>"), ("link #4", MISSING, "a link needs a name")),
        (
            robot('<material name="m"><color rgba="1 0 0 1"/></material>' * 2 + '<link name="a"/>'),
            ("material m", "m", "another material has this name"),
        ),
        (
            robot('<link name="a"/><link name="b"/><link name="c"/>' + fixed("j", "a", "b") + fixed("j", "b", "c")),
            ("joint j", "j", "another joint has this name"),
        ),
        (
            robot('<link name="a"/><link name="b"/><joint type="fixed"><parent link="a"/><child link="b"/></joint>'),
            ("joint #1", MISSING, "a joint needs a name"),
        ),
        (
            robot('<link name="a"/><link name="b"/>' + fixed("j", "a", "b", kind="hinge")),
            ("joint j/@type", "hinge", "one of"),
        ),
        (
            robot('<link name="a"/><link name="b"/>' + fixed("j", "a", "b").replace(' type="fixed"', "")),
            ("joint j/@type", MISSING, "one of revolute, continuous, prismatic, fixed, floating, planar"),
        ),
        (
            robot('<link name="a"/><link name="b"/>' + fixed("j", "a", "b", kind="revolute")),
            ("joint j/limit", MISSING, "a revolute joint needs <limit"),
        ),
        (
            robot('<link name="a"/><link name="b"/>' + fixed("j", "a", "b", kind="prismatic")),
            ("joint j/limit", MISSING, "a prismatic joint needs <limit"),
        ),
        (
            robot('<link name="a"/><link name="b"/>' + fixed("j", "a", "b", '<limit velocity="1"/>', "revolute")),
            ("joint j/limit/@effort", MISSING, "a <limit> needs effort"),
        ),
        (
            # urdfdom reads numbers as a C++ stream does: no inf
            robot('<link name="a"/><link name="b"/>' + fixed("j", "a", "b", '<limit effort="inf" velocity="1"/>')),
            ("joint j/limit/@effort", "inf", "must be a number"),
        ),
        (
            robot('<link name="a"/><link name="b"/>' + fixed("j", "a", "b", '<origin xyz="0 1"/>')),
            ("joint j/origin/@xyz", "0 1", "must be 3 numbers"),
        ),
        (
            robot('<link name="a"/><link name="b"/>' + fixed("j", "a", "b", '<axis xyz="0 0 z"/>', "continuous")),
            ("joint j/axis/@xyz", "0 0 z", "must be 3 numbers"),
        ),
        (
            robot('<link name="a"/><link name="b"/>' + fixed("j", "a", "b", "<dynamics/>", "continuous")),
            ("joint j/dynamics", MISSING, "a <dynamics> needs damping or friction"),
        ),
        (
            robot('<link name="a"/><link name="b"/>' + fixed("j", "a", "b", "<mimic/>", "continuous")),
            ("joint j/mimic/@joint", MISSING, "a <mimic> names the joint it follows"),
        ),
        (
            robot('<link name="a"/><link name="b"/><joint name="j" type="fixed"><parent link="a"/></joint>'),
            ("joint j/child", MISSING, "a joint needs <child link=...>"),
        ),
        (robot('<link name="a"/><link name="b"/>'), ("link b", "b", "no joint has it as child: a second root link")),
        (
            robot('<link name="a"/><link name="b"/>' + fixed("j1", "a", "b") + fixed("j2", "b", "a")),
            ("joint j2/child", "a", "closes a cycle of links: a -> b -> a"),
        ),
    ],
)
def test_each_rule(xml, expected):
    found = problems_of(xml)
    path, value, rule = expected
    assert any(p == path and v == value and rule in r for p, v, r in found), found


def test_stricter_than_check_urdf_two_parents_and_a_cycle_beside_the_tree():
    two_parents = robot(
        '<link name="a"/><link name="b"/><link name="c"/>'
        + fixed("j1", "a", "b")
        + fixed("j2", "a", "c")
        # c hangs from a already
        + fixed("j3", "b", "c")
    )
    assert problems_of(two_parents) == [
        ("joint j3/child", "c", "link hangs from joint j2 already (a link has one parent joint)")
    ]
    beside = robot(
        '<link name="a"/><link name="b"/><link name="c"/><link name="d"/>'
        + fixed("j1", "a", "b")
        + fixed("j2", "c", "d")
        + fixed("j3", "d", "c")
    )
    # j3 is the cycle's joint written last; the loop is read from its child down to its child again
    assert problems_of(beside) == [("joint j3/child", "c", "closes a cycle of links: c -> d -> c (no tree)")]


def test_every_problem_is_listed_at_once():
    xml = robot(
        LINKS
        + '<link name="lidar"/>'
        + fixed("lidar_joint", "base_lnk", "lidar")
        + fixed("bat_joint", "base_link", "bat0_lnk", kind="revolute")
    )
    assert [p for p, _, _ in problems_of(xml)] == [
        "link lidar",  # a second link of that name
        "joint bat_joint/limit",  # revolute without <limit>
        "joint lidar_joint/parent",  # base_lnk
        "joint bat_joint/child",  # bat0_lnk
        "link bat0_link",  # nothing hangs it from base_link: a second root
    ]


# ---- verdicts of the real check_urdf ------------------------------------------------------------
CHECK_URDF = shutil.which("check_urdf")
TREE = '<link name="a"/><link name="b"/><link name="c"/>'
PAIRS = {
    # name: (broken, the same description fixed)
    "leading slash": (
        robot(TREE + fixed("j1", "/a", "b") + fixed("j2", "a", "//c")),
        robot(TREE + fixed("j1", "a", "b") + fixed("j2", "a", "c")),
    ),
    "doubled slash": (
        robot('<link name="r1/a"/><link name="r1/b"/>' + fixed("j1", "r1//a", "r1/b")),
        robot('<link name="r1/a"/><link name="r1/b"/>' + fixed("j1", "r1/a", "r1/b")),
    ),
    "missing link": (
        robot(TREE + fixed("j1", "a", "b") + fixed("j2", "a", "cc")),
        robot(TREE + fixed("j1", "a", "b") + fixed("j2", "a", "c")),
    ),
    "two roots": (robot(TREE + fixed("j1", "a", "b")), robot(TREE + fixed("j1", "a", "b") + fixed("j2", "b", "c"))),
    "no root": (
        robot(TREE + fixed("j1", "a", "b") + fixed("j2", "b", "c") + fixed("j3", "c", "a")),
        robot(TREE + fixed("j1", "a", "b") + fixed("j2", "b", "c")),
    ),
    "duplicate link": (
        robot(TREE + '<link name="a"/>' + fixed("j1", "a", "b") + fixed("j2", "a", "c")),
        robot(TREE + fixed("j1", "a", "b") + fixed("j2", "a", "c")),
    ),
    "duplicate joint": (
        robot(TREE + fixed("j1", "a", "b") + fixed("j1", "a", "c")),
        robot(TREE + fixed("j1", "a", "b") + fixed("j2", "a", "c")),
    ),
    "revolute without limit": (
        robot(TREE + fixed("j1", "a", "b", kind="revolute") + fixed("j2", "a", "c")),
        robot(TREE + fixed("j1", "a", "b", '<limit effort="1" velocity="1"/>', "revolute") + fixed("j2", "a", "c")),
    ),
    "limit without velocity": (
        robot(TREE + fixed("j1", "a", "b", '<limit effort="1"/>', "prismatic") + fixed("j2", "a", "c")),
        robot(TREE + fixed("j1", "a", "b", '<limit effort="1" velocity="1"/>', "prismatic") + fixed("j2", "a", "c")),
    ),
    "unknown type": (
        robot(TREE + fixed("j1", "a", "b", kind="hinge") + fixed("j2", "a", "c")),
        robot(TREE + fixed("j1", "a", "b", kind="continuous") + fixed("j2", "a", "c")),
    ),
    "no robot name": (
        robot(TREE + fixed("j1", "a", "b") + fixed("j2", "a", "c"), "<robot>"),
        robot(TREE + fixed("j1", "a", "b") + fixed("j2", "a", "c")),
    ),
    "origin of 2 numbers": (
        robot(TREE + fixed("j1", "a", "b", '<origin xyz="1 2"/>') + fixed("j2", "a", "c")),
        robot(TREE + fixed("j1", "a", "b", '<origin xyz="1 2 3"/>') + fixed("j2", "a", "c")),
    ),
    "number with a trailing blank": (
        robot(TREE + fixed("j1", "a", "b", '<limit effort="1.0 " velocity="1"/>', "revolute") + fixed("j2", "a", "c")),
        robot(TREE + fixed("j1", "a", "b", '<limit effort=" 1.0" velocity="1"/>', "revolute") + fixed("j2", "a", "c")),
    ),
    "version": (
        robot(TREE + fixed("j1", "a", "b") + fixed("j2", "a", "c"), '<robot name="r" version="1">'),
        robot(TREE + fixed("j1", "a", "b") + fixed("j2", "a", "c"), '<robot name="r" version="1.0">'),
    ),
}


def check_urdf_accepts(xml: str, tmp_path) -> bool:
    path = tmp_path / "robot.urdf"
    path.write_text(xml)
    result = subprocess.run([CHECK_URDF, str(path)], capture_output=True, text=True, timeout=30)
    return result.returncode == 0


@pytest.mark.skipif(CHECK_URDF is None, reason="check_urdf (liburdfdom-tools) is not installed")
@pytest.mark.parametrize("name", sorted(PAIRS))
def test_verdicts_agree_with_check_urdf(name, tmp_path):
    broken, repaired = PAIRS[name]
    assert urdf_problems(broken) != [] and not check_urdf_accepts(broken, tmp_path)
    assert urdf_problems(repaired) == [] and check_urdf_accepts(repaired, tmp_path)
    # descriptions written with slashes are the repaired ones once normalised, for both
    if "slash" in name:
        normal = checked_urdf(broken, name)
        assert ET.fromstring(normal).find("joint/parent").get("link") == ET.fromstring(repaired).find(
            "joint/parent"
        ).get("link")
        assert check_urdf_accepts(normal, tmp_path)


@pytest.mark.skipif(CHECK_URDF is None, reason="check_urdf (liburdfdom-tools) is not installed")
def test_check_urdf_itself_accepts_a_link_with_two_parents_which_is_refused_here(tmp_path):
    """The module's documented difference: urdfdom 3.0 keeps the last joint of a link with two
    parents (check_urdf prints the link twice); tf would get two transforms for one frame."""
    xml = robot(TREE + fixed("j1", "a", "b") + fixed("j2", "a", "c") + fixed("j3", "b", "c"))
    assert check_urdf_accepts(xml, tmp_path)
    assert [p.path for p in urdf_problems(xml)] == ["joint j3/child"]
