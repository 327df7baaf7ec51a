"""The simulator node's private parameters, read once into one frozen value.

:meth:`SimulatorParams.read` takes a getter (``name, default -> value``: the node passes
``rospy.get_param("~" + name, default)``), checks every parameter against its rule and raises
:class:`~thorvald_sim.errors.ParameterError` naming the parameter, the value and the rule. The node
reads nothing else from the parameter server; everything after the start works on this value.
The parameters, their defaults and what each means:

========================  ================================================================
``~world``                a shipped world's name (``flat``, ``tarmac_gravel``, ``slope``,
                          ``greenhouse``) or a world file (default ``flat``)
``~gui``                  open pybullet's window (default false: headless)
``~physics``              the physics preset (:mod:`thorvald_sim.physics.presets`): ``default`` (240 Hz,
                          50 solver iterations) or ``fleet`` (120 Hz, 50: about half the CPU
                          per robot)
``~physics_rate``         physics steps per simulated second [Hz] (the preset's)
``~solver_iterations``    pybullet's solver iterations per step (the preset's)
``~real_time_factor``     simulated seconds per wall second (1; a Gazebo world's pace when not set); 0
                          runs as fast as it can
``~clock_rate``           /clock messages per simulated second [Hz] (80: every third step at 240 Hz
                          physics; at most one a step)
``~odometry_rate``        odometry/gazebo and joint_states per simulated second [Hz] (50)
``~drive_state_rate``     drive_states per simulated second [Hz] (80)
``~drive_current_rate``   drive_currents per simulated second [Hz] (10: base_driver reports them at
                          1 Hz; in lockstep they go with every drive_states, for the torque balance)
``~command_timeout``      a robot whose commands stop for this long [s] stops its wheels (0.5)
``~max_lag``              the simulator waits for a robot whose commands lag more than this behind
                          simulated time [s] (0.05; 0: never): a busy machine slows the
                          simulation instead of letting robots drive on stale commands
``~publish_tf``           default for robots: tf odom -> base_link from ground truth (true, as
                          the Gazebo plugin's users had it; spawn_robot's -no_publish_tf or
                          -publish_tf choose per robot)
``~tyre_contact_width``   width of the wheels' collision discs [m] (0.01; see physics/robot.py)
``~paused``               start paused (false)
``~diagnostics_rate``     /diagnostics per wall second [Hz] (1; 0: none): the real-time factor
                          reached and the CPU the simulation costs (see ``publish_performance``),
                          and per robot what each sensor read costs
``~seed``                 seed of every sensor's noise (0): the same seed repeats a run's noise
``~datum_file``           a robot_localization datum file: the GNSS reference of robots whose
                          description has neither a reference nor a datum of its own (none)
``~lockstep``             advance only when every robot's driver has answered the last instant's
                          drive states with its command (false; see below)
``~physics_workers``      pybullet clients stepping the robots, each in a process of its own (1: the
                          node's own client, as ever; 2..16: see below; 1 with ``~gui``)
``~worker_strips``        with physics workers: the x [m] between each two workers' strips (N - 1
                          increasing numbers, a list or a text "9 18"); a robot goes to the worker
                          of its spawn x's strip (none: to the worker with the fewest robots)
``~gazebo_namespace``     where Gazebo's ROS API is offered (/gazebo; spawn_model's
                          ``-gazebo_namespace``): docs/coming-from-gazebo.md
``~gazebo_states_rate``   ``model_states`` and ``link_states`` per simulated second, while
                          subscribed [Hz] (50: ground truth's rate; 0: after every physics step,
                          as Gazebo publishes them with every world update)
========================  ================================================================

Pure: no rospy.
"""

import math
from dataclasses import dataclass, replace
from typing import Any, Callable, Tuple

from ..errors import ParameterError
from ..physics.presets import MAX_WORKERS, PRESETS, physics_settings

Getter = Callable[[str, Any], Any]


