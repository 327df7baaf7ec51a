"""SDF models read into ModelSpecs (pure: no pybullet): versions 1.4 to 1.7 and their frames, nested
models and includes, defaults, surfaces, and every refusal with its source and element path."""

import ast
import math
import os

import pytest
from models_fixtures import box_sdf, gate_sdf, many_links_sdf, write_ascii_stl, write_dae, write_obj

from thorvald_sim.errors import ModelError, SpawnError
from thorvald_sim.models import reading
from thorvald_sim.models.sdf import default_finder, parse_sdf_model
from thorvald_sim.models.spec import IDENTITY, Box, Cylinder, Mesh, Plane, Sphere, compose, rotate_vector, tree

MODELS = os.path.join(os.path.dirname(__file__), "..", "..", "src", "thorvald_sim", "models")


def close(a, b, tol=1e-9):
    return all(abs(x - y) <= tol for x, y in zip(a, b))


def refused(text, find=None, **kwargs):
    with pytest.raises(ModelError) as e:
        parse_sdf_model(text, "test.sdf", find or default_finder(), **kwargs)
    assert str(e.value).startswith("test.sdf")
    return e.value


def test_the_pure_modules_import_no_pybullet_nor_ros():
    for name in ("spec.py", "sdf.py", "urdf_model.py", "reading.py", "meshes.py"):
        with open(os.path.join(MODELS, name)) as f:
            tree_ = ast.parse(f.read())
        imported = {a.name for n in ast.walk(tree_) if isinstance(n, ast.Import) for a in n.names}
        imported |= {n.module or "" for n in ast.walk(tree_) if isinstance(n, ast.ImportFrom)}
        assert not {m for m in imported if "bullet" in m or m.startswith(("rospy", "rospkg.", "gazebo"))}, name


def test_a_box_model_with_its_values():
    spec = parse_sdf_model(box_sdf(size=(0.4, 0.6, 0.2), mass=2.0), "box.sdf")
    assert spec.name == "box" and not spec.static and spec.source == "box.sdf"
    (link,) = spec.links
    assert link.name == "link" and link.pose == IDENTITY
    assert link.inertial.mass == 2.0
    assert link.inertial.inertia[0][0] == pytest.approx(2.0 * (0.36 + 0.04) / 12)  # m (y² + z²) / 12
    (collision,) = link.collisions
    assert collision.name == "collision" and collision.geometry == Box((0.4, 0.6, 0.2))
    assert (
        collision.surface.mu == 1.0 and collision.surface.mu2 == 1.0 and collision.surface.kp is None
    )  # SDF's defaults
    assert link.visuals[0].rgba is None


def test_sdf_defaults_of_inertial_and_shapes():
    spec = parse_sdf_model(
        """<sdf version="1.7"><model name="m"><static>1</static><link name="l">
        <collision name="a"><geometry><box/></geometry></collision>
        <collision name="b"><geometry><cylinder/></geometry></collision>
        <collision name="c"><geometry><sphere/></geometry></collision>
        <collision name="d"><geometry><plane/></geometry></collision>
        <collision name="e"><geometry><empty/></geometry></collision>
        </link></model></sdf>""",
        "m",
    )
    link = spec.links[0]
    assert spec.static
    # SDF's defaults (sdf/1.7/inertial.sdf, box.sdf, cylinder.sdf, sphere.sdf, plane.sdf)
    assert link.inertial.mass == 1.0 and link.inertial.inertia == ((1, 0, 0), (0, 1, 0), (0, 0, 1))
    assert [c.geometry for c in link.collisions] == [
        Box((1.0, 1.0, 1.0)), Cylinder(1.0, 1.0), Sphere(1.0), Plane((0.0, 0.0, 1.0), (1.0, 1.0)),
    ]  # fmt: skip
    assert any("collides with nothing" in note for note in spec.notes)  # the empty one, said


