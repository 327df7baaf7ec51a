"""Link names as tf2 reads them, and the check check_urdf makes, for any robot description (URDF).

**Leading slashes.** tf2 drops a leading slash from a frame id, so ``/base_link`` and ``base_link``
are one frame, and ``/thorvald_001/base_link`` is ``thorvald_001/base_link``. Older generators wrote
such names (they joined an empty tf_prefix with a slash), and users mixing the two tf_prefix
conventions (``thorvald_001`` and ``thorvald_001/``, :mod:`thorvald_model.frames`) write
``thorvald_001//base_link``. A URDF parser compares names as written, so such a description fails
to load ("Cannot load URDF file.") without naming the joint or the link. :func:`normalize_urdf`
(text) and :func:`normalize_document` (xacro's DOM) rewrite every link reference -- ``<link
name>``, a joint's ``<parent link>`` and ``<child link>``, ``<gazebo reference>`` -- with its
leading slashes dropped and repeated slashes collapsed (:func:`normalize_frame`). Joint names are
not frames and stay as written; so does a ``<gazebo reference>`` that names a joint.

**The check.** :func:`urdf_problems` applies urdfdom's rules (the parser of check_urdf,
robot_state_publisher and RViz; urdfdom 3.0): a ``<robot>`` with a name, version 1.0, at least one
link, unique link, joint and material names, every joint named, of a known type, with its parent
and child links, and those links defined; a ``<limit>`` (with effort and velocity) on every
revolute and prismatic joint; numbers and 3-vectors where urdfdom reads them (``<origin>``,
``<axis>``, ``<limit>``, ``<dynamics>``, ``<mimic>``, ``<safety_controller>``,
``<calibration>``); exactly one root link. Three rules are stricter than check_urdf 3.0, which
accepts a link hanging from two joints (it keeps the last one), a cycle of links beside the tree
(it never reaches it; a link that is its own parent makes it print forever) and a link without a
name: none of them is a tree, and tf would get two transforms for one frame or none.
urdfdom reads links' visuals, collisions and inertials too, but loads the robot whatever it finds
there, so they are not checked here.

Unlike urdfdom, which stops at the first broken rule, every problem is listed, each a
:class:`~thorvald_model.errors.Problem` naming the element, the value and the rule; a link that does
not exist comes with the closest existing names (difflib), e.g.
``joint lidar_joint/parent: 'base_lnk': link does not exist (closest: base_link, bat0_link)``.

Pure: the standard library's XML parsers only (no rospy, no pybullet).
"""

import difflib
import re
import xml.etree.ElementTree as ET
from typing import Any, Callable, Dict, Iterable, Iterator, List, Optional, Sequence, Tuple

from .errors import MISSING, Problem, UrdfCheckError

JOINT_TYPES = ("revolute", "continuous", "prismatic", "fixed", "floating", "planar")
NEEDS_LIMIT = ("revolute", "prismatic")
NO_AXIS = ("fixed", "floating")  # urdfdom reads <axis> of the other types only
CLOSE_NAME = 0.6  # difflib ratio from which an existing link is offered as the one meant
CLOSEST = 3  # at most this many names offered

# urdfdom's strToDouble: a C++ stream reading a double from the whole text (leading blanks allowed,
# trailing ones not; no inf, nan or hexadecimal)
_NUMBER = re.compile(r"\s*[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?\Z")
_REPEATED_SLASHES = re.compile(r"/{2,}")


def normalize_frame(name: str) -> str:
    """A frame (link) name as tf2 reads it: leading slashes dropped, repeated slashes collapsed.

    ``/base_link`` -> ``base_link``; ``/thorvald_001/base_link`` and ``thorvald_001//base_link`` ->
    ``thorvald_001/base_link``.
    """
    return _REPEATED_SLASHES.sub("/", name).lstrip("/")


# ---------------------------------------------------------------------------------------------
# Normalising
# ---------------------------------------------------------------------------------------------
Children = Callable[[Any, str], List[Any]]
Getter = Callable[[Any, str], Optional[str]]


def _link_references(root: Any, children: Children, get: Getter) -> Iterator[Tuple[Any, str]]:
    """(element, attribute) of every link name and link reference of a <robot>."""
    joints = {get(j, "name") for j in children(root, "joint")}
    for link in children(root, "link"):
        yield link, "name"
    for joint in children(root, "joint"):
        for tag in ("parent", "child"):
            for element in children(joint, tag):
                yield element, "link"
    for gazebo in children(root, "gazebo"):
        reference = get(gazebo, "reference")
        if reference is not None and reference not in joints:  # a joint's block: joint names are no frames
            yield gazebo, "reference"


