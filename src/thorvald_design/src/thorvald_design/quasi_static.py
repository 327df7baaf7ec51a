"""The quasi-static limits of a wheeled robot: how steep it climbs, how hard it pulls, how close it is
to tipping, from its weight, centre of mass, wheel contacts, surface friction and motor torques.

Pure: numbers in, numbers out (stdlib and numpy only; no rospy, no pybullet, no messages). A design
study predicts with it, and checks a simulation's results against it. A robot's layout is read from
its configuration and description apart, in :mod:`thorvald_design.robot_layout`.

Frames and signs. Everything is in base_link's axes (x forward, y left), SI units, angles in radians
(the results' ``to_dict`` gives degrees). The robot stands on a plane; z is the height above that
plane, so a :class:`Layout`'s centre of mass is (x, y in base_link, h above the ground). The plane is
inclined by ``pitch`` (positive: nose up, climbing forward; ROS's pitch has the opposite sign) and
``roll`` (positive: left side up, as ROS's roll).

Statics (derived once here; the functions' comments refer back to it)
----------------------------------------------------------------------
Body orientation Ry(-pitch) Rx(roll) (nose up, then left side up). Gravity, W = m g, in the body
frame (x, y along the plane, z normal to it)::

    F = R^T (0, 0, -W) = (-W sin(pitch),  -W cos(pitch) sin(roll),  -W cos(pitch) cos(roll))

acting at the centre of mass c = (xc, yc, h). A drawbar ``pull`` P acts along -x (backwards,
parallel to the ground) at height ``pull_height`` hp. Each wheel i touches the ground at
(x_i, y_i, 0) with a normal load N_i (along +z) and a tangential force (traction, braking, side
force) in the ground plane. Take moments about axes lying in the ground plane through the origin:
the tangential forces act in that plane, so their moments about those axes vanish, and three
equations hold whatever the tangential forces are::

    sum N_i           = W cos(pitch) cos(roll)                                =: Nz
    sum N_i x_i       = Nz xc - W h sin(pitch) - P hp                         =: My
    sum N_i y_i       = Nz yc - W h cos(pitch) sin(roll)                      =: Mx

(from r x F: the y-moment of gravity at c is h Fx - xc Fz, the x-moment yc Fz - h Fy; of the pull,
-hp P; of a load N_i at (x_i, y_i, 0), (y_i N_i, -x_i N_i)). The resultant normal load Nz acts at the
centre of pressure p = (My / Nz, Mx / Nz): the centre of mass moved downhill by h tan(pitch) /
cos(roll) along -x and h tan(roll) along -y, and back by hp P / Nz for a pull.

Three equations fix three loads: three contacts not on one line are statically determinate (each
load is Nz times the centre of pressure's barycentric coordinate in the triangle). More contacts are
indeterminate; the rigid-frame assumption closes the problem: the frame is a rigid plate on equal
wheel springs, so a wheel's load is linear in its position, N_i = a + b x_i + c y_i, and (a, b, c)
come from the three equations above (:func:`normal_loads`). This is also the least-squares load
sharing: of all load sets in equilibrium, the one with least sum N_i^2. With fewer than 3 contacts,
or all on one line, the 3 x 3 system is singular: such a robot cannot stand, and :class:`Layout`
refuses it.

A wheel cannot pull the ground: where the linear model gives a load below 0, that wheel lifts, and
the robot stands on the others. :func:`normal_loads` reports the linear model as is (a negative load
says that wheel lifts); :func:`contact_loads` gives the loads the wheels really carry: the same
springs, but one-sided (N_i = max(0, a + b x_i + c y_i), the plate's equilibrium found by Newton's
method), which differs from the linear model only once a wheel lifts. The robot itself tips when the
centre of pressure leaves the support polygon (the convex hull of the contacts in plan), at which
point no loads >= 0 balance it. On a two-axle layout with the centre of mass on the centre line, and
on any three-wheeler, the linear model's first zero load and the tipping point are the same angle; on
a robot with three axles (6WD) the front axle lifts well before the robot tips (it then stands on two
axles), so tipping is taken from the support polygon, never from the first zero load.

Friction, rolling resistance and motors. Rolling resistance is a torque C_rr r N_i at each wheel
against its rolling (the offset of a tyre's pressure under it; the simulator's rolling friction is
exactly this): it costs the motors torque, not the ground grip. A wheel's tangential force T_i is
bounded by the grip, |T_i| <= mu N_i; a driven wheel's motor gives T_i r + C_rr N_i r <= F_i r, F_i
its torque limit at the rim (max_wheel_torque / r_wheel); a free wheel turns with T_i = -C_rr N_i.
Driving, the driven wheels give at most min(mu N_i, F_i - C_rr N_i) each and the free wheels take
C_rr N_i each, which reads, with C_rr N_i added on both sides,

    sum_driven min((mu + C_rr) N_i, F_i) >= (what the task asks) + C_rr Nz

the familiar sum with rolling resistance on every wheel, whose driven wheels' grip is mu + C_rr (the
rolling resistance a driven wheel pays is its motor's, not its grip's).

The same torque has a moment about the ground-plane axes, which the statics above leave out unless
asked (``rolling_offset``): a tyre's pressure lying ahead of its axle puts its load's line of action
e = C_rr r ahead of the contact (the simulator's rolling friction, a torque of e N_i on each wheel,
is the same moment), so a robot rolling forward has sum N_i (x_i + e) = My: its centre of pressure
lies e further back than it would standing. Climbing, that is e less between the centre of pressure
and the rear edge: tan(theta) = (d - e) / h at tipping, 1.2 degrees less for the rear-driven
tricycle on grass (e = 12 mm, d = 138 mm, h = 0.5 m) than standing. The predictions a study reports
are the standing figures (``rolling_offset`` 0); the design study's explanation of a gap between a
simulated climb and its prediction gives the rolling one beside them. Braking (nose down) the
torque helps the motor and not the grip: min((mu - C_rr) N_i, F_i) each against the slope's pull less
C_rr Nz. Terramechanics' drawbar pull (thrust less motion resistance, both at the contact) is the
other model, of a wheel sinking into soft soil; the simulator's wheels roll on springs and pay the
rolling resistance as a torque, and a simulated pull agrees with this one (mud: mu W, not
(mu - C_rr) W).

Casters: :func:`thorvald_design.robot_layout.layout_of` puts a caster's contact at its swivel axis
(x, y). The wheel really trails the axis by caster_offset, behind it when the robot drives forward,
so the real support polygon is that much larger (at most caster_offset, 5 cm on the example robots)
in the direction of travel: the figures here are slightly conservative for a robot standing on
casters.
"""

