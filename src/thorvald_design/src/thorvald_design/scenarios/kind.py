"""What a scenario is: :class:`ScenarioKind`, one entry of the registry
(:mod:`thorvald_design.scenarios`), and what its procedure is given.

A scenario is a documented procedure with its metrics: its parameters (keys of the study file's
``scenarios.NAME`` with defaults and rules, checked as a robot file's keys are), the procedure that
drives a candidate through it and measures the metrics from ground truth, and the metrics it reports,
each declared with its unit, which way is better, what it means and the quasi-static figure it is to
agree with (:class:`Metric`). The procedure is pure: it drives through a :class:`Lab`, which the
study's worker makes (a simulation of the candidate's own, :mod:`thorvald_design.lab`), so a scenario
module imports neither pybullet nor ROS and its arithmetic is tested on its own.

Everything that shows a metric reads its declaration here: the report's arrows, its bold best, the
Pareto plane's directions, the charts of a measured limit beside its prediction and what the page
says when they disagree (:mod:`thorvald_design.report`); a search's objectives and requirements name
the metrics declared (:mod:`thorvald_design.optimise_spec`).
"""

from dataclasses import dataclass, field
from typing import Any, Callable, ContextManager, Dict, List, Mapping, Optional, Protocol, Sequence, Tuple

from thorvald_model.errors import Problem
from thorvald_model.schema import Key

from ..errors import ScenarioError

Twist = Tuple[float, float, float]  # vx [m/s], vy [m/s], wz [rad/s] in base_link


@dataclass(frozen=True)
class Pose:
    """base_link in the world at a control instant."""

    t: float  # [s]
    x: float  # [m]
    y: float
    z: float
    roll: float  # [rad]
    pitch: float  # nose up positive
    yaw: float


class Session(Protocol):
    """One drive of a candidate in a world of the scenario's (see :class:`thorvald_design.lab.LabSession`)."""

    track: List[Pose]  # base_link at every control instant so far
    marks: Dict[str, Any]  # what the report draws beside the track (JSON values), set by the scenario

    @property
    def time(self) -> float: ...

    def run(
        self,
        until: float,
        command: Callable[[float], Optional[Twist]],
        stop: Optional[Callable[["Session"], bool]] = None,
    ) -> bool: ...

    def pose(self) -> Pose: ...

    def motor_loads(self) -> List[Any]: ...  # per drive: wheel_torque, wheel_rate, steering_torque, steering_rate

    def push(self, force: Optional[Sequence[float]], at: Sequence[float] = (0.0, 0.0, 0.0)) -> None: ...

    def set_drive_params(self, changes: Sequence[Tuple[int, str, float]]) -> List[str]: ...

    @property
    def odometry(self) -> List[Any]: ...  # base_driver's odometry samples (t, x, y, yaw) in the odom frame


class Lab(Protocol):
    # [m] the simulated robot's centre of mass in base_link, known after the first session (the
    # physics' own, which need not be the description's: see thorvald_design.lab.LabSession)
    centre_of_mass: Optional[Tuple[float, float, float]]

    def session(
        self,
        world: Mapping,
        *,
        x: float = 0.0,
        y: float = 0.0,
        z: float = 0.0,
        yaw: float = 0.0,
        roll: float = 0.0,
        label: str = "",
    ) -> Any:
        """A session (a context manager giving a :class:`Session`) of the candidate spawned at (x, y, z, yaw)
        in the world of the given world-file contents."""
        ...


LARGER = +1  # a metric's direction: more of it is better
SMALLER = -1  # less of it is better
WORDS = 0  # a metric that is a word (what limited a climb, which turn): shown, neither better nor plotted


@dataclass(frozen=True)
class Prediction:
    """The quasi-static figure a measured limit is to agree with, and how the report compares them.

    A series measures a limit in steps: its value is the last try held, so a prediction the
    simulation bears out lies between it and the first try that failed, at most a step above it."""

    metric: str  # the prediction's metric, one of the scenario's ("predicted_climb_deg")
    step: str  # the scenario's parameter that is the series' step ("step_deg")
    tries: str = ""  # the results' key of the series' tries ([value, outcome, ...] each: "climbs"); "" none
    held: str = "held"  # what the measured value is, in a sentence: "climbed", "pulled"
    # what else parts them, from the metric's meaning (the scenario's docstring): the page's "why"
    rest: str = ""


