"""drawbar: the largest pull the robot holds at walking speed on each surface (the Thorvald II hardware
paper's traction trial).

Procedure: on level ground of each of the study's surfaces (``surface``: one kind or a list of them,
``surfaces`` as well) the robot drives straight ahead at ``speed`` [m/s] (its heading held); after
``settle`` [s] a horizontal pull backwards acts on the frame at ``hitch_height`` [m] above the
ground behind base_link, growing by ``step_n`` [N] every ``hold_s`` [s]. A pull is held when the
robot's mean speed over the last second of its step is at least ``held_speed`` (90 % by default) of
the command. ``max_pull_n`` is the largest held: past it the driven wheels slip (traction) or their
motors are at their torque limit (motor torque), as ``limited_by`` says (the motors' mean share of
their limit over that last second, as :mod:`~thorvald_design.scenarios.gradeability` decides it).
``max_pull_n``, ``limited_by`` and ``predicted_pull_n`` are the first surface's (``surface`` says
which); with more than one surface, ``max_pull_n.KIND``, ``limited_by.KIND`` and
``predicted_pull_n.KIND`` give every surface's, each in its own column of the table.

What it must agree with: at constant speed on level ground the driven wheels' forces balance the
pull and the rolling resistance: sum_driven min(mu N_i, F_i) = P + C_rr W, the loads N_i shifted
rearwards by the pull's moment P h about the contacts
(:func:`thorvald_design.quasi_static.max_pull`), reported as ``predicted_pull_n``. Beside it,
``as_simulated`` gives the same limit for the robot as the simulator holds it (its centre of mass,
measured there) standing and rolling
(each wheel's load the surface's rolling friction ahead of its contact), for the report to say what
a gap between the pull and its prediction owes to them.
"""

import math
from typing import Any, Dict, List, Mapping, Tuple

from thorvald_model.schema import Key
from thorvald_sim.world.surfaces import SURFACE_KINDS

from ..quasi_static import max_pull
from .driving import SURFACE_RULE, SURFACES, as_simulated, flat_world, heading_hold, mean, rolling_offset
from .gradeability import TORQUE_BOUND
from .kind import LARGER, WORDS, Metric, Prediction, ScenarioKind

KEYS = (
    Key(
        "surface",
        tuple,
        ("grass",),
        check=lambda kinds: all(k in SURFACES for k in kinds) and len(set(kinds)) == len(kinds),
        rule=SURFACE_RULE + ", or a list of them (each once)",
        aliases=("surfaces",),
    ),
    Key("speed", float, 1.0, check=lambda v: 0.05 <= v <= 3.0, rule="must be in [0.05, 3] [m/s]"),
    Key("hitch_height", float, 0.4, check=lambda v: 0.0 <= v <= 3.0, rule="must be in [0, 3] [m]"),
    Key("step_n", float, 50.0, check=lambda v: 1.0 <= v <= 10000.0, rule="must be in [1, 10000] [N]"),
    Key("hold_s", float, 2.0, check=lambda v: 0.5 <= v <= 30.0, rule="must be in [0.5, 30] [s]"),
    Key("settle", float, 3.0, check=lambda v: 0.5 <= v <= 30.0, rule="must be in [0.5, 30] [s]"),
    Key("held_speed", float, 0.9, check=lambda v: 0.1 <= v < 1.0, rule="must be in [0.1, 1)"),
)
METRICS = (
    Metric(
        "max_pull_n", "N", LARGER, "the largest backward pull held at the command's speed (the first surface's)",
        Prediction(
            "predicted_pull_n", "step_n", "", "held",
            "the model's contacts are points under the wheels' axes where the simulated wheels touch at one rim of "
            "their contact discs (and a caster's wheel trails its swivel axis), a soft surface's wheels sink, and a "
            "pull counts as held while the speed stays at held_speed of the command, which a wheel slipping a "
            "little still meets",
        ),
    ),
    Metric("limited_by", "", WORDS, "what stopped the next pull: traction or motor torque"),
    Metric("predicted_pull_n", "N", LARGER, "the quasi-static pull its weight distribution, grip and motors allow"),
    Metric("surface", "", WORDS, "the surface of the headline figures: the first of the study's"),
)  # fmt: skip
EACH = ("max_pull_n", "limited_by", "predicted_pull_n")  # per surface, when there are several
MAX_STEPS = 400  # of the pull: a robot holding 400 steps is out of the scenario's range


