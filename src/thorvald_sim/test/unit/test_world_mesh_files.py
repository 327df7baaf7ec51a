"""Mesh files a world names are read at load: a file that is not a mesh pybullet can load (junk
bytes, an STL of no triangles or of the wrong size, an ASCII STL, an OBJ without faces, ...) is
refused naming the file, the key path and why, instead of pybullet's "createCollisionShape failed."
(or, for a moving object, a crash of the whole simulator)."""

import os
import random
import struct

import pybullet as p
import pytest
import yaml
from sim_test_helpers import world_problems

from thorvald_sim.physics.scene import build_scene
from thorvald_sim.world import ConfigError, load_world, mesh_check, parse_world, worlds_dir
from thorvald_sim.world.kinds import objects as objects_kind
from thorvald_sim.world.mesh_check import mesh_problem

CRATE = os.path.join(worlds_dir(), "meshes", "crate.obj")
TRIANGLE = b"v 0 0 0\nv 1 0 0\nv 0 1 0\n"


def stl(triangles, header=b"\0" * 80, count=None):
    """A binary STL of the given triangles (three corners each), saying count triangles (default: as many)."""
    data = header + struct.pack("<I", len(triangles) if count is None else count)
    for corners in triangles:
        data += struct.pack("<3f", 0, 0, 1) + b"".join(struct.pack("<3f", *c) for c in corners) + b"\0\0"
    return data


ONE = [((0, 0, 0), (1, 0, 0), (0, 1, 0))]
# binary junk: a file some program wrote, not a mesh (its second byte a NUL)
JUNK = b"\x89\x00\xff\xfe" + bytes(random.Random(4).getrandbits(8) for _ in range(2996))
NO_FACES = "an OBJ file with no faces (f lines), so nothing to collide with"

# file name: (bytes, why it is not a mesh)
NOT_MESHES = {
    "junk.obj": (JUNK, "binary bytes (a NUL byte at offset 1), not an OBJ file, which is text"),
    "empty.obj": (b"", NO_FACES + " (0 vertices)"),
    "text.obj": (b"this is not a mesh\n", NO_FACES + " (0 vertices)"),
    "points.obj": (TRIANGLE, NO_FACES + " (3 vertices)"),
    "beyond.obj": (TRIANGLE + b"f 1 2 4\n", "line 4 names vertex 4 of an OBJ file of 3 vertices"),
    "back.obj": (TRIANGLE + b"f -1 -2 -4\n", "line 4 names vertex -4 with 3 vertices before it"),
    "edge.obj": (TRIANGLE + b"f 1 2\n", "line 4 is a face of fewer than three vertices"),
    "word.obj": (TRIANGLE + b"f 1 2 three\n", "line 4 is a face naming 'three', not a vertex index"),
    "nan.obj": (b"v 0 0 nan\n" + TRIANGLE + b"f 2 3 4\n", "line 1 is a vertex without three finite numbers x y z"),
    "flat.obj": (b"v 0 0\n" + TRIANGLE + b"f 2 3 4\n", "line 1 is a vertex without three finite numbers x y z"),
    "none.stl": (stl([]), "an STL file with no triangles"),
    "short.stl": (stl(ONE, count=5), "not a binary STL file: 134 bytes, not the 334 its header's 5 triangles take"),
    "tiny.stl": (b"\0" * 40, "not an STL file: 40 bytes, shorter than a binary STL's 84-byte header"),
    "ascii.stl": (
        b"solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 1 0\nendloop\nendfacet\n"
        b"endsolid t\n",
        "an ASCII STL file; pybullet reads binary STL only (export it as binary STL)",
    ),
    "junk.stl": (JUNK, "not a binary STL file: 3000 bytes, not the "),
    "nan.stl": (stl([*ONE, ((0, 0, 0), (float("nan"), 0, 0), (0, 1, 0))]), "triangle 1 of the STL file has a corner"),
}

MESHES = {
    "cube.stl": stl([((0, 0, 0), (1, 0, 0), (0, 1, 0)), ((1, 0, 0), (1, 1, 0), (0, 1, 0))] * 2),
    # a binary STL whose header begins with "solid", as some exporters write it: its size says binary
    "solid.stl": stl(ONE, header=b"solid exported by a CAD tool".ljust(80, b" ")),
    "quads.obj": TRIANGLE + b"v 1 1 0\nvn 0 0 1\nvt 0 0\nf 1/1/1 2/1/1 4/1/1 3/1/1\nf -4//1 -3//1 -2//1\n",
    "comments.obj": b"# made by hand\r\no tri\r\n" + TRIANGLE.replace(b"\n", b"\r\n") + b"f 1 2 3\r\n",
}


def mesh_object(file, **keys):
    return {"objects": {"object0": {"shape": "mesh", "x": 0, "y": 0, "file": file, **keys}}}