def _normalize(root: Any, children: Children, get: Getter, set_: Callable[[Any, str, str], None]) -> int:
    changed = 0
    for element, attribute in list(_link_references(root, children, get)):
        value = get(element, attribute)
        if value is None:
            continue
        normal = normalize_frame(value)
        if normal != value:
            set_(element, attribute, normal)
            changed += 1
    return changed


def _et_children(element: ET.Element, tag: str) -> List[ET.Element]:
    return element.findall(tag)


def _et_get(element: ET.Element, attribute: str) -> Optional[str]:
    return element.get(attribute)


def _et_set(element: ET.Element, attribute: str, value: str) -> None:
    element.set(attribute, value)


def normalize_tree(root: ET.Element) -> int:
    """Normalises the link references of an ElementTree <robot> in place; how many changed."""
    return _normalize(root, _et_children, _et_get, _et_set)


def normalize_urdf(xml: str) -> str:
    """The description with every link reference normalised (:func:`normalize_frame`); the text
    itself when none changes. ``xml.etree.ElementTree.ParseError`` when it is not XML."""
    root = ET.fromstring(xml)
    if not normalize_tree(root):
        return xml
    return ET.tostring(root, encoding="unicode")


def _dom_children(element: Any, tag: str) -> List[Any]:
    return [c for c in element.childNodes if c.nodeType == c.ELEMENT_NODE and c.tagName == tag]


def _dom_get(element: Any, attribute: str) -> Optional[str]:
    return element.getAttribute(attribute) if element.hasAttribute(attribute) else None


def _dom_set(element: Any, attribute: str, value: str) -> None:
    element.setAttribute(attribute, value)


def normalize_document(document: Any) -> int:
    """Normalises the link references of a ``xml.dom.minidom`` document (xacro's result) in place,
    so its own formatting is kept; how many changed."""
    return _normalize(document.documentElement, _dom_children, _dom_get, _dom_set)


# ---------------------------------------------------------------------------------------------
# Checking
# ---------------------------------------------------------------------------------------------
def closest_names(name: str, names: Iterable[str], n: int = CLOSEST) -> List[str]:
    """The names most like name (difflib's ratio, at least CLOSE_NAME), best first.

    Names are compared whole and by their last part after a slash, so a link written without its
    tf_prefix (``base_link``) or with another (``thorvald_002/base_link``) finds
    ``thorvald_001/base_link``.
    """
    tail = name.rsplit("/", 1)[-1]
    scored = []
    for candidate in set(names):
        whole = difflib.SequenceMatcher(None, name, candidate).ratio()
        score = max(whole, difflib.SequenceMatcher(None, tail, candidate.rsplit("/", 1)[-1]).ratio())
        if score >= CLOSE_NAME:
            scored.append((-score, -whole, candidate))  # equal last parts: the closer whole name first
    return [c for _, _, c in sorted(scored)[:n]]


def _missing_link_rule(name: str, links: Sequence[str]) -> str:
    close = closest_names(name, links)
    if close:
        return "link does not exist (closest: {})".format(", ".join(close))
    return f"link does not exist (none of the {len(links)} links has a close name)"


def _is_number(text: str) -> bool:
    return bool(_NUMBER.match(text))


def _is_vector3(text: str) -> bool:
    # urdfdom splits on single spaces and skips the empty pieces
    pieces = [p for p in text.split(" ") if p]
    return len(pieces) == 3 and all(_is_number(p) for p in pieces)


def _is_version_1_0(text: str) -> bool:
    parts = text.split(".")
    return len(parts) == 2 and all(re.match(r"\s*\d+\Z", p) for p in parts) and [int(p) for p in parts] == [1, 0]


class _Attributes:
    """The attribute rules of one element: optional numbers, required numbers, 3-vectors."""

    def __init__(self, element: ET.Element, path: str, problems: List[Problem]):
        self.element, self.path, self.problems = element, path, problems

    def number(self, name: str, required: str = "") -> None:
        value = self.element.get(name)
        if value is None:
            if required:
                self.problems.append(Problem(f"{self.path}/@{name}", MISSING, required))
        elif not _is_number(value):
            self.problems.append(Problem(f"{self.path}/@{name}", value, "must be a number"))

    def vector(self, name: str) -> None:
        value = self.element.get(name)
        if value is not None and not _is_vector3(value):
            self.problems.append(Problem(f"{self.path}/@{name}", value, "must be 3 numbers separated by spaces"))


