"""The scenarios a design study puts its candidates through: one module a scenario (its parameters,
its documented procedure, its declared metrics), one line of the registry below.

A new scenario is its module (a :class:`~thorvald_design.scenarios.kind.ScenarioKind`, its metrics
each a :class:`~thorvald_design.scenarios.kind.Metric`) and its line in ``BUILT_IN``: the study
file's keys, the checks, the runs, results.json, the table and the report follow it. A scenario of a
test or of a user's program is added for a while with :func:`registered`.
"""

from contextlib import contextmanager
from typing import Dict, Iterator, Optional, Tuple

from ..errors import ScenarioError
from .drawbar import DRAWBAR
from .energy import ENERGY
from .gradeability import GRADEABILITY
from .headland import HEADLAND
from .kind import LARGER, SMALLER, WORDS, Metric, Prediction, ScenarioKind, not_applicable
from .obstacle import OBSTACLE
from .rails import RAILS
from .side_slope import SIDE_SLOPE
from .turning import TURNING

BUILT_IN: Tuple[ScenarioKind, ...] = (GRADEABILITY, SIDE_SLOPE, TURNING, HEADLAND, OBSTACLE, DRAWBAR, RAILS, ENERGY)
SCENARIOS: Dict[str, ScenarioKind] = {kind.name: kind for kind in BUILT_IN}  # BUILT_IN, then registered()'s


@contextmanager
def registered(*kinds: ScenarioKind) -> Iterator[None]:
    """The kinds added to the registry for the duration of a ``with`` block (ScenarioError for a name
    the registry has, or given twice). In this process: the study command's worker processes import
    the registry afresh, so a scenario they run is a line of ``BUILT_IN``."""
    names = [kind.name for kind in kinds]
    for name in names:
        if name in SCENARIOS or names.count(name) > 1:
            raise ScenarioError(f"scenario kind {name!r} is registered twice")
    SCENARIOS.update({kind.name: kind for kind in kinds})
    try:
        yield
    finally:
        for name in names:
            del SCENARIOS[name]


def declared(column: str) -> Optional[Metric]:
    """The declaration of a results column ``SCENARIO.METRIC`` (``drawbar.max_pull_n.mud`` is
    ``max_pull_n``'s); None for a scenario or metric the registry does not know."""
    scenario, _, metric = column.partition(".")
    kind = SCENARIOS.get(scenario)
    return kind.metric(metric) if kind is not None else None


__all__ = [
    "BUILT_IN",
    "LARGER",
    "SCENARIOS",
    "SMALLER",
    "WORDS",
    "Metric",
    "Prediction",
    "ScenarioKind",
    "declared",
    "not_applicable",
    "registered",
]
