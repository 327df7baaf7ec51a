"""A pybullet world with its robots and its clock, without ROS (the simulator node wraps it).

The pybullet client is passed in (``pybullet.connect(pybullet.DIRECT)`` or ``GUI``); this module
never connects. Time is the simulated time [s], advanced by one physics step of 1 / physics_rate.
"""

import time
from dataclasses import dataclass
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from thorvald_model.errors import UrdfCheckError

from ..bullet import pybullet as p
from ..errors import SpawnError
from ..sensors.blocks import Datum
from ..sensors.mounted import build_sensors, disabled_report, sensor_report
from ..world import WorldConfig
from .as_built import SimAsBuilt
from .description import DescriptionError, MeshFinder, installed_package_path, mesh_finder, spawned_description
from .presets import PRESETS
from .robot import TYRE_CONTACT_WIDTH, Pose2D, SimRobot
from .scene import build_scene

SOLVER_ITERATIONS = PRESETS["default"].solver_iterations  # pybullet's default, set explicitly


@dataclass(frozen=True)
class Camera:
    """A camera pose for snapshots: from eye [m] towards target [m], z up."""

    eye: Tuple[float, float, float] = (6.0, -6.0, 5.0)
    target: Tuple[float, float, float] = (0.0, 0.0, 0.3)
    width: int = 960  # [px]
    height: int = 640  # [px]
    fov: float = 50.0  # vertical field of view [deg]


