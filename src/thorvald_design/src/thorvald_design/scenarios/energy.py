"""energy: what a field costs: Wh per km and per hectare, battery current, and the range it gives.

Procedure: a field of ``rows`` rows ``row_length`` [m] long, ``spacing`` [m] apart (the width the
robot works a pass), on the study's surface; the robot drives every row in turn at ``speed`` [m/s]
and turns in the headland from each row into the next: a U turn where it turns that tight, an omega
turn where it does not (:func:`thorvald_design.route.field_route`, with the robot's tightest turn:
:func:`thorvald_design.scenarios.turning.turn_centre`), followed by pure pursuit
(:class:`thorvald_design.route.PurePursuit`) through its own base_driver core.

At every control instant the simulator's joint motor torques and rates of every wheel and steering
joint are turned into electrical power by the drive's motor model (:mod:`thorvald_design.energy`:
its gear, torque constant, winding resistance and no-load current, the robot file's ``prp_motor_*``
and ``str_motor_*`` keys), regenerative braking on or off; a hotel load ``hotel_load_w`` [W]
(computer, sensors, the motor controllers) runs throughout; the robot's batteries (``batteries``
with a KC battery fitted: ``capacity``, ``voltage``, ``internal_resistance``) in parallel carry it.

Metrics: ``wh_per_km`` (the energy over the distance driven, turns included), ``wh_per_ha`` (over
the area worked: rows x row_length x spacing), ``peak_current_a`` and ``rms_current_a`` drawn from
the pack, ``end_soc`` (from ``start_soc``) and ``range_km``: the distance the pack's charge lasts at
the run's rate of use (charge, not energy, empties a battery: the pack's internal loss included).
A robot without a battery gets ``n/a``, and so does one that tips over on the route (a tricycle in
a tight headland turn at speed: the turn's centripetal acceleration v^2 / R against g tan of its
static overturning angle) or does not finish it in time.
"""

import math
from typing import Any, Dict, List, Mapping

import numpy as np

from thorvald_model.motors import propulsion_motor, steering_motor
from thorvald_model.schema import Key, one_of

from ..energy import Battery, energy_use, motor_power
from ..route import PurePursuit, field_route
from .driving import SURFACE_RULE, SURFACES, TIPPED, feasible_twist, flat_world
from .gradeability import SETTLE
from .kind import LARGER, SMALLER, Metric, ScenarioKind, not_applicable
from .turning import turn_centre

KEYS = (
    Key("surface", str, "grass", check=one_of(*SURFACES), rule=SURFACE_RULE),
    Key("speed", float, 1.0, check=lambda v: 0.05 <= v <= 3.0, rule="must be in [0.05, 3] [m/s]"),
    Key("rows", int, 4, check=lambda v: 1 <= v <= 200, rule="must be in [1, 200]"),
    Key("row_length", float, 20.0, check=lambda v: 1.0 <= v <= 1000.0, rule="must be in [1, 1000] [m]"),
    Key("spacing", float, 0.75, check=lambda v: 0.1 <= v <= 20.0, rule="must be in [0.1, 20] [m]"),
    Key("hotel_load_w", float, 60.0, check=lambda v: 0.0 <= v <= 10000.0, rule="must be in [0, 10000] [W]"),
    Key("regenerative", bool, False),
    Key("start_soc", float, 1.0, check=lambda v: 0.0 < v <= 1.0, rule="must be in (0, 1]"),
)
METRICS = (
    Metric("wh_per_km", "Wh/km", SMALLER, "the energy the route took over the distance driven, turns included"),
    Metric("wh_per_ha", "Wh/ha", SMALLER, "the energy the route took over the area worked"),
    Metric("peak_current_a", "A", SMALLER, "the largest current drawn from the pack"),
    Metric("rms_current_a", "A", SMALLER, "the root mean square of the pack's current"),
    Metric("end_soc", "1", LARGER, "the pack's state of charge left after the route"),
    Metric("range_km", "km", LARGER, "the distance the pack's charge lasts at the route's rate of use"),
)
RESULTS = tuple(m.name for m in METRICS)
MARGIN = 0.05  # [m] the route's turns are this much wider than the robot's tightest


