"""Physics in worker processes: the robots of one world stepped by several pybullet clients at once.

pybullet's ``stepSimulation`` holds the GIL, so one client in one process steps on one core. With
``~physics_workers`` N >= 2 the simulator node starts N worker processes, each a pybullet DIRECT
client holding the world's static scene (the same :class:`~thorvald_sim.physics.simulation.Simulation`,
built from the same WorldConfig and physics settings, in an :class:`~thorvald_sim.physics.engine.Engine`)
and its share of the robots. The node keeps every robot's ROS side; :class:`WorkerPool` offers the
physics interface of :mod:`thorvald_sim.physics.engine` as :class:`~thorvald_sim.physics.engine.LocalPhysics` does
in the node's own process, and a :class:`~thorvald_sim.physics.engine.RobotProxy` stands for each robot.

* **Processes:** each worker is a fresh interpreter (``python -c "from thorvald_sim.physics.workers import
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
  are there: :func:`thorvald_sim.sensors.mounted.read_due`, the one schedule); the reading (numpy arrays)
  or the failure's text comes back, and the node makes the messages and publishes them
  (:meth:`thorvald_sim.node.sensor_io.RobotSensors.publish_readings`). A lidar or a camera sees only
  its own worker's world: the static scene and the robots on that worker, not the robots on the
  others.
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

No ROS here: the node converts messages. pybullet is imported by the worker's side (the Engine).
"""

import bisect
import math
import os
import socket
import subprocess
import sys
import time
import traceback
from multiprocessing.connection import Connection, wait
from typing import Any, Dict, List, NamedTuple, Optional, Sequence, Tuple

from ..errors import SpawnError, WorkerError
from .engine import NOTHING, Engine, Reads, RobotProxy, WorldSettings, queued_and_asked, took
from .presets import MAX_WORKERS
from .robot import Pose2D
from .simulation import Camera