class Simulation:
    def __init__(
        self,
        client: int,
        world: WorldConfig,
        physics_rate: float = 240.0,
        tyre_contact_width: float = TYRE_CONTACT_WIDTH,
        find_mesh: Optional[MeshFinder] = None,
        *,
        seed: int = 0,
        datum: Optional[Datum] = None,
        solver_iterations: int = SOLVER_ITERATIONS,
    ):
        if not physics_rate > 0:
            raise ValueError(f"physics_rate: {physics_rate!r}: must be > 0 [Hz]")
        if isinstance(solver_iterations, bool) or not (isinstance(solver_iterations, int) and solver_iterations >= 1):
            raise ValueError(f"solver_iterations: {solver_iterations!r}: must be a whole number >= 1")
        if not tyre_contact_width > 0.0:
            raise ValueError(f"tyre_contact_width: {tyre_contact_width!r}: must be > 0 [m]")
        self.tyre_contact_width = tyre_contact_width
        self.seed = seed  # of every sensor's noise
        self.datum = datum  # the GNSS reference of robots whose description gives none
        self.world = world
        self.find_mesh = find_mesh or mesh_finder(installed_package_path)
        self.client = client
        self.dt = 1.0 / physics_rate
        self.solver_iterations = solver_iterations
        p.setPhysicsEngineParameter(
            fixedTimeStep=self.dt, numSolverIterations=solver_iterations, physicsClientId=client
        )
        self.scene = build_scene(client, world)
        self.gravity = (0.0, 0.0, -world.gravity)  # [m/s^2] as the scene set it (the Gazebo API may change it)
        self.robots: Dict[str, SimRobot] = {}
        self.time = 0.0  # [s] simulated
        self.steps = 0
        self.solver_cpu = 0.0  # [s] of this thread's CPU time spent in pybullet's stepSimulation, all steps

    def spawn(self, name: str, urdf: str, pose: Pose2D, as_built: Optional[SimAsBuilt] = None) -> SimRobot:
        """Loads a robot; SpawnError (the world unchanged) if the name is taken or the URDF unusable.

        Mesh files are resolved first; the elements whose mesh cannot be found are left out and
        listed in the robot's ``missing_meshes``, for the caller to say so. The description's Gazebo
        sensor blocks become the robot's ``sensors`` (:mod:`thorvald_sim.sensors.mounted`); what is not
        simulated and what is refused is in ``sensor_blocks`` and ``sensor_problems``, for the
        caller to say so too. The robot spawns whatever its sensor blocks hold. as_built: the robot
        as built (:mod:`thorvald_sim.physics.as_built`), None for as configured.

        The description may come from any generator (``spawn_robot -file``): before pybullet sees it,
        its link references are read as tf2 reads them (``/base_link`` is ``base_link``,
        ``thorvald_001//base_link`` is ``thorvald_001/base_link``) and it is checked as check_urdf
        would (:mod:`thorvald_model.urdf_check`), so a broken tree is refused naming each joint, the
        link that does not exist and the closest existing names, not with pybullet's "Cannot load URDF
        file.".
        """
        if not name:
            raise SpawnError("a robot needs a name")
        if name in self.robots:
            raise SpawnError(f"a robot named {name!r} exists already")
        try:
            spawned = spawned_description(urdf, name)  # parsed once: everything below reads this
        except UrdfCheckError as e:
            raise SpawnError(str(e)) from None  # "NAME: invalid robot description (...)", each line naming NAME
        except DescriptionError as e:
            raise SpawnError(f"{name}: {e}") from None
        description = spawned.robot
        try:
            tree, missing = spawned.for_pybullet(self.find_mesh)
            robot = SimRobot(
                self.client,
                name,
                description,
                tree,
                pose,
                tyre_contact_width=self.tyre_contact_width,
                as_built=as_built,
            )
        except DescriptionError as e:
            raise SpawnError(f"{name}: {e}") from None
        robot.missing_meshes = missing
        robot.sensor_blocks = spawned.sensor_blocks
        robot.sensors, robot.sensor_problems = build_sensors(
            spawned.sensor_blocks.sensors,
            robot,
            spawned.links,
            seed=self.seed,
            dt=self.dt,
            gravity=self.world.gravity,
            datum=description.datum or self.datum,
        )
        if self.gravity != (0.0, 0.0, -self.world.gravity):
            for sensor in robot.sensors:
                sensor.world_gravity(self.gravity)
        self.robots[name] = robot
        return robot

    def set_gravity(self, gravity: Tuple[float, float, float]) -> None:
        """The world's gravity [m/s^2, world axes] from now on (the Gazebo API's set_physics_properties),
        for the physics and every sensor that reads it."""
        p.setGravity(*gravity, physicsClientId=self.client)
        self.gravity = tuple(float(v) for v in gravity)
        for robot in self.robots.values():
            for sensor in robot.sensors:
                sensor.world_gravity(self.gravity)

    def delete(self, name: str) -> None:
        robot = self.robots.pop(name, None)
        if robot is None:
            raise SpawnError(f"no robot named {name!r}; robots: {', '.join(sorted(self.robots)) or 'none'}")
        robot.remove()

    def step(self) -> None:
        """One physics step of dt: the wheels' ramps and the suspensions' springs, then the solver."""
        for robot in self.robots.values():
            robot.before_step(self.dt)
        # the thread's CPU clock (0.2 us a read): what the solver costs here, beside whatever else runs
        start = time.thread_time()
        p.stepSimulation(physicsClientId=self.client)
        self.solver_cpu += time.thread_time() - start
        self.steps += 1
        self.time = self.steps * self.dt

    def reset(self) -> None:
        """Every robot back to its spawn pose, at rest. Time keeps running (nodes dislike a clock that jumps back)."""
        for robot in self.robots.values():
            robot.reset()

    def render(self, camera: Camera = Camera()):
        """An RGB image (numpy uint8, height x width x 3) from pybullet's software renderer: no display needed."""
        view = p.computeViewMatrix(camera.eye, camera.target, (0.0, 0.0, 1.0), physicsClientId=self.client)
        projection = p.computeProjectionMatrixFOV(
            camera.fov, camera.width / camera.height, 0.05, 100.0, physicsClientId=self.client
        )
        _, _, rgba, _, _ = p.getCameraImage(
            camera.width,
            camera.height,
            view,
            projection,
            renderer=p.ER_TINY_RENDERER,
            shadow=1,
            lightDirection=(2.0, -1.0, 4.0),
            physicsClientId=self.client,
        )
        return np.asarray(rgba, dtype=np.uint8).reshape(camera.height, camera.width, 4)[:, :, :3]


def save_png(image, path: str) -> None:
    """Writes an RGB image (numpy, height x width x 3) as PNG."""
    from PIL import Image  # noqa: PLC0415  (only when a snapshot is taken)

    Image.fromarray(image, "RGB").save(path)


@dataclass(frozen=True)
class Performance:
    """How the simulation ran over a window of wall time."""

    wall: float  # [s] the window's length
    simulated: float  # [s] simulated time that passed in it
    cpu: float  # [s] the simulator process's CPU time in it (every thread)
    solver_cpu: float  # [s] of that spent in pybullet's solver

    @property
    def real_time_factor(self) -> float:
        return self.simulated / self.wall if self.wall > 0 else 0.0

    def per_simulated_second(self, seconds: float) -> float:
        """A CPU time [s] of the window per simulated second (0 when time stood still)."""
        return seconds / self.simulated if self.simulated > 0 else 0.0


