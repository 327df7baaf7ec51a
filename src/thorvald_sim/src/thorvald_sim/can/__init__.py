"""The CAN device emulator: a robot's devices (``emulator``) on an SLCAN hub of pseudo-terminals
(``hub``), started by ``rosrun thorvald_sim can_emulator`` (``emulator_node``)."""
