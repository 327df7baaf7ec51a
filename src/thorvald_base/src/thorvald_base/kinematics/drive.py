"""The drive layer between a calculator and the drives (notes 3.2 and 3.5).

* :class:`SteeringInverter`: the original's 180-degree inversion with hysteresis, per steered drive,
  made to respect ``str_lim`` (the original left that to the motor controller script).
* :func:`limit_wheel_speeds`: scales every wheel down together so the fastest one is within its
  motor's limit, which keeps the direction of motion (WPILib's desaturateWheelSpeeds).
* :class:`DriveLayer`: both, for all drives of a robot.
* :class:`SimulatedDrive`: the ``simple_sim`` drive: speed ramps at ``prp_sim_a``, steering slews
  at ``str_sim_v``, the wheel angle integrates.
"""

import math
from dataclasses import dataclass
from typing import List, Optional, Sequence, Tuple

from .odometry import normalize_angle
from .types import DriveCommand, DriveState

# The original's hysteresis thresholds [rad] (notes 3.2).
NEVER_INVERT_BELOW = math.pi / 8
INVERT_ABOVE = math.pi / 2
UNINVERT_BELOW = math.pi / 4
# [rad] (1 degree): a command this close to the INVERT_ABOVE threshold is not inverted. A crab from
# straight ahead asks every wheel for exactly 90 degrees of travel; with the original's strict test,
# encoder noise of either sign decided it wheel by wheel, so some wheels turned left and some right,
# scrubbing against each other (seen in the simulator as a false turn in odometry: 0.6 m of end point).
INVERT_TIE = math.radians(1.0)
MAX_SIM_DT = 0.5  # [s]: a longer step is a pause; the simulated drive does not move (the original's rule)


class SteeringInverter:
    """Decides, per steered drive, whether to point the wheel backwards and reverse its speed.

    The commanded angle p and the measured angle a are compared unwrapped: the steering travels
    linearly between -str_lim and +str_lim (its cable stops it), so |p - a| is the real travel.
    """

    def __init__(self, str_lim: float):
        self.str_lim = str_lim
        self.inverted = False

    def apply(self, command: DriveCommand, measured_steering: float) -> DriveCommand:
        p = command.steering
        a = measured_steering
        if abs(p) < NEVER_INVERT_BELOW:
            self.inverted = False
        elif abs(p - a) > INVERT_ABOVE + INVERT_TIE and not self.inverted:
            self.inverted = True
        elif abs(p - a) < UNINVERT_BELOW and self.inverted:
            self.inverted = False
        q = normalize_angle(p + math.pi) if self.inverted else p
        if abs(q) > self.str_lim:
            # Beyond the steering stop. The other way round is within it whenever str_lim >= pi/2,
            # and the hysteresis follows the way that was taken.
            other = normalize_angle(q + math.pi)
            if abs(other) <= self.str_lim:
                self.inverted = not self.inverted
                q = other
        speed = -command.speed if self.inverted else command.speed
        if abs(q) > self.str_lim:
            # str_lim < pi/2 and neither way is reachable: steer to the stop and drive only the part
            # of the speed that lies along the wheel (it cannot roll where it cannot point).
            limited = math.copysign(self.str_lim, q)
            speed *= math.cos(q - limited)
            q = limited
        return DriveCommand(q, speed)


def limit_wheel_speeds(
    commands: Sequence[DriveCommand], max_speeds: Sequence[float]
) -> Tuple[List[DriveCommand], float]:
    """The commands with all speeds scaled by one factor <= 1 so none exceeds its max [m/s]; and the factor."""
    scale = 1.0
    for c, limit in zip(commands, max_speeds):
        if abs(c.speed) * scale > limit:
            scale = limit / abs(c.speed)
    if scale == 1.0:
        return list(commands), 1.0
    return [DriveCommand(c.steering, c.speed * scale) for c in commands], scale


@dataclass(frozen=True)
class DriveLayerOutput:
    """Commands ready for the drives, and the factor [0..1] all wheel speeds were scaled by."""

    commands: Tuple[DriveCommand, ...]
    speed_scale: float


class DriveLayer:
    """Inversion and speed limits for all drives of a robot (thorvald_model Drive entries)."""

    def __init__(self, drives: Sequence, invert: bool = True):
        self.set_params(drives)
        self.invert = invert

    def set_params(self, drives: Sequence) -> None:
        old = getattr(self, "inverters", None)
        self.drives = tuple(drives)
        self.max_speeds = [d.max_wheel_speed for d in self.drives]
        self.inverters: List[Optional[SteeringInverter]] = []
        for k, d in enumerate(self.drives):
            if not d.steerable:
                self.inverters.append(None)
                continue
            inv = SteeringInverter(d.str_lim)
            if old is not None and k < len(old) and old[k] is not None:
                inv.inverted = old[k].inverted
            self.inverters.append(inv)

    def apply(self, commands: Sequence[DriveCommand], measured_steering: Sequence[float]) -> DriveLayerOutput:
        limited, scale = limit_wheel_speeds(commands, self.max_speeds)
        out = []
        for c, inv, a in zip(limited, self.inverters, measured_steering):
            if inv is None:
                out.append(DriveCommand(0.0, c.speed))
            elif self.invert:
                out.append(inv.apply(c, a))
            else:
                q = max(-inv.str_lim, min(inv.str_lim, c.steering))
                out.append(DriveCommand(q, c.speed * math.cos(c.steering - q)))
        return DriveLayerOutput(tuple(out), scale)


class SimulatedDrive:
    """One drive of ``simple_sim`` (notes 3.5); it takes the drive layer's commands.

    The original inverted inside simulateDrive too; here the drive layer inverts once, before the
    commands go to simulated or real drives alike.
    """

    def __init__(self, drive, state: Optional[DriveState] = None):
        self.drive = drive
        self.state = state or DriveState(0.0, 0.0, 0.0)
        self._last_time: Optional[float] = None

    def step(self, command: DriveCommand, time: float) -> DriveState:
        """Advances to time [s] towards command and returns the new state."""
        dt = 0.0 if self._last_time is None else time - self._last_time
        self._last_time = time
        if not 0.0 < dt <= MAX_SIM_DT:
            return self.state
        d = self.drive
        s = self.state
        dv = d.prp_sim_a * dt
        speed = s.speed + max(-dv, min(dv, command.speed - s.speed))
        steering = s.steering
        if d.steerable:
            target = max(-d.str_lim, min(d.str_lim, command.steering))
            da = d.str_sim_v * dt
            # Linear in angle, no wrap-around: the steering cannot pass through its stops.
            steering = s.steering + max(-da, min(da, target - s.steering))
        # Mean of the speeds before and after the step: exact while ramping (the original used the new speed).
        wheel = s.wheel_angle + 0.5 * (s.speed + speed) / d.r_wheel * dt
        self.state = DriveState(steering, speed, wheel)
        return self.state
