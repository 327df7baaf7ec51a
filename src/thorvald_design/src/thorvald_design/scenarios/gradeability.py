"""gradeability: how steep a ramp the robot climbs, and descends under control.

Procedure: ramps of increasing angle (``start_deg``, then every ``step_deg`` up to ``max_deg``), each
a hill of the study's surface whose foot is 0.5 m ahead of the robot's front, climbing over
``ramp_length`` [m] of run (at least twice the robot's length and 1 m) to a level top. The robot is
commanded straight ahead at ``speed`` [m/s] (its own base_driver core, the heading held). A climb
succeeds when the foremost wheel reaches the crest (the whole robot has climbed the incline); it
fails when the robot stalls (less than 3 cm gained in 2 s), slides back (10 cm back from the
furthest point it reached), tips (rolled or pitched 25 degrees more than the ramp), or runs out of
time (twice the time the climb takes at speed, and 10 s). The series stops at the first failure:
``max_climb_deg`` is the steepest climbed, ``limited_by`` what stopped the next:

- ``tipping`` when it tipped;
- ``motor torque`` when the driven wheels that push (those above 10 % of their torque limit: a
  wheel off the ground turns freely) were at their torque limit (on average over the last second
  at least 95 % of it): they cannot turn the wheels any harder, the wheels do not slip;
- ``traction`` otherwise: the wheels turn below their torque limit, so the ground gives no more
  grip: they slip.

The crest is another obstacle: after the incline the robot drives on until base_link is over the
top. A frame on more than two axles bridges a sharp crest on its middle wheels (the front and rear
ones lift off, as at a vehicle's ramp breakover angle), which then carry the whole robot on their
own motors; ``max_crest_deg`` is the steepest ramp whose crest it crossed too (every gentler one
crossed as well). Each try in ``climbs`` is ``[angle, incline, crest]``.

Descent: from the level top of each ramp the robot drives down the far side at ``speed``; it is
under control when its speed along the ramp stays within ``max(0.1, 0.3 * speed)`` m/s of the
command (the driven wheels hold it back without sliding) and it does not tip.
``max_descent_deg`` is the steepest descended under control.

What the metric means, and what it must agree with: climbing at constant speed, the driven wheels
push the robot up with the forces the ground lets them have (at most mu N_i each, N_i the wheel's
load, which the grade shifts towards the downhill wheels) and the motors give (at most their torque
limit over the wheel radius), against the weight's component along the ramp and the rolling
resistance of every wheel: sum_driven min(mu N_i, F_i) >= W sin(theta) + C_rr W cos(theta). The
steepest theta that holds is the quasi-static limit (:func:`thorvald_design.quasi_static.gradeability`),
reported beside the measured one as ``predicted_climb_deg`` and ``predicted_limited_by``; the
simulated climb, a dynamic drive at speed, reaches it to within a step where traction or the motors
limit it.

Where tipping limits it, a rolling robot tips a little before the standing prediction. Measured on
the rear-driven tricycle of the drive-patterns study on grass (its right front wheel's load, the
centre of pressure from pybullet's contact forces, climbs at 0.5 and 0.1 m/s, with and without
rolling friction), the causes and their sizes:

- rolling up the ramp each wheel's load acts 12 mm ahead of its contact (grass's rolling friction,
  the rolling resistance's moment), which the standing prediction leaves out: -1.3 (15.45 to 14.17
  degrees). On a 13 degree ramp the lifting wheel kept 9.1 N without rolling friction and 3.6 N
  with it, the 5.5 N a 12 mm shift of the centre of pressure takes;
- on soft ground the loaded rear wheel sinks deeper than the front ones: the frame pitches 0.3
  degrees more than the ramp: -0.3;
- the simulated wheels touch the ground at one rim of their 1 cm contact discs, 4 mm to the left of
  their centre lines, which widens the support triangle on the battery's side: +1.0;
- at 0.5 m/s the ramp's foot and crest jolt a robot near its limit over: about -0.3.

It climbs 14 degrees and tips at 16, within a step of the prediction. (Before the simulator placed
each merged link's mass where the description has it, its centre of mass sat 3.9 cm high and it
tipped at 14.) The results carry the centre of mass's heights and the predictions of the robot as
simulated, standing and rolling (``as_simulated``: 14.17 degrees rolling for the tricycle), and the
report says so where a climb and its prediction differ by more than a step. The procedure is left
as it is: the rolling resistance's moment is real tyres' too, the rest the simulation's physics.
"""

import math
from typing import Any, Dict, List, Mapping, Tuple

from thorvald_model.schema import Key, one_of
from thorvald_sim.world.surfaces import SURFACE_KINDS

from ..quasi_static import gradeability
from .driving import (
    SURFACE_RULE,
    SURFACES,
    TIPPED,
    Progress,
    as_simulated,
    at_time,
    check_series,
    heading_hold,
    mean,
    ramp_world,
    rolling_offset,
    series,
)
from .kind import LARGER, WORDS, Metric, Prediction, ScenarioKind

