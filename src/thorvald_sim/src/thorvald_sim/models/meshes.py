"""Mesh files pybullet cannot read itself, read here as triangles: COLLADA (.dae) and ASCII STL.

pybullet 3.2.7's ``createCollisionShape(GEOM_MESH, fileName=...)`` reads OBJ and binary STL only
(checked: a .dae gives "createCollisionShape failed."; :mod:`thorvald_sim.world.mesh_check` records that it
reads no ASCII STL). Gazebo reads all four. So a .dae or ASCII .stl is read here into triangles and
written once per process as an OBJ file (:func:`pybullet_file`), which pybullet then loads like any
other (its file loader has no vertex limit; ``vertices=`` takes at most 131072).

COLLADA as Gazebo's ColladaLoader reads it (gazebo-classic, gazebo/common/ColladaLoader.cc): the
scene's nodes from ``<scene><instance_visual_scene>``, each node's ``<matrix>`` or its ``<translate>``,
``<rotate>`` s and ``<scale>`` composed down the tree, ``<instance_geometry>`` and ``<instance_node>``,
every ``<triangles>``, ``<polylist>``, ``<polygons>``, ``<trifans>`` and ``<tristrips>`` of a mesh
(polygons as fans), all scaled by ``<asset><unit meter>``; ``<up_axis>`` is ignored, as Gazebo ignores
it. Skins and animations are not read.

Pure: no pybullet (numpy).
"""

import atexit
import os
import shutil
import tempfile
import xml.etree.ElementTree as ET
from typing import Dict, List, Optional, Tuple

import numpy as np

from ..errors import MeshReadError

MAX_TRIANGLES = 2_000_000  # of one mesh file read here

STL_HEADER = 80
STL_TRIANGLE = 50


def is_ascii_stl(path: str) -> bool:
    """Whether the STL file is ASCII: it starts with ``solid`` and its size is not the binary size its
    header announces (binary files may start with ``solid`` too)."""
    size = os.path.getsize(path)
    with open(path, "rb") as f:
        head = f.read(STL_HEADER + 4)
    if len(head) == STL_HEADER + 4:
        count = int.from_bytes(head[STL_HEADER:], "little")
        if size == STL_HEADER + 4 + STL_TRIANGLE * count:
            return False
    return head.lstrip()[:5].lower() == b"solid"


def read_triangles(path: str) -> Tuple[np.ndarray, np.ndarray]:
    """(vertices (n, 3) [m, before the model's scale], triangles (m, 3) vertex indices) of a .dae or
    .stl file; MeshReadError saying why it cannot be read."""
    extension = os.path.splitext(path)[1].lower()
    try:
        with open(path, "rb") as f:
            data = f.read()
    except OSError as e:
        raise MeshReadError(f"cannot be read: {e.strerror}") from None
    if extension == ".dae":
        vertices, triangles = _collada(data)
    elif extension == ".stl":
        vertices, triangles = _ascii_stl(data) if is_ascii_stl(path) else _binary_stl(data)
    else:
        raise MeshReadError(f"{extension} files are read by pybullet itself, not here")
    if len(triangles) == 0:
        raise MeshReadError("no triangles, so nothing to collide with")
    if len(triangles) > MAX_TRIANGLES:
        raise MeshReadError(f"{len(triangles)} triangles, more than {MAX_TRIANGLES}")
    if not np.isfinite(vertices).all():
        raise MeshReadError("a vertex that is not a finite number")
    return vertices, triangles


def _binary_stl(data: bytes) -> Tuple[np.ndarray, np.ndarray]:
    count = int.from_bytes(data[STL_HEADER : STL_HEADER + 4], "little")
    record = np.dtype([("numbers", "<f4", (12,)), ("attribute", "<u2")])
    numbers = np.frombuffer(data, dtype=record, count=count, offset=STL_HEADER + 4)["numbers"]
    vertices = numbers[:, 3:].reshape(-1, 3).astype(np.float64)
    return vertices, np.arange(len(vertices), dtype=np.int64).reshape(-1, 3)


def _ascii_stl(data: bytes) -> Tuple[np.ndarray, np.ndarray]:
    corners: List[Tuple[float, float, float]] = []
    for number, line in enumerate(data.decode("utf-8", errors="replace").splitlines(), 1):
        words = line.split()
        if words and words[0].lower() == "vertex":
            try:
                x, y, z = (float(w) for w in words[1:4])
            except ValueError:
                raise MeshReadError(f"line {number}: a vertex without three numbers x y z") from None
            corners.append((x, y, z))
            if len(corners) > 3 * MAX_TRIANGLES:
                raise MeshReadError(f"more than {MAX_TRIANGLES} triangles")
    if len(corners) % 3:
        raise MeshReadError(f"{len(corners)} vertices, not three a facet")
    vertices = np.array(corners, dtype=np.float64).reshape(-1, 3)
    return vertices, np.arange(len(vertices), dtype=np.int64).reshape(-1, 3)


# ---- COLLADA --------------------------------------------------------------------------------------
def _local(tag: str) -> str:
    return tag.rsplit("}", 1)[-1]


