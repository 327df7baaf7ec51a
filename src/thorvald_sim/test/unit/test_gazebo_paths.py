"""Gazebo's models and worlds found as Gazebo 11 with gazebo_ros finds them: the model folders' order
(~/.gazebo/models, Gazebo's own, GAZEBO_MODEL_PATH, the packages' exports), model.config's choice of
SDF file, world names in the resource folders, the built-in ground_plane and sun, and every refusal as
a reason, never an exception. No ROS: the packages' exports come from a fake reader."""

import ast
import os

import pytest
from models_fixtures import box_sdf, write_obj

from thorvald_sim.models.gazebo_paths import (
    GROUND_PLANE_SDF,
    GazeboPaths,
    PackageExport,
    included_kind,
)
from thorvald_sim.models.sdf import parse_sdf_model
from thorvald_sim.models.spec import Plane

MODULE = os.path.join(os.path.dirname(__file__), "..", "..", "src", "thorvald_sim", "models", "gazebo_paths.py")


def write(path, text):
    os.makedirs(os.path.dirname(str(path)), exist_ok=True)
    with open(str(path), "w") as f:
        f.write(text)
    return str(path)


def obj(path):
    """A mesh (a cube, OBJ) at path, its folders made."""
    os.makedirs(os.path.dirname(str(path)), exist_ok=True)
    return write_obj(str(path))


def config(*sdfs):
    """A model.config naming (version, file) pairs; version None: no version attribute."""
    elements = "".join(
        f"<sdf>{name}</sdf>" if version is None else f'<sdf version="{version}">{name}</sdf>' for version, name in sdfs
    )
    return f'<?xml version="1.0"?><model><name>m</name><version>1.0</version>{elements}</model>'


def add_model(folder, name, sdf_name="model.sdf", text=None):
    """A model NAME in folder: model.config naming sdf_name (SDF 1.6), and that file (a box by default)."""
    write(os.path.join(str(folder), name, "model.config"), config(("1.6", sdf_name)))
    write(os.path.join(str(folder), name, sdf_name), text or box_sdf(name=name))
    return os.path.join(str(folder), name)


def gazebo(model_path=(), resource_path=(), *, exports=(), home=None, share=None, packages=None):
    env = {"GAZEBO_MODEL_PATH": ":".join(str(p) for p in model_path)}
    env["GAZEBO_RESOURCE_PATH"] = ":".join(str(p) for p in resource_path)
    if home is not None:
        env["HOME"] = str(home)
    return GazeboPaths(
        env,
        exports=lambda: list(exports),
        gazebo_share=None if share is None else str(share),
        package_folder=(packages or {}).get,
    )


