"""The scenarios a design study puts its candidates through: one module a scenario (its parameters,
its documented procedure, its metrics), one line of the registry below.

A new scenario is its module (a :class:`~thorvald_design.scenarios.kind.ScenarioKind`) and its line in
``BUILT_IN``: the study file's keys, the checks, the runs, results.json and the report follow it.
"""

from typing import Dict, Tuple

from .drawbar import DRAWBAR
from .energy import ENERGY
from .gradeability import GRADEABILITY
from .headland import HEADLAND
from .kind import ScenarioKind, not_applicable
from .obstacle import OBSTACLE
from .rails import RAILS
from .side_slope import SIDE_SLOPE
from .turning import TURNING

BUILT_IN: Tuple[ScenarioKind, ...] = (GRADEABILITY, SIDE_SLOPE, TURNING, HEADLAND, OBSTACLE, DRAWBAR, RAILS, ENERGY)
SCENARIOS: Dict[str, ScenarioKind] = {kind.name: kind for kind in BUILT_IN}

__all__ = ["BUILT_IN", "SCENARIOS", "ScenarioKind", "not_applicable"]
