"""Surfaces: pybullet's contact coefficients of a body (:class:`Surface`), the named surface kinds
(``surface:`` on the ground, on patches and on hills; a key given beside it overrides its number),
and the keys that give them.

Numbers for the simulator's wheels (lateral friction 1.0, radius 0.2 m), from the published ranges
for pneumatic and agricultural tyres:

============  ========  =====  ===============  ========  ==========================================
kind          lateral   C_rr   rolling_friction sinkage   what
============  ========  =====  ===============  ========  ==========================================
tarmac        0.9       0.015  0.003            0         dry asphalt
concrete      0.85      0.012  0.0024           0         a dry concrete floor or yard
gravel        0.6       0.05   0.01             0         loose gravel on a firm base
grass         0.55      0.06   0.012            0.004     dry mown grass on firm soil
wet_grass     0.3       0.08   0.016            0.008     wet grass, a field in the morning
mud           0.35      0.2    0.04             0.015     wet, soft soil: a rutted gateway, a track
sand          0.5       0.25   0.05             0.02      dry loose sand
ice           0.1       0.01   0.002            0         ice, or wet plastic sheeting
soil          0.6       0.08   0.016            0.006     bare field soil, tilled and settled
============  ========  =====  ===============  ========  ==========================================

- ``lateral_friction`` is the tyre's peak grip, the friction coefficient of pybullet's Coulomb
  cone in every direction, from the middle of the published ranges: dry asphalt and concrete 0.7
  to 1.0 (tarmac 0.9 as the world file's default ground, concrete a little smoother), loose gravel 0.5
  to 0.7, dry grass 0.45 to 0.65, dry field soil 0.5 to 0.7, wet grass 0.2 to 0.4, wet clay and
  mud 0.2 to 0.5, dry sand 0.4 to 0.6, ice 0.05 to 0.15.
- ``rolling_friction`` [m] is pybullet's rolling resistance: a torque against the wheel's turning of
  this times the normal force, so it is the coefficient of rolling resistance C_rr times the wheel's
  radius. C_rr (the middle of the published ranges: tyres on asphalt 0.01 to 0.02, on concrete
  0.01 to 0.015, on gravel 0.02 to 0.08, on grass and firm field soil 0.05 to 0.1 (bare tilled soil 0.08), on wet grass
  about 0.08, in soft wet soil 0.1 to 0.3, in loose sand 0.15 to 0.3, on ice about 0.01) times the
  Thorvald wheel's 0.2 m. A wheel of another radius r feels C_rr * 0.2 / r: a caster of 0.1 m
  rolls twice as hard. It costs the drive motors torque (the motors hold their speed, so it shows
  as odometry error only where it takes a motor to its torque limit); a coasting wheel slows. It
  costs the simulator too: a robot on rolling friction steps about a fifth slower.
- ``sinkage`` [m] is how far a rolling wheel carrying the reference load of 500 N (a 200 kg robot
  on four wheels) sinks in: turf and topsoil give a few millimetres, wet grass twice that, mud and
  sand 1 to 2 cm (the depth of the ruts a loaded wheel leaves); tarmac, concrete, ice, and gravel
  on its firm base, none. The ground (or the patch) is a spring under each contact point that
  bullet keeps: ``500 / sinkage`` [N/m], critically damped for the 51 kg that the reference load
  weighs (damping ``2 * sqrt(stiffness * 51)`` [N s/m]: it settles within 0.2 s and does not
  bounce at 240 Hz). So a wheel sinks in proportion to its load (the standard robot's wheels carry
  380 to 490 N: 0.76 to 0.98 of ``sinkage``). A body resting on it shares its weight among its
  points: a ball has one, a box four, and a wheel, a thin disc, one while it rolls; at rest bullet
  often keeps a second point at the disc's other rim, and the wheel stands up to half its sinkage
  higher until it rolls again. At most 0.05 m. What it does not do: pybullet applies friction at
  the wheel's own rim, so a sunk wheel still rolls r * omega (measured: the standard robot's 0.2 m
  wheels sunk 11 to 15 mm in mud travel 0.2000 m a radian): the ground truth and the sensors see
  the robot lower and tilted, odometry sees no shorter rolling radius. Neither does any kind's
  spinning friction: it is 0 for every kind (a steering motor turning a wheel on the spot is the
  motor's business).

Pure: no pybullet (the scene sets these numbers on its bodies, :mod:`thorvald_sim.world.bodies`).
"""