def test_surfaces_and_colours():
    extra = """<surface><friction><ode><mu>0.3</mu><mu2>0.2</mu2></ode></friction>
      <contact><ode><kp>1e5</kp><kd>100</kd></ode></contact><bounce><restitution_coefficient>0.5</restitution_coefficient></bounce>
    </surface>"""
    text = box_sdf(extra=extra).replace(
        '<visual name="visual">', '<visual name="visual"><material><script><name>Gazebo/Red</name></script></material>'
    )
    link = parse_sdf_model(text, "m").links[0]
    surface = link.collisions[0].surface
    assert (surface.mu, surface.mu2, surface.kp, surface.kd, surface.restitution) == (0.3, 0.2, 1e5, 100.0, 0.5)
    assert link.visuals[0].rgba == (1.0, 0.0, 0.0, 1.0)
    diffuse = text.replace("<script><name>Gazebo/Red</name></script>", "<diffuse>0 0.5 1 1</diffuse>")
    assert parse_sdf_model(diffuse, "m").links[0].visuals[0].rgba == (0.0, 0.5, 1.0, 1.0)


def test_a_gate_of_two_links_a_hinge_and_a_joint_to_the_world():
    spec = parse_sdf_model(gate_sdf(damping=2.0, friction=0.5), "gate")
    hinge = next(j for j in spec.joints if j.name == "hinge")
    assert (hinge.type, hinge.parent, hinge.child) == ("revolute", "post", "door")
    assert hinge.pose == ((-0.5, 0.0, 0.0), (0.0, 0.0, 0.0, 1.0))  # in the door's frame
    assert hinge.axis == (0.0, 0.0, 1.0)
    assert not hinge.limited and (hinge.damping, hinge.friction) == (2.0, 0.5)
    assert math.isinf(hinge.effort) and math.isinf(hinge.velocity)  # SDF's -1: none
    links_tree = tree(spec)
    assert links_tree.root.name == "post" and links_tree.parent_joint["post"].parent == "world"


AXIS_MODEL = """<sdf version="{version}"><model name="m">
  <link name="a"/>
  <link name="b"><pose>0 0 0 0 0 1.5707963267948966</pose></link>
  <joint name="j" type="revolute"><parent>a</parent><child>b</child>
    <axis>{use_parent}<xyz{expressed}>1 0 0</xyz>
      <limit><lower>-1</lower><upper>2</upper><effort>10</effort><velocity>3</velocity></limit></axis>
  </joint></model></sdf>"""


@pytest.mark.parametrize(
    "version, use_parent, expressed, in_model",
    [
        ("1.4", "", "", True),  # 1.4: the axis is in the model frame
        ("1.5", "", "", False),  # 1.5 and 1.6: in the joint frame ...
        ("1.6", "<use_parent_model_frame>true</use_parent_model_frame>", "", True),  # ... unless asked
        ("1.7", "", "", False),  # 1.7: in the joint frame ...
        ("1.7", "", " expressed_in='__model__'", True),  # ... unless expressed_in names another
        ("1.7", "", " expressed_in='a'", True),  # (a's frame is the model's here)
    ],
)
def test_a_joint_axis_in_the_frame_each_version_gives_it(version, use_parent, expressed, in_model):
    text = AXIS_MODEL.format(version=version, use_parent=use_parent, expressed=expressed)
    joint = parse_sdf_model(text, "m").joints[0]
    # b (and the joint frame) is turned 90° about z: the model's x is the joint frame's -y
    assert close(joint.axis, (0.0, -1.0, 0.0) if in_model else (1.0, 0.0, 0.0))
    assert (joint.lower, joint.upper, joint.effort, joint.velocity) == (-1.0, 2.0, 10.0, 3.0)


def test_poses_relative_to_other_frames_in_sdf_1_7():
    spec = parse_sdf_model(
        """<sdf version="1.7"><model name="m">
          <frame name="f" attached_to="a"><pose relative_to="a">0 0 1 0 0 0</pose></frame>
          <link name="a"><pose>1 0 0 0 0 0</pose></link>
          <link name="b"><pose relative_to="f">0 2 0 0 0 0</pose>
            <collision name="c"><pose relative_to="a">0 0 0 0 0 0</pose>
              <geometry><sphere><radius>0.1</radius></sphere></geometry></collision>
          </link>
          <joint name="j" type="fixed"><parent>f</parent><child>b</child></joint>
        </model></sdf>""",
        "m",
    )
    b = spec.link("b")
    assert close(b.pose[0], (1.0, 2.0, 1.0))  # a + f's 1 up + 2 along y
    assert close(b.collisions[0].pose[0], (0.0, -2.0, -1.0))  # at a, seen from b
    assert spec.joints[0].parent == "a"  # the frame f moves with link a


