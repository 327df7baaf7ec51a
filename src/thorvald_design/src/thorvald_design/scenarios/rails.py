"""rails: how far base_driver's odometry is off on a greenhouse's heating pipes, with and without the
wheel diameter switched (paper 3.1: the robot of Figure 2a on double wheels updates the diameter it
calculates with whenever it goes between the floor and the rails).

The robot: every drive carries a flanged rail wheel beside its tyre (``rail_r_wheel``, ``rail_w_wheel``,
``rail_offset`` of thorvald_model's drives), the rail wheels on two lines along base_link x, one pipe's
gauge apart; a robot without them gets every metric "n/a".

The world (:func:`rails_world`): a floor of ``surface`` (concrete); a pair of pipes (the world's ``rails``:
``pipe_radius``, centres ``pipe_height`` above the floor, the gauge and centre line the robot's rail
wheels run on) from the middle of a low hill (``slopes``) 0.5 m ahead of the robot's front, on to
well past where it turns back. A greenhouse trolley is lifted onto its pipes at their start; here the
hill does it: its faces climb at ``ramp_deg`` to a level top ``H`` high, into which the pipes' ends
are sunk. On the floor a drive's rail wheel hangs r - r_rail above it, so on a pipe (its top
h_p = pipe_height + pipe_radius above the floor) base_link stands s = h_p + r_rail - r higher than on
the floor: the rail-wheel step. On the top the tyres carry the robot H above the floor with the
flanges' bottom H + r - r_flange above it; with H = s + (r_flange - r_rail) + 1 cm that is 1 cm over
the pipes' tops (h_p = s - r_rail + r), so the flanges pass over the pipes' sunk ends. Down the far
face the tyres let the rail wheels onto the pipes, the flanges either side of each: a tyre on a face
at angle a has its centre r / cos a above the face below it, so the rail wheel takes over where the
face is h_land = h_p + r_rail - r / cos a high, (H - h_land) / tan a past the top's end, and the tyre
leaves it as the face goes on down.

Procedure: the robot stands 1 s, then drives straight ahead at ``speed`` [m/s] (its heading held),
over the hill and along the pipes until its rearmost drive has run ``rail_length`` [m] on them,
stands 1 s, drives straight back in reverse, up the far face and down the near one, to where it
started, and stands 1 s. It does this twice, in sessions of their own: with the switch and without
it; a drive that stalls, slides back or tips (:class:`~thorvald_design.scenarios.driving.Progress`)
makes its metric "n/a".

The switch: at every control cycle each drive's wheel centre is found from base_link's ground truth
pose (roll, pitch and height applied to the drive's position, the wheel centre r above base_link's
origin as the description stands it: a drive's suspension, if any, is not counted). A wheel whose
centre is past the top's end and within 5 mm of the height a rail wheel on a pipe holds it at
(h_p + r_rail) rides the pipe, and base_driver is told so through set_drive_params: r_wheel =
rail_r_wheel for that drive, and back to the file's r_wheel when it rides off. Each drive is switched
on its own, as it goes on or off: the front and rear drives do so a wheelbase apart, and switching
them all at once would leave half of them wrong by r / r_rail - 1 over that wheelbase each time (for
the greenhouse robot 2 x 1.094 m x 1/2 x 1/3 = 0.36 m: 1.4 % of its 27 m). Without the switch
r_wheel stays the floor's.

Metrics: ``odometry_error_pct`` (and ``odometry_error_pct_without_switch``) is the odometry's path
length against base_link's true path length (in 3-D: what the wheels rolled, the hill's faces
included), in % of the true one: 100 (D_odom - D_true) / D_true. ``end_point_error_m`` and
``turnaround_error_m`` (each also ``_without_switch``) are the distances between odometry's and the
truth's positions (odom frame: the spawn pose) where the robot ended and where it turned back.
``rail_share`` is the share of the true distance each drive ran on the pipes (the drives' mean), and
``max_rail_offset_m`` the furthest base_link strayed across the pipes' centre line while every drive
was on them (the flanges hold it within their play).

What the metric must agree with: a drive measures its wheel's turning rate w and base_driver reads
its rim speed w r with the r_wheel it is given. On the pipes the wheel rolls on its rail wheel,
v = w r_rail, so without the switch the drive reports v r / r_rail: too fast by r / r_rail - 1.
Driving straight, the standard calculator's velocity is the mean of its drives', so the odometry's
distance is the true one plus, from each drive, (r / r_rail - 1) times the distance it ran on the
pipes over the number of drives: 100 (r / r_rail - 1) x (the drives' mean share on the pipes) %
(``predicted_error_pct_without_switch``, a third of the share for 0.2 m tyres on 0.15 m rail
wheels). With the switch that error is gone, save the centimetres each switch comes late or early.
The end point hides it: out and back, the overshoot out is taken back on the way back; the turnaround
shows it.
"""