@dataclass(frozen=True)
class SimulatorParams:
    world: str = "flat"
    gui: bool = False
    physics: str = "default"  # the preset (thorvald_sim.physics.presets.PRESETS)
    physics_rate: float = PRESETS["default"].rate  # [Hz]; read: the preset's unless given
    solver_iterations: int = PRESETS["default"].solver_iterations  # read: the preset's unless given
    real_time_factor: float = 1.0  # 0: as fast as the machine can
    clock_rate: float = 80.0  # [Hz] of simulated time: every third step at 240 Hz physics
    odometry_rate: float = 50.0  # [Hz]
    drive_state_rate: float = 80.0  # [Hz]
    drive_current_rate: float = 10.0  # [Hz]; in lockstep: with every drive_states
    command_timeout: float = 0.5  # [s]
    max_lag: float = 0.05  # [s]; 0: never wait for a lagging robot
    publish_tf: bool = True
    tyre_contact_width: float = 0.01  # [m]
    paused: bool = False
    diagnostics_rate: float = 1.0  # [Hz] of wall time; 0: none
    seed: int = 0
    datum_file: str = ""
    lockstep: bool = False
    physics_workers: int = 1  # 1: the node's own pybullet client; N >= 2: N worker processes (physics.workers)
    worker_strips: Tuple[float, ...] = ()  # [m] N - 1 increasing x: worker k takes spawn x in its strip
    gazebo_namespace: str = "/gazebo"  # where Gazebo's ROS API is offered (thorvald_sim.gazebo.api)
    gazebo_states_rate: float = 50.0  # [Hz] of model_states and link_states; 0: every physics step

    def paced_by(self, world, given: bool) -> "SimulatorParams":
        """These parameters with a Gazebo world's pace (``WorldConfig.real_time_factor``: its physics'
        steps a second times their size) as the real-time factor, unless ``~real_time_factor`` was given."""
        if world.real_time_factor is None or given:
            return self
        return replace(self, real_time_factor=world.real_time_factor)

    @classmethod
    def read(cls, get: Getter) -> "SimulatorParams":
        """Every parameter through get (name, default), checked; ParameterError at the first broken one."""
        d = cls()
        seed = get("seed", d.seed)
        if isinstance(seed, bool) or not isinstance(seed, int):
            raise ParameterError(f"~seed: {seed!r}: must be a whole number")
        gui = bool(get("gui", d.gui))
        workers = get("physics_workers", d.physics_workers)
        if isinstance(workers, bool) or not isinstance(workers, int) or not 1 <= workers <= MAX_WORKERS:
            raise ParameterError(f"~physics_workers: {workers!r}: must be a whole number in 1..{MAX_WORKERS}")
        if gui and workers > 1:
            raise ParameterError(
                f"~physics_workers: {workers!r}: must be 1 with ~gui true (pybullet's window shows one client's world)"
            )
        strips = _strips(get("worker_strips", d.worker_strips), workers)
        physics = get("physics", d.physics)
        try:  # unset: the preset's
            preset = physics_settings(physics, None, get("solver_iterations", None))
        except ValueError as e:
            raise ParameterError(f"~{e}") from None
        return cls(
            world=str(get("world", d.world)),
            gui=gui,
            physics=physics,
            physics_rate=_number(get, "physics_rate", preset.rate),
            solver_iterations=preset.solver_iterations,
            real_time_factor=_number(get, "real_time_factor", d.real_time_factor, allow_zero=True),
            clock_rate=_number(get, "clock_rate", d.clock_rate),
            odometry_rate=_number(get, "odometry_rate", d.odometry_rate),
            drive_state_rate=_number(get, "drive_state_rate", d.drive_state_rate),
            drive_current_rate=_number(get, "drive_current_rate", d.drive_current_rate),
            command_timeout=_number(get, "command_timeout", d.command_timeout),
            max_lag=_number(get, "max_lag", d.max_lag, allow_zero=True),
            publish_tf=bool(get("publish_tf", d.publish_tf)),
            tyre_contact_width=_number(get, "tyre_contact_width", d.tyre_contact_width),
            paused=bool(get("paused", d.paused)),
            diagnostics_rate=_number(get, "diagnostics_rate", d.diagnostics_rate, allow_zero=True),
            seed=seed,
            datum_file=str(get("datum_file", d.datum_file) or ""),
            lockstep=bool(get("lockstep", d.lockstep)),
            physics_workers=workers,
            worker_strips=strips,
            gazebo_namespace=_namespace(get("gazebo_namespace", d.gazebo_namespace)),
            gazebo_states_rate=_number(get, "gazebo_states_rate", d.gazebo_states_rate, allow_zero=True),
        )


def _namespace(value: Any) -> str:
    """~gazebo_namespace: a global ROS name (``/gazebo``), as gazebo_ros's ``-gazebo_namespace`` is."""
    import rosgraph.names  # noqa: PLC0415  (ROS's name rules; not the ROS runtime)

    text = value if isinstance(value, str) else ""
    if not text.startswith("/") or not rosgraph.names.is_legal_name(text):
        raise ParameterError(
            f"~gazebo_namespace: {value!r}: must be a global ROS name, as /gazebo (a / first, then letters, "
            "digits, underscores and slashes)"
        )
    return text


def _number(get: Getter, name: str, default: float, allow_zero: bool = False) -> float:
    value = get(name, default)
    if isinstance(value, bool):
        raise ParameterError(f"~{name}: {value!r}: must be a number")
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ParameterError(f"~{name}: {value!r}: must be a number") from None
    if not math.isfinite(number) or number < 0 or (number == 0 and not allow_zero):
        raise ParameterError(f"~{name}: {value!r}: must be {'>= 0' if allow_zero else '> 0'}")
    return number


def _strips(value: Any, workers: int) -> Tuple[float, ...]:
    """~worker_strips: a list of numbers, one number, or a text of numbers apart by spaces or commas
    (roslaunch gives a launch argument's "9 18" as text); none, or workers - 1 increasing and finite."""
    rule = f"must be none or {workers - 1} increasing x [m] (one between each two of ~physics_workers' strips)"
    items = value
    if isinstance(value, str):
        items = value.replace(",", " ").split()
    elif isinstance(value, (int, float)) and not isinstance(value, bool):
        items = [value]
    try:
        strips = tuple(float(x) for x in items if not isinstance(x, bool))
    except (TypeError, ValueError):
        raise ParameterError(f"~worker_strips: {value!r}: {rule}") from None
    if len(strips) != len(items) or not all(math.isfinite(x) for x in strips):
        raise ParameterError(f"~worker_strips: {value!r}: {rule}")
    if strips and (len(strips) != workers - 1 or any(b <= a for a, b in zip(strips, strips[1:]))):
        raise ParameterError(f"~worker_strips: {value!r}: {rule}")
    return strips