def more(params: Mapping[str, Any]) -> Tuple[str, ...]:
    """Every surface's metrics, when the study lists more than one."""
    kinds = params["surface"]
    return tuple(f"{metric}.{kind}" for kind in kinds for metric in EACH) if len(kinds) > 1 else ()


def procedure(lab, design, params: Mapping[str, Any]) -> Dict[str, Any]:
    kinds = params["surface"]
    pulls = {kind: _pull(lab, design, params, kind) for kind in kinds}
    result = dict(pulls[kinds[0]])
    if len(kinds) > 1:
        result.update({f"{metric}.{kind}": pulls[kind][metric] for kind in kinds for metric in EACH})
    result["as_simulated"] = as_simulated(design, lab, _limits(design, params))
    return result


def _limits(design, params: Mapping[str, Any]):
    """The predicted pulls of a layout, standing or rolling, under the results' keys (each surface's too)."""
    kinds = params["surface"]

    def limits(layout, rolling: bool) -> Dict[str, Any]:
        out: Dict[str, Any] = {}
        for k, kind in enumerate(kinds):
            surface = SURFACE_KINDS[kind]
            e = rolling_offset(kind) if rolling else 0.0
            found = max_pull(
                layout, surface.lateral_friction, design.rolling_resistance(kind), params["hitch_height"],
                rolling_offset=e,
            )  # fmt: skip
            keys = ([""] if k == 0 else []) + ([f".{kind}"] if len(kinds) > 1 else [])
            for suffix in keys:
                out[f"predicted_pull_n{suffix}"] = round(found.pull, 1)
                out[f"predicted_limited_by{suffix}"] = found.limited_by
                if rolling:
                    out[f"rolling_offset_m{suffix}"] = e
        return out

    return limits


def _pull(lab, design, params: Mapping[str, Any], surface: str) -> Dict[str, Any]:
    speed = params["speed"]
    predicted = design.pull_limit(surface, params["hitch_height"])
    held, limited_by = 0.0, f"none up to {MAX_STEPS * params['step_n']:g} N"
    loads: List[tuple] = []
    with lab.session(flat_world(surface), label=f"pull on {surface}") as session:
        command = heading_hold(session, 0.0, speed)
        session.run(params["settle"], command)
        for k in range(1, MAX_STEPS + 1):
            pull = k * params["step_n"]
            # backwards along the robot's heading, at the hitch behind base_link
            yaw = session.track[-1].yaw
            session.push(
                (-pull * math.cos(yaw), -pull * math.sin(yaw), 0.0), (-design.rear, 0.0, params["hitch_height"])
            )
            start = session.time
            loads.clear()

            def stop(s) -> bool:
                loads.append((s.time, [abs(m.wheel_torque) for m in s.motor_loads()]))
                return False

            session.run(start + params["hold_s"], command, stop)
            last = [q for q in session.track if q.t >= session.time - 1.0]
            v = math.hypot(last[-1].x - last[0].x, last[-1].y - last[0].y) / max(last[-1].t - last[0].t, 1e-9)
            if v < params["held_speed"] * speed:
                torques = [tq for t, tq in loads if t >= session.time - 1.0]
                share = mean([mean([a / m for a, m in zip(tq, design.max_wheel_torques) if m > 0]) for tq in torques])
                limited_by = "motor torque" if share >= TORQUE_BOUND else "traction"
                break
            held = pull
        session.outcome = f"held {held:g} N"
    return {
        "max_pull_n": held,
        "limited_by": limited_by,
        "predicted_pull_n": round(predicted.pull, 1),
        "predicted_limited_by": predicted.limited_by,
        "surface": surface,
    }


DRAWBAR = ScenarioKind(
    name="drawbar",
    what="the largest pull held at walking speed on each surface, and what limited it",
    keys=KEYS,
    metrics=METRICS,
    procedure=procedure,
    more=more,
    cost=1.1,  # [s] the standard robot's run (ScenarioKind.cost)
)