import math
from dataclasses import dataclass, field
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

from thorvald_model.errors import Problem
from thorvald_model.schema import Key, one_of
from thorvald_model.values import RAIL_FLANGE_DEPTH

from .driving import SURFACE_RULE, SURFACES, Progress, heading_hold, surface_keys
from .kind import SMALLER, Metric, Pose, ScenarioKind, not_applicable

SETTLE = 1.0  # [s] the robot stands before it drives, and after
ON_RAIL = 0.005  # [m] a wheel centre this near the height a rail wheel on a pipe holds it at rides the pipe
FLANGE_CLEARANCE = 0.01  # [m] of the flanges over the pipes' tops on the hill's top
TOP_LENGTH = 0.6  # [m] of the hill's level top, the pipes' ends sunk in its middle
APPROACH = 0.5  # [m] from the robot's front to the hill's foot
PIPES_BEYOND = 1.0  # [m] of pipe past the front drive's flanges where it turns back
RAIL_LINE = 0.005  # [m]: rail wheels this near one line across run on one pipe (the flanges' play is 4.5 mm)
PIPE_FRICTION = 0.8  # steel pipe, as worlds/greenhouse.yaml

KEYS = (
    Key("surface", str, "concrete", check=one_of(*SURFACES), rule=SURFACE_RULE),
    Key("speed", float, 0.5, check=lambda v: 0.05 <= v <= 1.5, rule="must be in [0.05, 1.5] [m/s]"),
    Key("rail_length", float, 10.0, check=lambda v: 1.0 <= v <= 100.0, rule="must be in [1, 100] [m]"),
    Key("pipe_height", float, 0.1, check=lambda v: 0.03 <= v <= 0.5, rule="must be in [0.03, 0.5] [m]"),
    Key("pipe_radius", float, 0.0255, check=lambda v: 0.005 <= v <= 0.1, rule="must be in [0.005, 0.1] [m]"),
    Key("ramp_deg", float, 10.0, check=lambda v: 2.0 <= v <= 25.0, rule="must be in [2, 25] [deg]"),
)
METRICS = (
    Metric(
        "odometry_error_pct", "%", SMALLER, "the odometry's distance off ground truth's, the wheel diameter switched"
    ),
    Metric(
        "odometry_error_pct_without_switch", "%", SMALLER,
        "the odometry's distance off ground truth's, the floor's wheel diameter throughout",
    ),
)  # fmt: skip
RESULTS = tuple(m.name for m in METRICS)


def check(values: Mapping[str, Any], path: str, problems: List[Problem]) -> None:
    if values["pipe_radius"] >= values["pipe_height"]:
        problems.append(
            Problem(
                f"{path}.pipe_radius",
                values["pipe_radius"],
                f"must be < pipe_height ({values['pipe_height']:g} m): a pipe cannot sink into the floor",
            )
        )


