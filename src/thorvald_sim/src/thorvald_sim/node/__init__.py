"""The ``simulator`` node: its wiring (``simulator``), its parameters (``params``), each robot's topics
and its commands (``robot_io``, ``commands``), the sensors' topics (``sensor_io``), the services
(``services``), who else publishes ``/tf`` (``tf_watch``), real-time pacing (``pacing``) and
lockstep with base drivers (``lockstep``)."""