import math
from dataclasses import dataclass, field
from typing import Dict, Mapping, Optional, Tuple

from thorvald_model.schema import NON_NEGATIVE, Key, in_range, one_of

from .rules import Rgba

RGBA_TARMAC = (0.35, 0.35, 0.37, 1.0)
RGBA_CONCRETE = (0.75, 0.74, 0.70, 1.0)
RGBA_GRAVEL = (0.55, 0.48, 0.38, 1.0)
RGBA_ICE = (0.70, 0.85, 1.00, 1.0)

SINKAGE_LOAD = 500.0  # [N] on a wheel: the load a surface's sinkage is given for (a 200 kg robot on 4 wheels)
SINKAGE_MASS = SINKAGE_LOAD / 9.81  # [kg] the reference load's mass, critically damped
MAX_SINKAGE = 0.05  # [m]: deeper, a wheel is stuck, not sinking "a little"


@dataclass(frozen=True)
class Surface:
    """pybullet's contact coefficients of one body.

    pybullet multiplies the lateral frictions of the two bodies in a contact, and combines rolling
    and spinning friction as ``a.rolling * b.lateral + b.rolling * a.lateral`` and restitution as
    the product; the simulator's wheels have lateral friction 1.0 and no rolling or spinning
    friction, so these are the effective values under a wheel. A soft surface (``sinkage`` above 0)
    is a spring and damper under each contact point (pybullet's contact stiffness and damping,
    which it puts in series with the other body's: the wheels have none, so rigid).
    """

    lateral_friction: float  # [-] Coulomb coefficient
    rolling_friction: float  # [m] pybullet's rolling resistance (torque per normal force)
    spinning_friction: float  # [m] resistance to turning about the contact normal
    restitution: float = 0.0  # [-] 0 (no bounce) .. 1
    sinkage: float = 0.0  # [m] of a contact point carrying SINKAGE_LOAD; 0 rigid
    kind: str = field(default="", compare=False)  # the surface kind it was made from ("" for none)

    @property
    def soft(self) -> bool:
        return self.sinkage > 0.0

    @property
    def contact_stiffness(self) -> float:
        """[N/m] of each contact point: SINKAGE_LOAD sinks it by ``sinkage`` (infinite when rigid)."""
        return SINKAGE_LOAD / self.sinkage if self.soft else math.inf

    @property
    def contact_damping(self) -> float:
        """[N s/m] of each contact point: critical for SINKAGE_MASS on the spring (0 when rigid)."""
        return 2.0 * math.sqrt(self.contact_stiffness * SINKAGE_MASS) if self.soft else 0.0


@dataclass(frozen=True)
class SurfaceKind:
    """A named kind of ground (``surface: mud``): its numbers and colour (the module's table)."""

    lateral_friction: float  # [-]
    rolling_resistance: float  # [-] C_rr, the rolling resistance coefficient
    rolling_friction: float  # [m] C_rr times REFERENCE_WHEEL_RADIUS
    sinkage: float  # [m] under SINKAGE_LOAD
    rgba: Rgba
    what: str

    def surface(self, name: str) -> Surface:
        return Surface(self.lateral_friction, self.rolling_friction, 0.0, 0.0, self.sinkage, name)


REFERENCE_WHEEL_RADIUS = 0.2  # [m], Thorvald II's: rolling_friction = C_rr * this