TORQUE_BOUND = 0.95  # of the motors' torque limit, on average over the last second: the motors are the limit
PUSHING = 0.1  # of its torque limit: below this a wheel is not pushing (it is off the ground)
SPEED_WINDOW = 0.5  # [s] a descent's speed is measured over
SETTLE = 1.0  # [s] the robot stands before it is commanded (it settles on its suspension)

KEYS = (
    Key("surface", str, "tarmac", check=one_of(*SURFACES), rule=SURFACE_RULE),
    Key("speed", float, 0.5, check=lambda v: 0.05 <= v <= 3.0, rule="must be in [0.05, 3] [m/s]"),
    Key("start_deg", float, 4.0, check=lambda v: 0.5 <= v <= 60.0, rule="must be in [0.5, 60] [deg]"),
    Key("step_deg", float, 2.0, check=lambda v: 0.25 <= v <= 20.0, rule="must be in [0.25, 20] [deg]"),
    Key("max_deg", float, 40.0, check=lambda v: 0.5 <= v <= 60.0, rule="must be in [0.5, 60] [deg]"),
    Key("ramp_length", float, 3.0, check=lambda v: 0.5 <= v <= 30.0, rule="must be in [0.5, 30] [m] of run"),
    Key("descent", bool, True),
)
METRICS = (
    Metric("surface", "", WORDS, "the ramps' surface kind"),
    Metric(
        "max_climb_deg", "deg", LARGER, "the steepest ramp climbed, the foremost wheel at its crest",
        Prediction(
            "predicted_climb_deg", "step_deg", "climbs", "climbed",
            "a soft ramp sinks most under the most loaded wheel, the ramp's foot and crest jolt a robot near its "
            "limit, and the simulated wheels touch at one rim of their contact discs (the gradeability scenario's "
            "meaning gives their sizes for the rear-driven tricycle)",
        ),
    ),
    Metric("limited_by", "", WORDS, "what stopped the next climb: traction, motor torque or tipping"),
    Metric("max_crest_deg", "deg", LARGER, "the steepest ramp whose crest it crossed too (base_link over the top)"),
    Metric(
        "max_descent_deg", "deg", LARGER, "the steepest ramp descended under control, its speed near the command",
        Prediction(
            "predicted_descent_deg", "step_deg", "descents", "descended",
            "a descent is held while its speed stays near the command, the wheels braking at speed, where the "
            "prediction is the wheels' static hold",
        ),
    ),
    Metric("predicted_climb_deg", "deg", LARGER, "the quasi-static climb its weight distribution, grip, motors allow"),
    Metric("predicted_limited_by", "", WORDS, "what binds the quasi-static climb: traction, motor torque or tipping"),
    Metric("predicted_descent_deg", "deg", LARGER, "the quasi-static descent its driven wheels hold braking"),
)  # fmt: skip


check = check_series("start_deg", "max_deg")


def angles(params: Mapping[str, Any]) -> List[float]:
    """The ramps' angles [deg] in the order they are tried."""
    return series(params["start_deg"], params["step_deg"], params["max_deg"])


def procedure(lab, design, params: Mapping[str, Any]) -> Dict[str, Any]:
    surface = params["surface"]
    limits = design.grade_limits(surface)
    result: Dict[str, Any] = {
        "surface": surface,
        "predicted_climb_deg": round(math.degrees(limits.climb), 2),
        "predicted_limited_by": limits.limited_by,
        "predicted_descent_deg": round(math.degrees(limits.descent), 2),
    }
    climbed, crested, crest_held = 0.0, 0.0, True
    limited_by, tries = f"none up to {params['max_deg']:g} deg", []
    for angle in angles(params):
        outcome, over = _climb(lab, design, params, math.radians(angle))
        tries.append([angle, outcome, over])
        if outcome != "ok":
            limited_by = outcome
            break
        climbed = angle
        crest_held = crest_held and over == "ok"
        crested = angle if crest_held else crested
    result.update(max_climb_deg=climbed, limited_by=limited_by, max_crest_deg=crested, climbs=tries)
    descended, tries = 0.0, []
    if params["descent"]:
        for angle in angles(params):
            outcome = _descend(lab, design, params, math.radians(angle))
            tries.append([angle, outcome])
            if outcome != "ok":
                break
            descended = angle
    result.update(max_descent_deg=descended if params["descent"] else "n/a: descent: false", descents=tries)
    result["as_simulated"] = as_simulated(design, lab, _limits(design, surface))
    return result


def _limits(design, surface: str):
    """The predictions of a layout on the surface, standing or rolling (the results' keys)."""
    kind = SURFACE_KINDS[surface]

    def limits(layout, rolling: bool) -> Dict[str, Any]:
        found = gradeability(
            layout,
            kind.lateral_friction,
            design.rolling_resistance(surface),
            rolling_offset=rolling_offset(surface) if rolling else 0.0,
        )
        return {
            "predicted_climb_deg": round(found.climb_deg, 2),
            "predicted_limited_by": found.limited_by,
            "predicted_descent_deg": round(found.descent_deg, 2),
            **({"rolling_offset_m": rolling_offset(surface)} if rolling else {}),
        }

    return limits