def procedure(lab, design, params: Mapping[str, Any]) -> Dict[str, Any]:
    config = design.config
    batteries = [Battery(b.capacity, b.voltage, b.internal_resistance) for b in config.batteries if b.present]
    if not batteries:
        return {name: not_applicable("the robot carries no battery") for name in RESULTS}
    centre, _ = turn_centre(config.drives, config.passive_wheels)
    radius = math.hypot(*centre) + MARGIN  # base_link's circle in the tightest turn
    path = field_route(params["rows"], params["row_length"], params["spacing"], radius)
    speed = params["speed"]
    pursuit = PurePursuit(path, lookahead=max(0.4, min(1.5, 0.8 * max(radius, params["spacing"] / 2.0))), speed=speed)
    records: List[tuple] = []
    limit = SETTLE + 1.5 * path.length / speed + 30.0
    turn = "U" if radius <= params["spacing"] / 2.0 else "omega"
    with lab.session(flat_world(params["surface"]), label=f"{params['rows']} rows, {turn} turns") as session:
        session.run(SETTLE, lambda t: (0.0, 0.0, 0.0))
        start = len(session.track)

        def command(t: float):
            q = session.track[-1]
            vx, wz = pursuit.command(q.x, q.y, q.yaw)
            return feasible_twist(config, vx, wz)

        def stop(s) -> bool:
            records.append((s.time, s.motor_loads()))
            q = s.track[-1]
            return pursuit.done() or max(abs(q.roll), abs(q.pitch)) > TIPPED

        session.run(limit, command, stop)
        poses = session.track[start:]
        q = poses[-1]
        tipped = max(abs(q.roll), abs(q.pitch)) > TIPPED
        session.outcome = "ok" if pursuit.done() else "tipping" if tipped else "ran out of time"
    if tipped:
        why = f"it tipped over at ({q.x:.1f}, {q.y:.1f}) m, {q.t - SETTLE:.1f} s into the route"
        return {name: not_applicable(why) for name in RESULTS}
    if not pursuit.done():
        return {name: not_applicable(f"the route was not finished in {limit:.0f} s") for name in RESULTS}
    distance = float(np.sum(np.hypot(np.diff([q.x for q in poses]), np.diff([q.y for q in poses]))))
    report = energy_use(
        [t for t, _ in records],
        _powers(config, records, params["regenerative"]),
        params["hotel_load_w"],
        batteries,
        distance_m=distance,
        area_ha=params["rows"] * params["row_length"] * params["spacing"] / 10_000.0,
        start_soc=params["start_soc"],
    )
    return {
        "wh_per_km": _r(report.wh_per_km),
        "wh_per_ha": _r(report.wh_per_ha),
        "peak_current_a": _r(report.peak_current_a),
        "rms_current_a": _r(report.rms_current_a),
        "end_soc": round(report.end_soc, 5),
        "range_km": _r(report.range_km) if report.range_km is not None else not_applicable("no charge used"),
        "energy_wh": _r(report.energy_wh),
        "distance_m": _r(distance),
        "turn": turn,
        "by_motor_wh": {name: _r(wh) for name, wh in report.energy_by_motor_wh},
    }


def _r(value: float) -> float:
    return round(float(value), 3) + 0.0


def _powers(config, records, regenerative: bool) -> Dict[str, np.ndarray]:
    """Each motor's electrical power [W] at every record, by the drive's motor model."""
    out: Dict[str, np.ndarray] = {}
    for k, d in enumerate(config.drives):
        wheel = propulsion_motor(d)
        torque = np.array([loads[k].wheel_torque for _, loads in records])
        rate = np.array([loads[k].wheel_rate for _, loads in records])
        out[f"{d.name}.wheel"] = np.asarray(motor_power(wheel, torque, rate, regenerative)[0])
        if d.steerable:
            steer = steering_motor(d)
            torque = np.array([loads[k].steering_torque for _, loads in records])
            rate = np.array([loads[k].steering_rate for _, loads in records])
            out[f"{d.name}.steering"] = np.asarray(motor_power(steer, torque, rate, regenerative)[0])
    return out


ENERGY = ScenarioKind(
    name="energy",
    what="a field route of rows and headland turns: Wh per km and per hectare, battery current, range",
    keys=KEYS,
    metrics=METRICS,
    procedure=procedure,
    cost=2.4,  # [s] the standard robot's run (ScenarioKind.cost)
)
