"""The ``simulator`` node: one pybullet world, the clock, and per robot the original Gazebo plugin's topics.

The node is wiring: the world and its robots are :class:`thorvald_sim.simulation.Simulation`; the
loop's parts are pure modules tested with a clock of their own: the parameters read once
(:mod:`thorvald_sim.params`), real-time pacing and the wait for robots that lag
(:mod:`thorvald_sim.pacing`), lockstep (:mod:`thorvald_sim.lockstep`), each robot's commands
(:mod:`thorvald_sim.commands`), the grid of simulated time every periodic message falls on
(:mod:`thorvald_base.rate_grid`, the sensors' and base_driver's too) and the performance report
(:func:`thorvald_sim.simulation.performance_report`).

Private parameters:

========================  ================================================================
``~world``                a shipped world's name (``flat``, ``tarmac_gravel``, ``slope``,
                          ``greenhouse``) or a world file (default ``flat``)
``~gui``                  open pybullet's window (default false: headless)
``~physics``              the physics preset (:mod:`thorvald_sim.physics`): ``default`` (240 Hz,
                          50 solver iterations) or ``fleet`` (120 Hz, 50: about half the CPU
                          per robot)
``~physics_rate``         physics steps per simulated second [Hz] (the preset's)
``~solver_iterations``    pybullet's solver iterations per step (the preset's)
``~real_time_factor``     simulated seconds per wall second (1); 0 runs as fast as it can
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
``~tyre_contact_width``   width of the wheels' collision discs [m] (0.01; see robot.py)
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
========================  ================================================================

Physics workers (``~physics_workers`` N >= 2, :mod:`thorvald_sim.workers`): N processes each hold
the world's static scene and their share of the robots, and step at the same time, one round trip a
physics step; the node keeps every robot's topics, services, frames, /clock, lockstep and sensors as
with one client, and a robot's physics is the same to the bit. Robots on different workers cannot
touch each other (nor see each other through a lidar or camera): two that come closer than their
footprints allow are warned about and shown on /diagnostics. A worker that dies (killed, failed, or
silent for 5 s of wall time) is logged with its robots and is an error for each on /diagnostics; its
robots' topics go silent and lockstep lets them go, the others go on, and ``~delete_robot`` removes
them. The workers' pids are the parameter ``~worker_pids`` and in /diagnostics; ``~snapshot`` draws
the first live worker's world (it says so).

Lockstep (``~lockstep`` true): with measured drives, the simulator publishes each robot's
``drive_states`` with every ``/clock`` tick and steps no further until that robot's base_driver
(``~lockstep`` true as well) has answered them with a ``drive_commands`` stamped with the same
instant. The run is then the same on an idle and on a busy machine and at any real-time factor. A
robot joins with the first drive states it publishes to a reader (so the steps before its first
answer do not depend on how soon that answer came) and is let go, with a warning, when it has not
answered for 2 seconds of wall time (:data:`thorvald_sim.lockstep.TIMEOUT`; its driver died or
stopped, or it reads drive states without being in lockstep): the others go on, and it joins again
with its next command. A run that must repeat from its first instant starts paused (``~paused``), and whoever
drives it unpauses once every node is connected (see verification_drive's ``~unpause``). Without
lockstep the simulator waits only for robots that lag more than ``~max_lag``.

Sensors: the Gazebo sensor blocks of each robot's description (``model_extras``) are simulated
with the gazebo_ros plugins' topics, frames and parameters (:mod:`thorvald_sim.sensor_blocks`,
:mod:`thorvald_sim.sensors`, :mod:`thorvald_sim.sensor_io`), each only while somebody subscribes
to it; a sensor or plugin that is not simulated is logged once at spawn with its name and link,
and a broken block refuses that sensor with the link, the element path and the rule (so does a
block past the bounds of what one reading may cost, see :mod:`thorvald_sim.sensor_blocks`). A
sensor whose reading fails is disabled alone (see :mod:`thorvald_sim.sensor_io`); refused and
disabled sensors are errors on /diagnostics, one status each, as long as their robot is there.

Per robot, in its namespace: subscribes the command topic (``base_state``, as the original plugin,
or base_driver's ``drive_commands`` with measured drives); publishes ``odometry/gazebo``
(nav_msgs/Odometry: ``<tf_prefix>odom`` at the spawn pose -> ``<tf_prefix>base_link``, the twist in
base_link), ``joint_states`` of the joints base_driver does not report (casters, support wheels,
suspension), ``drive_states`` (thorvald_msgs/BaseState: what each drive's encoders measure) and, just
before them, ``drive_currents`` (thorvald_msgs/DriveCurrents: each drive's motor currents, as its motor
controller measures them: the joints' motor torques through the drive's motors and gears, with the
motor constants of the description's simulator block, the robot file's); each only while read.

Per robot, unless its spawn or ``~publish_tf`` say no, ``/tf`` carries ``<tf_prefix>odom ->
<tf_prefix>base_link`` from ground truth, the transform of ``odometry/gazebo``. Another node publishing
that transform too (base_driver with ``enable_odom_tf``, an EKF in the odom frame) would make the tree
flicker between the two: the simulator finds it on ``/tf`` (:mod:`thorvald_sim.tf_watch`), leaves the
transform to it and says so once, naming both publishers.

Services: ``~pause``, ``~unpause``, ``~reset`` (std_srvs/Empty, as Gazebo's), ``~spawn_robot``,
``~delete_robot``, ``~snapshot`` (thorvald_msgs). The node publishes ``/clock``, so everything with
``/use_sim_time`` runs on simulated time (its own pacing is on the wall clock), and ``/diagnostics``.
"""

