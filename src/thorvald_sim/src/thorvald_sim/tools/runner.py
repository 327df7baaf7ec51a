"""Drive a robot in the simulator without ROS: a robot file and a list of commands in, ground truth
and odometry out.

``rosrun thorvald_sim run_robot ROBOT.yaml --commands CMDS.csv --out DIR`` (:mod:`thorvald_sim.tools.run_robot`)
and :func:`run_robot` step the simulation of one robot with the robot's own base_driver core in
the same process: the calculator plugin, the drive layer, the calibration, the limits and the safety
rules base_driver runs (:class:`thorvald_base.core.BaseDriverCore`), on drives measured from the
simulated joints (the ``simulated_joints`` base handle, made by base_driver's own factory on ports
that reach the simulated robot instead of topics). There is no second copy of any of them, nor of
the timing: the simulator's clock ticks on its grid (``clock_rate``), every tick the drives are
measured and handed to the handle, and base_driver's lockstep rule
(:class:`thorvald_base.lockstep.LockstepCycles`) answers it, a control cycle on its own grid or the
last commands again. It is lockstep by construction, so a run is the same on any machine and under
any load, and the same as the ROS path (``robot.launch`` in lockstep with stamped commands) to the
float: times pass through the nanoseconds a ROS stamp keeps, as the ROS path's do.

Commands: ``t, vx, vy, wz`` (base_link: [s], [m/s], [m/s], [rad/s]), each holding from its ``t``
until the next, the last for ``hold`` seconds more (what base_driver does with a stamped stream,
:class:`thorvald_base.stamped_commands.StampedCommands`). Before the first, no command: the wheels
stand.

Outputs (:class:`RunResult`, and with ``out_dir``): ``ground_truth.csv`` and ``odometry.csv``
(``t,x,y,yaw`` at every control cycle: the simulator's true pose relative to the spawn pose, as
``odometry/gazebo`` gives it, and base_driver's odometry), and ``summary.json`` (``simulated_s``,
``wall_s`` (the whole run, ``drive_wall_s`` of it driving: the rest is making the description,
loading the world, spawning), ``distance_truth_m``, ``distance_odometry_m``,
``end_point_difference_m``, and what was run). With ``record_sensors``, every sensor of the
description is measured at its rate and its readings saved under ``sensors/`` (one ``NAME.npz`` a
sensor: ``t`` and each field of its readings stacked, a lidar's beam directions once; a camera's
images and depths too).

Not pure: it runs pybullet (a DIRECT client of its own, closed at the end). No ROS master, no rospy.
"""

import csv
import json
import math
import os
import time
from dataclasses import dataclass, field, fields
from typing import Callable, Dict, List, Optional, Sequence, Tuple

import numpy as np

from thorvald_base.bases import create_base_handle
from thorvald_base.bases.handle import Ports
from thorvald_base.core import BaseDriverCore
from thorvald_base.lockstep import LockstepCycles, apply_calibration
from thorvald_base.params import DriverParams
from thorvald_base.plugins import load_calculator
from thorvald_base.rate_grid import RateGrid
from thorvald_base.stamped_commands import StampedCommands
from thorvald_model import load_robot_config
from thorvald_model.description import generate_urdf
from thorvald_model.errors import MISSING, ConfigError, Problem

from ..bullet import pybullet as p
from ..physics.as_built import as_built_for, for_simulator
from ..physics.engine import Engine, WorldSettings
from ..physics.presets import physics_settings
from ..physics.robot import Pose2D, Vec3
from ..world import WorldConfig, load_world, resolve_world
from ..world.gazebo_world import world_bodies

WHAT = "list of commands"
ONCE = ("directions",)  # a lidar's beams in its frame: the same every reading
DERIVED = ("rgba",)  # a camera's renderer output, which its image already holds
COLUMNS = ("t", "vx", "vy", "wz")
MAX_COMMANDS = 1_000_000  # rows: a day of commands at 10 Hz
MAX_DURATION = 86_400.0  # [s] of simulated time a run may ask for


@dataclass(frozen=True)
class TimedTwist:
    """A command holding from t [s]: vx, vy [m/s] and wz [rad/s] in base_link."""

    t: float
    vx: float
    vy: float
    wz: float