import math
from dataclasses import dataclass
from typing import Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np

from .errors import StaticsError
from .geometry import hull_corners

__all__ = [
    "TIPPING",
    "TORQUE",
    "TRACTION",
    "Contact",
    "Edge",
    "GradeLimits",
    "Layout",
    "Overturning",
    "PullLimit",
    "contact_loads",
    "gradeability",
    "max_pull",
    "normal_loads",
    "overturning_angles",
    "support_polygon",
    "with_payload",
]

GRAVITY = 9.81  # [m/s^2]
ANGLE_TOLERANCE = 1e-6  # [rad] the limits' bisection stops within it
FORCE_TOLERANCE = 1e-6  # [N]
COLLINEAR_TOLERANCE = 1e-6  # [m] contacts nearer than this to one line stand on a line
_SCAN_STEPS = 256  # a limit is first bracketed on this many steps, so that it is the first crossing

# What binds a limit
TRACTION = "traction"  # the driven wheels' grip, mu N_i
TORQUE = "motor torque"  # the driven wheels' motors, max_wheel_torque / r_wheel
TIPPING = "tipping"  # the centre of pressure reaches the edge of the support polygon


# ---- the layout ------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Contact:
    """One wheel's ground contact."""

    name: str
    x: float  # [m] in base_link, horizontal
    y: float  # [m]
    driven: bool
    max_force: float  # [N] the motor's torque limit at the rim: max_wheel_torque / r_wheel (0 if not driven)

    def __post_init__(self) -> None:
        if not (math.isfinite(self.x) and math.isfinite(self.y)):
            raise StaticsError(f"contact {self.name}: position ({self.x}, {self.y}) is not finite")
        if not (self.max_force >= 0.0 and math.isfinite(self.max_force)):
            raise StaticsError(f"contact {self.name}: max_force {self.max_force} N must be finite and >= 0")


