"""The one physics interface the simulator node drives: a world that steps and reads what is asked.

Before each step the node says what is due to be read of each robot after it (:class:`Reads`: drive
states, currents, odometry, the passive joints, the sensors that have readers). The physics applies
each robot's queued command, steps, and reads at the instant after the step what was asked
(:meth:`Engine.step`); the node publishes from what was read, through each robot's
:class:`RobotProxy`. Two physics offer it, with the same methods and the same readings to the bit:

* :class:`LocalPhysics`: one :class:`Engine` in the node's own process (its client may be pybullet's
  GUI);
* :class:`thorvald_sim.physics.workers.WorkerPool`: an Engine in each of N worker processes, each with its
  share of the robots, stepping at the same time.

The sensors' schedule is one, :func:`thorvald_sim.sensors.mounted.read_due`: a sensor without readers
pauses, one with readers is read when due, a failure comes back as its text.

No ROS here: the node converts messages. pybullet only in the Engine (a worker's or the node's).
"""

import math
import time
from dataclasses import dataclass
from typing import Any, Dict, List, NamedTuple, Optional, Sequence, Tuple

from ..errors import SpawnError
from ..gazebo.bodies import GazeboBodies
from ..sensors.mounted import read_due
from .robot import TYRE_CONTACT_WIDTH, Pose2D
from .simulation import SOLVER_ITERATIONS, Camera, Simulation


@dataclass(frozen=True)
class WorldSettings:
    """What an Engine builds its Simulation from: the node's world and physics parameters."""

    world: Any  # thorvald_sim.world.WorldConfig
    physics_rate: float = 240.0
    tyre_contact_width: float = TYRE_CONTACT_WIDTH
    seed: int = 0
    datum: Any = None  # thorvald_sim.sensors.blocks.Datum
    solver_iterations: int = SOLVER_ITERATIONS


class Reads(NamedTuple):
    """What of one robot is read after a step: drive states, drive currents, odometry (pose and
    twist), the passive joints' states, and the indices of its sensors that have readers."""

    states: bool = False
    currents: bool = False
    odometry: bool = False
    joints: bool = False
    sensors: Tuple[int, ...] = ()


EVERYTHING = Reads(True, True, True, True)
NOTHING = Reads()


# ---------------------------------------------------------------------------------------------
# The world's side: an Engine (in a worker process, or the node's)
# ---------------------------------------------------------------------------------------------
def footprint_radius(robot) -> float:
    """[m] from base_link to the farthest corner of its links' bounding boxes in the world's xy, at spawn."""
    from ..bullet import pybullet as p  # noqa: PLC0415  (the world's side)

    (x, y, _), _ = robot.world_pose()
    radius = 0.0
    for link in range(-1, p.getNumJoints(robot.body, physicsClientId=robot.client)):
        low, high = p.getAABB(robot.body, link, physicsClientId=robot.client)
        for cx in (low[0], high[0]):
            for cy in (low[1], high[1]):
                radius = max(radius, math.hypot(cx - x, cy - y))
    return radius


def robot_collisions(urdf: str, name: str) -> Dict[str, List[str]]:
    """A robot's collisions as Gazebo names them (its URDF conversion's names), by link: what the
    Gazebo API lists and a bumper names; none when the conversion's reader refuses the description."""
    from ..models import gazebo_collision_names  # noqa: PLC0415  (the models' readers)

    out: Dict[str, List[str]] = {}
    try:
        for collision in gazebo_collision_names(urdf, name):
            out.setdefault(collision.link, []).append(collision.name)
    except SpawnError:  # a description pybullet took and the conversion's reader did not: names unknown
        return {}
    return out


