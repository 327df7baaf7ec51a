"""obstacle: the highest step the robot climbs, up and down.

Procedure: for each step height (``start_m``, then every ``step_m`` up to ``max_m``) a level platform
of the study's surface, that high, across the robot's path, its edge ``0.5 m`` ahead of the robot's
front; the robot is commanded straight ahead at ``speed`` [m/s] (its heading held). Up: it succeeds
when the whole robot stands on the platform (base_link further than its rear overhang past the
edge, and base_link at least half the step higher than it started); it fails when it stalls (less
than 3 cm gained in 2 s), slides back, tips or runs out of time. Down: set down on the platform, it
drives off the far edge and succeeds when it is wholly back on the ground without tipping. Each
series stops at its first failure.

``max_step_m`` is the highest step climbed up, ``max_step_down_m`` the highest driven down.

What it means: a wheel of radius r meets a step of height h at the step's edge, where the ground
pushes it along the line from the edge to its axle, at an angle a from the vertical with
cos a = (r - h) / r. For the wheel to roll up, the horizontal push P at its axle (from the other
wheels, through the frame, and its own torque through the edge's friction) must lift the load N it
carries: P >= N tan a. So a step is climbed when the robot's other wheels push hard enough (grip and
motor torque, as in gradeability), and never one as high as an axle (h < r: a vertical wall).
"""

import math
from typing import Any, Dict, List, Mapping

from thorvald_model.schema import Key, one_of

from .driving import SURFACE_RULE, SURFACES, Progress, check_series, heading_hold, series, surface_keys
from .gradeability import SETTLE
from .kind import LARGER, Metric, ScenarioKind

KEYS = (
    Key("surface", str, "tarmac", check=one_of(*SURFACES), rule=SURFACE_RULE),
    Key("speed", float, 0.3, check=lambda v: 0.05 <= v <= 3.0, rule="must be in [0.05, 3] [m/s]"),
    Key("start_m", float, 0.02, check=lambda v: 0.005 <= v <= 1.0, rule="must be in [0.005, 1] [m]"),
    Key("step_m", float, 0.02, check=lambda v: 0.005 <= v <= 0.5, rule="must be in [0.005, 0.5] [m]"),
    Key("max_m", float, 0.3, check=lambda v: 0.005 <= v <= 1.0, rule="must be in [0.005, 1] [m]"),
    Key("down", bool, True),
)
METRICS = (
    Metric("max_step_m", "m", LARGER, "the highest step climbed, the whole robot on it"),
    Metric("max_step_down_m", "m", LARGER, "the highest step driven down, the whole robot back on the ground"),
)


check = check_series("start_m", "max_m")


def heights(params: Mapping[str, Any]) -> List[float]:
    """The steps' heights [m] in the order they are tried."""
    return series(params["start_m"], params["step_m"], params["max_m"])


def step_world(surface: str, height: float, edge: float, length: float, width: float = 8.0) -> Dict:
    """A level platform height [m] high from x = edge [m] for length [m], width [m] across, on a ground
    of the surface kind (its top of the same)."""
    return {
        "description": f"a {height * 100:.0f} cm step of {surface}",
        "ground": {"surface": surface},
        "objects": {
            "object0": {
                "shape": "box", "x": edge + length / 2.0, "y": 0.0, "size_x": length, "size_y": width,
                "size_z": height, "rgba": [0.6, 0.6, 0.6, 1.0], **surface_keys(surface),
            }
        },
    }  # fmt: skip


def procedure(lab, design, params: Mapping[str, Any]) -> Dict[str, Any]:
    up, tries = 0.0, []
    for h in heights(params):
        outcome = _up(lab, design, params, h)
        tries.append([h, outcome])
        if outcome != "ok":
            break
        up = h
    result: Dict[str, Any] = {"max_step_m": up, "steps": tries}
    down, tries = 0.0, []
    if params["down"]:
        for h in heights(params):
            outcome = _down(lab, design, params, h)
            tries.append([h, outcome])
            if outcome != "ok":
                break
            down = h
    result.update(max_step_down_m=down if params["down"] else "n/a: down: false", steps_down=tries)
    return result


def _try(series_name: str, height: float) -> Dict[str, Any]:
    """The report's marks of one try: which series, its height; seen from the side along the drive."""
    return {"series": series_name, "value": round(height, 6), "unit": "m", "section": "along"}


def _up(lab, design, params, height: float) -> str:
    speed = params["speed"]
    length = 2.0 * design.length + 2.0
    world = step_world(params["surface"], height, 0.0, length)
    start_x = -(design.front + 0.5)
    goal = design.rear + 0.3  # base_link this far past the edge: the rear wheels are up too
    limit = SETTLE + 2.0 * (goal - start_x) / speed + 10.0
    progress = Progress(slope=math.radians(5.0))
    with lab.session(world, x=start_x, label=f"up {height * 100:.0f} cm") as session:
        session.marks = _try("up", height)
        session.run(SETTLE, lambda t: (0.0, 0.0, 0.0))
        z0 = session.track[-1].z

        def stop(s) -> bool:
            pose = s.track[-1]
            return (pose.x >= goal and pose.z - z0 >= 0.5 * height) or progress.failed(s.track)

        session.run(limit, heading_hold(session, 0.0, speed), stop)
        pose = session.track[-1]
        reached = pose.x >= goal and pose.z - z0 >= 0.5 * height
        session.outcome = "ok" if reached else progress.outcome or "ran out of time"
    return session.outcome


def _down(lab, design, params, height: float) -> str:
    speed = params["speed"]
    length = design.length + 2.0
    world = step_world(params["surface"], height, -length, length)  # its far edge at x = 0
    start_x = -(design.front + 0.5)
    goal = design.rear + 0.5  # the whole robot off the platform
    limit = SETTLE + 2.0 * (goal - start_x) / speed + 10.0
    progress = Progress(slope=math.radians(5.0))
    with lab.session(world, x=start_x, z=height, label=f"down {height * 100:.0f} cm") as session:
        session.marks = _try("down", height)
        session.run(SETTLE, lambda t: (0.0, 0.0, 0.0))

        def stop(s) -> bool:
            return s.track[-1].x >= goal or progress.failed(s.track)

        session.run(limit, heading_hold(session, 0.0, speed), stop)
        pose = session.track[-1]
        reached = pose.x >= goal and abs(pose.z) < 0.5 * height
        session.outcome = "ok" if reached else progress.outcome or "ran out of time"
    return session.outcome


OBSTACLE = ScenarioKind(
    name="obstacle",
    what="the highest step climbed, up and down",
    keys=KEYS,
    metrics=METRICS,
    procedure=procedure,
    check=check,
    cost=4.3,  # [s] the standard robot's run (ScenarioKind.cost)
)
