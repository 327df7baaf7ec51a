"""Physics in worker processes: the robots of one world stepped by several pybullet clients at once.

pybullet's ``stepSimulation`` holds the GIL, so one client in one process steps on one core. With
``~physics_workers`` N >= 2 the simulator node starts N worker processes, each a pybullet DIRECT
client holding the world's static scene (the same :class:`~thorvald_sim.simulation.Simulation`,
built from the same WorldConfig and physics settings) and its share of the robots. The node keeps
every robot's ROS side; :class:`WorkerPool` stands in for the Simulation it would otherwise step,
and :class:`RobotProxy` for each robot.

* **Processes:** each worker is a fresh interpreter (``python -c "from thorvald_sim.workers import
  serve; serve(FD)"``) talking over a socket pair with multiprocessing's Connection (pickled
  messages). Not multiprocessing's own "spawn" or "forkserver" start: both run the parent's main
  script again in the child (``__mp_main__``), and the ``simulator`` node script starts the node
  when it is run. Never a fork of the node, whose rospy threads would be copied half-way. A worker
  ends with the node: it reads EOF when the node's end closes (the node exits or dies) and exits.
* **One round trip a physics step:** :meth:`WorkerPool.step` sends every worker its robots' queued
  commands (:meth:`RobotProxy.command`, :meth:`RobotProxy.hold`) and what is due to be read after
  this step (:class:`Reads`: drive states, currents, odometry, passive joints, the sensors that have
  readers), then collects every reply (``multiprocessing.connection.wait``). The workers step at the
  same time. A worker applies the commands, steps, and reads at the instant after the step, as the
  node reads its own client today, so a robot's physics and its as-built delays (``_reported``:
  readings kept when they are read) are the same to the bit: pybullet steps a robot the same whatever
  other bodies its client holds (the unit tests compare a robot in a pool and in a Simulation).
* **Sensors:** the due check and ``Sensor.read`` run in the worker (its schedule, noise and state
  are there); the reading (numpy arrays) or the failure's text comes back, and the node makes the
  messages and publishes them (:meth:`thorvald_sim.sensor_io.RobotSensors.publish_readings`). A lidar
  or a camera sees only its own worker's world: the static scene and the robots on that worker,
  not the robots on the others.
* **Placement:** by strips along x of the spawn pose (``strips``: N - 1 increasing x [m]; worker k
  takes x in [strips[k-1], strips[k])); without strips, or when the strip's worker died, the worker
  with the fewest robots. A robot stays on its worker: robots on different workers cannot touch each
  other, so :meth:`WorkerPool.too_close` names the pairs that come closer than their footprints'
  radii and ``PROXIMITY_MARGIN`` (the node warns, throttled, and shows them on /diagnostics).
  Moving a robot to another worker is not done (yet).
* **A worker that dies** (EOF on its socket, a failure it reports, or no reply within
  ``REPLY_TIMEOUT`` of wall time to a step, ``REQUEST_TIMEOUT`` to a spawn, reset or snapshot: it is
  killed) is reported by the next :meth:`WorkerPool.step` as a :class:`WorkerDeath` naming it, its
  pid and its robots; its robots are marked dead (``RobotProxy.alive``), the other workers go on,
  and :meth:`WorkerPool.delete` still removes them.

No ROS here: the node converts messages. pybullet is imported by the worker's side (Simulation).
"""

import bisect
import math
import os
import socket
import subprocess
import sys
import time
import traceback
from dataclasses import dataclass
from multiprocessing.connection import Connection, wait
from typing import Any, Dict, List, NamedTuple, Optional, Sequence, Tuple

from .errors import SpawnError
from .params import MAX_WORKERS
from .robot import TYRE_CONTACT_WIDTH, Pose2D
from .simulation import SOLVER_ITERATIONS, Camera, Simulation

REPLY_TIMEOUT = 5.0  # [s] wall: a worker that has not answered a step in this long is killed
START_TIMEOUT = 60.0  # [s] wall: a worker's interpreter, pybullet and the world's scene, on a busy machine
REQUEST_TIMEOUT = 60.0  # [s] wall: a spawn (meshes to load), a reset, a snapshot (a large image to draw)
PROXIMITY_MARGIN = 0.5  # [m] beyond two robots' footprint radii: closer than that on two workers is warned


class WorkerError(RuntimeError):
    """A worker that could not start, or failed a request other than a spawn's refusal (its text)."""


