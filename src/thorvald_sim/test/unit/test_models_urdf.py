"""Generic URDFs read as Gazebo's URDF-to-SDF conversion reads them (pure: no pybullet): fixed joints
lumped (masses, inertias, collisions and their names), links without inertia left out, <gazebo>
extensions, joints, and the refusals."""

import math

import pytest
from models_fixtures import write_obj

from thorvald_sim.errors import ModelError
from thorvald_sim.models import GazeboCollision, gazebo_collision_names, parse_urdf_model

INERTIA = "<inertia ixx='{i}' iyy='{i}' izz='{i}' ixy='0' ixz='0' iyz='0'/>"


def link(name, mass=None, collisions=(), origin="0 0 0", inertia=0.1):
    inertial = ""
    if mass is not None:
        inertial = f"<inertial><origin xyz='{origin}'/><mass value='{mass}'/>{INERTIA.format(i=inertia)}</inertial>"
    shapes = "".join(
        f"<collision{' name=' + repr(n) if n else ''}><origin xyz='{o}'/>"
        "<geometry><box size='0.1 0.1 0.1'/></geometry></collision>"
        for n, o in collisions
    )
    return f"<link name='{name}'>{inertial}{shapes}</link>"


def joint(name, parent, child, kind="fixed", xyz="0 0 0", *, extra=""):
    return (
        f"<joint name='{name}' type='{kind}'><parent link='{parent}'/><child link='{child}'/>"
        f"<origin xyz='{xyz}'/>{extra}</joint>"
    )


def robot(*parts, name="cart"):
    return f"<robot name='{name}'>" + "".join(parts) + "</robot>"


# base_footprint (no inertia) -fixed-> base_link (10 kg, two collisions, one named) -fixed-> bumper
# (1 kg) -continuous-> wheel; base_link -fixed-> mount (no inertia) -revolute-> pan (left out with mount)
CART = robot(
    link("base_footprint"),
    joint("j_base", "base_footprint", "base_link", xyz="0 0 0.3"),
    link("base_link", 10, [("", "0 0 0"), ("top", "0 0 0.2")], inertia=1.0),
    joint("j_bumper", "base_link", "bumper", xyz="0.6 0 0"),
    link("bumper", 1, [("", "0 0 0")]),
    joint(
        "j_wheel",
        "bumper",
        "wheel",
        "continuous",
        "0 0 -0.2",
        extra="<axis xyz='0 2 0'/><dynamics damping='0.5' friction='0.1'/>",
    ),
    link("wheel", 2, [("", "0 0 0")]),
    joint("j_mount", "base_link", "mount"),
    link("mount"),
    joint("j_pan", "mount", "pan", "revolute", extra="<limit lower='1' upper='-1' effort='2' velocity='3'/>"),
    link("pan", 1),
    "<gazebo reference='bumper'><mu1>0.2</mu1><mu2>0.3</mu2><kp>1e6</kp></gazebo>",
    "<gazebo reference='base_link'><mu1>0.7</mu1></gazebo>",
)


def test_gazebo_names_of_lumped_collisions():
    # parser_urdf.cc (sdformat9): the n-th collision of a link is <name>_collision[_n], name being the
    # URDF collision's or its link's, prefixed <link>_fixed_joint_lump__ unless it begins with the link
    assert gazebo_collision_names(CART, "cart.urdf") == (
        GazeboCollision("base_footprint_fixed_joint_lump__base_link_collision", "base_footprint", "base_link", 0),
        GazeboCollision("base_footprint_fixed_joint_lump__top_collision_1", "base_footprint", "base_link", 1),
        GazeboCollision("base_footprint_fixed_joint_lump__bumper_collision_2", "base_footprint", "bumper", 0),
        GazeboCollision("wheel_collision", "wheel", "wheel", 0),
    )


