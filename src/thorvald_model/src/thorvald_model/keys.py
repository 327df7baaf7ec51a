"""The robot file's schema: its top-level keys and sections, read off the value types.

Each section is a mapping of entries ``<prefix>0``, ``<prefix>1``, ... whose keys are the fields of
the section's value type made with :func:`~thorvald_model.schema.key` (:mod:`thorvald_model.values`);
nothing here repeats a default, a rule or an alias.
"""

from dataclasses import dataclass
from typing import Tuple

from .schema import Key, keys_of
from .values import Battery, Beam, Corner, Drive, FramePart, IOBoard, PassiveWheel, Pipe, Suspension

# Top-level keys that robot files of users carry for their own xacro extras (LCAS sensor frames).
# They are kept verbatim in RobotConfig.extras, not validated, and not warned about.
PASSTHROUGH_KEYS = (
    "extras",
    "lidar_front",
    "lidar_back",
    "gnss_antenna_main",
    "gnss_antenna_aux",
    "imu",
    "cameras",
)

DRIVE_KEYS = keys_of(Drive)
RUNTIME_DRIVE_KEYS = tuple(k.name for k in DRIVE_KEYS if k.runtime)
"""Keys of ``motor_drives/driveN`` that set_drive_params may change while the robot runs."""

# The original's battery 'node' is deprecated (id = node - 344): read, never a field of its own.
DEPRECATED_BATTERY_NODE = Key("node", int, None)


@dataclass(frozen=True)
class Section:
    key: str  # top-level key, e.g. "motor_drives"
    prefix: str  # entry prefix, e.g. "drive"
    keys: Tuple[Key, ...]
    cls: type
    attr: str  # RobotConfig field


SECTIONS = (
    Section("motor_drives", "drive", DRIVE_KEYS, Drive, "drives"),
    Section("batteries", "bat", (*keys_of(Battery), DEPRECATED_BATTERY_NODE), Battery, "batteries"),
    Section("pipes", "pipe", keys_of(Pipe), Pipe, "pipes"),
    Section("corners", "corner", keys_of(Corner), Corner, "corners"),
    Section("beams", "beam", keys_of(Beam), Beam, "beams"),
    Section("io", "io", keys_of(IOBoard), IOBoard, "io"),
    Section("passive_wheels", "passive", keys_of(PassiveWheel), PassiveWheel, "passive_wheels"),
    Section("suspensions", "susp", keys_of(Suspension), Suspension, "suspensions"),
    Section("frame_parts", "part", keys_of(FramePart), FramePart, "frame_parts"),
)
SCHEMA_TOP_LEVEL_KEYS = ("base_calculator", *(s.key for s in SECTIONS))
TOP_LEVEL_KEYS = (*SCHEMA_TOP_LEVEL_KEYS, *PASSTHROUGH_KEYS)