def test_nested_models_are_flattened_with_gazebo_scoped_names():
    spec = parse_sdf_model(
        """<sdf version="1.6"><model name="outer">
          <link name="base"/>
          <model name="inner"><pose>0 0 1 0 0 1.5707963267948966</pose>
            <link name="arm"><pose>1 0 0 0 0 0</pose></link>
            <model name="deep"><pose>0 1 0 0 0 0</pose><link name="tip"/></model>
            <joint name="j" type="fixed"><parent>arm</parent><child>deep::tip</child></joint>
          </model>
          <joint name="mount" type="fixed"><parent>base</parent><child>inner::arm</child></joint>
        </model></sdf>""",
        "outer",
    )
    assert [link.name for link in spec.links] == ["base", "inner::arm", "inner::deep::tip"]
    assert close(spec.link("inner::arm").pose[0], (0.0, 1.0, 1.0))  # inner turned 90°: its x is y
    assert close(spec.link("inner::deep::tip").pose[0], (-1.0, 0.0, 1.0))  # deep's y is -x
    assert {(j.name, j.parent, j.child) for j in spec.joints} == {
        ("inner::j", "inner::arm", "inner::deep::tip"),
        ("mount", "base", "inner::arm"),
    }
    assert tree(spec).root.name == "base"


def test_includes_through_the_callers_loader():
    loaded = []

    def include(uri):
        loaded.append(uri)
        if uri == "model://wheel":
            return (box_sdf(name="wheel", mass=3.0), "/models/wheel/model.sdf"), ""
        return None, "not in /models"

    text = """<sdf version="1.6"><model name="cart"><link name="body"/>
      <include><uri>model://wheel</uri><name>left</name><pose>0 1 0 0 0 0</pose></include>
      <joint name="axle" type="revolute"><parent>body</parent><child>left::link</child></joint>
    </model></sdf>"""
    spec = parse_sdf_model(text, "cart", include=include)
    assert loaded == ["model://wheel"]
    assert close(spec.link("left::link").pose[0], (0.0, 1.0, 0.0)) and spec.link("left::link").inertial.mass == 3.0
    missing = refused(text.replace("model://wheel", "model://axle"), include=include)
    assert "model://axle" in str(missing) and "not in /models" in str(missing) and "include" in missing.path
    assert "no loader" in str(refused(text))


def test_a_model_wrapping_static_models_only_is_static():
    """Gazebo's populations wrap the model they replicate (``<model name="can"><include>...``): each
    included model keeps its own static; a wrapper of static models only is static here (one of static
    and moving models is one moving model here, refused unless joints join its links)."""

    def include(uri):
        static = uri == "model://post"
        return (box_sdf(name=uri[8:], static=static), f"/models/{uri[8:]}/model.sdf"), ""

    wrapper = "<sdf version='1.6'><model name='w'>{}</model></sdf>"
    post = "<include><uri>model://post</uri></include>"
    crate = "<include><uri>model://crate</uri></include>"
    assert parse_sdf_model(wrapper.format(post), "w", include=include).static
    with_static = "<include><uri>model://crate</uri><static>true</static></include>"
    assert parse_sdf_model(wrapper.format(with_static), "w", include=include).static
    assert not parse_sdf_model(wrapper.format(crate), "w", include=include).static
    mixed = refused(wrapper.format(post + crate.replace("<uri>", "<name>c</name><uri>")), include=include)
    assert "links that no joint connects" in str(mixed)


def test_a_bare_model_and_a_newer_version():
    bare = parse_sdf_model("<model name='m'><link name='l'/></model>", "m")
    assert bare.links[0].name == "l"
    newer = parse_sdf_model("<sdf version='1.9'><model name='m'><link name='l'/></model></sdf>", "m")
    assert any("read as SDF 1.7" in note for note in newer.notes)