def ramp_run(design, params) -> float:
    """[m] of the ramp's run: ``ramp_length``, or twice the robot's length and 1 m if that is longer,
    so that the robot stands wholly on the incline for a while (a robot bridging the foot and the
    crest stands on neither)."""
    return max(params["ramp_length"], 2.0 * design.length + 1.0)


def _climb(lab, design, params, angle: float) -> Tuple[str, str]:
    """Climbs one ramp: (the incline's outcome, the crest's), "ok" or what stopped it."""
    run, speed = ramp_run(design, params), params["speed"]
    top = design.length + 1.0
    world = ramp_world(params["surface"], angle, run, top)
    start_x = -(design.front + 0.5)  # the robot's front 0.5 m short of the foot
    crest = run - design.front * math.cos(angle)  # base_link where the foremost wheel reaches the crest
    goal = run + 0.5 * top  # base_link over the middle of the top
    limit = SETTLE + 2.0 * (goal - start_x) / speed + 10.0
    progress = Progress(slope=angle)
    loads: List[tuple] = []
    with lab.session(world, x=start_x, label=f"climb {math.degrees(angle):g} deg") as session:
        session.marks = _try("climb", angle)
        session.run(SETTLE, lambda t: (0.0, 0.0, 0.0))
        command = heading_hold(session, 0.0, speed)

        def stop(s) -> bool:
            loads.append((s.time, [abs(m.wheel_torque) for m in s.motor_loads()]))
            return s.track[-1].x >= goal or progress.failed(s.track)

        session.run(limit, command, stop)
        furthest = max(pose.x for pose in session.track)
        outcome = _climb_outcome(furthest >= crest, progress, loads, design)
        over = _climb_outcome(session.track[-1].x >= goal, progress, loads, design) if outcome == "ok" else outcome
        session.outcome = outcome if over == "ok" else f"{outcome}; the crest: {over}"
    return outcome, over


def _try(series_name: str, angle: float) -> Dict[str, Any]:
    """The report's marks of one try: which series, its angle; seen from the side along the drive."""
    return {"series": series_name, "value": round(math.degrees(angle), 6), "unit": "deg", "section": "along"}


def _climb_outcome(reached: bool, progress: Progress, loads, design) -> str:
    if reached:
        return "ok"
    if progress.outcome == "tipping":
        return "tipping"
    # what held it: the motors at their limit, or the ground's grip (the wheels turn below it); a
    # wheel off the ground (a long frame bridging a crest) turns freely and is not one that pushes
    last = [torques for t, torques in loads if t >= loads[-1][0] - 1.0]
    shares = [tq / m for torques in last for tq, m in zip(torques, design.max_wheel_torques) if m > 0]
    pushing = [share for share in shares if share >= PUSHING]
    return "motor torque" if pushing and mean(pushing) >= TORQUE_BOUND else "traction"


def _descend(lab, design, params, angle: float) -> str:
    run, speed = ramp_run(design, params), params["speed"]
    top = design.length + 1.0
    world = ramp_world(params["surface"], angle, run, top)
    height = run * math.tan(angle)
    start_x = run + 0.5 * top  # base_link over the middle of the top
    far_foot = 2.0 * run + top
    goal = far_foot + design.length  # off the ramp, on level ground again
    limit = SETTLE + 2.0 * (goal - start_x) / speed + 10.0
    tolerance = max(0.1, 0.3 * speed)
    outcome = []
    with lab.session(world, x=start_x, z=height, label=f"descend {math.degrees(angle):g} deg") as session:
        session.marks = _try("descent", angle)
        session.run(SETTLE, lambda t: (0.0, 0.0, 0.0))
        command = heading_hold(session, 0.0, speed)

        def stop(s) -> bool:
            pose = s.track[-1]
            if max(abs(pose.roll), abs(pose.pitch)) > angle + TIPPED:
                outcome.append("tipping")
            elif run + top + 0.5 * design.length < pose.x < far_foot:  # on the ramp
                before = at_time(s.track, pose.t - SPEED_WINDOW)
                v = math.hypot(pose.x - before.x, pose.y - before.y) / max(pose.t - before.t, 1e-9)
                if abs(v - speed) > tolerance:
                    outcome.append(f"ran away ({v:.2f} m/s for {speed:g})" if v > speed else "stalled")
            return bool(outcome) or pose.x >= goal

        session.run(limit, command, stop)
        reached = session.track[-1].x >= goal
        session.outcome = outcome[0] if outcome else "ok" if reached else "stalled"
    return session.outcome


GRADEABILITY = ScenarioKind(
    name="gradeability",
    what="the steepest ramp climbed, what limited it, and the steepest descended under control",
    keys=KEYS,
    metrics=METRICS,
    procedure=procedure,
    check=check,
    cost=12.0,  # [s] the standard robot's run (ScenarioKind.cost)
)