@dataclass(frozen=True)
class WorldSettings:
    """What a worker builds its Simulation from: the node's world and physics parameters."""

    world: Any  # thorvald_sim.world.WorldConfig
    physics_rate: float = 240.0
    tyre_contact_width: float = TYRE_CONTACT_WIDTH
    seed: int = 0
    datum: Any = None  # thorvald_sim.sensor_blocks.Datum
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


class WorkerDeath(NamedTuple):
    """A worker that died: its index, its pid, the robots it took with it, and why."""

    worker: int
    pid: int
    robots: Tuple[str, ...]
    reason: str

    def __str__(self) -> str:
        robots = ", ".join(self.robots) or "no robots"
        return f"physics worker {self.worker} (pid {self.pid}, {robots}) died: {self.reason}"


class TooClose(NamedTuple):
    """Two robots on different workers closer than their footprints allow: they cannot touch each other."""

    a: str
    b: str
    distance: float  # [m] between their base_links in the world's xy
    limit: float  # [m] the sum of their footprint radii and PROXIMITY_MARGIN


# ---------------------------------------------------------------------------------------------
# The node's side
# ---------------------------------------------------------------------------------------------
class SensorProxy:
    """One sensor of a robot on a worker: its spec (the SensorSpec the worker's model was made from)
    and its robot, what the node's SensorIO reads of a sensor; it is measured in the worker."""

    def __init__(self, spec, robot: "RobotProxy", index: int):
        self.spec = spec
        self.robot = robot
        self.index = index  # in its robot's sensors: how a worker's reading names it


class RobotProxy:
    """A robot on a worker, as the node's RobotIO, say_sensors and diagnostics read it: the metadata
    the worker's SimRobot had at its spawn, commands queued for the next step, and measurements
    answered from what the worker read for the instant after the last step (a measurement that was
    not read for that instant is a programming error: RuntimeError)."""

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


