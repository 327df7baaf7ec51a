"""What the scenarios share: the worlds they write (a ground of a surface kind, a ramp, a step) and the
rules that end a drive (reached, stalled, slid back, tipped).

Pure: numbers and world-file contents (mappings), no simulator.
"""

import dataclasses
import math
from dataclasses import dataclass
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

import numpy as np

from thorvald_model.errors import Problem
from thorvald_model.layout import axle_lines
from thorvald_sim.world.surfaces import SURFACE_KINDS

from ..metrics import Track
from ..quasi_static import Layout
from .kind import Pose

SURFACES = tuple(SURFACE_KINDS)
SURFACE_RULE = "must be one of " + ", ".join(SURFACES)
STALL_WINDOW = 2.0  # [s]: a drive that gains less than STALL_PROGRESS in this long has stalled
STALL_PROGRESS = 0.03  # [m]
SLID_BACK = 0.10  # [m] back from the furthest point reached: sliding, not stopping
TIPPED = math.radians(25.0)  # rolled or pitched this far beyond the ground's own slope: it has gone over


def surface_keys(kind: str) -> Dict[str, float]:
    """A surface kind's contact numbers as a ground's or an element's keys (the world file's)."""
    surface = SURFACE_KINDS[kind]
    return {"lateral_friction": surface.lateral_friction, "rolling_friction": surface.rolling_friction}


def flat_world(surface: str, description: str = "") -> Dict:
    return {"description": description, "ground": {"surface": surface}}


def ramp_world(surface: str, angle: float, run: float, top: float, width: float = 10.0) -> Dict:
    """A hill along +x whose foot is at x = 0: it climbs at angle [rad] over a horizontal run [m], stays
    level for top [m] and comes down the same way; its faces and the ground are of the surface kind,
    its sinkage included: a soft ramp shares a rigid frame's weight among all its wheels, as tyres and
    turf do (on a rigid one, a robot of more than three wheels stands on whichever three touch)."""
    footprint = 2.0 * run + top
    return {
        "description": f"a {math.degrees(angle):.1f} degree ramp of {surface}",
        "ground": {"surface": surface},
        "slopes": {
            "slope0": {
                "x": footprint / 2.0, "y": 0.0, "yaw": 0.0, "width": width, "angle": angle,
                "height": run * math.tan(angle), "top_length": top, "surface": surface,
            }
        },
    }  # fmt: skip


@dataclass
class Progress:
    """Watches a drive along a direction (unit vector (ux, uy)): how far it got, whether it stalled,
    slid back or tipped over a ground sloping at ``slope`` [rad]."""

    ux: float = 1.0
    uy: float = 0.0
    slope: float = 0.0
    start: Optional[Pose] = None
    furthest: float = 0.0
    outcome: str = ""  # "", "stalled", "slid back", "tipping"

    def along(self, pose: Pose) -> float:
        if self.start is None:
            self.start = pose
        return (pose.x - self.start.x) * self.ux + (pose.y - self.start.y) * self.uy

    def failed(self, track: Sequence[Pose]) -> bool:
        """Whether the drive so far has failed (outcome says how)."""
        pose = track[-1]
        s = self.along(pose)
        self.furthest = max(self.furthest, s)
        if max(abs(pose.roll), abs(pose.pitch)) > abs(self.slope) + TIPPED:
            self.outcome = "tipping"
        elif s < self.furthest - SLID_BACK:
            self.outcome = "slid back"
        elif pose.t - track[0].t > STALL_WINDOW + 1.0:
            earlier = at_time(track, pose.t - STALL_WINDOW)
            if s - self.along(earlier) < STALL_PROGRESS:
                self.outcome = "stalled"
        return bool(self.outcome)


def at_time(track: Sequence[Pose], t: float) -> Pose:
    """The last pose at or before t (the first if none)."""
    lo, hi = 0, len(track) - 1
    while lo < hi:
        mid = (lo + hi + 1) // 2
        if track[mid].t <= t:
            lo = mid
        else:
            hi = mid - 1
    return track[lo]


