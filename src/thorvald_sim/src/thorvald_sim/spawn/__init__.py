"""Spawning: the ``spawn_robot`` and ``spawn_model`` program (``spawn_robot``), its arguments
(``args``) and the names a robot is spawned under (``names``, which the simulator's spawn service
checks too)."""
