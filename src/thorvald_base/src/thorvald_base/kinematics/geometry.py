"""Wheel layout of a robot and the small linear algebra the calculators share.

A rigid body moving with twist t = (vx, vy, wz) moves a wheel contact at (x, y) with velocity
J t, J = [[1, 0, -y], [0, 1, x]]. Everything here is 3x3 at most, so plain floats beat numpy.

A wheel that cannot steer (a type-1 drive rolling along base_link x, a fixed passive wheel rolling
along its yaw) cannot slide sideways: n . J t = 0 for its axle direction n (thorvald_model.layout's
AxleLine, the one copy of that rule). Those rows form the constraint A t = 0; B is an orthonormal
basis of the twists that satisfy it. The loader allows one axle line only, so A has rank 0 or 1.

A twist that breaks the constraint is replaced by a realisable one (the projection):

* ``axle`` (default): keeps wz and the velocity along the wheels' rolling direction, and takes the
  velocity across it from the axle (the centre of rotation lies on the axle line, at vx / wz from
  the foot of base_link on it for an axle across x), as car-like and steered-wheel controllers do.
  A navigation stack's (vx, 0, wz) is followed exactly in vx and wz.
* ``lsq``: the realisable twist whose wheel velocities (drives and fixed wheels) are closest to the
  requested one's in least squares. It may trade yaw rate for speed across the axle; choose it
  when the command's source treats the robot as holonomic and the wheels should move as close to
  what it asked as they can.
"""

import math
from typing import List, Optional, Sequence, Tuple

from thorvald_model.layout import axle_lines, common_axle

from ..errors import KinematicsError

Vector = Tuple[float, float, float]
Matrix = Tuple[Vector, ...]  # rows

RANK_TOLERANCE = 1e-9  # a constraint row shorter than this after elimination repeats an earlier one
PROJECTIONS = ("axle", "lsq")
DEFAULT_PROJECTION = "axle"


def check_projection(name: str) -> str:
    """The projection's name, or KinematicsError listing the known ones."""
    if name not in PROJECTIONS:
        raise KinematicsError("projection must be one of {}, not {!r}".format(", ".join(PROJECTIONS), name))
    return name


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
    only fixed ones matter to kinematics (a caster swivels and constrains nothing); projection:
    how an unrealisable twist is made realisable, one of PROJECTIONS (see the module's docs).
    """

    def __init__(self, drives: Sequence, passive_wheels: Sequence = (), projection: str = DEFAULT_PROJECTION):
        if not drives:
            raise KinematicsError("a calculator needs at least one drive")
        self.drives = tuple(drives)
        self.fixed_wheels = tuple(w for w in passive_wheels if getattr(w, "fixed", False))
        self.projection_name = check_projection(projection)
        self.x = [float(d.x) for d in self.drives]
        self.y = [float(d.y) for d in self.drives]
        self.steerable = [d.steerable for d in self.drives]
        self.axle, problems = common_axle(self.drives, self.fixed_wheels)
        if problems:
            raise KinematicsError("; ".join(p.rule for p in problems))
        self.fixed_axles = axle_lines((), self.fixed_wheels)  # one per fixed wheel, in order
        self.constraints = [list(a.constraint) for a in axle_lines(self.drives, self.fixed_wheels)]
        self.basis = null_space(self.constraints)  # rows b_k; every realisable twist is sum z_k b_k
        bt = transpose(self.basis)  # 3 x k
        # The closest realisable twist in least squares compares twists by the velocities they give
        # the wheels that define the body's motion: the drives and the fixed wheels (casters follow,
        # so they do not).
        points = list(zip(self.x, self.y)) + [(w.x, w.y) for w in self.fixed_wheels]
        m_all = wheel_matrix(points)
        reduced = inverse(matmul(matmul(self.basis, m_all), bt))
        self.lsq_projection = matmul(matmul(matmul(bt, reduced), self.basis), m_all)
        # Least-squares odometry: minimise sum |J_i t - v_i|^2 over the measured drives, subject to
        # the constraints, so t = P b with b = sum J_i^T v_i.
        self.lsq = self.lsq_for(tuple(True for _ in self.drives))
        if self.lsq is None:
            raise KinematicsError(
                "the drives' wheel velocities cannot determine the robot's motion (one drive needs fixed "
                "passive wheels off its position)"
            )

    def lsq_for(self, heard: Sequence[bool]) -> Optional[Matrix]:
        """P of the least-squares odometry over the drives heard (t = P b, b summed over them), None if
        they cannot determine the motion. The constraints stay every wheel's: a type-1 drive whose
        reports stopped still cannot slide sideways."""
        bt = transpose(self.basis)
        m_heard = wheel_matrix([(x, y) for x, y, h in zip(self.x, self.y, heard) if h])
        try:
            reduced = inverse(matmul(matmul(self.basis, m_heard), bt))
        except KinematicsError:
            return None
        return tuple(tuple(row) for row in matmul(matmul(bt, reduced), self.basis))

    @property
    def constrained(self) -> bool:
        return self.axle is not None

    def project(self, vx: float, vy: float, wz: float) -> Vector:
        """The realisable twist this layout's projection gives for (vx, vy, wz)."""
        if self.axle is None:
            return (vx, vy, wz)
        if self.projection_name == "axle":
            a = self.axle
            ux, uy = a.rolling
            along = vx * ux + vy * uy
            # The axle's contact may not move across the axle: (v . d) + wz * moment = 0.
            across = -wz * a.moment
            # + 0.0 turns the -0.0 of an axle through base_link into 0.0 for whoever prints it
            return (along * ux + across * a.dx + 0.0, along * uy + across * a.dy + 0.0, wz)
        p = self.lsq_projection
        return (
            p[0][0] * vx + p[0][1] * vy + p[0][2] * wz,
            p[1][0] * vx + p[1][1] * vy + p[1][2] * wz,
            p[2][0] * vx + p[2][1] * vy + p[2][2] * wz,
        )