REPLY_TIMEOUT = 5.0  # [s] wall: a worker that has not answered a step in this long is killed
START_TIMEOUT = 60.0  # [s] wall: a worker's interpreter, pybullet and the world's scene, on a busy machine
REQUEST_TIMEOUT = 60.0  # [s] wall: a spawn (meshes to load), a reset, a snapshot (a large image to draw)
PROXIMITY_MARGIN = 0.5  # [m] beyond two robots' footprint radii: closer than that on two workers is warned


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
class _Worker:
    """One worker process and the node's end of its socket."""

    def __init__(self, index: int, settings: WorldSettings):
        self.index = index
        ours, theirs = socket.socketpair()
        env = dict(os.environ)
        # the node's own path (devel space, the venv) whatever its launcher gave the environment
        env["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p)
        code = f"from thorvald_sim.physics.workers import serve; serve({theirs.fileno()})"
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
    :class:`~thorvald_sim.physics.simulation.Simulation` (``time``, ``dt``, ``steps``, ``solver_cpu``,
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
        self.gazebo_states = None  # the Gazebo API's states after the last step that asked for them
        self.deaths: List[WorkerDeath] = []  # every worker that died, in order
        self.died_at: List[Tuple[WorkerDeath, float]] = []  # and the simulated time [s] it died at
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
    def cpu_elsewhere(self) -> float:
        """[s] of CPU the worker processes spent, every thread (each worker's last report)."""
        return sum(w.cpu for w in self.workers)

    def placed(self, robot: RobotProxy) -> str:
        """Where a spawned robot's physics runs, for the spawn's answer."""
        return f", on physics worker {robot.worker}"

    def statuses(self, node: str, alive: Dict[str, bool]) -> List[Tuple[str, str, int, str, Dict[str, str]]]:
        """The workers' /diagnostics, as (name, hardware id, level, message, values): one status with
        each worker's pid, robots and CPU (a warning while robots on different workers are too close,
        an error with a dead worker), and an error per robot whose worker died (alive: the robots the
        node still holds, by name, and whether their topics live)."""
        too_close = self.too_close()
        values = {"workers": str(len(self.workers))}
        for w in self.workers:
            state = "alive" if w.alive else "dead"
            values[f"worker {w.index}"] = f"pid {w.pid}, {state}, robots: {', '.join(w.robots) or 'none'}"
            values[f"worker {w.index} CPU [s]"] = f"{w.cpu:.3f}"
        for pair in too_close:
            values[f"{pair.a} and {pair.b}"] = f"{pair.distance:.2f} m apart, closer than {pair.limit:.2f} m"
        level, message = 0, f"{len(self.workers)} physics workers"
        if too_close:
            level = 1
            message += "; robots on different workers too close to touch: " + ", ".join(
                f"{pair.a} and {pair.b}" for pair in too_close
            )
        dead = [w for w in self.workers if not w.alive]
        if dead:
            level = 2
            message += "; dead: " + ", ".join(f"worker {w.index} (pid {w.pid})" for w in dead)
        out = [(f"{node}: physics workers", "pybullet", level, message, values)]
        for death, since in self.died_at:
            for name in death.robots:
                if alive.get(name) is False:  # not deleted since (nor spawned again, on another worker)
                    why = f"{name}: {death} at {since:.3f} s; its topics are silent"
                    robot = {"robot": name, "worker": str(death.worker), "pid": str(death.pid), "why": death.reason}
                    out.append((f"{node}: robot {name}", name, 2, why, robot))
        return out

    def worker_of(self, name: str) -> int:
        return self.robots[name].worker

    # ---- requests -------------------------------------------------------------------------------
    def _die(self, w: _Worker, reason: str) -> WorkerDeath:
        w.alive = False
        w.kill()
        death = WorkerDeath(w.index, w.pid, tuple(w.robots), reason)
        self.died_at.append((death, self.time))
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

    def render(self, camera: Optional[Camera] = None) -> Tuple[Any, str]:
        """(image, whose world it is) of the first live worker's world: its scene and its robots only."""
        for w in self.workers:
            if w.alive:
                reply = self._call(w, ("render", camera or Camera()))
                if reply is not None:
                    robots = ", ".join(w.robots) or "none"
                    return reply[1], f", the world of physics worker {w.index} only (its robots: {robots})"
        raise WorkerError("every physics worker died: nothing to render")

    def step(
        self,
        reads: Optional[Dict[str, Reads]] = None,
        positions: bool = False,
        stamped: Optional[float] = None,
        states: int = 0,
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
            commands, asked = queued_and_asked([self.robots[name] for name in w.robots], reads)
            if self._send(w, ("step", commands, asked, positions, stamped, states)):
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
        _, w.solver_cpu, w.cpu, readings, places, gazebo = reply
        took([self.robots[name] for name in w.robots], instant, asked, readings, places)
        if gazebo is not None and self.gazebo_states is not None:
            self.gazebo_states[0].update(gazebo[0])
            self.gazebo_states[1].update(gazebo[1])

    # ---- the Gazebo API's requests (thorvald_sim.gazebo) ------------------------------------------
    def ask(self, worker: int, request: tuple):
        """The Gazebo API's request (op, *args) answered by that worker's world; WorkerError when it is dead."""
        w = self.workers[worker]
        reply = self._call(w, ("gazebo", *request)) if w.alive else None
        if reply is None:
            raise WorkerError(f"physics worker {worker} (pid {w.pid}) is dead")
        return reply[1]

    def live_workers(self) -> Tuple[int, ...]:
        return tuple(w.index for w in self.workers if w.alive)

    def restart_time(self) -> None:
        """Simulated time back to zero in every live worker (Gazebo's reset_simulation)."""
        sent = [w for w in self.workers if w.alive and self._send(w, ("restart_time",))]
        for w in sent:
            self._receive(w, REQUEST_TIMEOUT)
        self.steps = 0
        self.time = 0.0

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
    "MAX_WORKERS",
    "PROXIMITY_MARGIN",
    "REPLY_TIMEOUT",
    "REQUEST_TIMEOUT",
    "TooClose",
    "WorkerDeath",
    "WorkerPool",
    "serve",
]