class Geometry:
    """The world of a robot's rails drive, along +x from the spawn point (base_link at the origin,
    heading +x): where the hill and the pipes are, where the rail wheels take over and where the robot
    turns back (the module's docstring derives each)."""

    def __init__(self, design, params: Mapping[str, Any], centre: float, gauge: float):
        drives = design.config.drives
        self.centre, self.gauge = centre, gauge  # [m] the pipes' centre line (y) and their gauge
        self.pipe_top = params["pipe_height"] + params["pipe_radius"]  # h_p
        self.angle = math.radians(params["ramp_deg"])
        step = max(self.pipe_top + d.rail_r_wheel - d.r_wheel for d in drives)  # s
        self.height = step + RAIL_FLANGE_DEPTH + FLANGE_CLEARANCE  # H
        self.run = self.height / math.tan(self.angle)  # of each face
        self.foot = design.front + APPROACH  # near foot
        self.top_end = self.foot + self.run + TOP_LENGTH
        self.pipes_start = self.foot + self.run + TOP_LENGTH / 2.0
        # base_link where the rearmost drive's rail wheel is on the pipes, then rail_length on
        self.turn = max(self.landing(d) - d.x for d in drives) + params["rail_length"]
        reach = max(d.x + d.rail_flange_radius for d in drives)
        self.pipes_end = self.turn + reach + PIPES_BEYOND
        self.width = 2.0 * max(abs(d.y - centre) + d.w_wheel / 2.0 for d in drives) + 0.4

    def landing(self, drive) -> float:
        """[m] x of the drive's wheel centre where its rail wheel takes over from its tyre, down the
        hill's far face: the face h_land = h_p + r_rail - r / cos a high, (H - h_land) / tan a on."""
        h_land = self.pipe_top + drive.rail_r_wheel - drive.r_wheel / math.cos(self.angle)
        return self.top_end + (self.height - max(h_land, 0.0)) / math.tan(self.angle)

    def world(self, surface: str, params: Mapping[str, Any]) -> Dict:
        """The world file's contents: the floor, the hill, the pipes."""
        length = self.pipes_end - self.pipes_start
        return {
            "description": f"{params['pipe_radius'] * 2000:.0f} mm heating pipes {self.gauge:.3f} m apart on "
            f"{surface}, their ends sunk in a {math.degrees(self.angle):g} degree hill",
            "ground": {"surface": surface},
            "slopes": {
                "slope0": {
                    "x": self.foot + self.run + TOP_LENGTH / 2.0, "y": self.centre, "yaw": 0.0, "width": self.width,
                    "angle": self.angle, "height": self.height, "top_length": TOP_LENGTH, **surface_keys(surface),
                }
            },
            "rails": {
                "rail0": {
                    "x": self.pipes_start + length / 2.0, "y": self.centre, "length": length, "gauge": self.gauge,
                    "height": params["pipe_height"], "radius": params["pipe_radius"],
                    "lateral_friction": PIPE_FRICTION,
                }
            },
        }  # fmt: skip


def rails_world(design, params: Mapping[str, Any]) -> Tuple[Optional[Geometry], str]:
    """The geometry of the robot's rails drive, or None and why the robot cannot ride pipes."""
    config = design.config
    drives = config.drives
    if not any(d.has_rail_wheel for d in drives):
        return None, "its drives have no rail wheels"
    bare = [d.name for d in drives if not d.has_rail_wheel]
    if bare:
        return None, f"{', '.join(bare)} {'has' if len(bare) == 1 else 'have'} no rail wheel"
    if config.passive_wheels:
        return None, "its passive wheels have no rail wheels"
    # every rail wheel on one of two lines along x: the pipes
    lines = sorted(d.y + d.rail_offset for d in drives)
    left, right = lines[-1], lines[0]
    if any(min(abs(y - left), abs(y - right)) > RAIL_LINE for y in lines):
        where = ", ".join(f"{y:.3f}" for y in lines)
        return None, f"its rail wheels are not on two lines along base_link x (y = {where} m)"
    if left - right <= 2.0 * params["pipe_radius"]:
        return None, f"its rail wheels are {left - right:.3f} m apart: not on two pipes"
    for d in drives:
        if d.rail_w_wheel <= 2.0 * params["pipe_radius"]:
            return None, f"{d.name}'s rail wheel tread ({d.rail_w_wheel:g} m) is no wider than a pipe"
        if d.r_wheel >= params["pipe_height"] + params["pipe_radius"] + d.rail_r_wheel:
            return None, f"{d.name}'s tyre would still touch the floor with its rail wheel on a pipe"
    return Geometry(design, params, (left + right) / 2.0, left - right), ""