@dataclass(frozen=True)
class Layout:
    """A robot as its quasi-static limits see it: its mass, its centre of mass and its wheel contacts.

    com: x, y in base_link; z is the height above the ground plane [m]. A layout has at least three
    contacts not on one line (the least a robot stands on); StaticsError otherwise.
    """

    mass: float  # [kg]
    com: Tuple[float, float, float]
    contacts: Tuple[Contact, ...]

    def __post_init__(self) -> None:
        object.__setattr__(self, "contacts", tuple(self.contacts))
        object.__setattr__(self, "com", tuple(float(v) for v in self.com))
        if not (self.mass > 0.0 and math.isfinite(self.mass)):
            raise StaticsError(f"the robot's mass must be finite and > 0 kg, not {self.mass}")
        if len(self.com) != 3 or not all(math.isfinite(v) for v in self.com):
            raise StaticsError(f"the centre of mass must be 3 finite numbers (x, y, height), not {self.com}")
        if self.com[2] < 0.0:
            raise StaticsError(f"the centre of mass is {-self.com[2]:.3f} m below the ground: its height must be >= 0")
        names = [c.name for c in self.contacts]
        if len(self.contacts) < 3:
            raise StaticsError(
                f"a robot needs at least 3 wheel contacts not on one line to stand; this layout has "
                f"{len(self.contacts)} ({', '.join(names) or 'none'})"
            )
        if len(set(names)) != len(names):
            raise StaticsError(f"the contacts' names repeat: {', '.join(names)}")
        # The contacts' RMS distance from their best-fitting line: the smaller singular value of their
        # centred positions over sqrt(n).
        xy = np.array([(c.x, c.y) for c in self.contacts])
        spread = np.linalg.svd(xy - xy.mean(axis=0), compute_uv=False)[-1] / math.sqrt(len(xy))
        if spread < COLLINEAR_TOLERANCE:
            raise StaticsError(
                f"the wheel contacts {', '.join(names)} lie on one line: a robot needs 3 contacts not on "
                "one line to stand"
            )

    @property
    def height(self) -> float:
        """The centre of mass's height above the ground [m]."""
        return self.com[2]

    @property
    def driven(self) -> Tuple[Contact, ...]:
        return tuple(c for c in self.contacts if c.driven)

    def weight(self, gravity: float = GRAVITY) -> float:
        """[N]"""
        return self.mass * gravity


def with_payload(layout: Layout, mass: float, x: float, y: float, z_above_ground: float) -> Layout:
    """The layout carrying a point mass [kg] at (x, y) in base_link, z_above_ground above the ground."""
    if not (mass >= 0.0 and math.isfinite(mass)):
        raise StaticsError(f"the payload's mass must be finite and >= 0 kg, not {mass}")
    if not all(math.isfinite(v) for v in (x, y, z_above_ground)):
        raise StaticsError(f"the payload's position ({x}, {y}, {z_above_ground}) is not finite")
    total = layout.mass + mass
    com = tuple((layout.mass * c + mass * p) / total for c, p in zip(layout.com, (x, y, z_above_ground)))
    return Layout(total, com, layout.contacts)  # type: ignore[arg-type]


# ---- the support polygon ---------------------------------------------------------------------------
def support_polygon(layout: Layout) -> Tuple[Contact, ...]:
    """The support polygon's corners: the convex hull of the contacts in plan, anticlockwise seen from
    above (:func:`thorvald_design.geometry.hull_corners`); a contact on an edge (a 6WD's middle wheel)
    is no corner."""
    return tuple(layout.contacts[i] for i in hull_corners([(c.x, c.y) for c in layout.contacts]))


def _edges(layout: Layout) -> List[Tuple[Contact, Contact, float, float]]:
    """(start, end, outward normal x, y) of each edge of the support polygon, anticlockwise."""
    hull = support_polygon(layout)
    out = []
    for k, a in enumerate(hull):
        b = hull[(k + 1) % len(hull)]
        dx, dy = b.x - a.x, b.y - a.y
        length = math.hypot(dx, dy)
        out.append((a, b, dy / length, -dx / length))  # outside is on the right of an anticlockwise edge
    return out


def _inside_distances(layout: Layout, px: float, py: float) -> List[float]:
    """The point's distance inside each edge's line (negative: outside it), in _edges' order."""
    return [-((px - a.x) * nx + (py - a.y) * ny) for a, _, nx, ny in _edges(layout)]


def _distance_to_edge(layout: Layout, px: float, py: float, ux: float, uy: float) -> float:
    """How far the point (inside the support polygon) moves along the unit vector u to its edge [m]."""
    best = math.inf
    for (_, _, nx, ny), d in zip(_edges(layout), _inside_distances(layout, px, py)):
        rate = nx * ux + ny * uy  # the distance to this edge's line shrinks at this rate along u
        if rate > 1e-12:
            best = min(best, d / rate)
    return best


def _check_stands(layout: Layout) -> None:
    if min(_inside_distances(layout, layout.com[0], layout.com[1])) <= 0.0:
        raise StaticsError(
            f"the centre of mass ({layout.com[0]:.3f}, {layout.com[1]:.3f}) is not inside the support polygon "
            f"({', '.join(c.name for c in support_polygon(layout))}): the robot falls over on level ground"
        )


