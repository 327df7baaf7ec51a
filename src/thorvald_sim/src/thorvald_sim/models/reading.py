"""What the SDF and URDF readers share: the limits of one model, XML read with those limits counted as
it streams in, numbers read with the element path of each, and the mesh files checked once.

A model's budget is checked while its text is parsed, before any tree of it is kept and long before
pybullet sees it: ``XMLPullParser`` is fed the text in chunks and every ``<link>``, ``<joint>``,
``<collision>``, ``<visual>`` and ``<model>`` start is counted, so a file of 10^6 links is refused
after its first thousand, in milliseconds and a few kB of tree. A text that declares XML entities is
refused unread (no SDF or URDF needs one; entities can expand without bound).

Pure: no pybullet, no ROS.
"""

import math
import os
import xml.etree.ElementTree as ET
from typing import Callable, Dict, List, Optional, Sequence, Tuple

from ..errors import MeshReadError, ModelError
from ..world.mesh_check import mesh_problem

# ---- the limits of one model (a spawned model, or one model of a world) ---------------------------
MAX_XML_CHARS = 16 * 2**20  # characters of one model's text (and of each file it includes)
MAX_LINKS = 1000  # links of one model, nested models and includes counted in
MAX_JOINTS = 1000
MAX_COLLISIONS = 1000  # collisions over all links of one model
MAX_VISUALS = 1000
MAX_MODELS = 100  # nested models and includes of one model, itself counted
MAX_NESTING = 16  # models within models (includes counted), deepest
MAX_ELEMENTS = 200_000  # XML elements of any kind in one text (10^6 <frame>s or <plugin>s is junk too)
MAX_MESH_BYTES = 64 * 2**20  # bytes of one mesh file
MAX_MESH_SCALE = 1000.0  # a mesh scaled beyond this (or below its inverse) is a mistake of units

COUNTED = {
    "link": ("links", MAX_LINKS),
    "joint": ("joints", MAX_JOINTS),
    "collision": ("collisions", MAX_COLLISIONS),
    "visual": ("visuals", MAX_VISUALS),
    "model": ("models", MAX_MODELS),
}
FEED = 1 << 16  # characters fed to the parser at a time

MESH_EXTENSIONS = (".obj", ".stl", ".dae")

MeshFinder = Callable[[str], Tuple[Optional[str], str]]
"""uri -> (absolute path of the file, "") or (None, where it looked and why it is not there)."""


class Budget:
    """Counts of one model's elements, over every text read for it (a model and its includes)."""

    def __init__(self) -> None:
        self.counts: Dict[str, int] = {}

    def add(self, tag: str, source: str) -> None:
        what, limit = COUNTED[tag]
        n = self.counts.get(tag, 0) + 1
        self.counts[tag] = n
        if n > limit:
            raise ModelError(source, "", f"more than {limit} {what}: a model here has at most {limit} {what}")


def read_xml(text: str, source: str, budget: Optional[Budget] = None) -> ET.Element:
    """The root element of text, its elements counted against budget as the text streams in
    (ModelError naming the source, and the line and column when the XML is broken)."""
    if not isinstance(text, str):
        raise ModelError(source, "", f"the model is {type(text).__name__}, not XML text")
    if len(text) > MAX_XML_CHARS:
        raise ModelError(source, "", f"{len(text)} characters, more than the {MAX_XML_CHARS} a model may have")
    if "<!ENTITY" in text:
        raise ModelError(
            source, "", "declares XML entities, which no SDF or URDF needs (they can expand without bound)"
        )
    budget = budget or Budget()
    parser = ET.XMLPullParser(events=("start",))
    root: Optional[ET.Element] = None
    elements = 0
    try:
        for at in range(0, max(len(text), 1), FEED):
            parser.feed(text[at : at + FEED])
            for _, element in parser.read_events():
                if root is None:
                    root = element
                elements += 1
                if elements > MAX_ELEMENTS:
                    raise ModelError(source, "", f"more than {MAX_ELEMENTS} XML elements")
                if element.tag in COUNTED:
                    budget.add(element.tag, source)
        parser.close()
    except ET.ParseError as e:
        line, column = e.position
        raise ModelError(source, f"line {line}, column {column}", f"not well-formed XML: {e.msg}") from None
    if root is None:
        raise ModelError(source, "", "no XML element at all")
    return root


# ---- numbers with their element paths -------------------------------------------------------------
def numbers(text: Optional[str], count: int, source: str, path: str) -> Tuple[float, ...]:
    """count finite numbers from whitespace-separated text."""
    words = (text or "").split()
    if len(words) != count:
        raise ModelError(source, path, f"{text!r}: must be {count} number{'s' if count > 1 else ''}")
    try:
        values = tuple(float(w) for w in words)
    except ValueError:
        raise ModelError(source, path, f"{text!r}: must be {count} number{'s' if count > 1 else ''}") from None
    if not all(math.isfinite(v) for v in values):
        raise ModelError(source, path, f"{text!r}: must be finite numbers (no NaN or inf)")
    return values


