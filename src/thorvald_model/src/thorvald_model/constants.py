"""Names and codes of the robot configuration file shared by the loader and the layout rules."""

STD_CALCULATOR = "pltf_clc_std::PltfClcStd"
"""The standard calculator: any number of steered drives, mixed with wheels that cannot steer."""
DIFF_CALCULATOR = "pltf_clc_2wdiff::PltfClc2WDiff"
"""Two type-1 drives on one axle (differential drive)."""
ONE_WHEEL_CALCULATOR = "pltf_clc_1wd::PltfClc1WD"
"""One steered drive supported by fixed passive wheels."""

DRIVE_STEERED = 0
"""Drive type 0: propulsion + steering module (one motor controller per drive)."""
DRIVE_DIFF = 1
"""Drive type 1: propulsion only, rolling along base_link x; two share one dual-channel controller."""

IO_MAIN_BOARD = 0
"""IO board type 0: the main enclosure PCB (1: sister enclosure PCB, 2: UV lamp board)."""

BATTERY_EMPTY = 0
"""Battery type 0: an empty battery enclosure."""
BATTERY_KC = 1
"""Battery type 1: a KC Electronics battery on the CAN bus."""
