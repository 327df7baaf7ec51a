"""Hardware-independent joystick teleoperation of a Thorvald robot."""