def feasible_twist(config, vx: float, wz: float) -> Tuple[float, float, float]:
    """The twist (vx, vy, wz) in base_link that drives base_link ahead at vx [m/s] turning at wz
    [rad/s] and that the robot's wheels allow: a wheel that cannot steer cannot slide sideways, so
    a point of its axle line must move along the wheel only. For the axle line through (lx, ly)
    along (dx, dy) (:func:`thorvald_model.layout.axle_lines`) that point moves at
    (vx - wz ly, vy + wz lx), whose component along the axle is 0:
    (vx - wz ly) dx + (vy + wz lx) dy = 0, so vy = -((vx - wz ly) dx) / dy - wz lx. A robot whose
    wheels all steer takes vy = 0; one whose axle line runs along x (dy = 0) cannot drive ahead and
    turn both, and is given vy = 0 too (its calculator refuses what it cannot do)."""
    lines = axle_lines(config.drives, config.passive_wheels)
    if not lines or abs(lines[0].dy) < 1e-9:
        return (vx, 0.0, wz)
    line = lines[0]
    return (vx, -((vx - wz * line.y) * line.dx) / line.dy - wz * line.x, wz)


def heading_hold(session, heading: float, speed: float, gain: float = 1.5, max_rate: float = 0.5):
    """A command (of t, for the session's run) that drives at speed [m/s] holding heading [rad] (yaw):
    the yaw error of the session's last pose fed back to the turn rate (a P controller, rate limited),
    as a twist the robot's wheels allow (:func:`feasible_twist`)."""

    def command(t: float) -> Tuple[float, float, float]:
        yaw = session.track[-1].yaw if session.track else heading
        error = math.atan2(math.sin(heading - yaw), math.cos(heading - yaw))
        return feasible_twist(session.config, speed, max(-max_rate, min(max_rate, gain * error)))

    return command


def series(start: float, step: float, stop: float) -> List[float]:
    """start, start + step, ... up to stop (rounded to a millionth: 0.1 + 0.2 is 0.3): the trials of a
    scenario that tries ever steeper slopes or higher steps."""
    out, k = [], 0
    while True:
        value = round(start + k * step, 6)
        if value > stop + 1e-9:
            return out
        out.append(value)
        k += 1


def check_series(start_key: str, stop_key: str):
    """A scenario's check that its series' last value is not below its first."""

    def check(values: Mapping[str, Any], path: str, problems: List[Problem]) -> None:
        if values[stop_key] < values[start_key]:
            rule = f"must be >= {start_key} ({values[start_key]:g})"
            problems.append(Problem(f"{path}.{stop_key}", values[stop_key], rule))

    return check


def track_of(poses: Sequence[Pose]) -> Track:
    """The metrics' track of a session's poses (plan view: t, x, y, yaw)."""
    return Track(
        t=np.array([q.t for q in poses]),
        x=np.array([q.x for q in poses]),
        y=np.array([q.y for q in poses]),
        yaw=np.array([q.yaw for q in poses]),
    )


def mean(values: Sequence[float]) -> float:
    return sum(values) / len(values) if values else 0.0


def rolling_offset(surface: str) -> float:
    """[m] how far ahead of its contact a rolling wheel's load acts on a surface kind: the simulator's
    rolling friction is a torque of this much times the load on every wheel (C_rr r for a tyre of
    radius r: the surfaces' table gives it for Thorvald's 0.2 m wheels), the moment
    :mod:`thorvald_design.quasi_static`'s ``rolling_offset`` takes."""
    return SURFACE_KINDS[surface].rolling_friction


def simulated_layout(design, lab) -> Optional[Layout]:
    """The quasi-static layout of the robot as the simulator holds it: the description's mass and wheel
    contacts, the centre of mass the physics has (``lab.centre_of_mass``, in base_link) above the
    description's ground plane; None before the lab has made a session."""
    com = getattr(lab, "centre_of_mass", None)
    if com is None:
        return None
    ground = design.com[2] - design.layout.com[2]  # base_link's height of the description's ground plane
    return dataclasses.replace(design.layout, com=(com[0], com[1], com[2] - ground))


def as_simulated(design, lab, limits) -> Dict[str, Any]:
    """What explains a gap between a simulated limit and its quasi-static prediction, for the report:
    the centre of mass's height above the ground, the description's and the simulated robot's, and
    ``limits(layout, rolling)`` (the scenario's predictions as a mapping of its result keys, for a
    layout, rolling or standing) of the simulated robot standing (``with_com``) and rolling
    (``with_com_and_rolling``). Empty before the lab has a session; a layout the model refuses (its
    centre of mass outside its wheels) says so."""
    layout = simulated_layout(design, lab)
    if layout is None:
        return {}
    out: Dict[str, Any] = {
        "com_height_m": round(design.layout.height, 4),
        "simulated_com_height_m": round(layout.height, 4),
    }
    try:
        out["with_com"] = limits(layout, False)
        out["with_com_and_rolling"] = limits(layout, True)
    except ValueError as e:
        out["why_not"] = str(e)
    return out