@dataclass(frozen=True)
class RunOptions:
    """How a run is made; every default is what ``robot.launch`` in lockstep gives."""

    world: str = "flat"  # a shipped world's name or a world file
    as_built: str = ""  # an as-built file or PROFILE:SEED (field:7); "": as configured
    calibration: str = ""  # base_driver's calibration file (calibrate_odometry writes it)
    model_extras: str = ""  # an extra xacro fitted to the robot (sensors)
    seed: int = 0  # of every sensor's noise
    record_sensors: bool = False
    hold: float = 1.0  # [s] the last command holds
    robot_name: str = "thorvald_001"
    tf_prefix: str = "thorvald_001/"
    x: float = 0.0  # [m] spawn pose
    y: float = 0.0
    z: float = 0.0  # [m] base_link in the world: 0 stands on flat ground
    yaw: float = 0.0  # [rad]
    roll: float = 0.0  # [rad] set down tilted (on a slope); the odom frame stays level
    pitch: float = 0.0  # [rad]
    physics: str = "default"  # the simulator's physics preset (thorvald_sim.physics.presets: default, fleet)
    physics_rate: Optional[float] = None  # [Hz], the simulator's; None: the preset's
    solver_iterations: Optional[int] = None  # None: the preset's
    clock_rate: float = 80.0  # [Hz], the simulator's ~clock_rate: the instants base_driver answers
    driver: Dict = field(default_factory=dict)  # base_driver's private parameters (rate, estimator, ...)


@dataclass(frozen=True)
class Sample:
    t: float  # [s]
    x: float  # [m]
    y: float  # [m]
    yaw: float  # [rad]


@dataclass(frozen=True)
class RunResult:
    ground_truth: Tuple[Sample, ...]
    odometry: Tuple[Sample, ...]
    summary: Dict


# ---- commands ------------------------------------------------------------------------------------
def read_commands(path: str) -> Tuple[TimedTwist, ...]:
    """A commands file (CSV, a header ``t,vx,vy,wz``), checked: ConfigError naming the file, the line,
    the value and the rule for every problem."""
    try:
        with open(path, newline="", encoding="utf-8") as f:
            rows = list(_limited(csv.reader(f), MAX_COMMANDS + 1))
    except OSError as e:
        raise ConfigError(path, [Problem("", MISSING, f"cannot read the {WHAT}: {e.strerror}")], WHAT) from None
    except (UnicodeDecodeError, csv.Error) as e:
        raise ConfigError(path, [Problem("", MISSING, f"not a CSV text file: {e}")], WHAT) from None
    return parse_commands(rows, path)


def _limited(rows, n):
    for k, row in enumerate(rows):
        if k >= n:
            raise ConfigError(None, [Problem("", MISSING, f"more than {MAX_COMMANDS} commands")], WHAT)
        yield row


def parse_commands(rows: Sequence[Sequence[str]], source: Optional[str] = None) -> Tuple[TimedTwist, ...]:
    """The commands of a CSV's rows (the first a header naming t, vx, vy, wz in any order)."""
    rows = [r for r in rows if any(cell.strip() for cell in r)]
    if not rows:
        raise ConfigError(source, [Problem("", MISSING, "no header and no command: the file is empty")], WHAT)
    header = [cell.strip() for cell in rows[0]]
    missing = [c for c in COLUMNS if c not in header]
    if missing:
        rule = f"the header must name the columns {', '.join(COLUMNS)}; missing {', '.join(missing)}"
        raise ConfigError(source, [Problem("line 1", ",".join(header), rule)], WHAT)
    where = [header.index(c) for c in COLUMNS]
    problems, commands = [], []
    for number, row in enumerate(rows[1:], 2):
        values = []
        for column, k in zip(COLUMNS, where):
            text = row[k].strip() if k < len(row) else ""
            try:
                value = float(text)
            except ValueError:
                problems.append(Problem(f"line {number}.{column}", text, "must be a number"))
                continue
            if not math.isfinite(value):
                problems.append(Problem(f"line {number}.{column}", text, "must be finite"))
            values.append(value)
        if len(values) != len(COLUMNS):
            continue
        command = TimedTwist(*values)
        if not 0.0 <= command.t <= MAX_DURATION:
            problems.append(Problem(f"line {number}.t", command.t, f"must be in [0, {MAX_DURATION:g}] [s]"))
        elif commands and command.t <= commands[-1].t:
            problems.append(
                Problem(f"line {number}.t", command.t, f"must be after the line before's ({commands[-1].t:g})")
            )
        commands.append(command)
    if not commands and not problems:
        problems.append(Problem("", MISSING, "no command after the header"))
    if problems:
        raise ConfigError(source, problems, WHAT)
    return tuple(commands)