@dataclass(frozen=True)
class Metric:
    """One metric a scenario reports (a key of its results in results.json), declared."""

    name: str  # "max_climb_deg"
    unit: str  # "deg", "m", "N", "Wh/km", "%", "1" (a fraction), a count's noun ("plants"); "" for words
    direction: int  # LARGER, SMALLER or WORDS
    meaning: str  # one line: what it is
    prediction: Optional[Prediction] = None  # the quasi-static figure it is to agree with, if any

    def __post_init__(self) -> None:
        if self.direction not in (LARGER, SMALLER, WORDS):
            raise ScenarioError(f"metric {self.name}: direction {self.direction!r}: must be +1, -1 or 0 (words)")
        if (self.direction == WORDS) != (self.unit == ""):
            rule = "a word has no unit and no direction" if self.direction == WORDS else "a number needs its unit"
            raise ScenarioError(f"metric {self.name}: unit {self.unit!r}, direction {self.direction}: {rule}")
        if self.prediction is not None and self.direction == WORDS:
            raise ScenarioError(f"metric {self.name}: a word has no prediction to agree with")

    @property
    def words(self) -> bool:
        """Whether it is a word, not a number: shown in the table, not plotted."""
        return self.direction == WORDS


@dataclass(frozen=True)
class ScenarioKind:
    """A kind of scenario: one entry of the registry."""

    name: str  # its key under ``scenarios:``
    what: str  # one line: what it measures
    keys: Tuple[Key, ...]  # its parameters
    metrics: Tuple[Metric, ...]  # the metrics it reports (results.json's keys, in order)
    # procedure(lab, design, params) -> {metric: value}; a metric it cannot give is "n/a: why"
    procedure: Callable[[Lab, Any, Mapping[str, Any]], Dict[str, Any]]
    # the rules between its parameters: problems appended at path.KEY
    check: Callable[[Mapping[str, Any], str, List[Problem]], None] = field(default=lambda values, path, problems: None)
    # the metrics a study's parameters give beyond ``results`` (drawbar's ``max_pull_n.mud`` for each
    # further surface, each declared by its metric's declaration): the table's, the CSV's and the
    # report's columns after ``results``
    more: Callable[[Mapping[str, Any]], Tuple[str, ...]] = field(default=lambda params: ())
    # [s] about what a run of it takes the standard robot (four drives) in one worker on the project's
    # machine with its default parameters: a study starts its longest runs first, and guesses their
    # length from this (times the candidate's drives over four) where no earlier run was timed
    cost: float = 1.0

    def __post_init__(self) -> None:
        object.__setattr__(self, "metrics", tuple(self.metrics))
        names = [m.name for m in self.metrics]
        for m in self.metrics:
            if names.count(m.name) > 1:
                raise ScenarioError(f"scenario {self.name}: metric {m.name} is declared twice")
            if "." in m.name:
                raise ScenarioError(f"scenario {self.name}: metric {m.name}: a name has no '.' (a column's suffix)")
            if m.prediction is not None and m.prediction.metric not in names:
                raise ScenarioError(
                    f"scenario {self.name}: metric {m.name}'s prediction {m.prediction.metric} is none of its metrics"
                )
            if m.prediction is not None and m.prediction.step not in [k.name for k in self.keys]:
                raise ScenarioError(
                    f"scenario {self.name}: metric {m.name}'s step {m.prediction.step} is none of its parameters"
                )

    @property
    def results(self) -> Tuple[str, ...]:
        """The metrics' names, in order (results.json's keys)."""
        return tuple(m.name for m in self.metrics)

    def metric(self, name: str) -> Optional[Metric]:
        """The declaration of a metric or column of it (``max_pull_n`` of ``max_pull_n.mud``); None if it
        declares none of that name."""
        base = name.split(".", 1)[0]
        return next((m for m in self.metrics if m.name == base), None)

    def columns(self, params: Mapping[str, Any]) -> Tuple[str, ...]:
        """The metrics a run of these parameters reports, in the table's order."""
        return (*self.results, *self.more(params))


def not_applicable(why: str) -> str:
    return f"n/a: {why}"


ContextSession = ContextManager[Session]