def _tipping_slope(layout: Layout, ux: float, uy: float, rolling_offset: float = 0.0) -> float:
    """The slope at which the robot tips when its fall line points along u (in plan, base_link) [rad].

    On a slope alpha the centre of pressure moves h tan(alpha) downhill (the statics above), so it
    reaches the edge when tan(alpha) = d / h, d the centre of mass's distance to the edge along u;
    rolling forward, d is measured from rolling_offset [m] behind the centre of mass (the module's
    docstring). A robot whose centre of pressure is outside already tips at 0.
    """
    d = _distance_to_edge(layout, layout.com[0] - rolling_offset, layout.com[1], ux, uy)
    return math.atan2(max(d, 0.0), layout.height)


# ---- loads -----------------------------------------------------------------------------------------
def _resultants(
    layout: Layout,
    pitch: float,
    roll: float,
    gravity: float,
    *,
    pull: float,
    pull_height: float,
    rolling_offset: float = 0.0,
) -> Tuple[float, float, float]:
    """(Nz, My, Mx) of the module's statics: the loads' sum, and their moments sum N x, sum N y; rolling
    forward, each load's line of action rolling_offset [m] ahead of its contact (the module's
    docstring), sum N x is rolling_offset Nz less."""
    for what, v in (("pitch", pitch), ("roll", roll)):
        if not (abs(v) <= math.pi / 2):
            raise StaticsError(f"{what} {v} rad is not within +-pi/2")
    if not (gravity > 0.0 and math.isfinite(gravity)):
        raise StaticsError(f"gravity must be finite and > 0, not {gravity}")
    if not (math.isfinite(pull) and math.isfinite(pull_height)):
        raise StaticsError(f"the pull {pull} N at {pull_height} m is not finite")
    if not (rolling_offset >= 0.0 and math.isfinite(rolling_offset)):
        raise StaticsError(f"rolling_offset must be finite and >= 0 m, not {rolling_offset}")
    w = layout.mass * gravity
    xc, yc, h = layout.com
    nz = w * math.cos(pitch) * math.cos(roll)
    my = nz * (xc - rolling_offset) - w * h * math.sin(pitch) - pull * pull_height
    mx = nz * yc - w * h * math.cos(pitch) * math.sin(roll)
    return nz, my, mx


def _system(layout: Layout, f: Tuple[float, float, float]) -> Tuple[np.ndarray, np.ndarray]:
    """The rows (1, x_i, y_i) and the resultants (Nz, My, Mx), both about the contacts' centroid (the
    same equations, better conditioned: My and Mx move by the centroid times Nz)."""
    xy = np.array([(c.x, c.y) for c in layout.contacts])
    centroid = xy.mean(axis=0)
    rows = np.column_stack([np.ones(len(xy)), xy - centroid])
    nz, my, mx = f
    return rows, np.array([nz, my - centroid[0] * nz, mx - centroid[1] * nz])


def normal_loads(
    layout: Layout,
    pitch: float,
    roll: float = 0.0,
    gravity: float = GRAVITY,
    *,
    pull: float = 0.0,
    pull_height: float = 0.0,
    rolling_offset: float = 0.0,
) -> Tuple[float, ...]:
    """Each contact's normal load [N], in the layout's order, by the rigid-frame linear model.

    N_i = a + b x_i + c y_i with a, b, c from the three equilibrium equations of the module's
    docstring: with rows r_i = (1, x_i, y_i), sum r_i N_i = (Nz, My, Mx), so (sum r_i r_i^T) (a, b, c)
    = (Nz, My, Mx). Exact statics for three contacts. A load below 0 is reported as it is: that
    wheel lifts (see :func:`contact_loads` for the loads once it has). rolling_offset [m]: rolling
    forward, each load's line of action that far ahead of its contact (the module's docstring).
    """
    f = _resultants(layout, pitch, roll, gravity, pull=pull, pull_height=pull_height, rolling_offset=rolling_offset)
    rows, f = _system(layout, f)
    coefficients = np.linalg.solve(rows.T @ rows, f)
    return tuple(float(n) for n in rows @ coefficients)


