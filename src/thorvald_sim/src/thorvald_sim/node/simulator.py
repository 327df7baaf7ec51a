"""The ``simulator`` node: one pybullet world, the clock, and per robot the original Gazebo plugin's topics.

The node is wiring. Its physics is :mod:`thorvald_sim.physics.engine`'s interface: the node's own client
(:class:`~thorvald_sim.physics.engine.LocalPhysics`) or robots on worker processes
(:class:`~thorvald_sim.physics.workers.WorkerPool`, ``~physics_workers``), which step, read what is due and
answer with one set of readings: one publish path (:meth:`SimulatorNode.step`). Each robot's ROS
side is :class:`~thorvald_sim.node.robot_io.RobotIO` (its commands, ground truth, joints, drive states
and currents, sensors: :mod:`thorvald_sim.node.sensor_io`); the services are
:mod:`thorvald_sim.node.services`; the loop's parts are pure modules tested with a clock of their own:
the parameters (:mod:`thorvald_sim.node.params`, which lists them), real-time pacing and the wait for
robots that lag (:mod:`thorvald_sim.node.pacing`), lockstep (:mod:`thorvald_sim.node.lockstep`: with it, each
robot's drive states go out with every ``/clock`` tick and the world waits for its base_driver's
answer), each robot's commands (:mod:`thorvald_sim.node.commands`), the grid of simulated time every
periodic message falls on (:mod:`thorvald_base.rate_grid`), another publisher of a robot's ``odom ->
base_link`` (:mod:`thorvald_sim.node.tf_watch`) and /diagnostics
(:func:`thorvald_sim.physics.simulation.simulator_statuses`).

The node publishes ``/clock``, so everything with ``/use_sim_time`` runs on simulated time (its own
pacing is on the wall clock), ``/tf`` (each robot's ground truth, unless it says no) and
``/diagnostics``. Per robot, in its namespace: ``odometry/gazebo``, ``joint_states`` of the joints
base_driver does not report, ``drive_states`` and ``drive_currents``, each only while read.
"""

import sys
import time

import rospy
from diagnostic_msgs.msg import DiagnosticArray
from rosgraph_msgs.msg import Clock
from tf2_msgs.msg import TFMessage

from thorvald_base import conversions
from thorvald_base.publishing import NonBlockingPublisher
from thorvald_base.rate_grid import RateGrid
from thorvald_base.stamped_commands import LOCKSTEP_BROKEN
from thorvald_model import ConfigError
from thorvald_model.datum import load_datum

from ..bullet import pybullet as p
from ..errors import ParameterError, WorkerError
from ..gazebo.api import GazeboApi
from ..physics.engine import LocalPhysics, WorldSettings
from ..physics.simulation import PerformanceMeter, simulator_statuses
from ..physics.workers import WorkerPool
from ..world import load_world, resolve_world
from .fleet_topics import FleetTopics
from .lockstep import Lockstep
from .pacing import FollowerWait, Pacer
from .params import SimulatorParams
from .robot_io import WARN_PERIOD, TfWatcher
from .services import SimulatorServices
from .turns import SWITCH_INTERVAL, TurnLock

EXIT_REFUSED = 1