def wheel_centre_height(pose: Pose, x: float, y: float, r: float) -> float:
    """[m] above the floor of a drive's wheel centre (x, y, r in base_link) at base_link's pose: the z
    row of R = Rz(yaw) Ry(-pitch) Rx(roll) (Pose.pitch is nose up positive) applied to (x, y, r)."""
    cp, sp, cr, sr = math.cos(pose.pitch), math.sin(pose.pitch), math.cos(pose.roll), math.sin(pose.roll)
    return pose.z + sp * x + cp * sr * y + cp * cr * r


def path_length(points: Sequence[Tuple[float, ...]]) -> float:
    """[m] along a sequence of points (2-D or 3-D)."""
    return sum(math.dist(a, b) for a, b in zip(points, points[1:]))


def procedure(lab, design, params: Mapping[str, Any]) -> Dict[str, Any]:
    geometry, why = rails_world(design, params)
    if geometry is None:
        return {name: not_applicable(why) for name in RESULTS}
    result: Dict[str, Any] = {}
    for switch, suffix in ((True, ""), (False, "_without_switch")):
        drive = _drive(lab, design, params, geometry, switch)
        if drive["outcome"] != "ok":
            result["odometry_error_pct" + suffix] = not_applicable(drive["outcome"])
            result["outcome" + suffix] = drive["outcome"]
            continue
        result["odometry_error_pct" + suffix] = drive["error_pct"]
        for name in ("end_point_error_m", "turnaround_error_m", "distance_m", "rail_share", "max_rail_offset_m"):
            result[name + suffix] = drive[name]
        if switch:
            result["switches"] = drive["switches"]
        else:
            result["predicted_error_pct_without_switch"] = drive["predicted_error_pct"]
    result["gauge_m"] = round(geometry.gauge, 4)
    return result


@dataclass
class _Recorded:
    """What one drive recorded at every control cycle: base_link's true pose, base_driver's odometry
    (x, y in the odom frame) and which drives rode the pipes; where it turned back (an index of
    them) and the switches made (time, [(drive, r_wheel)])."""

    track: Sequence[Pose]
    odometry: List[Tuple[float, float]]
    flags: List[Tuple[bool, ...]]
    turned: int = 0
    switches: List[Tuple[float, List[Tuple[int, float]]]] = field(default_factory=list)


def _drive(lab, design, params, geometry: Geometry, switch: bool) -> Dict[str, Any]:
    """One drive out along the pipes and back, the diameter switched or not; its figures, or its
    outcome if it did not come back."""
    drives = design.config.drives
    speed = params["speed"]
    rail_height = [geometry.pipe_top + d.rail_r_wheel for d in drives]  # of the wheel centre on a pipe
    on_rails = [False] * len(drives)
    problems: List[str] = []
    label = "rails, diameter switched" if switch else "rails, diameter kept"
    with lab.session(geometry.world(params["surface"], params), label=label) as session:
        recorded = _Recorded(session.track, [], [])

        def watch(s) -> None:
            """Which drives ride the pipes now (the module's docstring); base_driver told of a change."""
            pose = s.track[-1]
            changes = []
            for k, d in enumerate(drives):
                x = pose.x + math.cos(pose.yaw) * d.x - math.sin(pose.yaw) * d.y
                z = wheel_centre_height(pose, d.x, d.y, d.r_wheel)
                riding = x > geometry.top_end and z < rail_height[k] + ON_RAIL
                if riding != on_rails[k]:
                    on_rails[k] = riding
                    changes.append((k, "r_wheel", d.rail_r_wheel if riding else d.r_wheel))
            if changes and switch:
                problems.extend(s.set_drive_params(changes))
                recorded.switches.append((round(s.time, 3), [(k, v) for k, _, v in changes]))
            recorded.flags.append(tuple(on_rails))

        def stand(s) -> bool:
            watch(s)
            return False

        outcome = ""
        for sign, goal in ((1.0, geometry.turn), (-1.0, 0.0)):
            session.run(session.time + SETTLE, lambda t: (0.0, 0.0, 0.0), stand)  # from standing
            if sign < 0:
                recorded.turned = len(session.track) - 1  # at rest where it turns back
            progress = Progress(ux=sign, slope=geometry.angle)
            leg = _Since(session.track, len(session.track))  # this leg's poses: what progress judges
            limit = session.time + 4.0 * geometry.turn / speed + 10.0  # twice the leg's time at speed

            def stop(s, sign=sign, goal=goal, progress=progress, leg=leg) -> bool:
                watch(s)
                return sign * (s.track[-1].x - goal) >= 0.0 or progress.failed(leg)

            session.run(limit, heading_hold(session, 0.0, sign * speed), stop)
            if sign * (session.track[-1].x - goal) < 0.0:
                outcome = f"{progress.outcome or 'ran out of time'} at x = {session.track[-1].x:.2f} m"
                break
        session.run(session.time + SETTLE, lambda t: (0.0, 0.0, 0.0), stand)
        if problems:
            outcome = "set_drive_params refused: " + "; ".join(problems)
        session.outcome = outcome or "ok"
        recorded.odometry = _odometry(session)
    if session.outcome != "ok":
        return {"outcome": session.outcome}
    return _figures(design, geometry, recorded)


