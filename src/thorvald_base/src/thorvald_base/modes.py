"""The modes and states base_driver reports, once, for the pure core (no messages imported).

Drive and controller modes are thorvald_msgs/BaseState's ``MODE_*`` values (BaseState.drive_mode,
Controller.controller_mode) and the mode numbers the motor controllers take in RxPDO3; only -99 is
the original's known number (reference notes, section 8), the others are ours. Battery states are
BatteryData.battery_state. A unit test holds these against the message definitions.
"""

MODE_DRIVE = 0
MODE_HOME = 1
MODE_DECOUPLED = 2
MODE_ONLINE = 3
MODE_LOST_CONNECTION = 4
MODE_PRE_INITIATION = -99

BATTERY_OK = 0
BATTERY_ALARM = 1
BATTERY_LOST = 2