import math
import os
import sys
import tempfile
import threading
import time

import rosgraph
import rospy
from diagnostic_msgs.msg import DiagnosticArray
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import JointState
from std_srvs.srv import Empty, EmptyResponse
from tf2_msgs.msg import TFMessage

from thorvald_base import conversions
from thorvald_base.publishing import NonBlockingPublisher, recorded_publisher
from thorvald_base.rate_grid import RateGrid
from thorvald_base.stamped_commands import LOCKSTEP_BROKEN
from thorvald_model import ConfigError
from thorvald_model.datum import load_datum
from thorvald_msgs.msg import BaseState, DriveCurrents
from thorvald_msgs.srv import (
    DeleteRobot,
    DeleteRobotResponse,
    Snapshot,
    SnapshotResponse,
    SpawnRobot,
    SpawnRobotResponse,
)

from .as_built import SimAsBuilt
from .bullet import pybullet as p
from .commands import APPLY, HOLD, CommandSlot
from .errors import ParameterError, SpawnError
from .lockstep import Lockstep
from .pacing import FollowerWait, Pacer
from .params import SimulatorParams
from .robot import Pose2D
from .sensor_io import RobotSensors
from .sensors import disabled_report, refused_sensors, sensor_report
from .simulation import Camera, PerformanceMeter, Simulation, performance_report, save_png
from .tf_watch import TfWatch
from .workers import Reads, WorkerError, WorkerPool, WorldSettings
from .world import load_world, resolve_world

WARN_PERIOD = 5.0  # [s] between repeats of one warning
EXIT_REFUSED = 1
TF_POLL = 2.0  # [s] wall: how often the master is asked who publishes /tf (another odom -> base_link)