def write_commands(path: str, commands: Sequence[TimedTwist]) -> None:
    with open(path, "w", newline="", encoding="utf-8") as f:
        out = csv.writer(f)
        out.writerow(COLUMNS)
        out.writerows((repr(c.t), repr(c.vx), repr(c.vy), repr(c.wz)) for c in commands)


# ---- the run ----------------------------------------------------------------------------------------
def commands_from_plan(segments, start: float = 0.0) -> Tuple[TimedTwist, ...]:
    """A plan's segments (thorvald_base.verification.Segment: twist, duration) as commands from start
    [s], each held for its segment, then a stop."""
    t, out = start, []
    for segment in segments:
        out.append(TimedTwist(t, segment.twist.vx, segment.twist.vy, segment.twist.wz))
        t += segment.duration
    out.append(TimedTwist(t, 0.0, 0.0, 0.0))
    return tuple(out)


def stamp_time(t: float) -> float:
    """t [s] as a ROS stamp carries it: whole nanoseconds, truncated (genpy's Time.from_sec, to_sec)."""
    secs = int(t)
    return float(secs) + float(int((t - secs) * 1000000000)) / 1e9


class _SimulatedDrives:
    """The handle's ports to a robot of this process: commands straight to its joints, its measured
    motor currents and states handed over each tick (what the simulator's drive_commands,
    drive_currents and drive_states carry)."""

    def __init__(self, robot):
        self.robot = robot
        self.on_states = None
        self.on_currents = None

    def send(self, commands, time, drives):
        self.robot.command(
            [c.steering for c in commands], [c.speed for c in commands], [d.max_steering_speed for d in drives]
        )

    def listen(self, on_states):
        self.on_states = on_states

    def listen_currents(self, on_currents):
        self.on_currents = on_currents

    def measured(self, t: float) -> None:
        """Hands over the robot's measurement of instant t [s]: the currents first, then the states
        (which the lockstep handle waits for), as the simulator publishes them."""
        if self.on_currents is not None:
            currents = self.robot.drive_currents(t)
            self.on_currents([c[0] for c in currents], [c[1] for c in currents], t)
        self.on_states(self.robot.drive_states(t), t)

    def close(self):
        self.on_states = self.on_currents = None


class _InProcessPorts(Ports):
    def __init__(self, drives: _SimulatedDrives):
        self.drives = drives

    def drive_topics(self, command_topic, state_topic, current_topic="drive_currents"):
        return self.drives


def urdf_args(options: RunOptions) -> Dict[str, str]:
    """generate_urdf's arguments besides the robot file, as a session of these options spawns it."""
    return {"tf_prefix": options.tf_prefix, "model_extras": options.model_extras, "robot_name": options.robot_name}


def robot_urdf(robot_file: str, options: RunOptions = RunOptions()) -> str:
    """The robot's description as a session of these options spawns it (generate_urdf: about 0.2 s).
    A caller that makes many sessions of one robot file with the same ``tf_prefix``, ``model_extras``
    and ``robot_name`` makes it once and hands it to each (``RobotSession(..., urdf=)``)."""
    return generate_urdf(robot_file, **urdf_args(options))