def _one_sided(rows: np.ndarray, f: np.ndarray) -> np.ndarray:
    """The loads N_i = max(0, r_i . k) with sum r_i N_i = f (module's docstring: one-sided springs).

    k minimises the convex phi(k) = 1/2 sum max(0, r_i . k)^2 - k . f, whose gradient is
    sum r_i N_i - f: its minimum is the equilibrium. Newton's method on it (the Hessian is
    sum r_i r_i^T over the wheels in contact) with a backtracking line search; started from the
    linear model, which is the answer when no load is below 0. phi is bounded below, so this
    converges, exactly when the centre of pressure is inside the support polygon (the caller's check).
    """
    k = np.linalg.solve(rows.T @ rows, f)
    scale = abs(f[0]) * (1.0 + float(np.max(np.abs(rows[:, 1:]))))

    def phi(v: np.ndarray) -> float:
        return 0.5 * float(np.sum(np.maximum(rows @ v, 0.0) ** 2)) - float(v @ f)

    for _ in range(200):
        d = rows @ k
        loads = np.maximum(d, 0.0)
        gradient = rows.T @ loads - f
        if float(np.max(np.abs(gradient))) <= 1e-9 * scale:
            return loads
        touching = rows[d > 0.0]
        # least squares: the wheels in contact may lie on a line on the way (a singular Hessian)
        step = -np.linalg.lstsq(touching.T @ touching, gradient, rcond=None)[0]
        t, phi0, slope = 1.0, phi(k), float(gradient @ step)
        while phi(k + t * step) > phi0 + 1e-4 * t * slope and t > 1e-12:
            t *= 0.5
        k = k + t * step
    raise StaticsError(f"the wheel loads did not converge (resultants {f.tolist()})")


def contact_loads(
    layout: Layout,
    pitch: float,
    roll: float = 0.0,
    gravity: float = GRAVITY,
    *,
    pull: float = 0.0,
    pull_height: float = 0.0,
    rolling_offset: float = 0.0,
) -> Tuple[float, ...]:
    """Each contact's normal load [N] as the wheels carry it: all >= 0, a lifted wheel's 0.

    The same rigid frame on wheel springs as :func:`normal_loads`, the springs one-sided; equal to
    normal_loads while it has no load below 0. StaticsError if the robot tips: the centre of pressure is
    not inside the support polygon, so no loads >= 0 balance it.
    """
    nz, my, mx = _resultants(
        layout, pitch, roll, gravity, pull=pull, pull_height=pull_height, rolling_offset=rolling_offset
    )
    if nz <= 0.0 or min(_inside_distances(layout, my / nz, mx / nz)) <= 0.0:
        where = f"({my / nz:.3f}, {mx / nz:.3f})" if nz > 0.0 else "at infinity"
        raise StaticsError(
            f"the robot tips at pitch {math.degrees(pitch):.2f} deg, roll {math.degrees(roll):.2f} deg, pull "
            f"{pull:.1f} N: its centre of pressure {where} is outside the support polygon"
        )
    rows, f = _system(layout, (nz, my, mx))
    return tuple(float(n) for n in _one_sided(rows, f))


# ---- limits ----------------------------------------------------------------------------------------
def _first_failure(holds: Callable[[float], bool], upper: float, tolerance: float) -> Optional[float]:
    """The least x in [0, upper) at which holds(x) is False, to tolerance; None if it holds throughout.

    The conditions here are monotone on the layouts met, but a scan of _SCAN_STEPS points brackets
    the first failure before the bisection, so a condition that fails and holds again further on
    still gives its first failure. upper itself is never evaluated (the robot tips there).
    """
    if not holds(0.0):
        return 0.0
    low = 0.0
    for k in range(1, _SCAN_STEPS + 1):
        x = upper * k / _SCAN_STEPS if k < _SCAN_STEPS else upper - tolerance / 4.0
        if x <= low:
            continue
        if not holds(x):
            high = x
            while high - low > tolerance:
                mid = 0.5 * (low + high)
                if holds(mid):
                    low = mid
                else:
                    high = mid
            return 0.5 * (low + high)
        low = x
    return None


def _check_surface(friction: float, rolling_resistance: float, gravity: float) -> None:
    if not (friction >= 0.0 and math.isfinite(friction)):
        raise StaticsError(f"friction (mu) must be finite and >= 0, not {friction}")
    if not (rolling_resistance >= 0.0 and math.isfinite(rolling_resistance)):
        raise StaticsError(f"rolling_resistance (C_rr) must be finite and >= 0, not {rolling_resistance}")
    if not (gravity > 0.0 and math.isfinite(gravity)):
        raise StaticsError(f"gravity must be finite and > 0, not {gravity}")


def _check_driven(layout: Layout) -> None:
    if not layout.driven:
        raise StaticsError(f"no wheel of the layout is driven ({', '.join(c.name for c in layout.contacts)})")


def _driving(friction: float, rolling_resistance: float) -> float:
    """The driven wheels' grip coefficient in the sums when they drive: mu + C_rr (the module's docstring)."""
    return friction + rolling_resistance


def _braking(friction: float, rolling_resistance: float) -> float:
    """... and when they brake: mu - C_rr (none below 0)."""
    return max(friction - rolling_resistance, 0.0)