class RobotIO:
    """The ROS side of one simulated robot."""

    def __init__(self, node, robot, namespace: str, command_topic: str, publish_tf: bool):
        self.robot = robot
        d = robot.description
        ns = namespace.rstrip("/") + "/" if namespace else "/"
        self.namespace = ns
        self.publish_tf = publish_tf
        # ground truth and the sensors, which a lockstep run records: nothing lost then (the world waits)
        self.odom_pub = recorded_publisher(node.lockstep)(ns + d.odometry_topic, Odometry)
        self.joint_pub = NonBlockingPublisher(ns + "joint_states", JointState)
        self.drive_pub = NonBlockingPublisher(ns + "drive_states", BaseState)
        self.current_pub = NonBlockingPublisher(ns + "drive_currents", DriveCurrents)
        self.commands = CommandSlot(len(robot.wheels))  # the latest, to apply in the loop
        self.node = node
        self.alive = True  # False once its physics worker died: its topics go silent
        self.sub = rospy.Subscriber(ns + command_topic, BaseState, self.on_command, queue_size=1)
        self.passive = [j for j, _ in robot.passive] + [j for j, _ in robot.springs]
        self.passive_names = [info.name for _, info in robot.passive] + [s.joint for _, s in robot.springs]
        self.sensors = RobotSensors(
            robot.sensors,
            namespace or "/",
            refused_sensors(robot.sensor_blocks, robot.sensor_problems),
            publisher=recorded_publisher(node.lockstep),
        )

    def on_command(self, msg):
        stamp = msg.header.stamp.to_sec()
        problem = self.commands.put(msg.steer_pos, msg.prop_speed, msg.steer_max_speed, self.node.sim.time, stamp)
        if problem:
            rospy.logwarn_throttle(WARN_PERIOD, "simulator: %s: %s", self.robot.name, problem)
            return
        if self.node.lockstep and self.node.waits.answered(self.robot.name, stamp):
            rospy.loginfo("simulator: %s in lockstep", self.robot.name)

    def apply(self, now: float, timeout: float) -> None:
        """In the loop, before a step: the latest command, or a stop if commands stopped coming."""
        action, command = self.commands.take(now, timeout)
        if action == APPLY:
            self.robot.command(*command)
        elif action == HOLD:
            self.robot.hold()

    def reads(self, drives: bool, currents: bool, odometry: bool, tf_read: bool, now: float) -> Reads:
        """On a physics worker: what to read of this robot after the step to now (what is due, and read)."""
        return Reads(
            states=drives and self.drive_pub.get_num_connections() > 0,
            currents=currents and self.current_pub.get_num_connections() > 0,
            odometry=odometry and bool(self.odom_pub.get_num_connections() or (self.publish_tf and tf_read)),
            joints=odometry and bool(self.passive) and self.joint_pub.get_num_connections() > 0,
            sensors=self.sensors.requests(now),
        )

    def publish_odometry(self, stamp, tf_read: bool, odometry: bool = True, joints: bool = True):
        """odometry/gazebo, joint_states of the passive joints: only what somebody reads (and, on a
        physics worker, what it read); the transform of odometry/gazebo for /tf if tf_read and this
        robot publishes it, else None."""
        transform = None
        if odometry and (self.odom_pub.get_num_connections() or (self.publish_tf and tf_read)):
            transform = self._publish_odometry(stamp, tf_read)
        if joints and self.passive and self.joint_pub.get_num_connections():
            states = self.robot.joint_states(self.passive)
            self.joint_pub.publish(
                conversions.joint_state_msg(stamp, self.passive_names, [s[0] for s in states], [s[1] for s in states])
            )
        return transform

    def _publish_odometry(self, stamp, tf_read: bool):
        d = self.robot.description
        position, orientation = self.robot.odom_pose()
        linear, angular = self.robot.body_twist()
        msg = conversions.pose_odometry_msg(
            stamp,
            d.odometry_frame,
            d.base_frame,
            position=position,
            orientation=orientation,
            linear=linear,
            angular=angular,
        )
        self.odom_pub.publish(msg)
        return conversions.odometry_transform(msg) if self.publish_tf and tf_read else None

    def publish_drives(self, stamp, states: bool = True, currents: bool = True):
        """drive_currents and drive_states at stamp (those due), each if somebody reads it."""
        now = stamp.to_sec()
        # the currents first: a lockstep base_driver runs its cycle once the instant's states came
        if currents and self.current_pub.get_num_connections():
            currents = self.robot.drive_currents(now)
            self.current_pub.publish(
                conversions.currents_msg(stamp, [c[0] for c in currents], [c[1] for c in currents])
            )
        if states and self.drive_pub.get_num_connections():  # base_driver with measured drives
            # its reader is there: in lockstep from its first drive states on, not its first answer
            if self.node.lockstep and self.node.waits.published(self.robot.name, now):
                rospy.loginfo("simulator: %s in lockstep", self.robot.name)
            self.drive_pub.publish(conversions.state_msg(stamp, self.robot.drive_states(now)))

    def close(self):
        self.sub.unregister()
        for pub in (self.odom_pub, self.joint_pub, self.drive_pub, self.current_pub):
            pub.unregister()
        self.sensors.close()