def test_a_model_in_the_second_gazebo_model_path_folder(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    a.mkdir()
    crop = add_model(b, "crop")
    paths = gazebo([a, b])
    assert paths.find_model("model://crop") == (crop, "")
    (text, source), why = paths.model_sdf("model://crop")
    assert source == os.path.join(crop, "model.sdf") and 'model name="crop"' in text and why == ""


def test_the_first_folder_wins_when_both_have_the_model(tmp_path):
    first = add_model(tmp_path / "a", "crop")
    add_model(tmp_path / "b", "crop")
    assert gazebo([tmp_path / "a", tmp_path / "b"]).find_model("model://crop") == (first, "")
    assert gazebo([tmp_path / "b", tmp_path / "a"]).find_model("model://crop")[0] != first


def test_gazebos_order_home_then_its_own_then_the_environment_then_packages(tmp_path):
    home_crop = add_model(tmp_path / "home" / ".gazebo" / "models", "crop")
    share_crop = add_model(tmp_path / "share" / "models", "crop")
    env_crop = add_model(tmp_path / "env", "crop")
    package_crop = add_model(tmp_path / "farm" / "models", "crop")
    exports = [PackageExport("farm", str(tmp_path / "farm"), {"gazebo_model_path": "${prefix}/models"})]
    every = dict(model_path=[tmp_path / "env"], exports=exports, home=tmp_path / "home", share=tmp_path / "share")
    paths = gazebo(**every)
    assert [f.origin for f in paths.model_folders] == [
        "~/.gazebo/models",
        "Gazebo's own",
        "GAZEBO_MODEL_PATH",
        "gazebo_model_path of package farm",
    ]
    assert paths.find_model("model://crop")[0] == home_crop
    del every["home"]
    assert gazebo(**every).find_model("model://crop")[0] == share_crop
    del every["share"]
    assert gazebo(**every).find_model("model://crop")[0] == env_crop
    del every["model_path"]
    assert gazebo(**every).find_model("model://crop")[0] == package_crop


def test_a_package_export_with_prefix_for_models_and_media(tmp_path):
    farm = tmp_path / "farm_worlds"
    vine = add_model(farm / "models", "vine")
    world = write(farm / "media" / "worlds" / "vineyard.world", "<sdf version='1.6'><world name='v'/></sdf>")
    exports = [
        PackageExport("other", str(tmp_path / "other"), {"plugin_path": "${prefix}/lib"}),
        PackageExport(
            "farm_worlds",
            str(farm),
            {"gazebo_model_path": "${prefix}/models:${prefix}/more", "gazebo_media_path": "${prefix}/media"},
        ),
    ]
    paths = gazebo([tmp_path / "env"], exports=exports)
    assert paths.find_model("model://vine") == (vine, "")
    assert paths.find_world("worlds/vineyard.world") == (world, "")
    assert [f.path for f in paths.model_folders][1:] == [str(farm / "models"), str(farm / "more")]
    assert [f.origin for f in paths.resource_folders] == ["gazebo_media_path of package farm_worlds"]


@pytest.mark.parametrize(
    "sdfs, chosen",
    [
        ([("1.5", "a.sdf"), ("1.6", "b.sdf"), ("1.8", "c.sdf")], "b.sdf"),  # the highest not newer than 1.7
        ([("1.8", "c.sdf"), ("1.6", "b.sdf"), ("1.5", "a.sdf")], "b.sdf"),  # in any order
        ([("1.8", "c.sdf"), ("1.9", "d.sdf")], "c.sdf"),  # none readable: the first <sdf>
        ([("1.6", "a.sdf"), ("1.6", "b.sdf")], "a.sdf"),  # equals: the first
        ([(None, "a.sdf"), ("1.4", "b.sdf")], "b.sdf"),  # no version: not chosen over a versioned one
        ([(None, "a.sdf")], "a.sdf"),
        ([("1.7.0", "a.sdf"), ("1.10", "b.sdf")], "a.sdf"),  # versions compare as numbers: 1.10 > 1.7
    ],
)
def test_model_config_chooses_the_sdf_file_as_gazebo_does(tmp_path, sdfs, chosen):
    folder = tmp_path / "models" / "crop"
    write(folder / "model.config", config(*sdfs))
    for _, name in sdfs:
        write(folder / name, f"<sdf version='1.6'><model name='{name}'><link name='l'/></model></sdf>")
    (text, source), why = gazebo([tmp_path / "models"]).model_sdf("model://crop")
    assert source == str(folder / chosen) and f"name='{chosen}'" in text and why == ""


def test_the_deprecated_manifest_xml_is_read_without_a_model_config(tmp_path):
    folder = tmp_path / "models" / "crop"
    write(folder / "manifest.xml", config(("1.5", "crop.sdf")))
    write(folder / "crop.sdf", box_sdf(name="crop"))
    (_, source), _ = gazebo([tmp_path / "models"]).model_sdf("model://crop")
    assert source == str(folder / "crop.sdf")


def test_a_missing_model_names_the_uri_and_every_folder_searched(tmp_path):
    a, b, farm = tmp_path / "a", tmp_path / "b", tmp_path / "farm"
    for folder in (a, b, farm / "models"):
        folder.mkdir(parents=True)
    exports = [PackageExport("farm_worlds", str(farm), {"gazebo_model_path": "${prefix}/models"})]
    paths = gazebo([a, b, tmp_path / "gone"], exports=exports)
    found, why = paths.find_model("model://crop")
    assert found is None
    assert why == (
        f"model://crop not found in: {a}, {b}, {tmp_path / 'gone'} [no such folder] (GAZEBO_MODEL_PATH), "
        f"{farm / 'models'} (gazebo_model_path of package farm_worlds)"
    )
    assert paths.model_sdf("model://crop") == (None, why)
    assert gazebo().find_model("model://crop") == (
        None,
        "model://crop not found: no model folders (GAZEBO_MODEL_PATH is not set, there is no ~/.gazebo/models "
        "and no package exports gazebo_model_path)",
    )


def test_every_folder_searched_is_said_in_order(tmp_path):
    paths = gazebo([tmp_path / "m1", tmp_path / "m2"], [tmp_path / "r"])
    assert paths.searched() == (
        f"model folders: {tmp_path / 'm1'} [no such folder], {tmp_path / 'm2'} [no such folder] (GAZEBO_MODEL_PATH); "
        f"resource folders: {tmp_path / 'r'} [no such folder] (GAZEBO_RESOURCE_PATH)"
    )


def test_empty_and_repeated_path_entries_are_skipped(tmp_path):
    paths = GazeboPaths({"GAZEBO_MODEL_PATH": f"::{tmp_path}:{tmp_path}:"}, exports=lambda: [], gazebo_share=None)
    assert [f.path for f in paths.model_folders] == [str(tmp_path)]


def test_worlds_empty_world_is_found_under_a_resource_folder(tmp_path, monkeypatch):
    first, second = tmp_path / "r1", tmp_path / "r2"
    first.mkdir()
    empty = write(second / "worlds" / "empty.world", "<sdf version='1.6'><world name='default'/></sdf>")
    paths = gazebo(resource_path=[first, second])
    assert paths.find_world("worlds/empty.world") == (empty, "")
    assert paths.find_world(empty) == (empty, "")  # an existing path as it is
    assert paths.find_world("file://" + empty) == (empty, "")
    monkeypatch.chdir(second)
    assert paths.find_world("worlds/empty.world") == ("worlds/empty.world", "")  # relative to where it runs
    found, why = paths.find_world("worlds/farm.world")
    assert found is None and why == f"world worlds/farm.world not found in: {first}, {second} (GAZEBO_RESOURCE_PATH)"
    assert paths.find_world("") == (None, "an empty world_name names no world")
    assert "a folder" in paths.find_world(str(second))[1]
    assert "no such file" in paths.find_world(str(tmp_path / "nowhere.world"))[1]


def test_gazebos_own_share_folder_holds_its_worlds(tmp_path):
    empty = write(tmp_path / "share" / "worlds" / "empty.world", "<sdf version='1.6'><world name='default'/></sdf>")
    paths = gazebo(resource_path=[tmp_path / "user"], share=tmp_path / "share")
    assert paths.find_world("worlds/empty.world") == (empty, "")
    assert [f.origin for f in paths.resource_folders] == ["Gazebo's own", "GAZEBO_RESOURCE_PATH"]


def test_ground_plane_and_sun_are_built_in_unless_a_folder_has_them(tmp_path):
    paths = gazebo([tmp_path])
    (text, source), why = paths.model_sdf("model://ground_plane")
    assert text == GROUND_PLANE_SDF and "built in" in source and why == ""
    assert included_kind(text) == "model"
    (sun, _), _ = paths.model_sdf("model://sun")
    assert included_kind(sun) == "light"  # a light: nothing for the physics to build
    assert paths.find_model("model://sun")[0] is None
    write(tmp_path / "x" / "ground_plane", "a file first on the path hides the built-in too")
    assert "is not a folder" in gazebo([tmp_path / "x", tmp_path]).model_sdf("model://ground_plane")[1]
    own = add_model(tmp_path, "ground_plane", text=box_sdf(name="my_ground"))
    (text, source), _ = gazebo([tmp_path]).model_sdf("model://ground_plane")
    assert source == os.path.join(own, "model.sdf") and "my_ground" in text


def test_the_built_in_ground_plane_is_a_static_model_with_one_plane(tmp_path):
    spec = parse_sdf_model(GROUND_PLANE_SDF, "ground_plane")
    assert spec.static and len(spec.links) == 1
    (collision,) = spec.links[0].collisions
    assert collision.geometry == Plane((0.0, 0.0, 1.0), (100.0, 100.0))
    assert (collision.surface.mu, collision.surface.mu2) == (100.0, 50.0)


def test_included_kind_of_texts():
    assert included_kind("<model name='m'/>") == "model"
    assert included_kind("<sdf version='1.6'><actor name='a'/></sdf>") == "actor"
    assert included_kind("<sdf version='1.6'><world name='w'/></sdf>") is None
    assert included_kind("<sdf") is None


def test_find_file_for_model_file_package_and_relative_uris(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    add_model(a, "crop")  # no meshes here: the file is looked for on the rest of the path
    leaf = obj(b / "crop" / "meshes" / "leaf.obj")
    paths = gazebo([a, b], resource_path=[tmp_path / "media"], packages={"farm": str(tmp_path / "farm")})
    assert paths.find_file("model://crop/meshes/leaf.obj") == (leaf, "")
    found, why = paths.find_file("model://crop/meshes/stem.obj")
    assert found is None and why.startswith("model://crop/meshes/stem.obj not found in:") and str(b) in why
    assert paths.find_file("model://crop")[1].endswith("is not a file")
    assert paths.find_file("file://" + leaf) == (leaf, "")
    assert paths.find_file(leaf) == (leaf, "")
    assert paths.find_file(str(tmp_path / "no.obj")) == (None, f"{tmp_path / 'no.obj'}: no such file")
    mesh = obj(tmp_path / "leaf2.obj")
    assert paths.find_file("leaf2.obj", base_dir=str(tmp_path)) == (mesh, "")
    assert paths.finder(str(tmp_path))("leaf2.obj") == (mesh, "")
    texture = write(tmp_path / "media" / "media" / "models" / "bark.png", "")
    assert paths.find_file("bark.png", base_dir=str(a)) == (texture, "")  # then the resource folders
    found, why = paths.find_file("bark2.png", base_dir=str(a))
    assert found is None and str(a) in why and "(the model's folder)" in why and "GAZEBO_RESOURCE_PATH" in why
    part = write(tmp_path / "farm" / "meshes" / "post.stl", "")
    assert paths.find_file("package://farm/meshes/post.stl") == (part, "")
    assert "not installed" in paths.find_file("package://orchard/meshes/post.stl")[1]
    assert "has no meshes/gate.stl" in paths.find_file("package://farm/meshes/gate.stl")[1]
    assert "only model://" in paths.find_file("http://example.org/x.dae")[1]
    assert paths.find_file("") == (None, "an empty URI names no file")


def test_model_sdf_and_find_file_serve_parse_sdf_model(tmp_path):
    models = tmp_path / "models"
    obj(models / "crop" / "meshes" / "leaf.obj")
    leaf = """<sdf version="1.6"><model name="crop"><link name="leaf"><collision name="c"><geometry>
      <mesh><uri>model://crop/meshes/leaf.obj</uri></mesh></geometry></collision></link></model></sdf>"""
    write(models / "crop" / "model.config", config(("1.6", "model.sdf")))
    write(models / "crop" / "model.sdf", leaf)
    paths = gazebo([models])
    row = """<sdf version="1.6"><model name="row"><static>true</static><include><uri>model://crop</uri><name>c1</name></include>
      <include><uri>model://ground_plane</uri></include></model></sdf>"""
    spec = parse_sdf_model(row, "row.sdf", find=paths.find_file, include=paths.model_sdf)
    assert sorted(link.name for link in spec.links) == ["c1::leaf", "ground_plane::link"]


@pytest.mark.parametrize(
    "files, uri, reason",
    [
        ({"crop/model.config": "<model><sdf version='1.6'>model.sdf"}, "model://crop", "not well-formed XML"),
        ({"crop/model.config": "<sdf version='1.6'/>"}, "model://crop", "has <sdf>, not <model>"),
        ({"crop/model.config": "<model><name>c</name></model>"}, "model://crop", "names no SDF file"),
        ({"crop/model.config": "<model><sdf version='1.6'> </sdf></model>"}, "model://crop", "names no SDF file"),
        ({"crop/model.config": config(("1.6", "crop.sdf"))}, "model://crop", "names crop.sdf, and there is no such"),
        ({"crop/meshes/leaf.obj": ""}, "model://crop", "has no model.config, which Gazebo needs"),
        ({"crop/model.sdf": box_sdf()}, "model://crop", "it has a model.sdf: a model.config must name it"),
        ({"crop": "a file"}, "model://crop", "is not a folder, and Gazebo takes the first match"),
        ({}, "model://", "names no model"),
        ({}, "model://../x", "names no model"),
        ({}, "package://farm/crop", "is not a model:// URI"),
        ({}, "", "is not a model:// URI"),
    ],
)
def test_bad_models_give_a_reason_not_an_exception(tmp_path, files, uri, reason):
    for name, text in files.items():
        write(tmp_path / "models" / name, text)
    paths = gazebo([tmp_path / "models", tmp_path / "later"])
    add_model(tmp_path / "later", "crop")  # hidden by a bad crop earlier on the path, as in Gazebo
    found, why = paths.model_sdf(uri)
    assert found is None and reason in why, why
    if uri == "model://crop":
        assert why.startswith("model://crop: ")


def test_a_model_config_that_is_not_utf8_or_unreadable(tmp_path):
    folder = tmp_path / "models" / "crop"
    folder.mkdir(parents=True)
    (folder / "model.config").write_bytes(b"<model>\xff\xfe</model>")
    assert "is not UTF-8 text" in gazebo([tmp_path / "models"]).model_sdf("model://crop")[1]
    write(folder / "model.config", config(("1.6", "sub")))
    (folder / "sub").mkdir()
    assert "no such file" in gazebo([tmp_path / "models"]).model_sdf("model://crop")[1]


def test_an_exports_reader_that_fails_leaves_the_environments_folders(tmp_path):
    crop = add_model(tmp_path, "crop")

    def broken():
        raise RuntimeError("no package.xml today")

    paths = GazeboPaths({"GAZEBO_MODEL_PATH": str(tmp_path)}, exports=broken, gazebo_share=None)
    assert paths.find_model("model://crop") == (crop, "")
    found, why = paths.find_model("model://vine")
    assert found is None and why.endswith("the packages' gazebo_ros exports could not be read: no package.xml today")
    odd = GazeboPaths({}, exports=lambda: [("farm", str(tmp_path), {"gazebo_model_path": 3})], gazebo_share=None)
    assert odd.model_folders == () and odd.problems == []


def test_the_module_imports_no_pybullet_nor_ros_at_its_top():
    with open(MODULE) as f:
        module = ast.parse(f.read())
    top = {a.name for n in module.body if isinstance(n, ast.Import) for a in n.names}
    top |= {n.module or "" for n in module.body if isinstance(n, ast.ImportFrom)}
    assert not {m for m in top if "bullet" in m or m.startswith(("rospy", "rospkg", "gazebo"))}
    everywhere = {a.name for n in ast.walk(module) if isinstance(n, ast.Import) for a in n.names}
    assert not {m for m in everywhere if "bullet" in m or m.startswith("rospy")}