class RobotSession:
    """One robot in a simulation of its own, driven by its base_driver core in lockstep, for as long
    as its caller wants: what :func:`run_robot` runs a list of commands on, and what a caller who
    decides each command from what the robot does (a design study's scenario) runs a controller on.

    ``world`` (a loaded world) stands in for ``options.world`` when given. :meth:`run` advances
    simulated time; between runs the caller reads the robot (:attr:`robot`: ground truth, the joints'
    motor torques) and may push it (:meth:`push`). Close it (or use it as a context manager): it
    holds a pybullet DIRECT client. ``urdf``: the robot's description as :func:`robot_urdf` makes it
    for this file and these options, made once by a caller of many sessions; made here when None.
    """

    def __init__(
        self,
        robot_file: str,
        options: RunOptions = RunOptions(),
        world: Optional[WorldConfig] = None,
        *,
        urdf: Optional[str] = None,
    ):
        self.options = options
        self.config = config = load_robot_config(robot_file)
        self.driver = driver = DriverParams.from_dict(
            {**options.driver, "base_handle": "simulated_joints", "lockstep": True}
        )
        self.urdf = urdf if urdf is not None else robot_urdf(robot_file, options)
        as_built = for_simulator(as_built_for(options.as_built, config), config) if options.as_built else None
        physics = physics_settings(options.physics, options.physics_rate, options.solver_iterations)  # ValueError
        self.world = world if world is not None else load_world(resolve_world(options.world))
        # its world made as the simulator node makes its own (thorvald_sim.physics.engine): a DIRECT client
        rate, iterations = physics.rate, physics.solver_iterations
        # a Gazebo world's <spherical_coordinates> are its GNSS datum, as in the simulator node
        datum = self.world.datum
        settings = WorldSettings(self.world, rate, seed=options.seed, datum=datum, solver_iterations=iterations)
        self.engine = Engine(settings)
        self.client = self.engine.client
        self.sim = self.engine.sim
        try:
            for body in world_bodies(self.world):  # a Gazebo world's, built as the simulator node builds them
                built = self.engine.gazebo.spawn_model(body.name, body.spec, body.pose)
                if isinstance(built, str):
                    raise body.refused(self.world.source, built)
                if body.actor is not None:  # moved by its script
                    self.engine.gazebo.animate(body.name, body.actor)
            pose = Pose2D(options.x, options.y, options.z, options.yaw, options.roll, options.pitch)
            self.robot = self.sim.spawn(options.robot_name, self.urdf, pose, as_built)
            calculator = load_calculator(config, estimator=driver.estimator, projection=driver.projection)
            self.drives = _SimulatedDrives(self.robot)
            handle = create_base_handle(config, driver, _InProcessPorts(self.drives))
            self.core = BaseDriverCore(config, calculator, handle, command_timeout=driver.command_timeout)
            if options.calibration:
                apply_calibration(self.core, options.calibration)
        except BaseException:
            self.engine.close()
            raise
        sim = self.sim
        self.steps = LockstepCycles(self.core, driver.rate)
        self.clock = RateGrid(options.clock_rate, sim.dt)
        self.truth: List[Sample] = []
        self.odometry: List[Sample] = []
        self.sensors = list(self.robot.sensors) if options.record_sensors else []
        self.recordings: Dict[str, List] = {s.spec.name: [] for s in self.sensors}
        self.drive_wall = 0.0  # [s] of wall time spent in run()
        self._push: Optional[Tuple[Vec3, Vec3]] = None
        self._closed = False

    @property
    def time(self) -> float:
        """[s] simulated."""
        return self.sim.time

    # ---- what a caller reads of the robot between runs ------------------------------------------
    def pose(self) -> Tuple[float, float, float, float, float, float]:
        """base_link in the world: (x, y, z) [m] and (roll, pitch, yaw) [rad], pybullet's Euler angles
        (pitch about y: positive is nose down)."""
        position, orientation = self.robot.world_pose()
        return (*position, *p.getEulerFromQuaternion(orientation))

    def motor_torques(self):
        """Each drive's steering and wheel motor torques (thorvald_sim.physics.robot.MotorLoad), in drive order."""
        return self.robot.motor_torques()

    def wheel_loads(self) -> List[float]:
        """[N] the ground's normal force on each drive's wheel, in drive order."""
        return self.robot.wheel_loads()

    def outline(self) -> Tuple[Tuple[float, float], ...]:
        """The corners in plan of every link's bounding box, in base_link [m]: the robot's outermost
        points (the frame, the wheels, what it carries)."""
        robot, c = self.robot, self.client
        (x0, y0, _), orientation = robot.world_pose()
        yaw = p.getEulerFromQuaternion(orientation)[2]
        cy, sy = math.cos(yaw), math.sin(yaw)
        points = []
        for link in range(-1, p.getNumJoints(robot.body, physicsClientId=c)):
            lo, hi = p.getAABB(robot.body, link, physicsClientId=c)
            for x, y in ((lo[0], lo[1]), (lo[0], hi[1]), (hi[0], lo[1]), (hi[0], hi[1])):
                dx, dy = x - x0, y - y0
                points.append((cy * dx + sy * dy, -sy * dx + cy * dy))
        return tuple(points)

    def centre_of_mass(self) -> Vec3:
        """[m] the robot's centre of mass in base_link: every body's mass where pybullet holds it."""
        body, c = self.robot.body, self.client
        to_base_link = p.invertTransform(*self.robot.world_pose())
        total, moment = 0.0, [0.0, 0.0, 0.0]
        for link in range(-1, p.getNumJoints(body, physicsClientId=c)):
            mass = p.getDynamicsInfo(body, link, physicsClientId=c)[0]
            if link < 0:
                where = p.getBasePositionAndOrientation(body, physicsClientId=c)[0]
            else:
                where = p.getLinkState(body, link, computeForwardKinematics=True, physicsClientId=c)[0]
            local = p.multiplyTransforms(*to_base_link, where, (0.0, 0.0, 0.0, 1.0))[0]
            total += mass
            moment = [m + mass * v for m, v in zip(moment, local)]
        return tuple(m / total for m in moment) if total > 0.0 else (0.0, 0.0, 0.0)

    def set_drive_params(self, changes) -> List[str]:
        """Drive parameters changed while it runs, as base_driver's ``set_drive_params`` (each change
        (drive index, key, value) validated as the robot file is, used from the next control cycle
        on): the problems of the changes refused (the others are applied)."""
        return self.core.set_drive_params(changes)[1]

    def render(self, camera):
        """An RGB image of the world as it is (thorvald_sim.physics.simulation.Camera; software renderer)."""
        return self.sim.render(camera)

    def push(self, force: Optional[Sequence[float]], at: Sequence[float] = (0.0, 0.0, 0.0)) -> None:
        """A force [N] in world axes on the frame at the point ``at`` [m] of base_link, every physics
        step from now on (None: no more): a drawbar's pull, a wind."""
        self._push = None if force is None else (tuple(float(f) for f in force), tuple(float(a) for a in at))

    def run(
        self,
        until: float,
        command: Callable[[float], Optional[Tuple[float, float, float]]],
        stop: Optional[Callable[["RobotSession"], bool]] = None,
    ) -> bool:
        """Steps the simulation until simulated time ``until`` [s]. At every control cycle base_driver's
        core is handed ``command(t)`` (a twist ``(vx, vy, wz)`` in base_link, or None for no command),
        the instant's ground truth and odometry are recorded, then ``stop(self)`` may end the run
        early (True). Returns whether it stopped early."""
        started = time.monotonic()
        try:
            return self._run(until, command, stop)
        finally:
            self.drive_wall += time.monotonic() - started

    def _run(self, until, command, stop) -> bool:
        sim, robot, steps, clock, drives = self.sim, self.robot, self.steps, self.clock, self.drives
        animated = self.engine.gazebo if self.engine.gazebo.animated else None  # a Gazebo world's actors
        while sim.time < until - 1e-9:
            if animated is not None:
                animated.before_step()
            if self._push is not None:
                force, at = self._push
                point, _ = p.multiplyTransforms(*robot.world_pose(), at, (0.0, 0.0, 0.0, 1.0))
                p.applyExternalForce(robot.body, -1, force, point, p.WORLD_FRAME, physicsClientId=self.client)
            sim.step()
            now = sim.time
            for sensor in self.sensors:
                if sensor.due(now):
                    self.recordings[sensor.spec.name].append((now, sensor.read(now)))
            if not clock.due(now):
                continue
            t = stamp_time(now)
            drives.measured(t)
            if not steps.due(t):
                steps.answer(t)
                continue
            result, _refused = steps.cycle(t, command(t))
            position, orientation = robot.odom_pose()
            self.truth.append(Sample(t, position[0], position[1], _yaw(orientation)))
            pose = result.odometry.pose
            self.odometry.append(Sample(t, pose.x, pose.y, pose.yaw))
            if stop is not None and stop(self):
                return True
        return False

    def close(self) -> None:
        if self._closed:
            return
        self._closed = True
        try:
            self.core.shutdown(self.sim.time)
        finally:
            self.engine.close()

    def __enter__(self) -> "RobotSession":
        return self

    def __exit__(self, *exc) -> None:
        self.close()