@pytest.mark.parametrize("name", sorted(NOT_MESHES))
def test_a_file_that_is_not_a_mesh_is_refused_with_the_file_key_path_and_why(tmp_path, name):
    data, why = NOT_MESHES[name]
    (tmp_path / name).write_bytes(data)
    # moving (mass above 0): pybullet would crash on a bad STL; static: it would say it failed
    found = world_problems(mesh_object(name, mass=2.0), base_dir=str(tmp_path))
    assert list(found) == ["objects.object0.file"]
    problem = found["objects.object0.file"]
    assert problem.value == name
    prefix = f"is not a mesh pybullet can load ({tmp_path / name}): "
    assert problem.rule.startswith(prefix + why), problem.rule


def test_the_whole_message_names_the_world_file_the_key_the_value_and_the_mesh(tmp_path):
    (tmp_path / "meshes").mkdir()
    (tmp_path / "meshes" / "none.stl").write_bytes(stl([]))
    path = tmp_path / "world.yaml"
    path.write_text(yaml.safe_dump(mesh_object("meshes/none.stl")))
    with pytest.raises(ConfigError) as e:
        load_world(str(path))
    assert str(e.value).splitlines()[1] == (
        f"  {path}: objects.object0.file: 'meshes/none.stl': is not a mesh pybullet can load"
        f" ({tmp_path / 'meshes' / 'none.stl'}): an STL file with no triangles"
    )


@pytest.mark.parametrize("name", sorted(MESHES))
def test_real_meshes_pass_and_pybullet_loads_them(client, tmp_path, name):
    (tmp_path / name).write_bytes(MESHES[name])
    assert mesh_problem(str(tmp_path / name)) is None
    for mass in (0.0, 1.0):
        scene = build_scene(client, parse_world(mesh_object(name, mass=mass), base_dir=str(tmp_path)))
        assert scene.bodies["objects.object0"] >= 0


def test_the_shipped_crate_is_a_mesh():
    assert mesh_problem(CRATE) is None


@pytest.mark.parametrize("name", ["junk.obj", "empty.obj", "points.obj", "none.stl", "short.stl", "ascii.stl"])
def test_what_the_check_refuses_pybullet_cannot_load_either(client, tmp_path, name):
    # static (a concave triangle mesh): pybullet fails cleanly; moving it would crash the process
    (tmp_path / name).write_bytes(NOT_MESHES[name][0])
    with pytest.raises(p.error, match="createCollisionShape failed"):
        p.createCollisionShape(
            p.GEOM_MESH, fileName=str(tmp_path / name), flags=p.GEOM_FORCE_CONCAVE_TRIMESH, physicsClientId=client
        )


def test_a_file_named_by_many_objects_is_read_once(tmp_path, monkeypatch):
    (tmp_path / "cube.stl").write_bytes(MESHES["cube.stl"])
    read = []
    monkeypatch.setattr(objects_kind, "mesh_problem", lambda path: read.append(path) or mesh_check.mesh_problem(path))
    objects = {f"object{i}": {"shape": "mesh", "x": i, "y": 0, "file": "cube.stl"} for i in range(5)}
    assert len(parse_world({"objects": objects}, base_dir=str(tmp_path)).objects) == 5
    assert read == [str(tmp_path / "cube.stl")]


def test_a_missing_or_unreadable_mesh_is_its_own_problem(tmp_path):
    (tmp_path / "folder.obj").mkdir()
    found = world_problems(mesh_object("folder.obj"), base_dir=str(tmp_path))
    assert found["objects.object0.file"].rule.startswith("no such file: ")
    assert mesh_problem(str(tmp_path / "folder.obj")) == "cannot be read: Is a directory"
    assert mesh_problem(str(tmp_path / "mesh.ply")) == "not a mesh file: its name ends in none of .obj, .stl, .dae"


# ---------------------------------------------------------------------------------------------
# COLLADA (not a world's object file: pybullet makes no collision shape of one; checked for the
# files that name them elsewhere)
# ---------------------------------------------------------------------------------------------
COLLADA = (
    b'<?xml version="1.0"?>\n<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">'
    b"<library_geometries><geometry><mesh>{faces}</mesh></geometry></library_geometries></COLLADA>"
)


@pytest.mark.parametrize(
    ("data", "why"),
    [
        (COLLADA.replace(b"{faces}", b'<triangles count="1"><p>0 1 2</p></triangles>'), None),
        (COLLADA.replace(b"{faces}", b'<polylist count="1"><vcount>3</vcount></polylist>'), None),
        (COLLADA.replace(b"{faces}", b""), "a COLLADA file with no faces (triangles, polylist, polygons, "),
        (b'<?xml version="1.0"?><mesh><triangles/></mesh>', "not COLLADA XML: its root element is <mesh>"),
        (JUNK, "not COLLADA XML: "),
        (b"", "not COLLADA XML: no element found"),
        (
            b'<?xml version="1.0"?><!DOCTYPE c [<!ENTITY a "aaaaaaaaaa"><!ENTITY b "&a;&a;&a;&a;&a;&a;">]>'
            b"<COLLADA>&b;</COLLADA>",
            "not a COLLADA file: it declares a DOCTYPE or entities",
        ),
    ],
)
def test_a_dae_must_be_collada_xml_with_faces(tmp_path, data, why):
    (tmp_path / "thing.dae").write_bytes(data)
    found = mesh_problem(str(tmp_path / "thing.dae"))
    assert found is None if why is None else found.startswith(why), found
