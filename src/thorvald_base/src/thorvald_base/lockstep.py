"""base_driver in lockstep with a simulator, without ROS: what one simulator instant asks of it.

In lockstep the simulator publishes every robot's measured drive states at each tick of its clock
and steps no further until each driver answered that instant. base_driver's answer is a control
cycle at the first instant at or after each multiple of its period (its grid,
:class:`thorvald_base.rate_grid.RateGrid`, so two runs and two robots cycle at the same instants),
and at every other instant the last commands again, stamped for it (``BaseHandle.answer``); the very
first instant is a cycle too, as there are no commands yet to answer it with.
:class:`LockstepCycles` is that rule, once: base_driver's node runs it on the simulator's topics,
thorvald_sim's runner in the same process as the simulation.

:func:`apply_calibration` is base_driver's ``~calibration``: the file's values checked against the
robot and applied as ``set_drive_params`` applies them, its odometry correction to the calculator.

Pure: no rospy.
"""

from typing import Optional, Tuple

from .calibration.calibration_file import CalibrationValues, read_calibration
from .core import BaseDriverCore, CycleResult
from .errors import KinematicsError, ParameterError
from .rate_grid import RateGrid

Twist3 = Tuple[float, float, float]  # vx [m/s], vy [m/s], wz [rad/s]


class LockstepCycles:
    """One call per simulator instant: a control cycle on the grid, the last commands between."""

    def __init__(self, core: BaseDriverCore, rate: float):
        if not getattr(core.handle, "supports_lockstep", False):
            raise ParameterError(
                f"lockstep needs a base handle that answers a simulator instant by instant, not "
                f"{type(core.handle).__name__}"
            )
        self.core = core
        self.cycles = RateGrid(rate)  # the simulator's ticks are the instants: exact multiples count
        self.started = False

    def due(self, t: float) -> bool:
        """Whether the instant t [s] is a control cycle (asks the grid: call once per instant). The first
        instant always is: before any cycle there are no commands to answer it with, and a simulator in
        lockstep would wait for an answer that cannot come."""
        on_grid = self.cycles.due(t)
        if not self.started:
            self.started = True
            return True
        return on_grid

    def cycle(self, t: float, twist: Optional[Twist3]) -> Tuple[CycleResult, Optional[str]]:
        """The control cycle at t with the command holding then (None: none; the core's timeout
        rules): its result, and why the command was refused (None if it was not)."""
        refused = self.core.set_command(*twist, t) if twist is not None else None
        return self.core.step(t), refused

    def answer(self, t: float) -> None:
        """An instant that is not a cycle: the last commands again, stamped for it."""
        self.core.handle.answer(t)


def apply_calibration(core: BaseDriverCore, path: str) -> CalibrationValues:
    """A calibration file's values (calibrate_odometry writes it), checked against the core's robot
    and applied: the drives' through set_drive_params, the odometry correction to the calculator; what
    it set. ConfigError for a broken file, ParameterError for values the robot refuses."""
    values = read_calibration(path, core.config)
    _, problems = core.set_drive_params(list(values.changes))
    if problems:
        raise ParameterError(f"~calibration: {path}: " + "; ".join(problems))
    if values.odometry is not None:
        try:
            core.calculator.odometry_correction = values.odometry
        except KinematicsError as e:  # the file's rules are the calculator's: a floor for direct users
            raise ParameterError(f"~calibration: {path}: {e}") from None
    return values


def calibration_said(values: CalibrationValues) -> str:
    """What a calibration file set, in a few words (base_driver logs it)."""
    said = [f"drive{i} {key} {value:g}" for i, key, value in values.changes]
    for key in ("yaw_rate_multiplier", "yaw_per_metre", "yaw_per_metre_sideways"):
        if getattr(values, key) is not None:
            said.append(f"odometry {key} {getattr(values, key):g}")
    if values.wheel_weights is not None:
        said.append("odometry wheel_weights " + " ".join(f"{w:.3g}" for w in values.wheel_weights))
    return ", ".join(said) or "nothing to change"