def _joint_attributes(joint: ET.Element, where: str, kind: Optional[str], problems: List[Problem]) -> None:
    def first(tag: str) -> Optional[_Attributes]:
        element = joint.find(tag)
        return None if element is None else _Attributes(element, f"{where}/{tag}", problems)

    origin = first("origin")
    if origin:
        origin.vector("xyz")
        origin.vector("rpy")
    axis = first("axis")
    if axis and kind not in NO_AXIS:
        axis.vector("xyz")
    limit = first("limit")
    if limit:
        limit.number("lower")
        limit.number("upper")
        limit.number("effort", "a <limit> needs effort [N m or N]")
        limit.number("velocity", "a <limit> needs velocity [rad/s or m/s]")
    elif kind in NEEDS_LIMIT:
        problems.append(Problem(f"{where}/limit", MISSING, f"a {kind} joint needs <limit effort= velocity=>"))
    safety = first("safety_controller")
    if safety:
        for name in ("soft_lower_limit", "soft_upper_limit", "k_position"):
            safety.number(name)
        safety.number("k_velocity", "a <safety_controller> needs k_velocity")
    calibration = first("calibration")
    if calibration:
        calibration.number("rising")
        calibration.number("falling")
    mimic = first("mimic")
    if mimic:
        if mimic.element.get("joint") is None:
            problems.append(Problem(f"{where}/mimic/@joint", MISSING, "a <mimic> names the joint it follows"))
        mimic.number("multiplier")
        mimic.number("offset")
    dynamics = first("dynamics")
    if dynamics:
        dynamics.number("damping")
        dynamics.number("friction")
        if dynamics.element.get("damping") is None and dynamics.element.get("friction") is None:
            problems.append(Problem(f"{where}/dynamics", MISSING, "a <dynamics> needs damping or friction"))


def _unique(names: Iterable[Tuple[str, str]], what: str, problems: List[Problem]) -> None:
    seen = set()
    for name, path in names:
        if name in seen:
            problems.append(Problem(path, name, f"another {what} has this name ({what} names are unique)"))
        seen.add(name)


def _tree_problems(root: ET.Element, links: List[str], problems: List[Problem]) -> None:
    """Parent and child links of every joint, one parent per link, no cycle, one root."""
    before = len(problems)
    link_set = set(links)
    hung_by: Dict[str, str] = {}  # child link -> the first joint naming it as child
    parent_of: Dict[str, Tuple[str, str, int]] = {}  # child link -> (parent link, joint, its place in the file)
    for k, joint in enumerate(root.findall("joint"), 1):
        name = joint.get("name")
        label = name if name is not None else f"#{k}"
        ends = {}
        for tag in ("parent", "child"):
            element = joint.find(tag)
            link = element.get("link") if element is not None else None
            if not link:
                problems.append(Problem(f"joint {label}/{tag}", MISSING, f"a joint needs <{tag} link=...>"))
            elif link not in link_set:
                problems.append(Problem(f"joint {label}/{tag}", link, _missing_link_rule(link, links)))
            else:
                ends[tag] = link
        child = ends.get("child")
        if child is None:
            continue
        if child in hung_by:
            rule = f"link hangs from joint {hung_by[child]} already (a link has one parent joint)"
            problems.append(Problem(f"joint {label}/child", child, rule))
            continue
        hung_by[child] = label  # even when its parent link is missing: that is the problem, not a second root
        if "parent" in ends:
            parent_of[child] = (ends["parent"], label, k)
    for child in _cycles(parent_of):
        parent, joint, _ = parent_of[child]
        up = [parent]
        while up[-1] != child:
            up.append(parent_of[up[-1]][0])
        loop = " -> ".join([*reversed(up), child])
        problems.append(Problem(f"joint {joint}/child", child, f"closes a cycle of links: {loop} (no tree)"))
    roots = [link for link in links if link not in hung_by]
    if not roots and len(problems) == before:
        problems.append(Problem("robot", MISSING, "no root link: every link has a parent joint"))
    for extra in roots[1:]:
        problems.append(
            Problem(f"link {extra}", extra, f"no joint has it as child: a second root link (the first: {roots[0]})")
        )