class Engine:
    """A world: its client, its Simulation, and the requests of the node (:meth:`handle`)."""

    def __init__(self, settings: WorldSettings, gui: bool = False):
        from ..bullet import pybullet as p  # noqa: PLC0415  (the world's side)

        self.client = p.connect(p.GUI if gui else p.DIRECT)
        s = settings
        self.sim = Simulation(
            self.client, s.world, s.physics_rate, s.tyre_contact_width, seed=s.seed, datum=s.datum,
            solver_iterations=s.solver_iterations,
        )  # fmt: skip
        self.active: Dict[Tuple[str, int], bool] = {}  # a sensor had readers at its last step
        self.passive: Dict[str, List[int]] = {}  # each robot's joints RobotIO reports, listed once at its spawn
        self.gazebo = GazeboBodies(self.sim)  # the Gazebo API's side in this world (thorvald_sim.gazebo)

    def handle(self, request):
        kind = request[0]
        if kind == "step":
            return self.step(*request[1:])
        if kind == "spawn":
            return self.spawn(*request[1:])
        if kind == "delete":
            try:
                self.sim.delete(request[1])
            except SpawnError as e:
                return ("refused", str(e))
            self.passive.pop(request[1], None)
            self.gazebo.forget(request[1])
            return ("deleted",)
        if kind == "reset":
            self.sim.reset()
            self.gazebo.reset()
            return ("reset",)
        if kind == "gazebo":
            return ("answer", self.gazebo.handle(*request[1:]))
        if kind == "restart_time":
            self.restart_time()
            return ("restarted",)
        if kind == "render":
            return ("image", self.sim.render(request[1]))
        raise ValueError(f"unknown request {kind!r}")

    def spawn(self, name, urdf, pose, as_built):
        try:
            robot = self.sim.spawn(name, urdf, pose, as_built)
        except SpawnError as e:
            return ("refused", str(e))
        self.passive[name] = [j for j, _ in robot.passive] + [j for j, _ in robot.springs]
        info = {
            "description": robot.description,
            "wheels": robot.wheels,
            "passive": robot.passive,
            "springs": robot.springs,
            "sensors": [s.spec for s in robot.sensors],
            "sensor_blocks": robot.sensor_blocks,
            "sensor_problems": robot.sensor_problems,
            "missing_meshes": robot.missing_meshes,
            "radius": footprint_radius(robot),
            "entity": self.gazebo.describe(name, robot_collisions(urdf, name)),
        }
        return ("spawned", info)

    def step(self, commands, reads, positions, stamped=None, gazebo_states=0):
        """Each robot's command, the step, then what reads asks of each robot at the instant after it
        (drive states and currents for stamped, the instant as the node's messages carry it), and with
        states every model's (and link's) state for the Gazebo API's topics."""
        sim = self.sim
        for name, command in commands.items():
            robot = sim.robots[name]
            if command[0] == "apply":
                robot.command(*command[1])
            else:
                robot.hold()
        self.gazebo.before_step()
        sim.step()
        now = sim.time
        drives_now = now if stamped is None else stamped
        readings = {}
        for name, robot in sim.robots.items():
            r = reads.get(name, NOTHING)
            # in the node's order: currents, then drive states, then odometry and passive joints, then sensors
            currents = robot.drive_currents(drives_now) if r.currents else None
            states = robot.drive_states(drives_now) if r.states else None
            odometry = (robot.odom_pose(), robot.body_twist()) if r.odometry else None
            joints = None
            if r.joints:  # RobotIO's passive joints (pybullet reads no joints as None)
                passive = self.passive[name]
                joints = robot.joint_states(passive) if passive else []
            sensors = read_due(robot.sensors, r.sensors, now, self.active, robot.name)
            if r != NOTHING or sensors:
                readings[name] = (states, currents, odometry, joints, sensors)
        places = None
        if positions:
            places = {name: robot.world_pose()[0][:2] for name, robot in sim.robots.items()}
        gazebo = self.gazebo.states(gazebo_states) if gazebo_states else None
        return ("stepped", sim.solver_cpu, time.process_time(), readings, places, gazebo)

    def restart_time(self) -> None:
        """Simulated time back to zero (Gazebo's reset_simulation): every schedule starts again."""
        self.sim.steps = 0
        self.sim.time = 0.0
        self.gazebo.restart_time()
        for robot in self.sim.robots.values():
            for sensor in robot.sensors:
                sensor.schedule.pause()
        self.active.clear()

    def close(self) -> None:
        from ..bullet import pybullet as p  # noqa: PLC0415  (the world's side)

        if p.isConnected(self.client):
            p.disconnect(self.client)


