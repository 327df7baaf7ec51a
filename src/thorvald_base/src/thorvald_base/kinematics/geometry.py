"""Wheel layout of a robot and the small linear algebra the calculators share.

A rigid body moving with twist t = (vx, vy, wz) moves a wheel contact at (x, y) with velocity
J t, J = [[1, 0, -y], [0, 1, x]]. Everything here is 3x3 at most, so plain floats beat numpy.

A wheel that cannot steer (a type-1 drive rolling along base_link x, a fixed passive wheel rolling
along its yaw) cannot slide sideways: n . J t = 0 for its lateral direction n. Those rows form the
constraint A t = 0; B is an orthonormal basis of the twists that satisfy it.
"""

import math
from typing import List, Sequence, Tuple

from thorvald_model.constants import DRIVE_DIFF

from ..errors import KinematicsError

Vector = Tuple[float, float, float]
Matrix = Tuple[Vector, ...]  # rows

RANK_TOLERANCE = 1e-9  # a constraint row shorter than this after elimination repeats an earlier one


def wheel_matrix(points: Sequence[Tuple[float, float]]) -> List[List[float]]:
    """M = sum J^T J over the points: the metric in which twists are compared by wheel velocities."""
    n = float(len(points))
    sx = sum(p[0] for p in points)
    sy = sum(p[1] for p in points)
    sr = sum(p[0] * p[0] + p[1] * p[1] for p in points)
    return [[n, 0.0, -sy], [0.0, n, sx], [-sy, sx, sr]]


def matmul(a, b) -> List[List[float]]:
    return [[sum(a[i][k] * b[k][j] for k in range(len(b))) for j in range(len(b[0]))] for i in range(len(a))]


def transpose(a) -> List[List[float]]:
    return [list(row) for row in zip(*a)]


def inverse(a) -> List[List[float]]:
    """Inverse of a small square matrix by Gauss-Jordan with partial pivoting."""
    n = len(a)
    m = [list(map(float, row)) + [1.0 if i == j else 0.0 for j in range(n)] for i, row in enumerate(a)]
    scale = max((abs(v) for row in a for v in row), default=1.0) or 1.0
    for col in range(n):
        pivot = max(range(col, n), key=lambda r: abs(m[r][col]))
        if abs(m[pivot][col]) <= 1e-12 * scale:
            raise KinematicsError("singular wheel geometry: the wheels do not determine the robot's motion")
        m[col], m[pivot] = m[pivot], m[col]
        p = m[col][col]
        m[col] = [v / p for v in m[col]]
        for r in range(n):
            if r != col and m[r][col] != 0.0:
                f = m[r][col]
                m[r] = [vr - f * vc for vr, vc in zip(m[r], m[col])]
    return [row[n:] for row in m]


def orthonormal_rows(rows: Sequence[Sequence[float]]) -> List[List[float]]:
    """Gram-Schmidt; rows that depend on earlier ones are dropped."""
    basis: List[List[float]] = []
    for row in rows:
        v = list(map(float, row))
        for b in basis:
            d = sum(x * y for x, y in zip(v, b))
            v = [x - d * y for x, y in zip(v, b)]
        norm = math.sqrt(sum(x * x for x in v))
        if norm > RANK_TOLERANCE:
            basis.append([x / norm for x in v])
    return basis


def null_space(rows: Sequence[Sequence[float]]) -> List[List[float]]:
    """Orthonormal basis (as rows) of the twists t with row . t = 0 for every row."""
    row_basis = orthonormal_rows(rows)
    candidates = orthonormal_rows([*row_basis, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]])
    return candidates[len(row_basis) :]


class Layout:
    """Geometry of the wheels a calculator serves, with the matrices it needs precomputed.

    drives: the motor drives (thorvald_model Drive); passive_wheels: PassiveWheel entries, of which
    only fixed ones matter to kinematics (a caster swivels and constrains nothing).
    """

    def __init__(self, drives: Sequence, passive_wheels: Sequence = ()):
        if not drives:
            raise KinematicsError("a calculator needs at least one drive")
        self.drives = tuple(drives)
        self.fixed_wheels = tuple(w for w in passive_wheels if getattr(w, "fixed", False))
        self.x = [float(d.x) for d in self.drives]
        self.y = [float(d.y) for d in self.drives]
        self.steerable = [d.type != DRIVE_DIFF for d in self.drives]
        # Lateral direction n of each wheel that cannot steer; constraint row (n_x, n_y, x n_y - y n_x).
        lateral = [(0.0, 1.0, d.x, d.y) for d in self.drives if d.type == DRIVE_DIFF]
        lateral += [(-math.sin(w.yaw), math.cos(w.yaw), w.x, w.y) for w in self.fixed_wheels]
        self.constraints = [[nx, ny, x * ny - y * nx] for nx, ny, x, y in lateral]
        self.basis = null_space(self.constraints)  # rows b_k; every realisable twist is sum z_k b_k
        if not self.basis:
            raise KinematicsError("the wheels that cannot steer leave the robot no motion at all")
        bt = transpose(self.basis)  # 3 x k
        # The closest realisable twist compares twists by the velocities they give the wheels that
        # define the body's motion: the drives and the fixed wheels (casters follow, so they do not).
        points = list(zip(self.x, self.y)) + [(w.x, w.y) for w in self.fixed_wheels]
        m_all = wheel_matrix(points)
        reduced = inverse(matmul(matmul(self.basis, m_all), bt))
        self.projection = matmul(matmul(matmul(bt, reduced), self.basis), m_all)
        # Least-squares odometry: minimise sum |J_i t - v_i|^2 over the measured drives, subject to
        # the constraints, so t = P b with b = sum J_i^T v_i.
        m_drives = wheel_matrix(list(zip(self.x, self.y)))
        try:
            reduced = inverse(matmul(matmul(self.basis, m_drives), bt))
        except KinematicsError:
            raise KinematicsError(
                "the drives' wheel velocities cannot determine the robot's motion (one drive needs fixed "
                "passive wheels off its position)"
            ) from None
        self.lsq = matmul(matmul(bt, reduced), self.basis)

    @property
    def constrained(self) -> bool:
        return len(self.basis) < 3

    def project(self, vx: float, vy: float, wz: float) -> Vector:
        """The realisable twist whose wheel velocities are closest (least squares) to the given one's."""
        if not self.constrained:
            return (vx, vy, wz)
        p = self.projection
        return (
            p[0][0] * vx + p[0][1] * vy + p[0][2] * wz,
            p[1][0] * vx + p[1][1] * vy + p[1][2] * wz,
            p[2][0] * vx + p[2][1] * vy + p[2][2] * wz,
        )