def test_own_collisions_are_numbered_and_children_lumped_in_joint_name_order():
    urdf = robot(
        link("base_link", 1, [("", "0 0 0"), ("", "0 0 1")]),
        joint("z_joint", "base_link", "a"),  # urdfdom orders children by joint name: b (a_joint) first
        link("a", 1, [("", "0 0 0")]),
        joint("a_joint", "base_link", "b"),
        link("b", 1, [("", "0 0 0")]),
        joint("m_joint", "base_link", "base_link_sensor"),  # a name that begins with the link's: no prefix
        link("base_link_sensor", 1, [("", "0 0 0")]),
    )
    assert [c.name for c in gazebo_collision_names(urdf, "u")] == [
        "base_link_collision",
        "base_link_collision_1",
        "base_link_fixed_joint_lump__b_collision_2",
        "base_link_sensor_collision_3",
        "base_link_fixed_joint_lump__a_collision_4",
    ]


def test_lumped_masses_inertias_and_shapes():
    spec = parse_urdf_model(CART, "cart.urdf")
    assert [link.name for link in spec.links] == ["base_footprint", "wheel"]
    base = spec.links[0]
    inertial = base.inertial
    # base_link 10 kg at (0, 0, 0.3), I = 1; bumper 1 kg at (0.6, 0, 0.3), I = 0.1:
    # 11 kg at x = 0.6 / 11; Iyy = 1 + 10 (0.6/11)² + 0.1 + 1 (0.6 - 0.6/11)²
    assert inertial.mass == pytest.approx(11.0)
    x = 0.6 / 11
    assert inertial.pose[0] == pytest.approx((x, 0.0, 0.3))
    iyy = 1.0 + 10 * x**2 + 0.1 + (0.6 - x) ** 2
    assert inertial.inertia[1][1] == pytest.approx(iyy) and inertial.inertia[2][2] == pytest.approx(iyy)
    assert inertial.inertia[0][0] == pytest.approx(1.1)
    assert [c.pose[0] for c in base.collisions] == [(0.0, 0.0, 0.3), (0.0, 0.0, 0.5), (0.6, 0.0, 0.3)]
    # the wheel hangs from base_footprint now, its joint's origin through both fixed joints
    wheel = spec.links[1]
    assert wheel.pose[0] == pytest.approx((0.6, 0.0, 0.1))
    (j,) = spec.joints
    assert (j.name, j.type, j.parent, j.child) == ("j_wheel", "revolute", "base_footprint", "wheel")
    assert j.axis == (0.0, 1.0, 0.0) and not j.limited and (j.damping, j.friction) == (0.5, 0.1)


def test_links_without_inertia_are_left_out_with_what_hangs_below():
    spec = parse_urdf_model(CART, "cart.urdf")
    assert "pan" not in [link.name for link in spec.links]
    assert any("link[mount]" in note and "pan" in note for note in spec.notes)


def test_surfaces_follow_the_link_they_were_written_for():
    base = parse_urdf_model(CART, "cart.urdf").links[0]
    mu = {c.name: (c.surface.mu, c.surface.mu2, c.surface.kp) for c in base.collisions}
    # base_link's mu1 reaches only its unnamed collision (a named one's lumped name does not hold
    # "_fixed_joint_lump__base_link_collision", as in Gazebo); bumper's reaches its own
    assert mu == {
        "base_footprint_fixed_joint_lump__base_link_collision": (0.7, 1.0, None),
        "base_footprint_fixed_joint_lump__top_collision_1": (1.0, 1.0, None),
        "base_footprint_fixed_joint_lump__bumper_collision_2": (0.2, 0.3, 1e6),
    }


def test_static_and_self_collide_extensions():
    urdf = robot(
        link("a", 1, [("", "0 0 0")]),
        "<gazebo><static>true</static></gazebo><gazebo reference='a'><selfCollide>true</selfCollide>"
        "<material>Gazebo/Blue</material></gazebo>",
    )
    spec = parse_urdf_model(urdf, "u")
    assert spec.static and spec.links[0].self_collide


def test_preserved_fixed_joints_are_not_lumped():
    urdf = robot(
        link("a", 1, [("", "0 0 0")]),
        joint("keep", "a", "b", xyz="1 0 0"),
        link("b", 1, [("", "0 0 0")]),
        "<gazebo reference='keep'><preserveFixedJoint>true</preserveFixedJoint></gazebo>",
    )
    spec = parse_urdf_model(urdf, "u")
    assert [link.name for link in spec.links] == ["a", "b"] and spec.joints[0].type == "fixed"
    assert [c.name for c in gazebo_collision_names(urdf, "u")] == ["a_collision", "b_collision"]


