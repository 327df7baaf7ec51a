"""What a scenario is: :class:`ScenarioKind`, one entry of the registry
(:mod:`thorvald_design.scenarios`), and what its procedure is given.

A scenario is a documented procedure with its metrics: its parameters (keys of the study file's
``scenarios.NAME`` with defaults and rules, checked as a robot file's keys are), the procedure that
drives a candidate through it and measures the metrics from ground truth, and the names of the
metrics it reports. The procedure is pure: it drives through a :class:`Lab`, which the study's
worker makes (a simulation of the candidate's own, :mod:`thorvald_design.lab`), so a scenario module
imports neither pybullet nor ROS and its arithmetic is tested on its own.
"""

from dataclasses import dataclass, field
from typing import Any, Callable, ContextManager, Dict, List, Mapping, Optional, Protocol, Sequence, Tuple

from thorvald_model.errors import Problem
from thorvald_model.schema import Key

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


@dataclass(frozen=True)
class ScenarioKind:
    """A kind of scenario: one entry of the registry."""

    name: str  # its key under ``scenarios:``
    what: str  # one line: what it measures
    keys: Tuple[Key, ...]  # its parameters
    results: Tuple[str, ...]  # the metrics it reports (results.json's keys, in order)
    # procedure(lab, design, params) -> {metric: value}; a metric it cannot give is "n/a: why"
    procedure: Callable[[Lab, Any, Mapping[str, Any]], Dict[str, Any]]
    # the rules between its parameters: problems appended at path.KEY
    check: Callable[[Mapping[str, Any], str, List[Problem]], None] = field(default=lambda values, path, problems: None)
    # the metrics a study's parameters give beyond ``results`` (drawbar's ``max_pull_n.mud`` for each
    # further surface): the table's, the CSV's and the report's columns after ``results``
    more: Callable[[Mapping[str, Any]], Tuple[str, ...]] = field(default=lambda params: ())

    def columns(self, params: Mapping[str, Any]) -> Tuple[str, ...]:
        """The metrics a run of these parameters reports, in the table's order."""
        return (*self.results, *self.more(params))


def not_applicable(why: str) -> str:
    return f"n/a: {why}"


ContextSession = ContextManager[Session]