class _Since(Sequence):
    """The poses of a growing track from index start on, without copying them."""

    def __init__(self, track: List[Pose], start: int):
        self.track, self.start = track, start

    def __len__(self) -> int:
        return len(self.track) - self.start

    def __getitem__(self, k: int) -> Pose:
        return self.track[self.start + k] if k >= 0 else self.track[k]


def _odometry(session) -> List[Tuple[float, float]]:
    """base_driver's odometry (x, y in the odom frame, the spawn pose) at every control cycle of the
    session, as the runner records it (:attr:`thorvald_sim.tools.runner.RobotSession.odometry`), one for
    each of the session's poses (the lab's session records its pose at the same cycles)."""
    return [(o.x, o.y) for o in session.odometry]


def _figures(design, geometry: Geometry, recorded: _Recorded) -> Dict[str, Any]:
    """The drive's metrics (the module's docstring) from what it recorded."""
    drives = design.config.drives
    track, odometry, flags = recorded.track, recorded.odometry, recorded.flags
    n = min(len(track), len(odometry), len(flags))
    truth = [(q.x, q.y, q.z) for q in track[:n]]
    steps = [math.dist(a, b) for a, b in zip(truth, truth[1:])]  # [m] base_link moved between cycles
    true_distance = sum(steps)
    error = 100.0 * (path_length(odometry[:n]) - true_distance) / true_distance
    # each drive's share of the distance on the pipes: the steps that end with it riding them
    shares = [sum(ds for ds, f in zip(steps, flags[1:n]) if f[k]) / true_distance for k in range(len(drives))]
    predicted = 100.0 * sum((d.r_wheel / d.rail_r_wheel - 1.0) * s for d, s in zip(drives, shares)) / len(drives)
    riding = [q for q, f in zip(track[:n], flags[:n]) if all(f)]
    offset = max((abs(q.y - geometry.centre) for q in riding), default=float("nan"))
    end, back = n - 1, min(recorded.turned, n - 1)
    return {
        "outcome": "ok",
        "error_pct": round(error, 3),
        "predicted_error_pct": round(predicted, 3),
        "distance_m": round(true_distance, 3),
        "rail_share": round(sum(shares) / len(shares), 4),
        "end_point_error_m": round(math.dist(truth[end][:2], odometry[end]), 4),
        "turnaround_error_m": round(math.dist(truth[back][:2], odometry[back]), 4),
        "max_rail_offset_m": round(offset, 4),
        "switches": len(recorded.switches),
    }


RAILS = ScenarioKind(
    name="rails",
    what="base_driver's odometry error along greenhouse heating pipes, with and without the wheel diameter switched",
    keys=KEYS,
    metrics=METRICS,
    procedure=procedure,
    check=check,
    cost=0.1,  # [s] the standard robot's run (ScenarioKind.cost)
)
