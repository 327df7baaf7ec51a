"""What base_driver says on /diagnostics, and which changes of the hardware link it logs, without ROS.

:func:`base_statuses` turns the handle's motor controllers, batteries and link counters into one
:class:`Status` each (diagnostic_msgs/DiagnosticStatus's fields: level, name, message, hardware id,
key/values); the node only converts them to messages. :class:`LinkWatch` says what changed in the
link since the last look (a bus error, lost devices, a wrong script), for the node to log once.
"""

from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple

from .bases import BatteryInfo, ControllerInfo
from .modes import BATTERY_LOST, MODE_LOST_CONNECTION

# diagnostic_msgs/DiagnosticStatus levels (a unit test holds them against the message)
OK = 0
WARN = 1
ERROR = 2


@dataclass(frozen=True)
class Status:
    """One diagnostic_msgs/DiagnosticStatus."""

    name: str
    hardware_id: str
    level: int  # OK, WARN or ERROR
    message: str
    values: Tuple[Tuple[str, str], ...] = ()


def base_statuses(
    namespace: str,
    controllers: Sequence[ControllerInfo],
    batteries: Sequence[BatteryInfo],
    link: Dict[str, str],
) -> List[Status]:
    """One status per motor controller and battery, one for the hardware link when there is one.

    A lost controller or battery is an error; a controller's status flag or a battery's alarm is a
    warning; a closed bus, lost devices or a wrong script make the link an error. Names start with
    ``base_driver (<namespace>): `` so a fleet's statuses stay apart.
    """
    prefix = f"base_driver ({namespace}): " if namespace else "base_driver: "
    statuses = []
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
        failing = "closed" in link.get("bus", "") or link.get("wheels stopped: lost") or link.get("wrong script")
        level = ERROR if failing else OK
        statuses.append(Status(f"{prefix}CAN bus", "can", level, link.get("bus", ""), tuple(link.items())))
    return statuses


class LinkWatch:
    """The warnings a change of the hardware link deserves, each said once when it changes."""

    WATCHED = ("last error", "wheels stopped: lost", "wrong script")

    def __init__(self):
        self._seen: Dict[str, Optional[str]] = {}

    def changes(self, link: Dict[str, str]) -> List[str]:
        out = []
        for key in self.WATCHED:
            value = link.get(key)
            if value and value != self._seen.get(key):
                out.append(f"CAN: {key}: {value}")
            if value is None and self._seen.get(key) and key == "wheels stopped: lost":
                out.append("CAN: every device heard again: the wheels follow commands")
            self._seen[key] = value
        return out


__all__ = ["ERROR", "OK", "WARN", "LinkWatch", "Status", "base_statuses"]