# The module's table; rolling_friction is written out (C_rr * 0.2, checked by a test) so that the
# numbers are the table's to the last digit.
SURFACE_KINDS: Dict[str, SurfaceKind] = {
    "tarmac": SurfaceKind(0.9, 0.015, 0.003, 0.0, RGBA_TARMAC, "dry asphalt"),
    "concrete": SurfaceKind(0.85, 0.012, 0.0024, 0.0, RGBA_CONCRETE, "a dry concrete floor or yard"),
    "gravel": SurfaceKind(0.6, 0.05, 0.01, 0.0, RGBA_GRAVEL, "loose gravel on a firm base"),
    "grass": SurfaceKind(0.55, 0.06, 0.012, 0.004, (0.33, 0.55, 0.22, 1.0), "dry mown grass on firm soil"),
    "wet_grass": SurfaceKind(0.3, 0.08, 0.016, 0.008, (0.22, 0.45, 0.20, 1.0), "wet grass"),
    "mud": SurfaceKind(0.35, 0.2, 0.04, 0.015, (0.38, 0.28, 0.18, 1.0), "wet, soft soil"),
    "sand": SurfaceKind(0.5, 0.25, 0.05, 0.02, (0.82, 0.73, 0.52, 1.0), "dry loose sand"),
    "ice": SurfaceKind(0.1, 0.01, 0.002, 0.0, RGBA_ICE, "ice, or wet plastic sheeting"),
    "soil": SurfaceKind(0.6, 0.08, 0.016, 0.006, (0.45, 0.34, 0.24, 1.0), "bare field soil, tilled and settled"),
}


# ---------------------------------------------------------------------------------------------
# The keys
# ---------------------------------------------------------------------------------------------
def frictions(lateral: float) -> Tuple[Key, ...]:
    """The friction keys of an element of one material (no surface kind), lateral friction defaulting to lateral."""
    return (
        Key("lateral_friction", float, lateral, **NON_NEGATIVE),
        Key("rolling_friction", float, 0.0, **NON_NEGATIVE),
        Key("spinning_friction", float, 0.0, **NON_NEGATIVE),
    )


KINDS_RULE = "must be one of " + ", ".join(SURFACE_KINDS)
SINKAGE_RULE = f"must be in [0, {MAX_SINKAGE}] [m]"

# The keys of an element that may name a surface kind default to None: a key not in the file takes its
# surface kind's number (surface_of), or else the element's default (SURFACE_DEFAULTS).
SURFACE_KEYS = (
    Key("surface", str, None, check=one_of(*SURFACE_KINDS), rule=KINDS_RULE),
    Key("lateral_friction", float, None, **NON_NEGATIVE),
    Key("rolling_friction", float, None, **NON_NEGATIVE),
    Key("spinning_friction", float, None, **NON_NEGATIVE),
    Key("sinkage", float, None, check=in_range(0.0, MAX_SINKAGE), rule=SINKAGE_RULE),
)
SURFACE_DEFAULTS = {"rolling_friction": 0.0, "spinning_friction": 0.0, "sinkage": 0.0}
ZERO_HINT = "write sinkage: 0 beside a soft surface kind"
SURFACE_NUMBER = "the surface kind's, else 0"  # the keys' table's default of a surface number


def surface(values: Mapping) -> Surface:
    """The surface of an entry with the :func:`frictions` keys (and a restitution, else 0)."""
    return Surface(
        values["lateral_friction"],
        values["rolling_friction"],
        values["spinning_friction"],
        values.get("restitution", 0.0),
    )


def surface_of(v: Mapping, defaults: Mapping) -> Surface:
    """The surface of an entry with SURFACE_KEYS: each number the file's, else its kind's, else the
    default (0 for a key missing from defaults: the patches report a missing lateral friction)."""
    kind = SURFACE_KINDS.get(v["surface"])
    base = kind.surface(v["surface"]) if kind else None
    numbers = {}
    for name in ("lateral_friction", "rolling_friction", "spinning_friction", "sinkage"):
        if v[name] is not None:
            numbers[name] = v[name]
        elif base is not None:
            numbers[name] = getattr(base, name)
        else:
            numbers[name] = defaults.get(name, 0.0)
    return Surface(
        numbers["lateral_friction"],
        numbers["rolling_friction"],
        numbers["spinning_friction"],
        v.get("restitution", 0.0),
        numbers["sinkage"],
        v["surface"] or "",
    )


def kind_colour(surface: Surface) -> Optional[Rgba]:
    """The colour of the surface's kind; None if it names none."""
    kind = SURFACE_KINDS.get(surface.kind)
    return kind.rgba if kind else None


def rgba_text(name: str, rgba: Rgba) -> str:
    """A colour as the keys' table gives a default: its name and numbers."""
    return f"{name} [{', '.join(f'{c:g}' for c in rgba)}]"
