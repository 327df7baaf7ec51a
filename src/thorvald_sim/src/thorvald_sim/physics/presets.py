"""The simulator's physics settings by name: the default, and a cheaper one for fleets.

pybullet's cost per robot grows with the physics rate (collision detection and the solver run every
step) and hardly with the solver's iterations (its solver stops early once the contacts are
resolved: on 16 standard robots driving straight or crabbing, 50, 20 and 10 iterations at 240 Hz
cost the same; turning robots keep more contact points and use every iteration). So the
fleet preset halves the rate and keeps the iterations, which keep the contacts' accuracy at the
longer step (20 iterations at 120 Hz took a differential robot's path 1.4 m off the default's over
the paper's 80 m manoeuvre; 50 iterations 0.17 m). ``bench/physics_preset.py`` measures both
presets side by side, cost and paths; docs/simulator.md quotes its figures.

* ``default``: 240 Hz, 50 iterations (pybullet's default solver, set explicitly).
* ``fleet``: 120 Hz, 50 iterations: about half the CPU per robot and simulated second.

A rate or iteration count given explicitly (the node's ``~physics_rate`` / ``~solver_iterations``,
:class:`~thorvald_sim.tools.runner.RunOptions`) overrides the preset's.

Pure: no pybullet, no rospy.
"""

import math
from dataclasses import dataclass
from typing import Optional


@dataclass(frozen=True)
class Physics:
    name: str
    rate: float  # [Hz] physics steps per simulated second
    solver_iterations: int


PRESETS = {
    "default": Physics("default", 240.0, 50),
    "fleet": Physics("fleet", 120.0, 50),
}
MAX_ITERATIONS = 1000
MAX_WORKERS = 16  # ~physics_workers: the most worker processes (physics.workers; node.params checks it)


def physics_settings(name: str = "default", rate: Optional[float] = None, solver_iterations: Optional[int] = None):
    """The preset ``name`` with an explicit rate [Hz] or iteration count in place of its own;
    ValueError naming the setting, the value and the rule."""
    if not isinstance(name, str) or name not in PRESETS:
        raise ValueError(f"physics: {name!r}: must be one of {', '.join(PRESETS)}")
    preset = PRESETS[name]
    if rate is not None:
        if isinstance(rate, bool) or not isinstance(rate, (int, float)) or not (math.isfinite(rate) and rate > 0):
            raise ValueError(f"physics_rate: {rate!r}: must be a number > 0 [Hz]")
    if solver_iterations is not None and (
        isinstance(solver_iterations, bool)
        or not isinstance(solver_iterations, int)
        or not 1 <= solver_iterations <= MAX_ITERATIONS
    ):
        raise ValueError(f"solver_iterations: {solver_iterations!r}: must be a whole number in 1..{MAX_ITERATIONS}")
    return Physics(
        preset.name,
        float(rate) if rate is not None else preset.rate,
        solver_iterations if solver_iterations is not None else preset.solver_iterations,
    )


__all__ = ["MAX_ITERATIONS", "MAX_WORKERS", "PRESETS", "Physics", "physics_settings"]
