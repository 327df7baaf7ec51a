"""side_slope: across slopes of increasing angle, holding a heading: how far the robot drifts
downhill per metre, the steepest it holds, and its static overturning angle.

Procedure: for each angle (``start_deg``, then every ``step_deg`` up to ``max_deg``) a hill of the
study's surface whose face rises towards +y; the robot is set down on the middle of the face, heading
+x (along the contour, its left side uphill), and commanded ``speed`` [m/s] for ``distance`` [m],
its heading held by feeding the yaw error back to the turn rate (a driver's steering correction).
From ground truth:

- ``drift_per_m`` (at each angle; the value reported is the steepest held's): the downhill
  displacement perpendicular to the heading at the end of the traverse over the distance along it
  (:func:`thorvald_design.metrics.lateral_drift`): the sideways slip of the tyres the slope's
  downhill pull causes, which a robot holding its heading cannot correct (0: the wheels do not slip
  sideways; tan of the crab angle it slides at otherwise);
- a traverse is held when the robot covers the distance, does not tip, and ends at most
  ``max_drift`` [m per m] off its line, downhill or uphill (a robot that veers up the slope does not
  hold the traverse either: the differential robot ended 0.96 m per m uphill of its line at 10
  degrees); ``max_traverse_deg`` is the steepest held.

``static_overturning_deg`` is ISO 16231-2's static overturning angle to the side, from the centre of
mass and the wheel contacts, not from the drive: the tilt about the support polygon's side edge (the
line through the downhill wheels' contacts) at which the vertical through the centre of mass passes
over that edge, atan(d / h), d the horizontal distance from the centre of mass to the edge and h its
height above the ground (:func:`thorvald_design.quasi_static.overturning_angles`); the smaller of the
two sides. No robot should be driven near it: slip comes first on any real surface. Beside it,
``as_simulated`` gives the angle of the robot as the simulator holds it (its centre of mass,
measured there), for the report to say what a traverse that tipped before the static angle owes to
it.
"""

import math
from typing import Any, Dict, Mapping

from thorvald_model.schema import Key, one_of

from ..metrics import lateral_drift
from ..quasi_static import overturning_angles
from .driving import SURFACE_RULE, SURFACES, Progress, as_simulated, check_series, heading_hold, track_of
from .gradeability import SETTLE, angles
from .kind import LARGER, SMALLER, Metric, Prediction, ScenarioKind

KEYS = (
    Key("surface", str, "grass", check=one_of(*SURFACES), rule=SURFACE_RULE),
    Key("speed", float, 0.5, check=lambda v: 0.05 <= v <= 3.0, rule="must be in [0.05, 3] [m/s]"),
    Key("start_deg", float, 5.0, check=lambda v: 0.5 <= v <= 60.0, rule="must be in [0.5, 60] [deg]"),
    Key("step_deg", float, 5.0, check=lambda v: 0.25 <= v <= 20.0, rule="must be in [0.25, 20] [deg]"),
    Key("max_deg", float, 35.0, check=lambda v: 0.5 <= v <= 60.0, rule="must be in [0.5, 60] [deg]"),
    Key("distance", float, 5.0, check=lambda v: 1.0 <= v <= 100.0, rule="must be in [1, 100] [m]"),
    Key("max_drift", float, 0.05, check=lambda v: 0.0 < v <= 1.0, rule="must be in (0, 1] [m per m]"),
)
METRICS = (
    Metric(
        "max_traverse_deg", "deg", LARGER, "the steepest side slope held both ways along its contour",
        Prediction(
            "static_overturning_deg", "step_deg", "traverses", "held",
            "a traverse fails by sliding downhill (more than max_drift a metre) before it tips, which the static "
            "overturning angle, a bound on tipping alone, does not count; one that tips is driven at speed across "
            "soft ground, which sinks most under its downhill wheels, its heading held by steering",
        ),
    ),
    Metric("static_overturning_deg", "deg", LARGER, "ISO 16231-2's static overturning angle, the weaker side"),
    Metric("drift_per_m", "m/m", SMALLER, "the downhill drift per metre along the steepest slope held"),
)  # fmt: skip


check = check_series("start_deg", "max_deg")