# ---------------------------------------------------------------------------------------------
# The node's side: its robots as the physics read them
# ---------------------------------------------------------------------------------------------
class SensorProxy:
    """One sensor of a robot: its spec (the SensorSpec its model was made from) and its robot, what
    the node's SensorIO reads of a sensor; it is measured in the Engine."""

    def __init__(self, spec, robot: "RobotProxy", index: int):
        self.spec = spec
        self.robot = robot
        self.index = index  # in its robot's sensors: how a reading names it


class RobotProxy:
    """A robot as the node's RobotIO, say_sensors and diagnostics read it: the metadata its SimRobot
    had at its spawn, commands queued for the next step, and measurements answered from what the
    Engine read for the instant after the last step (a measurement that was not read for that instant
    is a programming error: RuntimeError). worker: the physics worker holding it (0 in the node's own)."""

    def __init__(self, name: str, worker: int, pose: Pose2D, info: Dict[str, Any]):
        self.name = name
        self.worker = worker
        self.spawn_pose = pose
        self.description = info["description"]
        self.wheels = info["wheels"]
        self.passive = info["passive"]
        self.springs = info["springs"]
        self.sensor_blocks = info["sensor_blocks"]
        self.sensor_problems = info["sensor_problems"]
        self.missing_meshes = info["missing_meshes"]
        self.radius = info["radius"]  # [m] footprint: base_link to the farthest corner of its links' boxes, xy
        self.entity = info["entity"]  # its links, joints and collisions as the Gazebo API names them
        self.sensors = [SensorProxy(spec, self, k) for k, spec in enumerate(info["sensors"])]
        self.alive = True  # False once its worker died
        self.queued: Optional[tuple] = None  # ("apply", command) or ("hold",) for the next step
        self.instant: Optional[float] = None  # [s] simulated: what follows was read then (drives: as stamped)
        self.got = NOTHING
        self.position: Optional[Tuple[float, float]] = None  # base_link in the world's xy at the last positions read
        self._reading: tuple = (None, None, None, None, None)  # states, currents, odometry, joints, sensors

    # ---- commands, queued for the next step -----------------------------------------------------
    def command(self, steering, speeds, max_steering_speeds=None) -> None:
        n = len(self.wheels)
        if len(steering) != n or len(speeds) != n:
            raise ValueError(f"{self.name}: {n} drives, got {len(steering)} steering and {len(speeds)} speed values")
        limits = list(max_steering_speeds) if max_steering_speeds else None
        self.queued = ("apply", (list(steering), list(speeds), limits))

    def hold(self) -> None:
        self.queued = ("hold",)

    # ---- measurements of the last step's instant ---------------------------------------------
    def _read(self, what: str, index: int, now: Optional[float]):
        if not getattr(self.got, what) or (now is not None and now != self.instant):
            raise RuntimeError(f"{self.name}: {what} not read at {now} (read at {self.instant}: {self.got})")
        return self._reading[index]

    def drive_states(self, now: Optional[float] = None):
        return self._read("states", 0, now)

    def drive_currents(self, now: Optional[float] = None):
        return self._read("currents", 1, now)

    def odom_pose(self):
        return self._read("odometry", 2, None)[0]

    def body_twist(self):
        return self._read("odometry", 2, None)[1]

    def joint_states(self, joints: Sequence[int]):
        return self._read("joints", 3, None)

    @property
    def sensor_results(self) -> Dict[int, tuple]:
        """The sensors measured at the last step's instant, by index: ("read", reading, CPU [s]) or
        ("failed", the error's type and text, its traceback)."""
        return self._reading[4] or {}

    def _took(self, instant: float, reads: Reads, reading: Optional[tuple]) -> None:
        self.instant = instant
        self.got = reads if reading is not None else NOTHING
        self._reading = reading if reading is not None else (None, None, None, None, None)


def queued_and_asked(robots: Sequence[RobotProxy], reads: Optional[Dict[str, Reads]]):
    """(commands, asked) of these robots for one step: each robot's queued command (taken), and what
    reads asks of it (None: EVERYTHING of every robot; a robot left out: nothing)."""
    commands, asked = {}, {}
    for robot in robots:
        if robot.queued is not None:
            commands[robot.name], robot.queued = robot.queued, None
        r = EVERYTHING if reads is None else reads.get(robot.name, NOTHING)
        if r != NOTHING:
            asked[robot.name] = r
    return commands, asked