class _Worker:
    """One worker process and the node's end of its socket."""

    def __init__(self, index: int, settings: WorldSettings):
        self.index = index
        ours, theirs = socket.socketpair()
        env = dict(os.environ)
        # the node's own path (devel space, the venv) whatever its launcher gave the environment
        env["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p)
        code = f"from thorvald_sim.workers import serve; serve({theirs.fileno()})"
        self.process = subprocess.Popen(
            [sys.executable, "-c", code], pass_fds=(theirs.fileno(),), stdin=subprocess.DEVNULL, env=env
        )
        theirs.close()
        self.conn = Connection(ours.detach())
        self.pid = self.process.pid
        self.alive = True
        self.robots: List[str] = []  # in spawn order
        self.cpu = 0.0  # [s] the process's CPU time, every thread, as it last reported
        self.solver_cpu = 0.0  # [s] its stepSimulation's, as it last reported
        self.conn.send(("init", settings))

    def kill(self) -> None:
        if self.process.poll() is None:
            self.process.kill()
        try:
            self.process.wait(timeout=1.0)
        except subprocess.TimeoutExpired:  # a zombie the OS has not reaped yet: it is killed all the same
            pass
        self.conn.close()

    def ended(self) -> str:
        """How its process ended, as far as is known."""
        try:
            code = self.process.wait(timeout=1.0)
        except subprocess.TimeoutExpired:
            return "its socket closed"
        return f"its process ended (killed by signal {-code})" if code < 0 else f"its process exited with {code}"


class WorkerPool:
    """N worker processes stepping one world's robots: what the simulator node uses in place of a
    :class:`~thorvald_sim.simulation.Simulation` (``time``, ``dt``, ``steps``, ``solver_cpu``,
    ``solver_iterations``, :meth:`spawn`, :meth:`delete`, :meth:`step`, :meth:`reset`,
    :meth:`render`, :meth:`close`), and the workers' pids and CPU. See the module's docstring."""

    def __init__(
        self,
        workers: int,
        settings: WorldSettings,
        strips: Sequence[float] = (),
        timeout: float = REPLY_TIMEOUT,
        start_timeout: float = START_TIMEOUT,
    ):
        if isinstance(workers, bool) or not isinstance(workers, int) or not 1 <= workers <= MAX_WORKERS:
            raise ValueError(f"workers: {workers!r}: must be a whole number in 1..{MAX_WORKERS}")
        strips = tuple(float(x) for x in strips)
        if strips and (len(strips) != workers - 1 or any(b <= a for a, b in zip(strips, strips[1:]))):
            raise ValueError(f"strips: {strips!r}: must be {workers - 1} increasing x [m], one between two workers")
        if not physics_rate_ok(settings.physics_rate):
            raise ValueError(f"physics_rate: {settings.physics_rate!r}: must be > 0 [Hz]")
        self.strips = strips
        self.timeout = timeout
        self.dt = 1.0 / settings.physics_rate
        self.solver_iterations = settings.solver_iterations
        self.time = 0.0  # [s] simulated
        self.steps = 0
        self.robots: Dict[str, RobotProxy] = {}
        self.deaths: List[WorkerDeath] = []  # every worker that died, in order
        self._unreported: List[WorkerDeath] = []  # died since the last step's report
        self.workers: List[_Worker] = []
        try:
            for k in range(workers):
                self.workers.append(_Worker(k, settings))
            for w in self.workers:  # they build their scenes at the same time
                reply = self._receive(w, start_timeout)
                if reply is None or reply[0] != "ready":
                    why = reply[1] if reply is not None else self.deaths[-1].reason
                    raise WorkerError(f"physics worker {w.index} (pid {w.pid}) could not start: {why}")
        except BaseException:
            self.close()
            raise

    # ---- what the node reads ------------------------------------------------------------------
    @property
    def pids(self) -> List[int]:
        return [w.pid for w in self.workers]

    @property
    def solver_cpu(self) -> float:
        """[s] of CPU the workers' solvers spent, all steps (each worker's last report)."""
        return sum(w.solver_cpu for w in self.workers)

    @property
    def workers_cpu(self) -> float:
        """[s] of CPU the worker processes spent, every thread (each worker's last report)."""
        return sum(w.cpu for w in self.workers)

    def worker_of(self, name: str) -> int:
        return self.robots[name].worker

    # ---- requests -------------------------------------------------------------------------------
    def _die(self, w: _Worker, reason: str) -> WorkerDeath:
        w.alive = False
        w.kill()
        death = WorkerDeath(w.index, w.pid, tuple(w.robots), reason)
        for name in w.robots:
            robot = self.robots[name]
            robot.alive = False
            robot._took(self.time, NOTHING, None)  # nothing of it is read any more
        self.deaths.append(death)
        self._unreported.append(death)
        return death

    def _receive(self, w: _Worker, timeout: float):
        """The worker's reply, or None when it died (then it is reported)."""
        if not w.conn.poll(timeout):
            self._die(w, f"no answer within {timeout:g} s of wall time: killed")
            return None
        try:
            return w.conn.recv()
        except (EOFError, OSError):
            self._die(w, w.ended())
            return None

    def _send(self, w: _Worker, message) -> bool:
        try:
            w.conn.send(message)
            return True
        except OSError:  # its end closed: it died
            self._die(w, w.ended())
            return False

    def _call(self, w: _Worker, message, timeout: float = REQUEST_TIMEOUT):
        """One request and its reply; None when the worker died meanwhile."""
        if not self._send(w, message):
            return None
        reply = self._receive(w, timeout)
        if reply is not None and reply[0] == "failed":
            raise WorkerError(f"physics worker {w.index} (pid {w.pid}): {reply[1]}")
        return reply

    # ---- the world --------------------------------------------------------------------------------
    def placement(self, pose: Pose2D) -> int:
        """The worker a robot spawning at pose goes to: its strip's, else (no strips, or that worker
        died) the live one with the fewest robots (the first of those)."""
        live = [w for w in self.workers if w.alive]
        if not live:
            raise SpawnError("every physics worker died: no robot can be spawned (restart the simulator)")
        if self.strips:
            w = self.workers[bisect.bisect_right(self.strips, pose.x)]
            if w.alive:
                return w.index
        return min(live, key=lambda w: len(w.robots)).index

    def spawn(self, name: str, urdf: str, pose: Pose2D, as_built=None) -> RobotProxy:
        """As Simulation.spawn, on the worker of its placement; the same SpawnError texts."""
        if not name:
            raise SpawnError("a robot needs a name")
        if name in self.robots:
            raise SpawnError(f"a robot named {name!r} exists already")
        w = self.workers[self.placement(pose)]
        reply = self._call(w, ("spawn", name, urdf, pose, as_built))
        if reply is None:
            raise SpawnError(f"{name}: physics worker {w.index} died while spawning it: {self.deaths[-1].reason}")
        if reply[0] == "refused":
            raise SpawnError(reply[1])
        robot = RobotProxy(name, w.index, pose, reply[1])
        self.robots[name] = robot
        w.robots.append(name)
        return robot

    def delete(self, name: str) -> None:
        robot = self.robots.get(name)
        if robot is None:
            raise SpawnError(f"no robot named {name!r}; robots: {', '.join(sorted(self.robots)) or 'none'}")
        w = self.workers[robot.worker]
        if w.alive:
            reply = self._call(w, ("delete", name))
            if reply is not None and reply[0] == "refused":
                raise SpawnError(reply[1])
        del self.robots[name]
        w.robots.remove(name)

    def reset(self) -> None:
        """Every robot back to its spawn pose, at rest (each live worker's)."""
        live = [w for w in self.workers if w.alive]
        sent = [w for w in live if self._send(w, ("reset",))]
        for w in sent:
            self._receive(w, REQUEST_TIMEOUT)

    def render(self, camera: Optional[Camera] = None):
        """(image, worker) of the first live worker's world (its scene and its robots only)."""
        for w in self.workers:
            if w.alive:
                reply = self._call(w, ("render", camera or Camera()))
                if reply is not None:
                    return reply[1], w.index
        raise WorkerError("every physics worker died: nothing to render")

    def step(
        self, reads: Optional[Dict[str, Reads]] = None, positions: bool = False, stamped: Optional[float] = None
    ) -> List[WorkerDeath]:
        """One physics step of dt on every live worker at once: each robot's queued command, then the
        step, then what reads asks of each robot (None: EVERYTHING of every robot; a robot left out:
        nothing) and, with positions, every robot's place for :meth:`too_close`. stamped: the instant
        after the step as the node's messages carry it (its stamp's seconds, whole nanoseconds), which
        drive states and currents are asked for (the node's own client is asked so; its as-built
        delays keep their readings by it); None: the step's time. Returns the workers that died since
        the last step's report (their robots are dead; the others stepped)."""
        instant = (self.steps + 1) * self.dt if stamped is None else stamped
        sent = []
        for w in self.workers:
            if not w.alive:
                continue
            commands, asked = {}, {}
            for name in w.robots:
                robot = self.robots[name]
                if robot.queued is not None:
                    commands[name], robot.queued = robot.queued, None
                r = EVERYTHING if reads is None else reads.get(name, NOTHING)
                if r != NOTHING:
                    asked[name] = r
            if self._send(w, ("step", commands, asked, positions, stamped)):
                sent.append((w, asked))
        pending = {w.conn: (w, asked) for w, asked in sent}
        deadline = time.monotonic() + self.timeout
        while pending:
            ready = wait(list(pending), timeout=max(0.0, deadline - time.monotonic()))
            if not ready:
                for w, _ in pending.values():
                    self._die(w, f"no answer to a step within {self.timeout:g} s of wall time: killed")
                break
            for conn in ready:
                w, asked = pending.pop(conn)
                try:
                    reply = conn.recv()
                except (EOFError, OSError):
                    self._die(w, w.ended())
                    continue
                if reply[0] == "failed":
                    self._die(w, f"its step failed: {reply[1]}: killed")
                    continue
                self._took(w, instant, asked, reply)
        self.steps += 1
        self.time = self.steps * self.dt
        deaths, self._unreported = self._unreported, []
        return deaths

    def _took(self, w: _Worker, instant: float, asked: Dict[str, Reads], reply) -> None:
        _, w.solver_cpu, w.cpu, readings, places = reply
        for name in w.robots:
            robot = self.robots[name]
            robot._took(instant, asked.get(name, NOTHING), readings.get(name))
            if places is not None:
                robot.position = places.get(name)

    def too_close(self, margin: float = PROXIMITY_MARGIN) -> List[TooClose]:
        """The pairs of live robots on different workers whose last positions are closer than their
        footprint radii and margin [m]: they would touch, and cannot."""
        robots = [r for r in self.robots.values() if r.alive and r.position is not None]
        out = []
        for k, a in enumerate(robots):
            for b in robots[k + 1 :]:
                if a.worker == b.worker:
                    continue
                limit = a.radius + b.radius + margin
                distance = math.hypot(a.position[0] - b.position[0], a.position[1] - b.position[1])
                if distance < limit:
                    out.append(TooClose(a.name, b.name, distance, limit))
        return out

    def close(self) -> None:
        """Every worker asked to end, and killed if it does not within a second."""
        for w in self.workers:
            if w.alive:
                try:
                    w.conn.send(("close",))
                except OSError:  # it is gone already
                    pass
        for w in self.workers:
            if w.alive:
                w.alive = False
                try:
                    w.process.wait(timeout=1.0)
                except subprocess.TimeoutExpired:
                    pass
                w.kill()


def physics_rate_ok(rate) -> bool:
    return isinstance(rate, (int, float)) and not isinstance(rate, bool) and math.isfinite(rate) and rate > 0


# ---------------------------------------------------------------------------------------------
# The worker's side
# ---------------------------------------------------------------------------------------------
def footprint_radius(robot) -> float:
    """[m] from base_link to the farthest corner of its links' bounding boxes in the world's xy, at spawn."""
    from .bullet import pybullet as p  # noqa: PLC0415  (the worker's side: the node never calls it)

    (x, y, _), _ = robot.world_pose()
    radius = 0.0
    for link in range(-1, p.getNumJoints(robot.body, physicsClientId=robot.client)):
        low, high = p.getAABB(robot.body, link, physicsClientId=robot.client)
        for cx in (low[0], high[0]):
            for cy in (low[1], high[1]):
                radius = max(radius, math.hypot(cx - x, cy - y))
    return radius


class Engine:
    """A worker's world: a DIRECT client, its Simulation, and the requests of the node
    (:meth:`handle`). Usable in one process too (the tests compare it with a plain Simulation)."""

    def __init__(self, settings: WorldSettings):
        from .bullet import pybullet as p  # noqa: PLC0415  (the worker's side: the node never calls it)

        self.client = p.connect(p.DIRECT)
        s = settings
        self.sim = Simulation(
            self.client, s.world, s.physics_rate, s.tyre_contact_width, seed=s.seed, datum=s.datum,
            solver_iterations=s.solver_iterations,
        )  # fmt: skip
        self.active: Dict[Tuple[str, int], bool] = {}  # a sensor had readers at its last step
        self.passive: Dict[str, List[int]] = {}  # each robot's joints RobotIO reports, listed once at its spawn

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
            return ("deleted",)
        if kind == "reset":
            self.sim.reset()
            return ("reset",)
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
        }
        return ("spawned", info)

    def step(self, commands, reads, positions, stamped=None):
        sim = self.sim
        for name, command in commands.items():
            robot = sim.robots[name]
            if command[0] == "apply":
                robot.command(*command[1])
            else:
                robot.hold()
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
            sensors = self.read_sensors(robot, now, r.sensors)
            if r != NOTHING or sensors:
                readings[name] = (states, currents, odometry, joints, sensors)
        places = None
        if positions:
            places = {name: robot.world_pose()[0][:2] for name, robot in sim.robots.items()}
        return ("stepped", sim.solver_cpu, time.process_time(), readings, places)

    def read_sensors(self, robot, now: float, wanted: Sequence[int]) -> Dict[int, tuple]:
        """Each sensor of the robot as the node's SensorIO steps it: a sensor without readers pauses
        its schedule; one with readers is read when due (its failure's text instead of raising)."""
        out = {}
        for k, sensor in enumerate(robot.sensors):
            key = (robot.name, k)
            if k not in wanted:
                if self.active.get(key):
                    sensor.schedule.pause()
                    self.active[key] = False
                continue
            self.active[key] = True
            if not sensor.due(now):
                continue
            start = time.thread_time()
            try:
                reading = sensor.read(now)
            except Exception as e:  # whatever one sensor raises disables it alone (the node says so)
                out[k] = ("failed", f"{type(e).__name__}: {e}", traceback.format_exc())
                continue
            out[k] = ("read", reading, time.thread_time() - start)
        return out


