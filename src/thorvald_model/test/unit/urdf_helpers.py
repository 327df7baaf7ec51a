"""Helpers of the URDF tests: the robots, the URDF of each (generated once), structural comparison.

Expected values come from the raw YAML files and from the original's published figures, never
from the generator under test.
"""

import functools
import glob
import os
import xml.etree.ElementTree as ET
from typing import Any, Dict, List, Tuple

import numpy as np
import yaml

from thorvald_model.description import generate_urdf

PKG = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
EXAMPLE_ROBOTS = sorted(glob.glob(os.path.join(PKG, "config", "*", "*.yaml")))
FIGURE5 = os.path.join(PKG, "test", "data", "paper_figure5.yaml")
ROBOTS = [*EXAMPLE_ROBOTS, FIGURE5]
GOLDEN_DIR = os.path.join(PKG, "test", "golden")
EXTRAS = os.path.join(PKG, "test", "data", "extras_sensor.xacro")

# The original's default steering limit [rad] (reconstruction notes 1.2), for files that omit it.
ORIGINAL_STR_LIM = 3.078027759


def robot_name(path: str) -> str:
    return os.path.splitext(os.path.basename(path))[0]


def robot_id(path: str) -> str:
    return robot_name(path)


@functools.lru_cache(maxsize=None)
def urdf_text(path: str, tf_prefix: str = "", extras: str = "") -> str:
    return generate_urdf(path, tf_prefix=tf_prefix, model_extras=extras)


def urdf_tree(path: str, tf_prefix: str = "", extras: str = "") -> ET.Element:
    return ET.fromstring(urdf_text(path, tf_prefix, extras).encode())


def raw_yaml(path: str) -> Dict[str, Any]:
    with open(path) as f:
        return yaml.safe_load(f) or {}


def expected_moving_joints(path: str) -> Dict[str, str]:
    """Joint name -> URDF type of every joint that moves, read off the raw configuration file."""
    data = raw_yaml(path)
    drives = data.get("motor_drives") or {}
    expected = {}
    for name, d in drives.items():
        n = name[len("drive") :]
        if int(d.get("type", 0)) == 0:
            expected[d.get("steering_name") or "steering" + n] = "revolute"
        expected[d.get("wheel_name") or "wheel" + n] = "continuous"
    for s in (data.get("suspensions") or {}).values():
        expected["suspension" + s["drive"][len("drive") :]] = "prismatic"
    for name, p in (data.get("passive_wheels") or {}).items():
        if p["type"] == "caster":
            expected[name + "_swivel"] = "continuous"
        expected[name + "_wheel"] = "continuous"
    return expected


def floats(text: str) -> List[float]:
    return [float(v) for v in text.split()]


def origin_of(element: ET.Element) -> Tuple[List[float], List[float]]:
    o = element.find("origin")
    if o is None:
        return [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
    return floats(o.get("xyz", "0 0 0")), floats(o.get("rpy", "0 0 0"))


def inertia_problems(link: ET.Element) -> List[str]:
    """Why a link's inertial is not physically valid (empty list if it is)."""
    name = link.get("name")
    inertial = link.find("inertial")
    if inertial is None:
        return [f"{name}: no inertial"]
    mass = float(inertial.find("mass").get("value"))
    i = inertial.find("inertia")
    m = np.array(
        [
            [float(i.get("ixx")), float(i.get("ixy")), float(i.get("ixz"))],
            [float(i.get("ixy")), float(i.get("iyy")), float(i.get("iyz"))],
            [float(i.get("ixz")), float(i.get("iyz")), float(i.get("izz"))],
        ]
    )
    problems = []
    if not mass > 0:
        problems.append(f"{name}: mass {mass} <= 0")
    principal = sorted(np.linalg.eigvalsh(m))
    if principal[0] <= 0:
        problems.append(f"{name}: inertia not positive definite, principal moments {principal}")
    a, b, c = principal
    if a + b < c * (1 - 1e-9):
        problems.append(f"{name}: principal moments {principal} break the triangle inequality")
    return problems


# ---------------------------------------------------------------------------------------------
# Structural comparison (goldens): elements by name, numbers with a tolerance, comments ignored.
# ---------------------------------------------------------------------------------------------
TOLERANCE = 1e-6


def _numbers(text: str):
    try:
        return [float(v) for v in text.split()]
    except ValueError:
        return None


def _compare_element(a: ET.Element, b: ET.Element, path: str, out: List[str]) -> None:
    if a.tag != b.tag:
        out.append(f"{path}: <{a.tag}> != <{b.tag}>")
        return
    for key in sorted(set(a.attrib) | set(b.attrib)):
        va, vb = a.get(key), b.get(key)
        if va is None or vb is None:
            out.append(f"{path}@{key}: {va!r} != {vb!r}")
            continue
        na, nb = _numbers(va), _numbers(vb)
        if na is not None and nb is not None and len(na) == len(nb) and len(na) > 0:
            if any(abs(x - y) > TOLERANCE * max(1.0, abs(y)) for x, y in zip(na, nb)):
                out.append(f"{path}@{key}: {va} != {vb}")
        elif va != vb:
            out.append(f"{path}@{key}: {va!r} != {vb!r}")
    ta, tb = (a.text or "").strip(), (b.text or "").strip()
    na, nb = _numbers(ta), _numbers(tb)
    if (na is not None and nb is not None and na and nb) and len(na) == len(nb):
        if any(abs(x - y) > TOLERANCE * max(1.0, abs(y)) for x, y in zip(na, nb)):
            out.append(f"{path}/text(): {ta} != {tb}")
    elif ta != tb:
        out.append(f"{path}/text(): {ta!r} != {tb!r}")
    ca, cb = list(a), list(b)
    if [c.tag for c in ca] != [c.tag for c in cb]:
        out.append(f"{path}: children {[c.tag for c in ca]} != {[c.tag for c in cb]}")
        return
    for i, (x, y) in enumerate(zip(ca, cb)):
        _compare_element(x, y, f"{path}/{x.tag}[{i}]", out)


def structural_differences(actual: ET.Element, golden: ET.Element) -> List[str]:
    """Differences between two URDF trees: robot name, links, joints, materials, gazebo tags."""
    out: List[str] = []
    if actual.get("name") != golden.get("name"):
        out.append(f"robot name {actual.get('name')!r} != {golden.get('name')!r}")
    for tag in ("link", "joint", "material", "gazebo"):
        key = "reference" if tag == "gazebo" else "name"
        # the simulator block is the one <gazebo> without a reference: keyed ""
        ea = {e.get(key) or "": e for e in actual.findall(tag)}
        eb = {e.get(key) or "": e for e in golden.findall(tag)}
        for name in sorted(set(ea) - set(eb)):
            out.append(f"{tag} {name!r} is new (not in the golden)")
        for name in sorted(set(eb) - set(ea)):
            out.append(f"{tag} {name!r} is missing (in the golden)")
        for name in sorted(set(ea) & set(eb)):
            _compare_element(ea[name], eb[name], f"{tag}[{name}]", out)
    return out


def golden_path(path: str) -> str:
    return os.path.join(GOLDEN_DIR, robot_name(path) + ".urdf")