def run_robot(
    robot_file: str,
    commands: Sequence[TimedTwist],
    options: RunOptions = RunOptions(),
    out_dir: Optional[str] = None,
) -> RunResult:
    """Drives the robot of robot_file through commands in a simulation of its own; writes the
    outputs into out_dir when given. ConfigError for a broken robot, world, as-built, calibration or
    extras file; RuntimeError when the simulator refuses the robot."""
    if not commands:
        raise ValueError("no commands")
    started = time.monotonic()
    stamped = StampedCommands()
    for c in commands:
        stamped.add(c.t, (c.vx, c.vy, c.wz))
    with RobotSession(robot_file, options) as session:
        session.run(commands[-1].t + options.hold, lambda t: stamped.at(t) if stamped.begun(t) else None)
    wall = time.monotonic() - started
    truth, odometry = session.truth, session.odometry
    summary = _summary(truth, odometry, sim_time=truth[-1].t if truth else 0.0, wall=wall)
    summary.update(
        drive_wall_s=round(session.drive_wall, 3),
        robot=os.path.abspath(robot_file),
        world=session.world.source,
        as_built=options.as_built,
        calibration=options.calibration,
        model_extras=options.model_extras,
        seed=options.seed,
        commands=len(commands),
    )
    run = RunResult(tuple(truth), tuple(odometry), summary)
    if out_dir is not None:
        write_outputs(out_dir, run, session.recordings)
    return run