def test_the_model_pose_is_kept_for_the_spawner():
    spec = parse_sdf_model(box_sdf().replace("<static>", "<pose>1 2 3 0 0 0</pose><static>"), "m")
    assert spec.pose == ((1.0, 2.0, 3.0), (0.0, 0.0, 0.0, 1.0))


def test_meshes_found_through_the_finder(tmp_path):
    obj = write_obj(tmp_path / "cube.obj")
    asked = []

    def model_finder(uri):
        asked.append(uri)
        return obj, ""

    text = """<sdf version="1.6"><model name="m"><static>true</static><link name="l">
      <collision name="c">
        <geometry><mesh><uri>model://crop/meshes/cube.obj</uri><scale>2 2 3</scale></mesh></geometry></collision>
      <visual name="v"><geometry><mesh><uri>cube.obj</uri></mesh></geometry></visual></link></model></sdf>"""
    spec = parse_sdf_model(text, "m", default_finder(base_dir=str(tmp_path), model=model_finder))
    assert spec.links[0].collisions[0].geometry == Mesh(obj, (2.0, 2.0, 3.0), "model://crop/meshes/cube.obj")
    assert spec.links[0].visuals[0].geometry.path == os.path.join(str(tmp_path), "cube.obj")
    assert asked == ["model://crop/meshes/cube.obj"]


def test_collada_and_ascii_stl_meshes_are_read(tmp_path):
    for path in (write_dae(tmp_path / "cube.dae"), write_ascii_stl(tmp_path / "cube.stl")):
        text = f"""<model name="m"><link name="l"><collision name="c"><geometry><mesh><uri>{path}</uri></mesh>
        </geometry></collision></link></model>"""
        assert parse_sdf_model(text, "m").links[0].collisions[0].geometry.path == path


# ---- refusals ---------------------------------------------------------------------------------------
def test_model_error_is_a_spawn_error():
    assert issubclass(ModelError, SpawnError)


def test_broken_xml_names_line_and_column():
    e = refused("<sdf version='1.6'><model name='m'><link name='l'></model></sdf>")
    assert e.path.startswith("line 1, column") and "not well-formed" in e.rule


def test_no_model():
    assert "no <model>" in str(refused("<sdf version='1.6'><world name='w'/></sdf>"))
    assert "neither <sdf> nor <model>" in str(refused("<robot name='r'/>"))
    assert "without links" in str(refused("<sdf version='1.6'><model name='m'/></sdf>"))


def test_unknown_joint_parent_and_child():
    e = refused(gate_sdf().replace("<parent>post</parent>", "<parent>pots</parent>"))
    assert e.path.endswith("joint[hinge]/parent") and "'pots'" in e.rule and "post" in e.rule
    e = refused(gate_sdf().replace("<child>door</child>", "<child>dor</child>"))
    assert e.path.endswith("joint[hinge]/child")


def test_a_loop_of_joints():
    e = refused(
        """<sdf version="1.6"><model name="m"><link name="a"/><link name="b"/><link name="c"/>
        <joint name="ab" type="fixed"><parent>a</parent><child>b</child></joint>
        <joint name="bc" type="fixed"><parent>b</parent><child>c</child></joint>
        <joint name="ca" type="fixed"><parent>c</parent><child>a</child></joint></model></sdf>"""
    )
    assert "loop" in e.rule


def test_a_loop_of_relative_poses():
    e = refused(
        """<sdf version="1.7"><model name="m"><link name="a"><pose relative_to="b"/></link>
        <link name="b"><pose relative_to="a"/></link></model></sdf>"""
    )
    assert ("loop" in e.rule and "a -> b -> a" in e.rule) or "b -> a -> b" in e.rule


def test_two_links_of_one_name():
    e = refused("<sdf version='1.6'><model name='m'><link name='l'/><link name='l'/></model></sdf>")
    assert "second link named 'l'" in e.rule


@pytest.mark.parametrize("bad", ["nan", "inf", "1e999", "one"])
def test_numbers_that_are_not_finite(bad):
    e = refused(box_sdf().replace("<mass>2.0</mass>", f"<mass>{bad}</mass>"))
    assert e.path.endswith("link[link]/inertial/mass")
    e = refused(
        box_sdf().replace("<size>0.4 0.4 0.2</size></box></geometry><", f"<size>0.4 {bad} 0.2</size></box></geometry><")
    )
    assert e.path.endswith("collision[collision]/geometry/box/size")