def serve(fd: int) -> None:
    """A worker process's life: its world from the first message, then one reply per request until
    the node closes its end (or says "close")."""
    import signal  # noqa: PLC0415

    # Ctrl-C in a terminal reaches the whole process group: the worker ends with the node, not before it
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    conn = Connection(fd)
    try:
        _, settings = conn.recv()
        engine = Engine(settings)
    except EOFError:
        return
    except Exception as e:  # the node refuses to start with this text
        conn.send(("error", f"{type(e).__name__}: {e}"))
        return
    conn.send(("ready", os.getpid()))
    while True:
        try:
            request = conn.recv()
        except (EOFError, OSError):  # the node is gone: so is its world
            return
        if request[0] == "close":
            return
        try:
            reply = engine.handle(request)
        except Exception as e:  # reported to the node (a failed step kills this worker there); the trace to the log
            traceback.print_exc()
            reply = ("failed", f"{type(e).__name__}: {e}")
        try:
            conn.send(reply)
        except OSError:
            return


__all__ = [
    "EVERYTHING",
    "MAX_WORKERS",
    "NOTHING",
    "PROXIMITY_MARGIN",
    "REPLY_TIMEOUT",
    "REQUEST_TIMEOUT",
    "Engine",
    "Reads",
    "RobotProxy",
    "SensorProxy",
    "TooClose",
    "WorkerDeath",
    "WorkerError",
    "WorkerPool",
    "WorldSettings",
    "serve",
]