class SimulatorNode:
    def __init__(self):
        params = SimulatorParams.read(lambda name, default: rospy.get_param("~" + name, default))
        world = load_world(resolve_world(params.world))
        self.params = params = params.paced_by(world, rospy.has_param("~real_time_factor"))  # a Gazebo world's pace
        self.gui = params.gui
        self.real_time_factor = params.real_time_factor
        self.command_timeout = params.command_timeout
        self.max_lag = params.max_lag
        self.default_tf = params.publish_tf
        self.paused = params.paused
        datum = load_datum(params.datum_file) if params.datum_file else world.datum
        self.lockstep = params.lockstep
        self.waits = Lockstep()  # lockstep: which robots the world waits for, for which instant
        self.pacer = Pacer(params.real_time_factor)
        self.followers = FollowerWait()  # without lockstep: robots whose commands lag ~max_lag behind
        settings = WorldSettings(
            world, params.physics_rate, params.tyre_contact_width, params.seed, datum, params.solver_iterations
        )
        # the physics (thorvald_sim.physics.engine): the node's own client, or the robots on worker processes
        if params.physics_workers > 1:
            self.sim = WorkerPool(params.physics_workers, settings, params.worker_strips)
            rospy.set_param("~worker_pids", self.sim.pids)
        else:
            self.sim = LocalPhysics(settings, self.gui)
        self.physics = params.physics
        self.lock = TurnLock()  # the loop lets requests in between its steps (node.turns)
        self.io = {}
        # one grid of simulated time for everything periodic (thorvald_base.rate_grid): the step nearest
        # each multiple of a period, so 80 Hz at the default 240 Hz physics is every third step
        self.clock = RateGrid(params.clock_rate, self.sim.dt)
        self.odometry = RateGrid(params.odometry_rate, self.sim.dt)
        self.drives = RateGrid(params.drive_state_rate, self.sim.dt)
        self.currents = RateGrid(params.drive_current_rate, self.sim.dt)
        # written in the loop, never a thread per reader, never waiting (thorvald_base.publishing)
        self.clock_pub = NonBlockingPublisher("/clock", Clock)
        self.tf = NonBlockingPublisher("/tf", TFMessage)
        self.tf_watch = TfWatcher(rospy.get_name(), self.io)  # other publishers of a robot's odom -> base_link
        self.fleet = FleetTopics(self.io, self.lock)  # every robot's drive topics in one message an instant
        self.diagnostics = NonBlockingPublisher("/diagnostics", DiagnosticArray)
        self.meter = PerformanceMeter(1.0 / params.diagnostics_rate) if params.diagnostics_rate else None
        with self.lock:  # a request that comes as soon as a service is offered waits for both
            self.gazebo = GazeboApi(self, params.gazebo_namespace, params.gazebo_states_rate)  # Gazebo's API
            self.gazebo.add_world_models(world)  # a Gazebo world file's models, as Gazebo loads them
            self.services = SimulatorServices(self)
        self.publish_clock()
        rospy.loginfo("simulator: world %s (%s), physics %s: %g Hz, %d solver iterations, real-time factor %s%s",
                      params.world, world.source, params.physics, params.physics_rate, params.solver_iterations,
                      self.real_time_factor or "as fast as possible", ", paused" if self.paused else "")  # fmt: skip
        if self.sim.pids:
            rospy.loginfo(
                "simulator: %d physics workers, pids %s, %s",
                params.physics_workers,
                " ".join(str(pid) for pid in self.sim.pids),
                f"strips split at x = {', '.join(f'{x:g}' for x in params.worker_strips)} m"
                if params.worker_strips
                else "each robot to the worker with the fewest",
            )

    # ---- the loop ---------------------------------------------------------------------------
    def publish_clock(self):
        self.clock_pub.publish(Clock(clock=rospy.Time.from_sec(self.sim.time)))

    def spin(self):
        while not rospy.is_shutdown():
            if not self.paused:
                self.wait_for_followers()
            with self.lock:
                paused = self.paused
                if not paused:
                    now = self.sim.time
                    for io in self.io.values():
                        io.apply(now, self.command_timeout)
                    ticked = self.step()
            self.lock.let_waiters_in()
            if not paused and self.lockstep and ticked:
                self.wait_for_answers()
            if self.meter is not None:
                self.publish_performance(time.monotonic())
            if paused:
                self.pacer.paused()
                time.sleep(0.01)
                continue
            self.pacer.stepped(self.sim.time)

    def wait_for_answers(self):
        """Lockstep: the world held until each robot in lockstep answered (one silent for the timeout is let go)."""
        for name in self.waits.wait(rospy.is_shutdown):
            rospy.logwarn(
                "simulator: %s did not answer its drive states for %.1f s: going on without it "
                "(%s; it joins lockstep again with its next command)",
                name,
                self.waits.timeout,
                LOCKSTEP_BROKEN,
            )

    def wait_for_followers(self):
        """Holds the world while a robot's commands lag more than ~max_lag behind (see FollowerWait)."""
        if self.max_lag <= 0 or self.lockstep:
            return

        def lagging():
            with self.lock:
                now = self.sim.time
                return [name for name, io in self.io.items() if io.alive and io.commands.lagging(now, self.max_lag)]

        given_up = self.followers.wait(lagging, self.publish_clock, rospy.is_shutdown)
        if given_up:
            rospy.logwarn_throttle(
                WARN_PERIOD,
                "simulator: %s lag more than %.2f s behind simulated time; going on without them",
                ", ".join(given_up),
                self.max_lag,
            )

    def due(self, now: float):
        """(clock, drive states, drive currents, odometry): what is due at simulated time now (each grid asked once)."""
        ticked = self.clock.due(now)
        drives = self.drives.due(now) if not self.lockstep else ticked
        # the currents cost a fleet more than their readers need (base_driver reports them once a second);
        # in lockstep every instant's, for what a recorded drive balances (calibrate_odometry --balance)
        currents = self.currents.due(now) if not self.lockstep else drives
        return ticked, drives, currents, self.odometry.due(now)

    def step(self) -> bool:
        """One physics step and what is due after it: known before the step, so the physics reads it
        at the instant after it (thorvald_sim.physics.engine), then published in this order: drive currents
        and states (in lockstep with every tick, before it: a driver woken by the tick finds them),
        /clock, odometry and /tf, the sensors. Whether /clock ticked."""
        now = (self.sim.steps + 1) * self.sim.dt  # the instant after the step, as the physics computes it
        ticked, drives, currents, odometry = self.due(now)
        tf_read = odometry and self.tf.get_num_connections() > 0
        live = [io for io in self.io.values() if io.alive]
        fleet = self.fleet.read() if drives or currents else (False, False)  # the fleet topics' readers
        reads = {io.robot.name: io.reads(drives, currents, odometry, tf_read, now, fleet=fleet) for io in live}
        stamp = rospy.Time.from_sec(now)
        # drive states and currents are read at the stamp's instant (whole nanoseconds), as they are published
        states = self.gazebo.wanted(now)
        for death in self.sim.step(reads, positions=odometry, stamped=stamp.to_sec(), states=states):
            self.worker_died(death)
        live = [io for io in live if io.alive]
        if drives or currents:
            batches = ([] if fleet[0] else None, [] if fleet[1] else None)
            for io in live:
                io.publish_drives(stamp, batches)
            self.fleet.publish(stamp, *batches)
        if ticked:
            self.publish_clock()
        if odometry:
            transforms = [io.publish_odometry(stamp, tf_read) for io in live]
            transforms = [t for t in transforms if t is not None]
            if transforms:  # every robot's in one message: one write per tf reader, not one per robot
                self.tf.publish(TFMessage(transforms))
            self.check_proximity()
        for io in live:
            io.sensors.publish_readings(now, io.robot.sensor_results)
        self.gazebo.publish(self.sim.gazebo_states)
        return ticked

    def reset_world(self) -> None:
        """Every model back where it was spawned, at rest (~reset, /gazebo/reset_world); time goes on."""
        self.sim.reset()
        rospy.loginfo("simulator: models back at their spawn poses")

    def restart_time(self) -> None:
        """Time back to zero (/gazebo/reset_simulation): everything periodic starts again, as with Gazebo."""
        self.sim.restart_time()
        for grid in (self.clock, self.odometry, self.drives, self.currents, self.gazebo.grid):
            grid.pause()
        self.pacer.paused()
        self.waits.restart()
        for io in self.io.values():
            io.restart_time()
        self.publish_clock()
        rospy.loginfo("simulator: simulated time back to 0")

    def worker_died(self, death) -> None:
        """A physics worker died: said once with its robots, which go silent and leave lockstep."""
        rospy.logerr(
            "simulator: %s at %.3f s: its robots' topics go silent (delete them with ~delete_robot); "
            "the other workers' robots go on", death, self.sim.time,
        )  # fmt: skip
        for name in death.robots:
            io = self.io.get(name)
            if io is not None:
                io.alive = False
            self.waits.forget(name)

    def check_proximity(self) -> None:
        """At odometry ticks: robots on different workers closer than their footprints (they cannot touch)."""
        for pair in self.sim.too_close():
            rospy.logwarn_throttle(
                WARN_PERIOD,
                "simulator: %s and %s are %.2f m apart, closer than %.2f m, on different physics workers "
                "(%d and %d): they cannot touch each other",
                pair.a, pair.b, pair.distance, pair.limit, self.sim.worker_of(pair.a), self.sim.worker_of(pair.b),
            )  # fmt: skip

    def publish_performance(self, wall: float) -> None:
        """/diagnostics once per ~diagnostics_rate period of wall time
        (:func:`thorvald_sim.physics.simulation.simulator_statuses`)."""
        if not self.meter.due(wall):
            return
        cpu = time.process_time() + self.sim.cpu_elsewhere  # the physics workers' processes too
        perf = self.meter.sample(wall, self.sim.time, cpu, self.sim.solver_cpu)
        if perf is None:
            return
        with self.lock:  # each window's sensor costs are taken whether anybody reads them or not
            sensors = [(name, io.sensors.uses()) for name, io in self.io.items() if io.sensors.ios]
            disabled = [(name, sensor) for name, io in self.io.items() for sensor in io.sensors.disabled()]
            alive = {name: io.alive for name, io in self.io.items()}
        if not self.diagnostics.get_num_connections():
            return
        node = rospy.get_name()
        statuses = simulator_statuses(
            node, perf, asked=self.real_time_factor, paused=self.paused, physics_rate=1.0 / self.sim.dt,
            simulated_now=self.sim.time, preset=self.physics, solver_iterations=self.sim.solver_iterations,
            workers=len(self.sim.pids), physics=self.sim.statuses(node, alive), sensors=sensors, disabled=disabled,
            robots=len(alive),
        )  # fmt: skip
        msg = DiagnosticArray(status=[conversions.diagnostic_status(*status) for status in statuses])
        msg.header.stamp = rospy.Time.from_sec(self.sim.time)
        self.diagnostics.publish(msg)

    def shutdown(self):
        with self.lock:
            self.sim.close()


def main():
    rospy.init_node("simulator")
    sys.setswitchinterval(SWITCH_INTERVAL)  # requests' threads wait less for the loop's steps (node.turns)
    try:
        node = SimulatorNode()
    except (ConfigError, ParameterError, WorkerError) as e:
        rospy.logfatal("simulator: refusing to start: %s", e)
        sys.exit(EXIT_REFUSED)
    except p.error as e:
        rospy.logfatal("simulator: refusing to start: pybullet: %s", e)
        sys.exit(EXIT_REFUSED)
    try:
        node.spin()
    finally:
        node.shutdown()