def _effort(layout: Layout, loads: Sequence[float], grip: float, friction: bool = True, torque: bool = True) -> float:
    """sum over the driven wheels of min(grip N_i, F_i) [N], grip the coefficient of :func:`_driving` or
    :func:`_braking` (friction False: F_i alone; torque False: grip N_i alone)."""
    total = 0.0
    for c, n in zip(layout.contacts, loads):
        if c.driven:
            limits = ([grip * max(n, 0.0)] if friction else []) + ([c.max_force] if torque else [])
            total += min(limits)
    return total


def _binding(layout: Layout, loads: Sequence[float], grip: float) -> str:
    """Which bound the driven wheels' force at these loads: the one that limits the larger share of it."""
    by_grip = by_torque = 0.0
    for c, n in zip(layout.contacts, loads):
        if c.driven:
            held = grip * max(n, 0.0)
            if held <= c.max_force:
                by_grip += held
            else:
                by_torque += c.max_force
    return TRACTION if by_grip >= by_torque else TORQUE


@dataclass(frozen=True)
class GradeLimits:
    """How steep the robot drives straight up and down a slope, quasi-statically [rad].

    climb: the steepest slope it climbs forward (the first to bind of its driven wheels' force and
    tipping), limited_by says which (TRACTION, TORQUE or TIPPING). traction: friction alone (motors
    unlimited); torque: the motors alone (friction unlimited); tipping: where it tips backwards. Each
    of traction and torque ignores the other limits; past tipping, traction is what friction would
    allow the robot held onto the slope (the textbook two-axle figure). lift: where the first wheel
    leaves the ground climbing (by the linear model; the robot stands on the others until tipping).
    descent: the steepest slope on which the driven wheels hold the robot nose down, braking (or
    where it tips forwards), descent_limited_by which.
    """

    climb: float
    limited_by: str
    traction: float
    torque: float
    tipping: float
    lift: float
    descent: float
    descent_limited_by: str

    @property
    def climb_deg(self) -> float:
        return math.degrees(self.climb)

    @property
    def traction_deg(self) -> float:
        return math.degrees(self.traction)

    @property
    def torque_deg(self) -> float:
        return math.degrees(self.torque)

    @property
    def tipping_deg(self) -> float:
        return math.degrees(self.tipping)

    @property
    def descent_deg(self) -> float:
        return math.degrees(self.descent)

    def to_dict(self) -> Dict[str, object]:
        """The limits in degrees (``*_deg``), and what bound them."""
        out: Dict[str, object] = {}
        for name in ("climb", "traction", "torque", "tipping", "lift", "descent"):
            out[f"{name}_deg"] = math.degrees(getattr(self, name))
        out["limited_by"] = self.limited_by
        out["descent_limited_by"] = self.descent_limited_by
        return out