class _Collada:
    def __init__(self, root: ET.Element):
        for element in root.iter():
            element.tag = _local(element.tag)
        self.root = root
        self.ids: Dict[str, ET.Element] = {e.get("id", ""): e for e in root.iter() if e.get("id")}
        self.vertices: List[np.ndarray] = []
        self.triangles: List[np.ndarray] = []
        self.count = 0  # vertices so far
        self.depth = 0

    def element(self, url: Optional[str], tag: str) -> ET.Element:
        element = self.ids.get((url or "").lstrip("#"))
        if element is None or element.tag != tag:
            raise MeshReadError(f"no <{tag}> of id {url!r}")
        return element

    def node(self, node: ET.Element, transform: np.ndarray) -> None:
        self.depth += 1
        if self.depth > 64:
            raise MeshReadError("nodes nested more than 64 deep (an <instance_node> loop?)")
        transform = transform @ _node_transform(node)
        for child in node.findall("node"):
            self.node(child, transform)
        for instance in node.findall("instance_node"):
            self.node(self.element(instance.get("url"), "node"), transform)
        for instance in node.findall("instance_geometry"):
            self.geometry(self.element(instance.get("url"), "geometry"), transform)
        self.depth -= 1

    def geometry(self, geometry: ET.Element, transform: np.ndarray) -> None:
        mesh = geometry.find("mesh")
        if mesh is None:
            return  # splines and convex meshes: nothing Gazebo draws either
        for primitive in mesh:
            if primitive.tag in ("triangles", "polylist", "polygons", "trifans", "tristrips"):
                self.primitive(mesh, primitive, transform)

    def primitive(self, mesh: ET.Element, primitive: ET.Element, transform: np.ndarray) -> None:
        inputs = primitive.findall("input")
        if not inputs:
            return
        stride = max(int(i.get("offset", "0")) for i in inputs) + 1
        vertex_input = next((i for i in inputs if i.get("semantic") == "VERTEX"), None)
        if vertex_input is None:
            raise MeshReadError(f"a <{primitive.tag}> without a VERTEX input")
        offset = int(vertex_input.get("offset", "0"))
        positions = self.positions(vertex_input.get("source"))
        lists = [_ints(p.text) for p in primitive.findall("p")]
        kind = primitive.tag
        if kind in ("triangles", "polylist"):
            indices = np.concatenate(lists) if lists else np.zeros(0, dtype=np.int64)
            corners = indices.reshape(-1, stride)[:, offset] if len(indices) % stride == 0 else None
            if corners is None:
                raise MeshReadError(f"a <{kind}> whose <p> is not a whole number of vertices")
            if kind == "triangles":
                faces = corners[: len(corners) // 3 * 3].reshape(-1, 3)
            else:
                counts = _ints(primitive.findtext("vcount", ""))
                if counts.sum() != len(corners):
                    raise MeshReadError("a <polylist> whose <vcount> does not add up to its <p>")
                faces = _fans(np.split(corners, np.cumsum(counts)[:-1]))
        else:
            polygons = [p.reshape(-1, stride)[:, offset] for p in lists if len(p) % stride == 0]
            faces = _strips(polygons) if kind == "tristrips" else _fans(polygons)
        if len(faces) == 0:
            return
        if faces.min() < 0 or faces.max() >= len(positions):
            raise MeshReadError("a face naming a vertex the mesh does not have")
        used = np.unique(faces)
        points = positions[used]
        points = (np.c_[points, np.ones(len(points))] @ transform.T)[:, :3]
        remap = np.full(len(positions), -1, dtype=np.int64)
        remap[used] = np.arange(len(used)) + self.count
        self.vertices.append(points)
        self.triangles.append(remap[faces])
        self.count += len(points)
        if sum(len(t) for t in self.triangles) > MAX_TRIANGLES:
            raise MeshReadError(f"more than {MAX_TRIANGLES} triangles")

    def positions(self, url: Optional[str]) -> np.ndarray:
        element = self.ids.get((url or "").lstrip("#"))
        if element is not None and element.tag == "vertices":
            position = next((i for i in element.findall("input") if i.get("semantic") == "POSITION"), None)
            if position is None:
                raise MeshReadError(f"<vertices> {url!r} without a POSITION input")
            element = self.ids.get((position.get("source") or "").lstrip("#"))
        if element is None or element.tag != "source":
            raise MeshReadError(f"no vertex positions of id {url!r}")
        array = element.find("float_array")
        if array is None:
            raise MeshReadError(f"source {element.get('id')!r} without a <float_array>")
        values = _floats(array.text)
        accessor = element.find("technique_common/accessor")
        stride = int(accessor.get("stride", "3")) if accessor is not None else 3
        if stride < 3 or len(values) % stride:
            raise MeshReadError(f"source {element.get('id')!r}: {len(values)} numbers, not points of {stride}")
        return values.reshape(-1, stride)[:, :3]


def _collada(data: bytes) -> Tuple[np.ndarray, np.ndarray]:
    if b"<!DOCTYPE" in data or b"<!ENTITY" in data:
        raise MeshReadError("not a COLLADA file: it declares a DOCTYPE or entities, which COLLADA files do not use")
    try:
        root = ET.fromstring(data)
    except ET.ParseError as e:
        raise MeshReadError(f"not COLLADA XML: {e}") from None
    if _local(root.tag) != "COLLADA":
        raise MeshReadError(f"not COLLADA XML: its root element is <{_local(root.tag)}>, not <COLLADA>")
    collada = _Collada(root)
    unit = root.find("asset/unit")
    meter = float(unit.get("meter", "1")) if unit is not None else 1.0
    scene = root.find("scene/instance_visual_scene")
    if scene is not None:
        visual_scene = collada.element(scene.get("url"), "visual_scene")
    else:
        visual_scene = root.find("library_visual_scenes/visual_scene")
    try:
        if visual_scene is not None:
            for node in visual_scene.findall("node"):
                collada.node(node, np.eye(4))
        else:  # no scene: every geometry where it stands
            for geometry in root.iter("geometry"):
                collada.geometry(geometry, np.eye(4))
    except ValueError as e:
        if isinstance(e, MeshReadError):
            raise
        raise MeshReadError(f"a number that cannot be read: {e}") from None
    if not collada.triangles:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    return np.concatenate(collada.vertices) * meter, np.concatenate(collada.triangles)


def _node_transform(node: ET.Element) -> np.ndarray:
    """A node's transform as Gazebo reads it: its <matrix>, or <translate> then each <rotate> then <scale>."""
    matrix = node.find("matrix")
    if matrix is not None:
        values = _floats(matrix.text)
        if len(values) != 16:
            raise MeshReadError("a <matrix> of other than 16 numbers")
        return values.reshape(4, 4)
    transform = np.eye(4)
    translate = node.find("translate")
    if translate is not None:
        transform[:3, 3] = _floats(translate.text)[:3]
    for rotate in node.findall("rotate"):
        values = _floats(rotate.text)
        transform = transform @ _axis_angle(values[:3], np.radians(values[3]))
    scale = node.find("scale")
    if scale is not None:
        transform = transform @ np.diag([*_floats(scale.text)[:3], 1.0])
    return transform


def _axis_angle(axis: np.ndarray, angle: float) -> np.ndarray:
    norm = np.linalg.norm(axis)
    result = np.eye(4)
    if norm == 0:
        return result
    x, y, z = axis / norm
    c, s, t = np.cos(angle), np.sin(angle), 1 - np.cos(angle)
    result[:3, :3] = [
        [t * x * x + c, t * x * y - s * z, t * x * z + s * y],
        [t * x * y + s * z, t * y * y + c, t * y * z - s * x],
        [t * x * z - s * y, t * y * z + s * x, t * z * z + c],
    ]
    return result


def _fans(polygons: List[np.ndarray]) -> np.ndarray:
    faces = [np.c_[np.full(len(p) - 2, p[0]), p[1:-1], p[2:]] for p in polygons if len(p) >= 3]
    return np.concatenate(faces).astype(np.int64) if faces else np.zeros((0, 3), dtype=np.int64)


def _strips(strips: List[np.ndarray]) -> np.ndarray:
    faces = [np.c_[s[:-2], s[1:-1], s[2:]] for s in strips if len(s) >= 3]
    return np.concatenate(faces).astype(np.int64) if faces else np.zeros((0, 3), dtype=np.int64)


def _floats(text: Optional[str]) -> np.ndarray:
    return np.array((text or "").split(), dtype=np.float64)


def _ints(text: Optional[str]) -> np.ndarray:
    return np.array((text or "").split(), dtype=np.int64)


# ---- OBJ files for pybullet -----------------------------------------------------------------------
_FOLDER: List[str] = []  # this process's folder of converted meshes, made when first needed
_CONVERTED: Dict[Tuple[str, float, int], str] = {}


def pybullet_file(path: str) -> str:
    """A file pybullet reads with the geometry of the mesh file at path: the file itself when it is an
    OBJ or a binary STL, else an OBJ written once per process (while the file is unchanged)."""
    extension = os.path.splitext(path)[1].lower()
    if extension == ".obj" or (extension == ".stl" and not is_ascii_stl(path)):
        return path
    stat = os.stat(path)
    key = (path, stat.st_mtime, stat.st_size)
    if key not in _CONVERTED:
        vertices, triangles = read_triangles(path)
        if not _FOLDER:
            _FOLDER.append(tempfile.mkdtemp(prefix="thorvald_sim_meshes_"))
            atexit.register(shutil.rmtree, _FOLDER[0], True)
        name = f"{len(_CONVERTED)}_{os.path.splitext(os.path.basename(path))[0]}.obj"
        out = os.path.join(_FOLDER[0], name)
        with open(out, "w") as f:
            f.write(f"# {path}\no mesh\n")
            np.savetxt(f, vertices, fmt="v %.9g %.9g %.9g")
            np.savetxt(f, triangles + 1, fmt="f %d %d %d")
        _CONVERTED[key] = out
    return _CONVERTED[key]