def test_negative_sizes_and_masses():
    assert "must be > 0" in str(refused(box_sdf(size=(0.4, -0.4, 0.2))))
    assert refused(box_sdf(mass=-1.0)).path.endswith("inertial/mass")
    box = "<geometry><box><size>0.4 0.4 0.2</size></box></geometry><"
    e = refused(box_sdf().replace(box, "<geometry><sphere><radius>-1</radius></sphere></geometry><"))
    assert e.path.endswith("geometry/sphere/radius")


def test_an_unresolvable_mesh_names_its_uri_and_where_it_looked(tmp_path):
    text = """<model name="m"><link name="l"><collision name="c"><geometry><mesh><uri>{}</uri></mesh></geometry>
    </collision></link></model>"""
    e = refused(text.format("model://crop/meshes/leaf.dae"))
    assert "model://crop/meshes/leaf.dae" in e.rule and "GAZEBO_MODEL_PATH" in e.rule
    e = refused(text.format("leaf.obj"), default_finder(base_dir=str(tmp_path)))
    assert "leaf.obj" in e.rule and str(tmp_path) in e.rule
    assert e.path.endswith("collision[c]/geometry/mesh/uri")
    e = refused(text.format("package://no_such_package_here/leaf.obj"))
    assert "no_such_package_here" in e.rule


def test_an_unreadable_mesh(tmp_path):
    junk = tmp_path / "junk.obj"
    junk.write_text("this is not a mesh\n")
    ascii_junk = tmp_path / "junk.stl"
    ascii_junk.write_text("solid x\nvertex 1 2\nendsolid\n")
    dae = tmp_path / "junk.dae"
    dae.write_text("<COLLADA><library_geometries/></COLLADA>")
    text = (
        "<model name='m'><link name='l'><collision name='c'>"
        "<geometry><mesh><uri>{}</uri></mesh></geometry></collision></link></model>"
    )
    for path, why in (
        (junk, "no faces"),
        (ascii_junk, "three numbers"),
        (dae, "no triangles"),
        (tmp_path / "x.ply", ""),
    ):
        if why == "":
            path.write_text("ply")
        e = refused(text.format(path))
        assert str(path) in e.rule and why in e.rule


def test_joint_types_not_simulated():
    e = refused(gate_sdf().replace('type="revolute"', 'type="ball"'))
    assert "'ball'" in e.rule and e.path.endswith("joint[hinge]")


def test_a_moving_model_of_links_no_joint_connects():
    e = refused("<sdf version='1.6'><model name='m'><link name='a'/><link name='b'/></model></sdf>")
    assert "no joint connects" in e.rule
    static = parse_sdf_model(
        "<sdf version='1.6'><model name='m'><static>true</static><link name='a'/><link name='b'/></model></sdf>", "m"
    )
    assert [link.name for link in tree(static).loose] == ["b"]


def test_entities_are_refused_unread():
    text = "<?xml version='1.0'?><!DOCTYPE m [<!ENTITY a 'aaaa'>]><model name='m'><link name='&a;'/></model>"
    assert "entities" in refused(text).rule


def test_a_million_links_refused():  # how fast and in how little memory: bench/gazebo_api.py
    e = refused(many_links_sdf(10**6))
    assert f"more than {reading.MAX_LINKS} links" in e.rule


def test_too_long_a_text():
    assert "characters" in refused(" " * (reading.MAX_XML_CHARS + 1)).rule


def test_too_deep_nesting():
    text = "<model name='m0'>" + "".join(f"<model name='m{i}'>" for i in range(1, 20)) + "<link name='l'/>"
    text += "</model>" * 20
    assert "nested more than" in refused(text).rule


def test_poses_compose_as_transforms():
    a = ((1.0, 0.0, 0.0), (0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4)))
    assert close(compose(a, ((1.0, 0.0, 0.0), (0, 0, 0, 1)))[0], (1.0, 1.0, 0.0))
    assert close(rotate_vector(a, (1.0, 0.0, 0.0)), (0.0, 1.0, 0.0))