def gradeability(
    layout: Layout,
    friction: float,
    rolling_resistance: float = 0.0,
    gravity: float = GRAVITY,
    *,
    rolling_offset: float = 0.0,
) -> GradeLimits:
    """The robot's grade limits (:class:`GradeLimits`) on a surface of friction mu and rolling
    resistance C_rr; StaticsError if no wheel is driven or the robot cannot stand on level ground.

    Climbing forward at constant speed on a slope theta, the driven wheels must push up the slope
    the weight's component along it and the rolling resistance of every wheel (the statics: the
    tangential forces balance W sin(theta), the loads sum to W cos(theta)):

        sum_driven min((mu + C_rr) N_i(theta), F_i) >= W sin(theta) + C_rr W cos(theta)

    with N_i the loads the wheels carry (:func:`contact_loads`; load moves to the rear as theta
    grows: rear drive gains, front drive loses) and mu + C_rr the driven wheels' grip in this sum
    (the module's docstring: rolling resistance is a torque; every wheel driven, tan(theta) = mu).
    traction drops the F_i, torque the grip (W (sin + C_rr cos) = sum F_i: theta = asin(sum F /
    (W sqrt(1 + C_rr^2))) - atan(C_rr)). tipping:
    the centre of pressure moves h tan(theta) back, out of the support polygon at tan(theta) = d / h,
    d the distance from the centre of mass back to its edge. Nose down, braking, the weight pulls
    down the slope and rolling resistance helps hold it:

        sum_driven min((mu - C_rr) N_i(-theta), F_i) >= W sin(theta) - C_rr W cos(theta)

    Each limit is the first theta where its condition fails, bracketed on a scan and bisected to
    1e-6 rad. rolling_offset [m]: the loads' lines of action that far ahead of their contacts, the
    moment of the rolling resistance (the module's docstring; C_rr r for wheels of radius r; 0: the
    standing figures).
    """
    _check_surface(friction, rolling_resistance, gravity)
    _check_driven(layout)
    _check_stands(layout)
    w = layout.weight(gravity)
    c_rr = rolling_resistance

    def climbing(theta: float) -> float:  # what the slope asks of the driven wheels [N]
        return w * (math.sin(theta) + c_rr * math.cos(theta))

    e = rolling_offset

    def standing(pitch: float) -> Tuple[float, ...]:
        return contact_loads(layout, pitch, gravity=gravity, rolling_offset=e)

    tipping = _tipping_slope(layout, -1.0, 0.0, e)  # climbing, it tips backwards: u = -x
    tipping_forward = _tipping_slope(layout, 1.0, 0.0, e)

    drive, brake = _driving(friction, c_rr), _braking(friction, c_rr)
    climb = _first_failure(lambda t: _effort(layout, standing(t), drive) >= climbing(t), tipping, ANGLE_TOLERANCE)
    if climb is None:
        climb, limited_by = tipping, TIPPING
    else:
        limited_by = _binding(layout, standing(climb), drive)

    def held_loads(theta: float) -> Tuple[float, ...]:  # past tipping: the robot held onto the slope
        return standing(theta) if theta < tipping else normal_loads(layout, theta, gravity=gravity, rolling_offset=e)

    traction = _first_failure(
        lambda t: _effort(layout, held_loads(t), drive, torque=False) >= climbing(t), math.pi / 2, ANGLE_TOLERANCE
    )
    motors = sum(c.max_force for c in layout.driven)
    torque = _first_failure(lambda t: motors >= climbing(t), math.pi / 2, ANGLE_TOLERANCE)

    lift = _first_failure(
        lambda t: min(normal_loads(layout, t, gravity=gravity, rolling_offset=e)) > 0.0, tipping, ANGLE_TOLERANCE
    )

    descent = _first_failure(
        lambda t: _effort(layout, standing(-t), brake) >= w * (math.sin(t) - c_rr * math.cos(t)),
        tipping_forward,
        ANGLE_TOLERANCE,
    )
    if descent is None:
        descent, descent_limited_by = tipping_forward, TIPPING
    else:
        descent_limited_by = _binding(layout, standing(-descent), brake)

    return GradeLimits(
        climb=climb,
        limited_by=limited_by,
        traction=math.pi / 2 if traction is None else traction,
        torque=math.pi / 2 if torque is None else torque,
        tipping=tipping,
        lift=tipping if lift is None else lift,
        descent=descent,
        descent_limited_by=descent_limited_by,
    )


@dataclass(frozen=True)
class PullLimit:
    """The largest drawbar pull the robot holds on level ground, and what bounds it."""

    pull: float  # [N] horizontal, backwards, at the pull height
    limited_by: str  # TRACTION, TORQUE or TIPPING

    def to_dict(self) -> Dict[str, object]:
        return {"pull_n": self.pull, "limited_by": self.limited_by}


def max_pull(
    layout: Layout,
    friction: float,
    rolling_resistance: float,
    pull_height: float,
    gravity: float = GRAVITY,
    *,
    rolling_offset: float = 0.0,
) -> PullLimit:
    """The largest horizontal backward pull P at pull_height [m] that the driven wheels hold on level
    ground at constant speed: sum_driven min((mu + C_rr) N_i(P), F_i) >= P + C_rr W (every wheel
    driven and the motors strong enough: P = mu W).

    The pull moves load to the rear (My falls by P hp: the centre of pressure moves hp P / W back),
    which helps rear drive and lifts the front; the robot tips backwards at P = W d / hp, d the
    distance from the centre of mass back to the support polygon's edge. sum min(...) is at most
    min((mu + C_rr) W, sum F_i), so the pull is too; the first failing pull is bracketed and bisected to 1e-6 N.
    rolling_offset [m]: as :func:`gradeability`'s (the centre of pressure that much further back).
    StaticsError if no wheel is driven, the robot cannot stand or pull_height < 0.
    """
    _check_surface(friction, rolling_resistance, gravity)
    _check_driven(layout)
    _check_stands(layout)
    if not (pull_height >= 0.0 and math.isfinite(pull_height)):
        raise StaticsError(f"pull_height must be finite and >= 0 m, not {pull_height}")
    w = layout.weight(gravity)
    e = rolling_offset
    back = max(_distance_to_edge(layout, layout.com[0] - e, layout.com[1], -1.0, 0.0), 0.0)
    tipping = w * back / pull_height if pull_height > 0.0 else math.inf
    drive = _driving(friction, rolling_resistance)
    cap = min(drive * w, sum(c.max_force for c in layout.driven))

    def loads(pull: float) -> Tuple[float, ...]:
        return contact_loads(layout, 0.0, gravity=gravity, pull=pull, pull_height=pull_height, rolling_offset=e)

    def holds(pull: float) -> bool:
        return _effort(layout, loads(pull), drive) >= pull + rolling_resistance * w

    upper = min(tipping, cap)
    pull = _first_failure(holds, upper, FORCE_TOLERANCE)
    if pull is None:
        if tipping <= cap:
            return PullLimit(tipping, TIPPING)
        pull = cap  # holds up to the cap, which no pull beyond can pass
    return PullLimit(pull, _binding(layout, loads(pull), drive))