class PerformanceMeter:
    """Cuts the simulator's run into windows of at least period [s] of wall time and measures each."""

    def __init__(self, period: float = 1.0):
        self.period = period
        self._start = None  # (wall, simulated, cpu, solver cpu) at the window's start

    def due(self, wall: float) -> bool:
        """Whether a sample at wall [s] would end a window (or start the first): the caller reads its
        clocks only then."""
        return self._start is None or wall - self._start[0] >= self.period

    def sample(self, wall: float, simulated: float, cpu: float, solver_cpu: float) -> Optional[Performance]:
        """The Performance of the window that ends here, or None while it is shorter than period."""
        now = (wall, simulated, cpu, solver_cpu)
        if self._start is None:
            self._start = now
            return None
        if not self.due(wall):
            return None
        start, self._start = self._start, now
        return Performance(*(b - a for a, b in zip(start, now)))


def performance_report(
    perf: Performance, *, robots: int, asked: float, paused: bool, physics_rate: float, simulated_now: float
) -> Tuple[int, str, Dict[str, str]]:
    """(level, message, values) of the simulator's /diagnostics for a window: the real-time factor
    reached, and the process's CPU time per simulated second, all of it and pybullet's solver's part (the
    rest is ROS and Python: messages in and out, the loop). A warning (level 1) when a real-time factor
    asked for is not held (below 90 %); asked 0: as fast as possible."""
    rtf = perf.real_time_factor
    level = 0
    if paused:
        message = "paused"
    else:
        message = f"{robots} robot{'' if robots == 1 else 's'}, {rtf:.2f} x real time"
        if asked and rtf < 0.9 * asked:
            level = 1
            message += f" (asked for {asked:g} x: the machine cannot keep up)"
    values = {
        "robots": str(robots),
        "simulated time [s]": f"{simulated_now:.3f}",
        "real-time factor": f"{rtf:.3f}",
        "real-time factor asked": f"{asked:g}" if asked else "as fast as possible",
        "physics rate [Hz]": f"{physics_rate:g}",
        "CPU per simulated second [s]": f"{perf.per_simulated_second(perf.cpu):.5f}",
        "solver CPU per simulated second [s]": f"{perf.per_simulated_second(perf.solver_cpu):.5f}",
        "CPU share [cores]": f"{perf.cpu / perf.wall:.3f}",
    }
    return level, message, values


Status = Tuple[str, str, int, str, Dict[str, str]]  # diagnostic_msgs/DiagnosticStatus: name, hardware id, level, ...


def simulator_statuses(
    node: str,
    perf: Performance,
    *,
    asked: float,
    paused: bool,
    physics_rate: float,
    simulated_now: float,
    preset: str,
    solver_iterations: int,
    workers: int,
    physics: Sequence[Status] = (),
    sensors: Sequence[Tuple[str, list]] = (),
    disabled: Sequence[Tuple[str, object]] = (),
    robots: int = 0,
) -> List[Status]:
    """The simulator node's /diagnostics for a window of wall time: the simulation's
    (:func:`performance_report`, its physics preset and workers), the physics' own statuses (a worker
    pool's), each robot's sensors' (sensors: (robot, SensorUse list),
    :func:`thorvald_sim.sensors.mounted.sensor_report`) and one per sensor a robot goes without
    (disabled: (robot, DisabledSensor)). workers: 0 when the node's own client steps the robots."""
    level, message, values = performance_report(
        perf, robots=robots, asked=asked, paused=paused, physics_rate=physics_rate, simulated_now=simulated_now
    )
    values["physics preset"] = preset
    values["solver iterations"] = str(solver_iterations)
    if workers:
        values["physics workers"] = str(workers)
        values["CPU"] = "the node's and its physics workers' processes"
    out: List[Status] = [(f"{node}: simulation", "pybullet", level, message, values), *physics]
    out += [
        (f"{node}: sensors of {name}", name, *sensor_report(uses, perf.simulated, physics_rate, asked))
        for name, uses in sensors
    ]
    out += [
        (f"{node}: sensor {sensor.name} of {name}", name, *disabled_report(name, sensor)) for name, sensor in disabled
    ]
    return out