class SimulatorNode:
    def __init__(self):
        self.params = params = SimulatorParams.read(lambda name, default: rospy.get_param("~" + name, default))
        world = load_world(resolve_world(params.world))
        self.gui = params.gui
        self.real_time_factor = params.real_time_factor
        self.command_timeout = params.command_timeout
        self.max_lag = params.max_lag
        self.default_tf = params.publish_tf
        self.paused = params.paused
        datum = load_datum(params.datum_file) if params.datum_file else None
        self.lockstep = params.lockstep
        self.waits = Lockstep()  # lockstep: which robots the world waits for, for which instant
        self.pacer = Pacer(params.real_time_factor)
        self.followers = FollowerWait()  # without lockstep: robots whose commands lag ~max_lag behind
        self.pool = params.physics_workers > 1  # the robots on worker processes (thorvald_sim.workers)
        self.worker_deaths = []  # thorvald_sim.workers.WorkerDeath of each worker that died, with its instant
        self.too_close = []  # thorvald_sim.workers.TooClose at the last odometry tick
        if self.pool:
            self.client = None
            settings = WorldSettings(
                world, params.physics_rate, params.tyre_contact_width, params.seed, datum, params.solver_iterations
            )
            self.sim = WorkerPool(params.physics_workers, settings, params.worker_strips)
            rospy.set_param("~worker_pids", self.sim.pids)
        else:
            self.client = p.connect(p.GUI if self.gui else p.DIRECT)
            self.sim = Simulation(
                self.client, world, params.physics_rate, params.tyre_contact_width, seed=params.seed, datum=datum,
                solver_iterations=params.solver_iterations,
            )  # fmt: skip
        self.physics = params.physics
        self.lock = threading.RLock()
        self.missing_meshes_said = set()  # mesh URIs warned about: once each, however many robots name them
        self.io = {}
        # one grid of simulated time for everything periodic (thorvald_base.rate_grid): the step nearest
        # each multiple of a period, so 80 Hz at the default 240 Hz physics is every third step
        self.clock = RateGrid(params.clock_rate, self.sim.dt)
        self.odometry = RateGrid(params.odometry_rate, self.sim.dt)
        self.drives = RateGrid(params.drive_state_rate, self.sim.dt)
        self.currents = RateGrid(params.drive_current_rate, self.sim.dt)
        # Written in the loop on non-blocking sockets (thorvald_base.publishing): a writer thread per reader
        # cost more than the physics; a blocking write froze the simulation when one reader's link dropped.
        self.clock_pub = NonBlockingPublisher("/clock", Clock)
        self.tf = NonBlockingPublisher("/tf", TFMessage)
        self.tf_watch = TfWatch(rospy.get_name())
        self.tf_reader = None  # the /tf subscription while TfWatch has publishers to judge
        self.tf_conflicts_said = set()  # robots whose other publisher of odom -> base_link was warned about
        self.tf_poll_now = threading.Event()  # a spawn: look at /tf's publishers now, not at the next poll
        threading.Thread(target=self.watch_tf, name="tf_watch", daemon=True).start()
        self.diagnostics = NonBlockingPublisher("/diagnostics", DiagnosticArray)
        self.meter = PerformanceMeter(1.0 / params.diagnostics_rate) if params.diagnostics_rate else None
        rospy.Service("~pause", Empty, self.srv_pause)
        rospy.Service("~unpause", Empty, self.srv_unpause)
        rospy.Service("~reset", Empty, self.srv_reset)
        rospy.Service("~spawn_robot", SpawnRobot, self.srv_spawn)
        rospy.Service("~delete_robot", DeleteRobot, self.srv_delete)
        rospy.Service("~snapshot", Snapshot, self.srv_snapshot)
        self.publish_clock()
        rospy.loginfo(
            "simulator: world %s (%s), physics %s: %g Hz, %d solver iterations, real-time factor %s%s",
            params.world,
            world.source,
            params.physics,
            params.physics_rate,
            params.solver_iterations,
            self.real_time_factor or "as fast as possible",
            ", paused" if self.paused else "",
        )
        if self.pool:
            rospy.loginfo(
                "simulator: %d physics workers, pids %s, %s",
                params.physics_workers,
                " ".join(str(pid) for pid in self.sim.pids),
                f"strips split at x = {', '.join(f'{x:g}' for x in params.worker_strips)} m"
                if params.worker_strips
                else "each robot to the worker with the fewest",
            )

    # ---- services -------------------------------------------------------------------------
    def srv_pause(self, _req):
        with self.lock:
            self.paused = True
        return EmptyResponse()

    def srv_unpause(self, _req):
        with self.lock:
            self.paused = False
        return EmptyResponse()

    def srv_reset(self, _req):
        with self.lock:
            self.sim.reset()
        rospy.loginfo("simulator: robots back at their spawn poses")
        return EmptyResponse()

    def srv_spawn(self, req):
        from .spawn_names import model_name_problem, namespace_problem  # noqa: PLC0415 (the spawn's own rules)

        # any client may call: the names are checked before either appears in a line or a topic
        problem = model_name_problem(req.model_name) or namespace_problem(req.robot_namespace)
        if problem:
            rospy.logerr("simulator: refused to spawn: %s", problem)
            return SpawnRobotResponse(False, problem)
        pose = Pose2D(req.x, req.y, req.z, req.yaw)
        if not all(math.isfinite(v) for v in (req.x, req.y, req.z, req.yaw)):
            return SpawnRobotResponse(False, f"{req.model_name}: the spawn pose must be finite")
        as_built = None
        if req.as_built:
            try:
                as_built = SimAsBuilt.from_json(req.as_built)  # its drives are counted at the spawn
            except ValueError as e:
                rospy.logerr("simulator: refused to spawn %s: %s", req.model_name, e)
                return SpawnRobotResponse(False, f"{req.model_name}: {e}")
        with self.lock:
            try:
                robot = self.sim.spawn(req.model_name, req.robot_description, pose, as_built)
            except SpawnError as e:
                rospy.logerr("simulator: refused to spawn: %s", e)
                return SpawnRobotResponse(False, str(e))
            for mesh in robot.missing_meshes:
                if mesh.uri not in self.missing_meshes_said:
                    self.missing_meshes_said.add(mesh.uri)
                    rospy.logwarn(
                        "simulator: %s: mesh %s not found (%s): link %s drawn from its other geometry",
                        req.model_name,
                        mesh.uri,
                        mesh.reason,
                        mesh.link,
                    )
            self.say_sensors(req.model_name, robot)
            topic = req.command_topic or robot.description.command_topic
            # by default a robot with the generator's block (odometry/gazebo's frames), not a passive model:
            # a post's "odom -> base_link" would be another robot's
            tf = self.default_tf and bool(robot.description.drives) if req.publish_tf < 0 else bool(req.publish_tf)
            self.io[req.model_name] = RobotIO(self, robot, req.robot_namespace, topic, tf)
            if tf:
                self.tf_watch.watch(req.model_name, robot.description.base_frame)
                self.tf_poll_now.set()
        kind = f"{len(robot.wheels)} drives following {topic}" if robot.wheels else "passive (no drive block)"
        message = f"spawned {req.model_name} in {req.robot_namespace or '/'} at ({req.x:g}, {req.y:g}), {kind}"
        if tf:
            d = robot.description
            message += f", {d.odometry_frame} -> {d.base_frame} on /tf from ground truth"
        if as_built is not None:
            message += f", as built: {as_built.source}"
        if self.pool:
            message += f", on physics worker {robot.worker}"
        rospy.loginfo("simulator: %s", message)
        return SpawnRobotResponse(True, message)

    @staticmethod
    def say_sensors(name, robot):
        """The robot's sensors at spawn: what is simulated, what is not (once, by name and link), and
        what is refused (the link, the element path and the rule)."""
        blocks = robot.sensor_blocks
        for other in blocks.unsupported:
            rospy.logwarn(
                "simulator: %s: %s%s not simulated", name, other.what, f" on link {other.link}" if other.link else ""
            )
        for refused in blocks.refused:
            rospy.logerr("simulator: %s: sensor refused: %s", name, refused)
        for problem in robot.sensor_problems:
            rospy.logerr("simulator: %s: sensor refused: %s", name, problem)
        if robot.sensors:
            rospy.loginfo(
                "simulator: %s: sensors %s",
                name,
                ", ".join(f"{s.spec.kind} {s.spec.name} ({s.spec.rate:g} Hz)" for s in robot.sensors),
            )

    def srv_delete(self, req):
        with self.lock:
            try:
                self.sim.delete(req.model_name)
            except SpawnError as e:
                return DeleteRobotResponse(False, str(e))
            self.io.pop(req.model_name).close()
            self.tf_watch.forget(req.model_name)
            self.waits.forget(req.model_name)
        return DeleteRobotResponse(True, f"deleted {req.model_name}")

    def srv_snapshot(self, req):
        camera = Camera()
        for name in ("eye", "target"):
            values = tuple(getattr(req, name))
            if values:
                if len(values) != 3 or not all(math.isfinite(v) for v in values):
                    return SnapshotResponse(False, f"{name} must be 3 finite numbers [m]", "")
                camera = Camera(**{**camera.__dict__, name: values})
        if req.width or req.height:
            camera = Camera(camera.eye, camera.target, req.width or camera.width, req.height or camera.height)
        path = req.path or tempfile.mkstemp(prefix="thorvald_sim_", suffix=".png")[1]
        whose = ""
        with self.lock:
            if self.pool:  # each worker holds its own robots: one world is drawn, and the answer says whose
                try:
                    image, worker = self.sim.render(camera)
                except RuntimeError as e:
                    return SnapshotResponse(False, str(e), "")
                robots = [name for name, robot in self.sim.robots.items() if robot.worker == worker]
                whose = f", the world of physics worker {worker} only (its robots: {', '.join(robots) or 'none'})"
            else:
                image = self.sim.render(camera)
        try:
            save_png(image, path)
        except OSError as e:
            return SnapshotResponse(False, f"{path}: {e.strerror}", "")
        return SnapshotResponse(True, f"{camera.width} x {camera.height} px{whose}", os.path.abspath(path))

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
                    if self.pool:
                        ticked = self.step_workers()
                    else:
                        self.sim.step()
                        ticked = self.publish(self.sim.time)
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
        """Lockstep: holds the world until every robot in lockstep answered its last drive states; a
        robot silent for the lockstep's timeout of wall time is let go (it joins again with its next command)."""
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

    def publish(self, now: float) -> bool:
        """What is due at simulated time now; whether /clock ticked. In lockstep the drive states go
        with every tick, before it: a driver woken by the tick finds them."""
        stamp = rospy.Time.from_sec(now)
        ticked, drives, currents, odometry = self.due(now)
        if drives or currents:
            for io in self.io.values():
                io.publish_drives(stamp, drives, currents)
        if ticked:
            self.publish_clock()
        if odometry:
            tf_read = self.tf.get_num_connections() > 0
            transforms = [io.publish_odometry(stamp, tf_read) for io in self.io.values()]
            transforms = [t for t in transforms if t is not None]
            if transforms:  # every robot's in one message: one write per tf reader, not one per robot
                self.tf.publish(TFMessage(transforms))
        for io in self.io.values():
            io.sensors.step(now)
        return ticked

    def step_workers(self) -> bool:
        """publish's twin with physics workers: what is due after the step is known before it, so each
        worker reads it right after its step, at the instant the node's own client would be read; then
        the same messages, in the same order. Whether /clock ticked."""
        now = (self.sim.steps + 1) * self.sim.dt  # the instant after the step, as the pool computes it
        ticked, drives, currents, odometry = self.due(now)
        tf_read = odometry and self.tf.get_num_connections() > 0
        live = [io for io in self.io.values() if io.alive]
        reads = {io.robot.name: io.reads(drives, currents, odometry, tf_read, now) for io in live}
        stamp = rospy.Time.from_sec(now)
        # drive states and currents are asked at the stamp's instant, as publish_drives asks the node's client
        for death in self.sim.step(reads, positions=odometry, stamped=stamp.to_sec()):
            self.worker_died(death)
        live = [io for io in live if io.alive]
        if drives or currents:
            for io in live:
                got = io.robot.got
                io.publish_drives(stamp, drives and got.states, currents and got.currents)
        if ticked:
            self.publish_clock()
        if odometry:
            transforms = [
                io.publish_odometry(stamp, tf_read, io.robot.got.odometry, io.robot.got.joints) for io in live
            ]
            transforms = [t for t in transforms if t is not None]
            if transforms:
                self.tf.publish(TFMessage(transforms))
            self.check_proximity()
        for io in live:
            io.sensors.publish_readings(now, io.robot.sensor_results)
        return ticked

    def worker_died(self, death) -> None:
        """A physics worker died: said once with its robots, which go silent and leave lockstep."""
        rospy.logerr(
            "simulator: %s at %.3f s: its robots' topics go silent (delete them with ~delete_robot); "
            "the other workers' robots go on",
            death,
            self.sim.time,
        )
        self.worker_deaths.append((death, self.sim.time))
        for name in death.robots:
            io = self.io.get(name)
            if io is not None:
                io.alive = False
            self.waits.forget(name)

    def check_proximity(self) -> None:
        """At odometry ticks: robots on different workers closer than their footprints (they cannot touch)."""
        self.too_close = self.sim.too_close()
        for pair in self.too_close:
            rospy.logwarn_throttle(
                WARN_PERIOD,
                "simulator: %s and %s are %.2f m apart, closer than %.2f m, on different physics workers "
                "(%d and %d): they cannot touch each other",
                pair.a, pair.b, pair.distance, pair.limit, self.sim.worker_of(pair.a), self.sim.worker_of(pair.b),
            )  # fmt: skip

    # ---- other publishers of the robots' transforms ---------------------------------------------
    def watch_tf(self):
        """Every TF_POLL seconds of wall time: the master's /tf publishers to TfWatch, /tf read while it
        has something to judge, and the robots whose other publisher went silent handed back."""
        master = rosgraph.Master(rospy.get_name())
        while not rospy.is_shutdown():
            try:
                publishers = dict(master.getSystemState()[0]).get("/tf", [])
            except Exception as e:  # the master went away: nothing to judge until it is back
                rospy.logdebug("simulator: cannot ask the master for /tf's publishers: %s", e)
                publishers = []
            self.tf_watch.publishers(publishers)
            for conflict in self.tf_watch.resumed(time.monotonic()):
                io = self.io.get(conflict.robot)
                if io is not None:
                    io.publish_tf = True
                    rospy.loginfo(
                        "simulator: %s: %s stopped publishing %s -> %s: the simulator publishes it again",
                        conflict.robot,
                        conflict.publisher,
                        conflict.parent,
                        conflict.child,
                    )
            listening = self.tf_watch.listening()
            if listening and self.tf_reader is None:
                self.tf_reader = rospy.Subscriber("/tf", rospy.AnyMsg, self.on_tf, queue_size=50)
            elif not listening and self.tf_reader is not None:
                self.tf_reader.unregister()
                self.tf_reader = None
            self.tf_poll_now.wait(TF_POLL)
            self.tf_poll_now.clear()

    def on_tf(self, msg):
        caller = msg._connection_header.get("callerid", "")
        for conflict in self.tf_watch.message(caller, msg._buff, time.monotonic()):
            io = self.io.get(conflict.robot)
            if io is None:
                continue
            io.publish_tf = False
            if conflict.robot in self.tf_conflicts_said:
                rospy.loginfo(
                    "simulator: %s: %s publishes %s -> %s again: the simulator leaves it to it",
                    conflict.robot,
                    conflict.publisher,
                    conflict.parent,
                    conflict.child,
                )
                continue
            self.tf_conflicts_said.add(conflict.robot)
            rospy.logwarn(
                "simulator: %s: %s publishes %s -> %s on /tf, and so does the simulator (%s, from ground truth): "
                "the simulator leaves it to %s while it does, so the tree does not flicker between the two "
                "(spawn with -no_publish_tf, or give base_driver enable_odom_tf:=false, to choose one yourself)",
                conflict.robot,
                conflict.publisher,
                conflict.parent,
                conflict.child,
                rospy.get_name(),
                conflict.publisher,
            )

    def publish_performance(self, wall: float) -> None:
        """/diagnostics once per ~diagnostics_rate period of wall time: the simulation's
        (:func:`thorvald_sim.simulation.performance_report`), each robot's sensors' and each sensor a
        robot goes without."""
        if not self.meter.due(wall):
            return
        cpu = time.process_time() + (self.sim.workers_cpu if self.pool else 0.0)  # the workers' processes too
        perf = self.meter.sample(wall, self.sim.time, cpu, self.sim.solver_cpu)
        if perf is None:
            return
        asked = self.real_time_factor
        with self.lock:  # each window's sensor costs are taken whether anybody reads them or not
            sensor_reports = [
                (name, sensor_report(io.sensors.uses(), perf.simulated, 1.0 / self.sim.dt, asked))
                for name, io in self.io.items()
                if io.sensors.ios
            ]
            disabled = [(name, sensor) for name, io in self.io.items() for sensor in io.sensors.disabled()]
        if not self.diagnostics.get_num_connections():
            return
        simulation = performance_report(
            perf, robots=len(self.io), asked=asked, paused=self.paused, physics_rate=1.0 / self.sim.dt,
            simulated_now=self.sim.time,
        )  # fmt: skip
        simulation[2]["physics preset"] = self.physics
        simulation[2]["solver iterations"] = str(self.sim.solver_iterations)
        if self.pool:
            simulation[2]["physics workers"] = str(len(self.sim.workers))
            simulation[2]["CPU"] = "the node's and its physics workers' processes"
        statuses = [conversions.diagnostic_status(rospy.get_name() + ": simulation", "pybullet", *simulation)]
        if self.pool:
            statuses += self.worker_statuses()
        statuses += [
            conversions.diagnostic_status(f"{rospy.get_name()}: sensors of {name}", name, *report)
            for name, report in sensor_reports
        ]
        statuses += [
            conversions.diagnostic_status(
                f"{rospy.get_name()}: sensor {sensor.name} of {name}", name, *disabled_report(name, sensor)
            )
            for name, sensor in disabled
        ]
        msg = DiagnosticArray(status=statuses)
        msg.header.stamp = rospy.Time.from_sec(self.sim.time)
        self.diagnostics.publish(msg)

    def worker_statuses(self):
        """/diagnostics of the physics workers: one status with each worker's pid, robots and CPU (a
        warning while robots on different workers are too close), and an error per robot whose worker died."""
        node = rospy.get_name()
        values = {"workers": str(len(self.sim.workers))}
        for w in self.sim.workers:
            state = "alive" if w.alive else "dead"
            values[f"worker {w.index}"] = f"pid {w.pid}, {state}, robots: {', '.join(w.robots) or 'none'}"
            values[f"worker {w.index} CPU [s]"] = f"{w.cpu:.3f}"
        for pair in self.too_close:
            values[f"{pair.a} and {pair.b}"] = f"{pair.distance:.2f} m apart, closer than {pair.limit:.2f} m"
        level, message = 0, f"{len(self.sim.workers)} physics workers"
        if self.too_close:
            level = 1
            message += "; robots on different workers too close to touch: " + ", ".join(
                f"{pair.a} and {pair.b}" for pair in self.too_close
            )
        dead = [w for w in self.sim.workers if not w.alive]
        if dead:
            level = 2
            message += "; dead: " + ", ".join(f"worker {w.index} (pid {w.pid})" for w in dead)
        statuses = [conversions.diagnostic_status(f"{node}: physics workers", "pybullet", level, message, values)]
        for death, since in self.worker_deaths:
            for name in death.robots:
                io = self.io.get(name)
                if io is not None and not io.alive:  # not deleted since (nor spawned again, on another worker)
                    why = f"{name}: {death} at {since:.3f} s; its topics are silent"
                    values = {"robot": name, "worker": str(death.worker), "pid": str(death.pid), "why": death.reason}
                    statuses.append(conversions.diagnostic_status(f"{node}: robot {name}", name, 2, why, values))
        return statuses

    def shutdown(self):
        with self.lock:
            if self.pool:
                self.sim.close()
            elif p.isConnected(self.client):
                p.disconnect(self.client)


def main():
    rospy.init_node("simulator")
    try:
        node = SimulatorNode()
    except (ConfigError, ParameterError) as e:
        rospy.logfatal("simulator: refusing to start: %s", e)
        sys.exit(EXIT_REFUSED)
    except p.error as e:
        rospy.logfatal("simulator: refusing to start: pybullet: %s", e)
        sys.exit(EXIT_REFUSED)
    except WorkerError as e:
        rospy.logfatal("simulator: refusing to start: %s", e)
        sys.exit(EXIT_REFUSED)
    try:
        node.spin()
    finally:
        node.shutdown()