def number(
    text: Optional[str],
    source: str,
    path: str,
    *,
    minimum: Optional[float] = None,
    positive: bool = False,
    allow_infinite: bool = False,
) -> float:
    """One number; below minimum (or not > 0 when positive) is refused with the rule."""
    try:
        value = float((text or "").strip())
    except ValueError:
        raise ModelError(source, path, f"{text!r}: must be a number") from None
    if math.isnan(value) or (math.isinf(value) and not allow_infinite):
        raise ModelError(source, path, f"{text!r}: must be a finite number (no NaN or inf)")
    if positive and not value > 0:
        raise ModelError(source, path, f"{value:g}: must be > 0")
    if minimum is not None and value < minimum:
        raise ModelError(source, path, f"{value:g}: must be >= {minimum:g}")
    return value


def child_number(element: Optional[ET.Element], tag: str, default: float, source: str, path: str, **rules) -> float:
    """The number of element's child tag (its default when element or the child is absent)."""
    child = None if element is None else element.find(tag)
    if child is None:
        return default
    return number(child.text, source, f"{path}/{tag}", **rules)


def flag(text: Optional[str], source: str, path: str) -> bool:
    """An SDF or URDF boolean: true/false/1/0, in any case."""
    word = (text or "").strip().lower()
    if word in ("true", "1"):
        return True
    if word in ("false", "0"):
        return False
    raise ModelError(source, path, f"{text!r}: must be true, false, 1 or 0")


def positive_scale(values: Sequence[float], source: str, path: str) -> Tuple[float, float, float]:
    for v in values:
        if not 1.0 / MAX_MESH_SCALE <= v <= MAX_MESH_SCALE:
            raise ModelError(
                source, path, f"{v:g}: a mesh scale must be in [{1 / MAX_MESH_SCALE:g}, {MAX_MESH_SCALE:g}]"
            )
    return (values[0], values[1], values[2])


# ---- mesh files -----------------------------------------------------------------------------------
_CHECKED: Dict[Tuple[str, float, int], Optional[str]] = {}  # (path, mtime, size) -> why not a mesh


def mesh_file(uri: str, find: MeshFinder, source: str, path: str) -> str:
    """The absolute path of the mesh file uri names, found and checked to be a mesh this simulator
    reads (each file read once while it is unchanged: 10,000 models of one mesh read it once)."""
    if not uri:
        raise ModelError(source, path, "a mesh needs a uri")
    found, reason = find(uri)
    if found is None:
        raise ModelError(source, path, f"mesh {uri} cannot be found: {reason}")
    extension = os.path.splitext(found)[1].lower()
    if extension not in MESH_EXTENSIONS:
        raise ModelError(
            source, path, f"mesh {uri} ({found}): not a mesh file read here (" + ", ".join(MESH_EXTENSIONS) + ")"
        )
    try:
        stat = os.stat(found)
    except OSError as e:
        raise ModelError(source, path, f"mesh {uri} ({found}) cannot be read: {e.strerror}") from None
    if stat.st_size > MAX_MESH_BYTES:
        raise ModelError(source, path, f"mesh {uri} ({found}): {stat.st_size} bytes, more than {MAX_MESH_BYTES}")
    key = (found, stat.st_mtime, stat.st_size)
    if key not in _CHECKED:
        _CHECKED[key] = _mesh_problem(found)
    problem = _CHECKED[key]
    if problem:
        raise ModelError(source, path, f"mesh {uri} ({found}) cannot be used: {problem}")
    return found


def _mesh_problem(path: str) -> Optional[str]:
    """Why the file is not a mesh read here: pybullet's own loaders read OBJ and binary STL (checked by
    mesh_check, as pybullet crashes on some junk); ASCII STL and COLLADA are read by :mod:`.meshes`."""
    from . import meshes  # noqa: PLC0415  (numpy, only for files that need it)

    extension = os.path.splitext(path)[1].lower()
    if extension == ".dae" or (extension == ".stl" and meshes.is_ascii_stl(path)):
        try:
            meshes.read_triangles(path)
        except MeshReadError as e:
            return str(e)
        return None
    return mesh_problem(path)


def tag_path(parent: str, element: ET.Element) -> str:
    """An element's path: ``parent/tag[name]`` (the name attribute when it has one)."""
    name = element.get("name")
    step = f"{element.tag}[{name}]" if name is not None else element.tag
    return f"{parent}/{step}" if parent else step


def unique(names: List[Tuple[str, str]], what: str, source: str) -> None:
    """(name, path) pairs: two of one name are refused (the second's path)."""
    seen: Dict[str, str] = {}
    for name, path in names:
        if name in seen:
            raise ModelError(source, path, f"a second {what} named {name!r} (the first: {seen[name]})")
        seen[name] = path