def _cycles(parent_of: Dict[str, Tuple[str, str, int]]) -> List[str]:
    """The child link of each cycle's closing joint (the cycle's joint written last), once per cycle."""
    state: Dict[str, int] = {}  # 1: on the current walk up, 2: done
    closing = []
    for start in parent_of:
        walk = []
        link = start
        while link in parent_of and link not in state:
            state[link] = 1
            walk.append(link)
            link = parent_of[link][0]
        if state.get(link) == 1:  # the walk met itself: the cycle is the walk from link on
            members = walk[walk.index(link) :]
            closing.append(max(members, key=lambda m: parent_of[m][2]))
        for visited in walk:
            state[visited] = 2
    return closing


def _check_tree(root: ET.Element) -> List[Problem]:
    if root.tag != "robot":
        return [Problem("", MISSING, f"the robot description's root element is <{root.tag}>, not <robot>")]
    problems: List[Problem] = []
    if root.get("name") is None:
        problems.append(Problem("robot/@name", MISSING, "a robot needs a name"))
    version = root.get("version")
    if version is not None and not _is_version_1_0(version):
        problems.append(Problem("robot/@version", version, "only URDF version 1.0 is supported"))
    materials = [(m.get("name"), f"material {m.get('name')}") for m in root.findall("material")]
    _unique(((n, p) for n, p in materials if n is not None), "material", problems)
    link_elements = root.findall("link")
    if not link_elements:
        return [*problems, Problem("robot", MISSING, "the robot description has no <link>")]
    links = []
    for k, link in enumerate(link_elements, 1):
        name = link.get("name")
        if name is None:
            problems.append(Problem(f"link #{k}", MISSING, "a link needs a name"))
        else:
            links.append(name)
    _unique(((n, f"link {n}") for n in links), "link", problems)
    joints = []
    for k, joint in enumerate(root.findall("joint"), 1):
        name = joint.get("name")
        if name is None:
            problems.append(Problem(f"joint #{k}", MISSING, "a joint needs a name"))
        else:
            joints.append(name)
        where = f"joint {name}" if name is not None else f"joint #{k}"
        kind = joint.get("type")
        if kind not in JOINT_TYPES:
            problems.append(
                Problem(f"{where}/@type", MISSING if kind is None else kind, "one of " + ", ".join(JOINT_TYPES))
            )
        _joint_attributes(joint, where, kind, problems)
    _unique(((n, f"joint {n}") for n in joints), "joint", problems)
    _tree_problems(root, list(dict.fromkeys(links)), problems)
    return problems


def urdf_problems(xml: str) -> List[Problem]:
    """Every rule of urdfdom (and the three stricter ones, see the module) that the description
    breaks; empty when check_urdf would accept it. Link names are compared as written: normalise
    first (:func:`checked_urdf` does both)."""
    if not xml or not xml.strip():
        return [Problem("", MISSING, "the robot description is empty")]
    try:
        root = ET.fromstring(xml)
    except ET.ParseError as e:
        return [Problem("", MISSING, f"the robot description is not valid XML ({e})")]
    return _check_tree(root)


def _checked(xml: str, source: str) -> Tuple[ET.Element, int]:
    if not xml or not xml.strip():
        raise UrdfCheckError(source, urdf_problems(xml))
    try:
        root = ET.fromstring(xml)
    except ET.ParseError:
        raise UrdfCheckError(source, urdf_problems(xml)) from None
    changed = normalize_tree(root)
    problems = _check_tree(root)
    if problems:
        raise UrdfCheckError(source, problems)
    return root, changed


def checked_tree(xml: str, source: str) -> ET.Element:
    """The description parsed, its link references normalised in place, after checking it as
    check_urdf would; UrdfCheckError listing every problem (source: what to name, e.g. a file or a
    robot). For what reads a description once and goes on with the tree (the simulator's spawn)."""
    return _checked(xml, source)[0]


def checked_urdf(xml: str, source: str) -> str:
    """The description with its link references normalised, after checking it as check_urdf would
    (:func:`checked_tree`); the text itself when no reference changes."""
    root, changed = _checked(xml, source)
    return ET.tostring(root, encoding="unicode") if changed else xml


__all__ = [
    "JOINT_TYPES",
    "checked_tree",
    "checked_urdf",
    "closest_names",
    "normalize_document",
    "normalize_frame",
    "normalize_tree",
    "normalize_urdf",
    "urdf_problems",
]