# ---- overturning -----------------------------------------------------------------------------------
SIDES = ("front", "rear", "left", "right")


@dataclass(frozen=True)
class Edge:
    """One edge of the support polygon and the tilt about it that overturns the robot."""

    contacts: Tuple[str, str]  # its end contacts, anticlockwise seen from above
    side: str  # where its outward normal points: "front" (+x), "rear", "left" (+y) or "right"
    distance: float  # [m] from the centre of mass's plan position to the edge's line (negative: outside)
    angle: float  # [rad] atan(distance / h)


@dataclass(frozen=True)
class Overturning:
    """ISO 16231-2 static overturning angles [rad]: the tilt about a support polygon edge at which the
    centre of mass's vertical passes over that edge, atan(d / h).

    front, rear, left, right: the smallest over the edges on that side (an edge's side is where its
    outward normal points, the nearer of +-x, +-y); a side with a corner instead of an edge (a
    three-wheeler's single wheel) tips about one of the two edges meeting there: the smaller of
    their angles. minimum: the smallest of all, about the edge ``edge``.
    """

    front: float
    rear: float
    left: float
    right: float
    minimum: float
    edge: Tuple[str, str]
    edges: Tuple[Edge, ...]

    @property
    def lateral(self) -> float:
        return min(self.left, self.right)

    @property
    def longitudinal(self) -> float:
        return min(self.front, self.rear)

    def to_dict(self) -> Dict[str, object]:
        """The angles in degrees (``*_deg``) and the edge of the minimum."""
        out: Dict[str, object] = {f"{s}_deg": math.degrees(getattr(self, s)) for s in SIDES}
        out["lateral_deg"] = math.degrees(self.lateral)
        out["longitudinal_deg"] = math.degrees(self.longitudinal)
        out["minimum_deg"] = math.degrees(self.minimum)
        out["edge"] = list(self.edge)
        return out


def _side(nx: float, ny: float) -> str:
    if abs(ny) >= abs(nx):
        return "left" if ny > 0.0 else "right"
    return "front" if nx > 0.0 else "rear"


def overturning_angles(layout: Layout) -> Overturning:
    """The static overturning angles (:class:`Overturning`) of the layout.

    Tilting the ground about an edge by alpha moves the centre of pressure h tan(alpha) towards it
    (the statics, with the edge as the tilt axis), perpendicular to it: it reaches the edge when
    tan(alpha) = d / h, d the perpendicular distance from the centre of mass's plan position to the
    edge's line. A centre of mass outside the polygon gives a negative angle for the edges it is
    past. (GradeLimits.tipping is the slope falling along -x, whose tilt axis need not be an edge:
    atan(d_x / h) with d_x the distance along -x, at least the rear angle here.)
    """
    xc, yc, h = layout.com
    edges = []
    for (a, b, nx, ny), d in zip(_edges(layout), _inside_distances(layout, xc, yc)):
        edges.append(Edge((a.name, b.name), _side(nx, ny), d, math.atan2(d, h)))
    angles: Dict[str, float] = {}
    hull = support_polygon(layout)
    units = {"front": (1.0, 0.0), "rear": (-1.0, 0.0), "left": (0.0, 1.0), "right": (0.0, -1.0)}
    for side in SIDES:
        own = [e.angle for e in edges if e.side == side]
        if not own:  # a corner: the edges meeting at the corner furthest out that way
            ux, uy = units[side]
            corner = max(hull, key=lambda c: c.x * ux + c.y * uy).name
            own = [e.angle for e in edges if corner in e.contacts]
        angles[side] = min(own)
    lowest = min(edges, key=lambda e: e.angle)
    return Overturning(
        front=angles["front"],
        rear=angles["rear"],
        left=angles["left"],
        right=angles["right"],
        minimum=lowest.angle,
        edge=lowest.contacts,
        edges=tuple(edges),
    )
