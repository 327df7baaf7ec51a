"""Joint transforms as robot_state_publisher computes them, against rotation matrices (numpy)."""

import math

import numpy as np
import pytest

from thorvald_model.errors import UrdfError
from thorvald_model.joint_tree import JointTree, joint_positions, quaternion_from_rpy

URDF = """<robot name="t">
  <link name="base"/><link name="arm"/><link name="slide"/><link name="copy"/><link name="cam"/>
  <joint name="turn" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0.1 0.2 0.3" rpy="0.3 -0.4 1.2"/><axis xyz="0 1 1"/></joint>
  <joint name="push" type="prismatic"><parent link="arm"/><child link="slide"/>
    <origin xyz="1 0 0" rpy="1.5707963 0 0"/><axis xyz="0 0 2"/></joint>
  <joint name="twin" type="continuous"><parent link="base"/><child link="copy"/>
    <origin rpy="0 0 0.5"/><mimic joint="turn" multiplier="-2" offset="0.1"/></joint>
  <joint name="mount" type="fixed"><parent link="slide"/><child link="cam"/>
    <origin xyz="0 0 0.5" rpy="0 1.0 0"/></joint>
</robot>"""


def matrix_rpy(r, p, y):
    cx, sx, cy, sy, cz, sz = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return rz @ ry @ rx  # URDF: roll, pitch, yaw about fixed axes


def matrix_axis(axis, angle):
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + math.sin(angle) * kx + (1 - math.cos(angle)) * kx @ kx


def matrix_quat(q):
    x, y, z, w = q
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def test_rpy_quaternion_is_urdfs_fixed_axis_rotation():
    for rpy in [(0.3, -0.4, 1.2), (2.0, 1.0, -3.0), (0, 0, 0)]:
        np.testing.assert_allclose(matrix_quat(quaternion_from_rpy(*rpy)), matrix_rpy(*rpy), atol=1e-12)


def test_a_revolute_joint_turns_about_its_axis_in_the_child_after_the_origin():
    tree = JointTree(URDF)
    xyz, q = tree.transform("turn", 0.7)
    assert xyz == pytest.approx((0.1, 0.2, 0.3))
    np.testing.assert_allclose(matrix_quat(q), matrix_rpy(0.3, -0.4, 1.2) @ matrix_axis((0, 1, 1), 0.7), atol=1e-12)


def test_a_prismatic_joint_slides_along_its_axis_turned_by_the_origin():
    tree = JointTree(URDF)
    xyz, q = tree.transform("push", 0.25)
    expected = np.array([1, 0, 0]) + matrix_rpy(1.5707963, 0, 0) @ np.array([0, 0, 0.25])  # axis normalised
    np.testing.assert_allclose(xyz, expected, atol=1e-9)
    np.testing.assert_allclose(matrix_quat(q), matrix_rpy(1.5707963, 0, 0), atol=1e-12)


def test_a_mimic_joint_follows_its_joint_and_fixed_joints_are_separate():
    tree = JointTree(URDF)
    out = {child: (parent, t) for parent, child, t in tree.moving_transforms({"turn": 0.7, "unknown": 1.0})}
    assert set(out) == {"arm", "copy"}  # the unknown joint is skipped, the mimic follows
    _, (_, q) = out["copy"]
    np.testing.assert_allclose(
        matrix_quat(q), matrix_rpy(0, 0, 0.5) @ matrix_axis((1, 0, 0), -2 * 0.7 + 0.1), atol=1e-12
    )
    fixed = tree.fixed_transforms()
    assert [(p, c) for p, c, _ in fixed] == [("slide", "cam")]
    assert not tree.moving("mount") and tree.moving("push")


def test_bad_descriptions_are_refused_with_the_joint():
    with pytest.raises(UrdfError, match="not valid XML"):
        JointTree("<robot><joint")
    with pytest.raises(UrdfError, match="joint turn axis"):
        JointTree(URDF.replace('xyz="0 1 1"', 'xyz="0 0 0"'))
    with pytest.raises(UrdfError, match="joint twin mimic: no joint 'nope'"):
        JointTree(URDF.replace('mimic joint="turn"', 'mimic joint="nope"'))
    with pytest.raises(UrdfError, match="joint mount origin rpy"):
        JointTree(URDF.replace('rpy="0 1.0 0"', 'rpy="0 1.0"'))


def test_non_finite_positions_are_left_out():
    assert joint_positions(["a", "b", "c"], [1.0, math.nan, math.inf]) == {"a": 1.0}
