"""What base_driver says on /diagnostics, and which changes of the hardware link it logs, without ROS.

:func:`base_statuses` turns the handle's motor controllers, batteries and link counters into one
:class:`Status` each (diagnostic_msgs/DiagnosticStatus's fields: level, name, message, hardware id,
key/values), and odometry's estimate into one more (from every drive, degraded, blind); the node only
converts them to messages. :class:`LinkWatch` says what changed in the link since the last look (a bus
error, lost devices, a wrong script), and :class:`OdometryWatch` what changed in odometry's drives, for
the node to log once.
"""

from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple

from .bases import BatteryInfo, ControllerInfo
from .kinematics import OdometryResult
from .modes import BATTERY_LOST, MODE_LOST_CONNECTION

# diagnostic_msgs/DiagnosticStatus levels (a unit test holds them against the message)
OK = 0
WARN = 1
ERROR = 2

LOST = "wheels stopped: lost"  # the link's key of the devices heard, then silent past their timeout
NOT_HEARD_YET = "wheels stopped: not heard since start"  # and of those never heard since base_driver started
PATIENCE = 5  # looks (a second apart) a device may stay unheard since start before it is logged


@dataclass(frozen=True)
class Status:
    """One diagnostic_msgs/DiagnosticStatus."""

    name: str
    hardware_id: str
    level: int  # OK, WARN or ERROR
    message: str
    values: Tuple[Tuple[str, str], ...] = ()


def odometry_sentence(odometry: OdometryResult, names: Sequence[str]) -> Tuple[int, str]:
    """(level, message) of what odometry rests on: every drive (OK), the drives heard when some are
    unheard (WARN: degraded), or too few to tell the motion (ERROR: blind, the wheels stopped)."""
    if not odometry.unheard:
        return OK, "from every drive"
    unheard = ", ".join(names[k] if k < len(names) else str(k) for k in odometry.unheard)
    heard = len(names) - len(odometry.unheard)
    if odometry.blind:
        what = (
            f"the estimate is the {heard} heard drive(s)' speed along the last commanded motion"
            if heard
            else "no drive heard: zero twist, the pose held"
        )
        return ERROR, f"blind ({unheard} unheard): the wheels are stopped; {what}"
    return WARN, f"degraded: from {heard} of {len(names)} drives ({unheard} unheard)"


def base_statuses(
    namespace: str,
    controllers: Sequence[ControllerInfo],
    batteries: Sequence[BatteryInfo],
    link: Dict[str, str],
    *,
    odometry: Optional[OdometryResult] = None,
    drive_names: Sequence[str] = (),
) -> List[Status]:
    """One status per motor controller and battery, one for the hardware link when there is one, and
    one for odometry when it is given (what its estimate rests on, odometry_sentence).

    A lost controller or battery is an error; a controller's status flag or a battery's alarm is a
    warning; a closed bus, lost devices or a wrong script make the link an error. Names start with
    ``base_driver (<namespace>): `` so a fleet's statuses stay apart.
    """
    prefix = f"base_driver ({namespace}): " if namespace else "base_driver: "
    statuses = []
    if odometry is not None:
        level, message = odometry_sentence(odometry, drive_names)
        heard = len(drive_names) - len(odometry.unheard)
        values = (("drives heard", f"{heard} of {len(drive_names)}"), ("residual", f"{odometry.residual:.4f} m/s"))
        statuses.append(Status(f"{prefix}odometry", "odometry", level, message, values))
    for c in controllers:
        lost = c.mode == MODE_LOST_CONNECTION
        flags = [name for name, on in c.status_flags if on]
        level = ERROR if lost else (WARN if flags else OK)
        message = "lost connection" if lost else (", ".join(flags) if flags else "ok")
        values = (("mode", str(c.mode)), ("battery volts", f"{c.battery_volts:.1f}"), ("version", c.version))
        statuses.append(Status(f"{prefix}motor controller {c.name}", f"node {c.can_id}", level, message, values))
    for b in batteries:
        lost = b.state == BATTERY_LOST
        level = ERROR if lost else (WARN if b.alarms else OK)
        message = "lost connection" if lost else (", ".join(b.alarms) if b.alarms else "ok")
        values = (("voltage", f"{b.voltage:.2f}"), ("state of charge", f"{b.state_of_charge:.0f} %"))
        statuses.append(Status(f"{prefix}battery {b.id}", f"battery {b.id}", level, message, values))
    if link:
        failing = "closed" in link.get("bus", "") or link.get(LOST) or link.get("wrong script")
        level = ERROR if failing else (WARN if link.get(NOT_HEARD_YET) else OK)
        statuses.append(Status(f"{prefix}CAN bus", "can", level, link.get("bus", ""), tuple(link.items())))
    return statuses


class OdometryWatch:
    """The log line a change of what odometry rests on deserves, said once when it changes; nothing
    before every drive has been heard once (a base starting up hears its drives one by one)."""

    def __init__(self, drive_names: Sequence[str]):
        self.names = list(drive_names)
        self._seen: Optional[Tuple[Tuple[int, ...], bool]] = None

    def change(self, odometry: OdometryResult) -> Optional[Tuple[int, str]]:
        """(level, sentence) when the drives unheard or blindness changed since the last call; else None."""
        now = (odometry.unheard, odometry.blind)
        if self._seen is None and odometry.unheard:
            return None
        if self._seen is None or now == self._seen:
            self._seen = now
            return None
        self._seen = now
        level, message = odometry_sentence(odometry, self.names)
        return level, "odometry " + (message if odometry.unheard else "from every drive again")


class LinkWatch:
    """The warnings a change of the hardware link deserves, each said once when it changes."""

    WATCHED = ("last error", LOST, "wrong script")

    def __init__(self):
        self._seen: Dict[str, Optional[str]] = {}
        self._unheard_looks = 0  # consecutive looks with devices not heard since start

    def changes(self, link: Dict[str, str]) -> List[str]:
        """The lines to log for this look at the link (one a second). Devices not heard since start are
        normal for the first moments (their first reports are on their way): said only when they stay
        unheard for PATIENCE looks."""
        out = []
        for key in self.WATCHED:
            value = link.get(key)
            if value and value != self._seen.get(key):
                out.append(f"CAN: {key}: {value}")
            if value is None and self._seen.get(key) and key == LOST:
                out.append("CAN: every device heard again: the wheels follow commands")
            self._seen[key] = value
        unheard = link.get(NOT_HEARD_YET)
        self._unheard_looks = self._unheard_looks + 1 if unheard else 0
        if self._unheard_looks == PATIENCE:
            out.append(
                f"CAN: {NOT_HEARD_YET}: {unheard} (check each controller's node id in the robot file, its power "
                "and the bus's wiring and termination)"
            )
        return out


__all__ = [
    "ERROR",
    "LOST",
    "NOT_HEARD_YET",
    "OK",
    "PATIENCE",
    "WARN",
    "LinkWatch",
    "OdometryWatch",
    "Status",
    "base_statuses",
    "odometry_sentence",
]
