"""Whether a file is a mesh pybullet can load: a small check of its header and structure.

pybullet reports a mesh it cannot read as "createCollisionShape failed." without the file's name,
and a moving object made from a binary STL whose size does not match its triangle count (or an
ASCII STL, or junk) crashes it (a segmentation fault, pybullet 3.2.7). So a world's mesh files are
read here first, and a file that is not a mesh is refused with the reason:

- OBJ (text, as tinyobjloader reads it): no NUL bytes; every ``v`` line three finite numbers;
  every ``f`` line at least three vertices, each an index of a vertex the file has (1-based;
  negative counts back from the latest vertex); at least one face;
- STL: binary only (pybullet's loader reads no ASCII STL): an 80-byte header, the triangle count,
  then exactly that many 50-byte triangles, at least one, every coordinate finite;
- DAE: COLLADA XML (a ``COLLADA`` root element) with at least one ``triangles``, ``polylist``,
  ``polygons``, ``tristrips`` or ``trifans`` element, and no DOCTYPE or entity declarations
  (COLLADA needs none; entities can expand without bound).

Pure: no pybullet (numpy is imported when an STL is checked).
"""

import math
import os
from typing import Callable, Dict, Optional

MESH_KINDS = (".obj", ".stl", ".dae")

# bytes of a binary STL: the header, the triangle count, and 50 a triangle (12 floats and 2 bytes)
STL_HEADER = 80
STL_TRIANGLE = 50


def mesh_problem(path: str) -> Optional[str]:
    """Why the file at path is not a mesh pybullet can load (a phrase), or None if it is one.

    The kind is the file's extension (case ignored); the caller bounds the file's size first, as
    the whole file is read.
    """
    check = _CHECKS.get(os.path.splitext(path)[1].lower())
    if check is None:
        return "not a mesh file: its name ends in none of " + ", ".join(MESH_KINDS)
    try:
        with open(path, "rb") as f:
            data = f.read()
    except OSError as e:
        return f"cannot be read: {e.strerror}"
    return check(data)


def _obj_problem(data: bytes) -> Optional[str]:
    nul = data.find(b"\0")
    if nul >= 0:
        return f"binary bytes (a NUL byte at offset {nul}), not an OBJ file, which is text"
    vertices = 0
    faces = 0
    highest = (0, 0)  # (index, line) of the highest positive vertex index a face names
    # tinyobjloader skips what it does not know; the lines it makes geometry of are checked
    for number, line in enumerate(data.decode("utf-8", errors="replace").splitlines(), 1):
        words = line.split()
        if not words:
            continue
        if words[0] == "v":
            if len(words) < 4 or not all(_finite(w) for w in words[1:4]):
                return f"line {number} is a vertex without three finite numbers x y z"
            vertices += 1
        elif words[0] == "f":
            if len(words) < 4:
                return f"line {number} is a face of fewer than three vertices"
            for word in words[1:]:
                index = _int(word.split("/", 1)[0])
                if index is None or index == 0:
                    return f"line {number} is a face naming {word!r}, not a vertex index"
                if index < 0 and -index > vertices:
                    return f"line {number} names vertex {index} with {vertices} vertices before it"
                if index > highest[0]:
                    highest = (index, number)
            faces += 1
    if faces == 0:
        return f"an OBJ file with no faces (f lines), so nothing to collide with ({vertices} vertices)"
    if highest[0] > vertices:
        return f"line {highest[1]} names vertex {highest[0]} of an OBJ file of {vertices} vertices"
    return None


def _stl_problem(data: bytes) -> Optional[str]:
    size = len(data)
    ascii_stl = data.lstrip()[:5].lower() == b"solid"
    if size >= STL_HEADER + 4:
        triangles = int.from_bytes(data[STL_HEADER : STL_HEADER + 4], "little")
        if size == STL_HEADER + 4 + STL_TRIANGLE * triangles:
            return _binary_stl_problem(data, triangles)
    else:
        triangles = None
    if ascii_stl:
        return "an ASCII STL file; pybullet reads binary STL only (export it as binary STL)"
    if triangles is None:
        return f"not an STL file: {size} bytes, shorter than a binary STL's {STL_HEADER + 4}-byte header"
    expected = STL_HEADER + 4 + STL_TRIANGLE * triangles
    return f"not a binary STL file: {size} bytes, not the {expected} its header's {triangles} triangles take"


def _binary_stl_problem(data: bytes, triangles: int) -> Optional[str]:
    if triangles == 0:
        return "an STL file with no triangles"
    import numpy as np  # noqa: PLC0415  (only for STL files)

    record = np.dtype([("numbers", "<f4", (12,)), ("attribute", "<u2")])  # normal and three corners
    numbers = np.frombuffer(data, dtype=record, count=triangles, offset=STL_HEADER + 4)["numbers"]
    corners = numbers[:, 3:]  # the normal is recomputed by pybullet; the corners are the mesh
    if not np.isfinite(corners).all():
        bad = int(np.argwhere(~np.isfinite(corners).all(axis=1))[0][0])
        return f"triangle {bad} of the STL file has a corner that is not a finite number"
    return None


COLLADA_FACES = ("triangles", "polylist", "polygons", "tristrips", "trifans")


def _dae_problem(data: bytes) -> Optional[str]:
    from xml.etree import ElementTree  # noqa: PLC0415  (only for COLLADA files)

    if b"<!DOCTYPE" in data or b"<!ENTITY" in data:
        return "not a COLLADA file: it declares a DOCTYPE or entities, which COLLADA files do not use"
    try:
        root = ElementTree.fromstring(data)
    except ElementTree.ParseError as e:
        return f"not COLLADA XML: {e}"
    if _local(root.tag) != "COLLADA":
        return f"not COLLADA XML: its root element is <{_local(root.tag)}>, not <COLLADA>"
    if not any(_local(e.tag) in COLLADA_FACES for e in root.iter()):
        return "a COLLADA file with no faces (" + ", ".join(COLLADA_FACES) + ")"
    return None


def _local(tag: str) -> str:
    """The tag without its XML namespace."""
    return tag.rsplit("}", 1)[-1]


def _finite(word: str) -> bool:
    try:
        return math.isfinite(float(word))
    except ValueError:
        return False


def _int(word: str) -> Optional[int]:
    try:
        return int(word)
    except ValueError:
        return None


_CHECKS: Dict[str, Callable[[bytes], Optional[str]]] = {
    ".obj": _obj_problem,
    ".stl": _stl_problem,
    ".dae": _dae_problem,
}