def _yaw(q) -> float:
    x, y, z, w = q
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def path_length(samples: Sequence[Sample]) -> float:
    return sum(math.hypot(b.x - a.x, b.y - a.y) for a, b in zip(samples, samples[1:]))


def _summary(truth, odometry, sim_time: float, wall: float) -> Dict:
    end = math.hypot(truth[-1].x - odometry[-1].x, truth[-1].y - odometry[-1].y) if truth else 0.0
    return {
        "simulated_s": round(sim_time, 9),
        "wall_s": round(wall, 3),
        "distance_truth_m": path_length(truth),
        "distance_odometry_m": path_length(odometry),
        "end_point_difference_m": end,
    }


# ---- outputs --------------------------------------------------------------------------------------
def write_outputs(out_dir: str, run: RunResult, recordings: Optional[Dict[str, List]] = None) -> None:
    os.makedirs(out_dir, exist_ok=True)
    for name, samples in (("ground_truth.csv", run.ground_truth), ("odometry.csv", run.odometry)):
        with open(os.path.join(out_dir, name), "w", newline="", encoding="utf-8") as f:
            out = csv.writer(f)
            out.writerow(("t", "x", "y", "yaw"))
            out.writerows((repr(s.t), repr(s.x), repr(s.y), repr(s.yaw)) for s in samples)
    with open(os.path.join(out_dir, "summary.json"), "w", encoding="utf-8") as f:
        json.dump(run.summary, f, indent=2, sort_keys=True)
        f.write("\n")
    if recordings:
        folder = os.path.join(out_dir, "sensors")
        os.makedirs(folder, exist_ok=True)
        for name, readings in recordings.items():
            np.savez_compressed(os.path.join(folder, name + ".npz"), **_arrays(readings))


def _arrays(readings) -> Dict[str, np.ndarray]:
    """A sensor's readings as arrays: t, and each field of its readings stacked (None fields dropped)."""
    out = {"t": np.array([t for t, _ in readings], dtype=float)}
    if not readings:
        return out
    first = readings[0][1]
    for name in (f.name for f in fields(first) if getattr(first, f.name) is not None):
        if name in ONCE:  # the same at every reading: kept once
            out[name] = np.asarray(getattr(first, name))
        elif name not in DERIVED:
            out[name] = np.stack([np.asarray(getattr(r, name)) for _, r in readings])
    return out


__all__ = [
    "RobotSession",
    "RunOptions",
    "RunResult",
    "Sample",
    "TimedTwist",
    "commands_from_plan",
    "parse_commands",
    "path_length",
    "read_commands",
    "run_robot",
    "stamp_time",
    "write_commands",
]