def test_revolute_limits_swapped_as_gazebo_does():
    urdf = robot(
        link("a", 1),
        joint(
            "j", "a", "b", "revolute", extra="<axis xyz='0 0 1'/><limit lower='1' upper='-1' effort='2' velocity='3'/>"
        ),
        link("b", 1),
    )
    (j,) = parse_urdf_model(urdf, "u").joints
    assert (j.lower, j.upper, j.effort, j.velocity) == (-1.0, 1.0, 2.0, 3.0)


def test_a_model_fixed_to_the_world():
    urdf = robot(link("world"), joint("anchor", "world", "post", xyz="0 0 1"), link("post", 1))
    spec = parse_urdf_model(urdf, "u")
    assert [link.name for link in spec.links] == ["post"] and spec.links[0].pose[0] == (0.0, 0.0, 1.0)
    assert spec.joints[0].parent == "world"


def test_meshes_of_a_urdf(tmp_path):
    obj = write_obj(tmp_path / "m.obj")
    urdf = robot(f"<link name='a'><inertial><mass value='1'/>{INERTIA.format(i=1)}</inertial><collision>"
                 f"<geometry><mesh filename='file://{obj}' scale='2 2 2'/></geometry></collision></link>")  # fmt: skip
    assert parse_urdf_model(urdf, "u").links[0].collisions[0].geometry.path == obj
    assert (
        gazebo_collision_names(urdf.replace(obj, "/nowhere.obj"), "u")[0].name == "a_collision"
    )  # meshes not looked for


# ---- refusals ---------------------------------------------------------------------------------------
def refused(text):
    with pytest.raises(ModelError) as e:
        parse_urdf_model(text, "u.urdf")
    assert str(e.value).startswith("u.urdf")
    return e.value


def test_urdf_refusals():
    assert "not a URDF" in refused("<sdf version='1.6'/>").rule
    assert "line 1" in refused("<robot name='r'><link name='a'></robot>").path
    assert "second link" in refused(robot(link("a", 1), link("a", 1))).rule
    e = refused(robot(link("a", 1), joint("j", "a", "c")))
    assert e.path.endswith("joint[j]/child") and "'c'" in e.rule
    e = refused(robot(link("a", 1), link("b", 1), joint("j1", "a", "b"), joint("j2", "b", "a")))
    assert "loop" in e.rule
    assert "2 root links" in refused(robot(link("a", 1), link("b", 1))).rule
    assert "floating" in refused(robot(link("a", 1), link("b", 1), joint("j", "a", "b", "floating"))).rule
    assert "<limit>" in refused(robot(link("a", 1), link("b", 1), joint("j", "a", "b", "revolute"))).rule
    assert refused(robot(link("a", -1))).path.endswith("inertial/mass")
    assert "finite" in refused(robot(link("a", "nan"))).rule
    e = refused(robot(link("a", 1, [("", "0 0 0")]).replace("0.1 0.1 0.1", "0.1 -1 0.1")))
    assert e.path.endswith("geometry/box@size")
    assert "no link Gazebo simulates" in refused(robot(link("a"))).rule
    e = refused(robot("<link name='a'><inertial><mass value='1'/></inertial><collision><geometry>"
                      "<mesh filename='package://nowhere_pkg/m.dae'/></geometry></collision></link>"))  # fmt: skip
    assert "nowhere_pkg" in e.rule and e.path.endswith("mesh@filename")


def test_continuous_joints_have_no_limits():
    urdf = robot(
        link("a", 1), joint("j", "a", "b", "continuous", extra="<limit effort='5' velocity='6'/>"), link("b", 1)
    )
    (j,) = parse_urdf_model(urdf, "u").joints
    assert math.isinf(j.lower) and math.isinf(j.upper) and (j.effort, j.velocity) == (5.0, 6.0)