def side_slope_world(surface: str, angle: float, run: float, length: float) -> Dict:
    """A hill whose face rises towards +y from its foot at y = 0 over a horizontal run [m], length [m]
    along x (centred on x = 0), a level top as wide as the run, of the surface kind (its sinkage too)."""
    top = run
    footprint = 2.0 * run + top
    return {
        "description": f"a {math.degrees(angle):.1f} degree side slope of {surface}",
        "ground": {"surface": surface},
        "slopes": {
            "slope0": {
                "x": 0.0, "y": footprint / 2.0, "yaw": math.pi / 2.0, "width": length, "angle": angle,
                "height": run * math.tan(angle), "top_length": top, "surface": surface,
            }
        },
    }  # fmt: skip


def procedure(lab, design, params: Mapping[str, Any]) -> Dict[str, Any]:
    overturning = design.overturning()
    result: Dict[str, Any] = {
        "static_overturning_deg": _deg(overturning.lateral),
        "static_overturning_left_deg": _deg(overturning.left),
        "static_overturning_right_deg": _deg(overturning.right),
    }
    held, drift, tries = 0.0, None, []
    for angle in angles(params):
        # both ways: the left side uphill (heading +x), then the right (heading -x)
        outcomes = [_traverse(lab, design, params, math.radians(angle), way) for way in (1.0, -1.0)]
        tries.append([angle, *[[outcome, None if d is None else _rounded(d)] for outcome, d in outcomes]])
        failed = [outcome for outcome, _ in outcomes if outcome != "ok"]
        if failed:
            break
        held, drift = angle, max(d for _, d in outcomes)
    result.update(
        max_traverse_deg=held,
        drift_per_m=_rounded(drift) if drift is not None else "n/a: no slope held",
        traverses=tries,
    )
    result["as_simulated"] = as_simulated(design, lab, _limits)
    return result


def _limits(layout, rolling: bool) -> Dict[str, Any]:
    """The static overturning angle of a layout (standing: the same rolling or not)."""
    return {"static_overturning_deg": _deg(overturning_angles(layout).lateral)}


def _deg(angle: float) -> float:
    return round(math.degrees(angle), 2)


def _rounded(value: float) -> float:
    return round(value, 4) + 0.0  # no -0.0


def _traverse(lab, design, params, angle: float, way: float):
    """One traverse (way +1: heading +x, the left side uphill; -1: heading -x): its outcome and the
    downhill drift per metre."""
    speed, distance = params["speed"], params["distance"]
    run = max(4.0, design.width + 2.0)
    length = distance + design.length + 6.0
    world = side_slope_world(params["surface"], angle, run, length)
    y = run / 2.0
    start_x = way * (-length / 2.0 + design.rear + 1.0)
    z = y * math.tan(angle) + 0.01
    heading = 0.0 if way > 0 else math.pi
    progress = Progress(ux=way, slope=angle)
    limit = SETTLE + 2.0 * distance / speed + 10.0
    label = f"{math.degrees(angle):g} deg, {'left' if way > 0 else 'right'} side uphill"
    with lab.session(world, x=start_x, y=y, z=z, yaw=heading, roll=way * angle, label=label) as session:
        session.marks = {
            "series": f"{'left' if way > 0 else 'right'} side uphill", "value": round(math.degrees(angle), 6),
            "unit": "deg", "section": "across", "distance_m": distance,
        }  # fmt: skip
        session.run(SETTLE, lambda t: (0.0, 0.0, 0.0))
        first = len(session.track)
        command = heading_hold(session, heading, speed)

        def stop(s) -> bool:
            return way * (s.track[-1].x - s.track[first].x) >= distance or progress.failed(s.track[first:])

        session.run(limit, command, stop)
        outcome, downhill = _traverse_outcome(session.track[first:], progress, way, heading, params)
        session.outcome = outcome
    return outcome, downhill


def _traverse_outcome(poses, progress: Progress, way: float, heading: float, params):
    distance = params["distance"]
    if progress.outcome:
        return progress.outcome, None
    if way * (poses[-1].x - poses[0].x) < distance:
        return "ran out of time", None
    track = track_of(poses)
    # the face rises to +y: downhill is to the right of heading +x, to the left of heading -x
    downhill = -way * lateral_drift(track, heading).per_m
    if downhill > params["max_drift"]:
        return f"drifted {downhill:.3f} m per m", downhill
    if -downhill > params["max_drift"]:  # off its line uphill: it does not hold the traverse either
        return f"veered {-downhill:.3f} m per m uphill", downhill
    return "ok", downhill


SIDE_SLOPE = ScenarioKind(
    name="side_slope",
    what="across slopes holding a heading: drift per metre, the steepest held, the static overturning angle",
    keys=KEYS,
    metrics=METRICS,
    procedure=procedure,
    check=check,
    cost=3.0,  # [s] the standard robot's run (ScenarioKind.cost)
)