def took(robots: Sequence[RobotProxy], instant: float, asked: Dict[str, Reads], readings, places) -> None:
    """What an Engine read after a step, to each robot's proxy."""
    for robot in robots:
        robot._took(instant, asked.get(robot.name, NOTHING), readings.get(robot.name))
        if places is not None:
            robot.position = places.get(robot.name)


class LocalPhysics:
    """The physics in the node's own process: one Engine (with pybullet's window if gui), its robots
    seen through RobotProxy, as a pool of one worker that cannot die. The same methods as
    :class:`thorvald_sim.physics.workers.WorkerPool` (see the module's docstring)."""

    cpu_elsewhere = 0.0  # [s] no other process steps its robots
    pids: Tuple[int, ...] = ()

    def __init__(self, settings: WorldSettings, gui: bool = False):
        self.engine = Engine(settings, gui)
        self.sim = self.engine.sim
        self.dt = self.sim.dt
        self.solver_iterations = self.sim.solver_iterations
        self.robots: Dict[str, RobotProxy] = {}
        self.gazebo_states = None  # the Gazebo API's states after the last step that asked for them

    @property
    def time(self) -> float:
        return self.sim.time

    @property
    def steps(self) -> int:
        return self.sim.steps

    @property
    def solver_cpu(self) -> float:
        return self.sim.solver_cpu

    def spawn(self, name: str, urdf: str, pose: Pose2D, as_built=None) -> RobotProxy:
        reply = self.engine.spawn(name, urdf, pose, as_built)
        if reply[0] == "refused":
            raise SpawnError(reply[1])
        robot = self.robots[name] = RobotProxy(name, 0, pose, reply[1])
        return robot

    def delete(self, name: str) -> None:
        reply = self.engine.handle(("delete", name))
        if reply[0] == "refused":
            raise SpawnError(reply[1])
        del self.robots[name]

    def reset(self) -> None:
        self.sim.reset()

    def render(self, camera: Optional[Camera] = None) -> Tuple[Any, str]:
        """(image, what it shows beyond the whole world: nothing here)."""
        return self.sim.render(camera or Camera()), ""

    def step(
        self,
        reads: Optional[Dict[str, Reads]] = None,
        positions: bool = False,
        stamped: Optional[float] = None,
        states: int = 0,
    ) -> List[Any]:
        """As WorkerPool.step: the queued commands, the step, what reads asks; no worker dies here."""
        instant = (self.sim.steps + 1) * self.dt if stamped is None else stamped
        robots = list(self.robots.values())
        commands, asked = queued_and_asked(robots, reads)
        _, _, _, readings, places, self.gazebo_states = self.engine.step(commands, asked, positions, stamped, states)
        took(robots, instant, asked, readings, places)
        return []

    def ask(self, worker: int, request: tuple):
        """The Gazebo API's request (op, *args) answered by the world (thorvald_sim.gazebo.bodies)."""
        return self.engine.gazebo.handle(*request)

    def live_workers(self) -> Tuple[int, ...]:
        return (0,)

    def placement(self, pose: Pose2D) -> int:
        """The world a body at pose goes to: the one there is."""
        return 0

    def restart_time(self) -> None:
        self.engine.restart_time()

    def too_close(self, margin: float = 0.0) -> list:
        """Robots of one client touch each other: none is ever too close to."""
        return []

    def placed(self, robot: RobotProxy) -> str:
        """Where a spawned robot's physics runs, for the spawn's answer: the node's own client."""
        return ""

    def statuses(self, node: str, alive: Dict[str, bool]) -> list:
        """The physics' own /diagnostics statuses beyond the simulation's: none here."""
        return []

    def close(self) -> None:
        self.engine.close()


__all__ = [
    "EVERYTHING",
    "NOTHING",
    "Engine",
    "LocalPhysics",
    "Reads",
    "RobotProxy",
    "SensorProxy",
    "WorldSettings",
    "footprint_radius",
    "queued_and_asked",
    "took",
]
