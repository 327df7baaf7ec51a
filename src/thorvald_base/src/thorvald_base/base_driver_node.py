"""The ``base_driver`` node (paper section 3.1; the original's ROS interface, notes section 2).

The robot configuration comes from the node's private namespace (the original's launch files load
the robot's YAML there) or, when the namespace holds none, from the file ``~robot_model`` names,
read through the shared loader; the node then puts the validated configuration, every default
filled in, into its private namespace, so ``rosparam get ~motor_drives`` shows what it drives.

Private parameters besides the configuration:

=================================  ===========================================================
``~robot_model``                   path of the YAML: read when the namespace holds no
                                   configuration, and named in configuration errors
``~calibration``                   path of a calibration file (``calibrate_odometry`` writes it:
                                   ``motor_drives: {driveN: {r_wheel: X, steering_offset: Y}}``),
                                   applied at start through set_drive_params and checked as the
                                   robot file is; default empty: none
``~simple_sim``                    simulate the drives (true) or drive the real base over CAN
``~base_handle``                   the base handle (thorvald_base.bases): default
                                   ``simple_sim`` with simple_sim true, else ``can``
``~tf_prefix``                     prefix of frame and joint names: ``robot_1/`` or the older
                                   original's ``robot_1``, both giving ``robot_1/base_link``
``~enable_odom_tf``                broadcast odom -> base_link (default true): the transform of the
                                   odometry it publishes (with passthrough, the simulator's)
``~odom_frame_id``                 default ``odom``
``~passthrough_gazebo_odometry``   republish ``odometry/gazebo`` (a simulator's ground truth)
                                   on ``odometry/base_raw`` once it arrives (default false)
``~rate``                          control loop rate [Hz] (default 50)
``~command_timeout``               a command older than this stops the wheels [s] (default 0.5)
``~twist_covariance``              36 values; default diagonal 0.001 x 5, 0.03 for the yaw rate
``~estimator``                     odometry: ``lsq`` (default) or ``paper``
``~projection``                    unrealisable twists on a fixed axle: ``axle`` (default) or ``lsq``
``~measured_timeout``              with ``base_handle: simulated_joints``: drive states older than
                                   this stop the wheels [s] (default 0.5)
``~lockstep``                      with ``base_handle: simulated_joints`` and the simulator's
                                   ``~lockstep``: the loop runs on the arrival of drive states
                                   instead of the clock, a cycle at the first instant ~rate asks
                                   for, and answers every other instant with the last commands, so
                                   the simulator steps only when base_driver has (default false);
                                   it then also follows ``cmd_vel_stamped`` (below)
``~can_interface_type/name``       the CAN line of a real base: a python-can interface
                                   (``socketcan``, ``slcan``, ``virtual``, ``pcan``, ...) and channel
``~can_bitrate``                   for interfaces that set it (default 1000000)
``~allow_relay_to_base_devices``   relay frames addressed to the base's own devices (default false)
=================================  ===========================================================

In lockstep, base_driver also subscribes ``cmd_vel_stamped`` (geometry_msgs/TwistStamped): the
commands of a source that publishes each before the instant in its stamp (verification_drive).
Once one comes, each cycle at instant t waits until a command stamped after t has come, applies
the last one stamped at or before t, and ignores ``cmd_vel``: what each cycle commands is then the
same in every run, however loaded the machine (see :mod:`thorvald_base.stamped_commands`). A
source that stops publishing (its node left, or nothing for ``STAMPED_WAIT`` s of wall time) is
let go with a warning, and ``cmd_vel`` rules again.

A bad configuration, calibration file or parameter stops the node at start with a fatal log naming
it (the file, the key path, the value and the rule), exit status 1.
"""

import sys
import threading
import time
import traceback

import rospy
import tf2_ros
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import Twist, TwistStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import BatteryState, JointState
from std_srvs.srv import SetBool, SetBoolResponse, Trigger, TriggerResponse

from thorvald_model import ConfigError, config_to_dict, load_robot_config, parse_robot_config
from thorvald_msgs.msg import BaseState, BatteryArray, CANFrame, ControllerArray, DriveCurrents, IOArray
from thorvald_msgs.srv import (
    CanID,
    CanIDResponse,
    DriveParams,
    DriveParamsResponse,
    MotorControllerSetup,
    MotorControllerSetupResponse,
)

from . import conversions
from .bases import create_base_handle, handle_class, handle_class_named, known_handles
from .bases.handle import DriveTopics, Ports
from .core import BaseDriverCore, PoseCovariance
from .diagnostics import OK, LinkWatch, OdometryWatch, base_statuses
from .errors import ParameterError, ThorvaldBaseError
from .lockstep import LockstepCycles, apply_calibration, calibration_said
from .node_names import Names, Throttle
from .params import PARAMETER_NAMES, DriverParams
from .plugins import load_calculator
from .publishing import BlockingPublisher
from .stamped_commands import LOCKSTEP_BROKEN, StampedCommands

STATUS_PERIOD = 1.0  # [s] between battery_data / motor_controller_data messages
EXIT_REFUSED = 1  # exit status when the node refuses to start
STAMPED_WAIT = 2.0  # [s] of wall time a lockstep cycle waits for its stamped command before letting the source go
RECORDED_QUEUE = 100  # messages queued per reader of the per-cycle streams (2 s at 50 Hz) before rospy drops one


def load_config(raw: dict, params: DriverParams, names: Names = None):
    """The robot configuration: the private namespace's, else the ~robot_model file's."""
    names = names or Names()
    if any(key not in PARAMETER_NAMES for key in raw):
        source = params.robot_model or rospy.resolve_name(names.param()) + " parameters"
        return parse_robot_config(raw, source, ignore=PARAMETER_NAMES), False
    if not params.robot_model:
        raise ParameterError(
            "~robot_model: <missing>: no robot configuration: give the robot's YAML file as ~robot_model "
            "or load it into the node's private namespace"
        )
    return load_robot_config(params.robot_model), True


class MessageDriveTopics(DriveTopics):
    """What a handle's drive topics do with messages, wherever they travel: the commands as a
    BaseState (:meth:`command_msg`), and each arriving BaseState or DriveCurrents handed to the handle,
    a malformed one refused with a throttled warning (:meth:`states_reader`, :meth:`currents_reader`)."""

    def __init__(self, state_topic: str, current_topic: str):
        self.state_topic = state_topic
        self.current_topic = current_topic
        self.throttle = Throttle()

    @staticmethod
    def command_msg(commands, time, drives):
        return conversions.command_msg(
            rospy.Time.from_sec(time), commands, [d.max_steering_speed for d in drives], [d.channel for d in drives]
        )

    def states_reader(self, on_states):
        def on_message(msg):
            try:
                on_states(conversions.measured_drives(msg), msg.header.stamp.to_sec())
            except ValueError as e:
                self.throttle.warn("base_driver: %s ignored: %s", self.state_topic, e)

        return on_message

    def currents_reader(self, on_currents):
        def on_message(msg):
            try:
                on_currents(*conversions.drive_currents(msg), msg.header.stamp.to_sec())
            except ValueError as e:
                self.throttle.warn("base_driver: %s ignored: %s", self.current_topic, e)

        return on_message


class RosDriveTopics(MessageDriveTopics):
    """A handle's drive commands and measured states on the node's topics (thorvald_msgs/BaseState),
    and the measured motor currents (thorvald_msgs/DriveCurrents)."""

    def __init__(self, command_topic: str, state_topic: str, current_topic: str):
        super().__init__(state_topic, current_topic)
        self.pub = rospy.Publisher(command_topic, BaseState, queue_size=1)
        self.sub = None
        self.current_sub = None

    def send(self, commands, time, drives):
        self.pub.publish(self.command_msg(commands, time, drives))

    def listen(self, on_states):
        self.sub = rospy.Subscriber(self.state_topic, BaseState, self.states_reader(on_states), queue_size=1)

    def listen_currents(self, on_currents):
        reader = self.currents_reader(on_currents)
        self.current_sub = rospy.Subscriber(self.current_topic, DriveCurrents, reader, queue_size=1)

    def close(self):
        for endpoint in (self.pub, self.sub, self.current_sub):
            if endpoint is not None:
                endpoint.unregister()


class RosPorts(Ports):
    """The node's topics; with fleet (a FleetDriveTopics), its drive topics are entries of the simulator's
    fleet topics (sent at once when immediate: in lockstep, each robot's answer on its own)."""

    def __init__(self, names: Names, fleet=None, immediate: bool = False):
        self.names = names
        self.fleet = fleet
        self.immediate = immediate

    def drive_topics(self, command_topic, state_topic, current_topic="drive_currents"):
        names = self.names
        topics = (names.topic(command_topic), names.topic(state_topic), names.topic(current_topic))
        if self.fleet is not None:
            return self.fleet.robot(*topics, immediate=self.immediate)
        return RosDriveTopics(*topics)


class BaseDriverNode:
    def __init__(self, names: Names = None, tf_broadcaster=None, fleet_topics=None):
        """names: where this robot's names are (default: this process's node); tf_broadcaster: one
        to share (a fleet_driver's), else the node makes its own when it broadcasts odom; fleet_topics:
        a fleet_driver's FleetDriveTopics, for drive topics on the simulator's fleet topics."""
        self.names = names = names or Names()
        # log lines name the robot when several share a process
        self.label = names.label("base_driver")
        self.throttle = Throttle()
        raw = rospy.get_param(names.param(), {})
        self.params = params = DriverParams.from_dict(raw)
        self.config, from_file = load_config(raw, params, names)
        self.tf_prefix = params.tf_prefix
        self.odom_frame = params.odom_frame_id
        self.base_frame = params.base_frame
        self.enable_tf = params.enable_odom_tf
        self.rate = params.rate
        self.lockstep = params.lockstep
        if self.lockstep and not handle_class(params).supports_lockstep:
            lockstep_handles = ", ".join(n for n in known_handles() if handle_class_named(n).supports_lockstep)
            raise ParameterError(
                f"~lockstep: true needs a base handle that answers a simulator instant by instant ({lockstep_handles}),"
                f" not {params.handle}"
            )
        self.covariance = PoseCovariance(params.twist_covariance, len(self.config.drives))
        calculator = load_calculator(self.config, estimator=params.estimator, projection=params.projection)
        handle = create_base_handle(self.config, params, RosPorts(names, fleet_topics, immediate=self.lockstep))
        try:
            self.core = BaseDriverCore(self.config, calculator, handle, command_timeout=params.command_timeout)
            if params.calibration:
                self.apply_calibration(params.calibration)
        except (ConfigError, ThorvaldBaseError):
            handle.close()
            raise
        # the calibrated configuration is what it drives (set_drive_params may change it later: core.config)
        self.config = self.core.config
        if from_file:
            for key, value in config_to_dict(self.config).items():
                rospy.set_param(names.param(key), value)
        self.lock = threading.Lock()
        self.joint_names = conversions.joint_names(self.config.drives, self.tf_prefix)

        # Every cycle's odometry and states, also to a recorder on a loaded machine: rospy writes to each
        # reader from a thread of its own and drops the oldest message when its queue is full; with 10
        # (0.2 s at 50 Hz) a writer thread starved beside a busy core lost five base_state messages of a
        # recorded drive, and the report replayed from them differed by 14 mm. In lockstep nothing may be
        # lost: the cycle waits for every reader (the world waits for the cycle anyway)
        def recorded(topic, kind):
            if self.lockstep:
                return BlockingPublisher(names.topic(topic), kind)
            return rospy.Publisher(names.topic(topic), kind, queue_size=RECORDED_QUEUE)

        self.odom_pub = recorded("odometry/base_raw", Odometry)
        self.joint_pub = recorded("joint_states", JointState)
        self.state_pub = recorded("base_state", BaseState)
        self.command_pub = recorded("joint_commands", BaseState)
        self.battery_pub = rospy.Publisher(names.topic("battery_data"), BatteryArray, queue_size=1)
        self.controller_pub = rospy.Publisher(names.topic("motor_controller_data"), ControllerArray, queue_size=1)
        self.io_pub = rospy.Publisher(names.topic("io_data"), IOArray, queue_size=1)
        self.battery_state_pubs = {
            b.id: rospy.Publisher(names.topic("battery_state/" + b.name), BatteryState, queue_size=1)
            for b in self.config.present_batteries
        }
        self.diagnostics_pub = rospy.Publisher("/diagnostics", DiagnosticArray, queue_size=1)
        self.frames_base_pub = rospy.Publisher(names.topic("can_frames_base_r"), CANFrame, queue_size=200)
        self.frames_device_pub = rospy.Publisher(names.topic("can_frames_device_r"), CANFrame, queue_size=200)
        rospy.Subscriber(names.topic("can_frames_device_t"), CANFrame, self.on_device_frame, queue_size=100)
        self.tf = (tf_broadcaster or tf2_ros.TransformBroadcaster()) if self.enable_tf else None
        self.gazebo_odom = None
        if params.passthrough_gazebo_odometry:
            rospy.Subscriber(names.topic("odometry/gazebo"), Odometry, self.on_gazebo_odometry, queue_size=10)
        rospy.Subscriber(names.topic("cmd_vel"), Twist, self.on_cmd_vel, queue_size=1)
        self.stamped = StampedCommands()
        self.stamped_arrived = threading.Condition()  # guards self.stamped
        self.stamped_sub = None
        if self.lockstep:
            self.stamped_sub = rospy.Subscriber(
                names.topic("cmd_vel_stamped"), TwistStamped, self.on_cmd_vel_stamped, queue_size=1000
            )
        rospy.Service(names.param("home_steering"), Trigger, self.srv_home_steering)
        rospy.Service(names.param("reset_base_odom"), Trigger, self.srv_reset_odom)
        rospy.Service(names.param("safety_stop"), SetBool, self.srv_safety_stop)
        rospy.Service(names.param("set_drive_params"), DriveParams, self.srv_set_drive_params)
        rospy.Service(names.param("mute_extra_can_device_commands"), SetBool, self.srv_mute)
        rospy.Service(names.param("setup_motor_controller"), MotorControllerSetup, self.srv_setup_motor_controller)
        rospy.Service(names.param("set_home_count_current_pos_zero"), CanID, self.srv_set_home_count)
        boards = handle.io_config
        for board in boards:
            for relay in range(2):
                rospy.Service(names.param(f"io{board.id}_rl{relay}"), SetBool, self._relay_service(board.id, relay))
        main = next((b for b in boards if b.is_main), None)
        if main is not None:
            # the original's names of the main board's relays, 1-based (LCAS: setRl1 lights, setRl2 AC)
            for relay in range(2):
                rospy.Service(names.param(f"setRl{relay + 1}"), SetBool, self._relay_service(main.id, relay))
        self._last_status_publish = None
        self.link_watch = LinkWatch()
        self.odometry_watch = OdometryWatch([d.name for d in self.config.drives])
        for warning in self.config.warnings:
            rospy.logwarn(self.label + ": %s", warning.format(self.config.source))
        rospy.loginfo(
            self.label + ": %d drives, calculator %s, base %s, %.0f Hz, odom tf %s",
            len(self.config.drives),
            self.config.base_calculator,
            params.handle,
            self.rate,
            "on" if self.enable_tf else "off",
        )

    def apply_calibration(self, path):
        """The calibration file's values, checked against the robot and applied as set_drive_params
        applies them (the handle built on the robot file keeps its spawn radii: simulated_joints)."""
        rospy.loginfo(self.label + ": calibration %s: %s", path, calibration_said(apply_calibration(self.core, path)))

    # ---- callbacks: message -> core -> message -----------------------------------------------
    def on_cmd_vel(self, msg):
        if self.lockstep:
            with self.stamped_arrived:
                if self.stamped.active:  # following a stamped stream
                    return
        with self.lock:
            refused = self.core.set_command(msg.linear.x, msg.linear.y, msg.angular.z, rospy.get_time())
        if refused:
            self.throttle.warn(self.label + ": %s", refused)

    def on_cmd_vel_stamped(self, msg):
        t = msg.twist
        with self.stamped_arrived:
            if not self.stamped.active:
                rospy.loginfo(self.label + ": following the stamped commands of cmd_vel_stamped (lockstep)")
            self.stamped.add(msg.header.stamp.to_sec(), (t.linear.x, t.linear.y, t.angular.z))
            self.stamped_arrived.notify_all()

    def stamped_command(self, t):
        """Lockstep: the stamped command holding at t, once it is certain (a command stamped after t
        came), or None when no stamped stream holds at t (or its source was let go)."""
        deadline = None
        with self.stamped_arrived:
            if not self.stamped.begun(t):
                return None
            while not self.stamped.known(t):
                now = time.monotonic()
                deadline = deadline or now + STAMPED_WAIT
                if now > deadline or not self.stamped_sub.get_num_connections() or rospy.is_shutdown():
                    self.stamped.clear()
                    rospy.logwarn(
                        self.label + ": cmd_vel_stamped: no command stamped after %.3f s came (%s): following cmd_vel",
                        t,
                        "its source left" if now <= deadline else f"waited {STAMPED_WAIT:g} s; {LOCKSTEP_BROKEN}",
                    )
                    return None
                self.stamped_arrived.wait(0.01)
            return self.stamped.at(t)

    def on_gazebo_odometry(self, msg):
        if self.gazebo_odom is None:
            rospy.logwarn("Switching to using Gazebo odometry for odometry/base_raw (passthrough_gazebo_odometry)")
        msg.header.frame_id = self.odom_frame
        self.gazebo_odom = msg
        self.odom_pub.publish(msg)
        if self.tf is not None:  # the transform follows the odometry published, whichever it is
            self.tf.sendTransform(conversions.odometry_transform(msg))

    def on_device_frame(self, msg):
        try:
            frame = conversions.frame_of(msg)
        except ValueError as e:
            self.throttle.warn(self.label + ": can_frames_device_t: a frame refused: %s", e)
            return
        with self.lock:
            problem = self.core.handle.relay(frame)
        if problem:
            self.throttle.warn(self.label + ": can_frames_device_t: %s", problem)

    def srv_mute(self, req):
        with self.lock:
            message = self.core.handle.mute(bool(req.data))
        return SetBoolResponse(True, message)

    def srv_setup_motor_controller(self, req):
        with self.lock:
            status, message = self.core.handle.setup_motor_controller(req.can_id, req.setup_id, req.setup_value)
        return MotorControllerSetupResponse(status, message)

    def srv_set_home_count(self, req):
        with self.lock:
            status, message = self.core.handle.set_home_count_current_pos_zero(req.can_id)
        return CanIDResponse(status, message)

    def _relay_service(self, io_id, relay):
        def call(req):
            try:
                with self.lock:
                    message = self.core.handle.set_relay(io_id, relay, bool(req.data))
            except ThorvaldBaseError as e:
                return SetBoolResponse(False, str(e))
            return SetBoolResponse(True, message)

        return call

    def srv_home_steering(self, _req):
        with self.lock:
            message = self.core.home_steering()
        return TriggerResponse(True, message)

    def srv_reset_odom(self, _req):
        with self.lock:
            self.core.reset_odometry()
            self.covariance.reset()
        return TriggerResponse(True, "odometry pose reset to zero")

    def srv_safety_stop(self, req):
        with self.lock:
            message = self.core.safety_stop(req.data)
        rospy.logwarn(self.label + ": %s", message)
        return SetBoolResponse(True, message)

    def srv_set_drive_params(self, req):
        changes = [(p.index, p.type, p.value) for p in req.params]
        with self.lock:
            applied, problems = self.core.set_drive_params(changes)
        for problem in problems:
            rospy.logwarn(self.label + ": set_drive_params: %s", problem)
        message = f"{applied} of {len(changes)} parameter(s) applied" + ("; " + "; ".join(problems) if problems else "")
        return DriveParamsResponse(applied, message)

    # ---- the loop ----------------------------------------------------------------------------
    def spin(self):
        if self.lockstep:
            return self.spin_lockstep()
        return spin_together([self], self.rate)

    def cycle(self, now) -> bool:
        """One cycle of the loop at rospy time now: step, publish. False once the handle is closed."""
        with self.lock:
            if self.core.closed:
                return False
            result = self.core.step(now.to_sec())
            if result.odometry.valid:
                self.covariance.update(result.odometry)
        self.publish(result, now)
        if result.twist_changed:
            self.throttle.warn(self.label + ": this robot cannot realise the commanded twist; driving a realisable one")
        return True

    def spin_lockstep(self):
        """The loop in lockstep with the simulator: each arrival of drive states at instant t is either
        a cycle or answered with the last commands. The cycles are the first instants at or after
        each multiple of 1 / ~rate of simulated time, the same whenever base_driver started, so two
        runs (and two robots) cycle at the same instants; what a cycle sees is the states of its
        instant, never an older or a newer one."""
        handle = self.core.handle
        steps = LockstepCycles(self.core, self.rate)
        last = None
        while not rospy.is_shutdown():
            t = handle.wait_for_states(last, 0.2)
            if t is None:
                continue
            last = t
            if steps.due(t):
                stamp = rospy.Time.from_sec(t)
                twist = self.stamped_command(t)
                with self.lock:
                    if self.core.closed:
                        break
                    result, refused = steps.cycle(t, twist)
                    if result.odometry.valid:
                        self.covariance.update(result.odometry)
                if refused:
                    self.throttle.warn(self.label + ": cmd_vel_stamped: %s", refused)
                self.publish(result, stamp)
            else:
                with self.lock:
                    if self.core.closed:
                        break
                    steps.answer(t)

    def publish(self, result, stamp):
        # core.config, not self.config: set_drive_params may have changed r_wheel since start-up
        drives = self.core.config.drives
        change = self.odometry_watch.change(result.odometry)
        if change is not None:
            (rospy.loginfo if change[0] == OK else rospy.logwarn)(self.label + ": %s", change[1])
        channels = [d.channel for d in drives]
        # Each message is built only when somebody reads it (50 a second per topic; in a fleet the
        # building costs more than the driving): nothing is latched, so nobody misses one.
        if self.command_pub.get_num_connections():
            self.command_pub.publish(
                conversions.command_msg(stamp, result.commands, [d.max_steering_speed for d in drives], channels)
            )
        if self.state_pub.get_num_connections():
            self.state_pub.publish(conversions.state_msg(stamp, result.states, result.stopped_by == "homing", channels))
        if self.joint_pub.get_num_connections():
            self.joint_pub.publish(conversions.drive_joint_state_msg(stamp, self.joint_names, drives, result.states))
        if self.gazebo_odom is None:
            self.publish_odometry(result.odometry, stamp)
        handle = self.core.handle
        with self.lock:
            claimed, unclaimed = handle.take_received()
        for pub, frames in ((self.frames_base_pub, claimed), (self.frames_device_pub, unclaimed)):
            if frames and pub.get_num_connections():  # hundreds a second: built only when somebody reads
                for frame in frames:
                    pub.publish(conversions.frame_msg(stamp, frame))
        if self._last_status_publish is None or (stamp - self._last_status_publish).to_sec() >= STATUS_PERIOD:
            self._last_status_publish = stamp
            with self.lock:
                batteries = handle.batteries(result.time)
                controllers = handle.controllers(result.time)
                boards = handle.io_boards(result.time)
                link = handle.diagnostics(result.time)
            if batteries:
                self.battery_pub.publish(conversions.battery_array_msg(stamp, batteries))
                for b in batteries:
                    pub = self.battery_state_pubs.get(b.id)
                    if pub is not None:
                        pub.publish(conversions.battery_state_msg(stamp, self.base_frame, b))
            if controllers:
                self.controller_pub.publish(conversions.controller_array_msg(stamp, controllers))
            if boards:
                self.io_pub.publish(conversions.io_array_msg(stamp, boards))
            self.publish_diagnostics(stamp, controllers, batteries, link, result.odometry)

    def publish_diagnostics(self, stamp, controllers, batteries, link, odometry):
        """/diagnostics: one status per motor controller and battery, one for the bus, one for odometry."""
        for change in self.link_watch.changes(link):
            rospy.logwarn(self.label + ": %s", change)
        names = [d.name for d in self.core.config.drives]
        statuses = base_statuses(self.names.robot, controllers, batteries, link, odometry=odometry, drive_names=names)
        if statuses:
            msg = DiagnosticArray(
                status=[
                    conversions.diagnostic_status(st.name, st.hardware_id, st.level, st.message, dict(st.values))
                    for st in statuses
                ]
            )
            msg.header.stamp = stamp
            self.diagnostics_pub.publish(msg)

    def publish_odometry(self, odometry, stamp):
        if not odometry.valid:
            self.throttle.warn(self.label + ": odometry calculation failed (a non-finite twist)")
            return
        if self.tf is None and not self.odom_pub.get_num_connections():
            return
        msg = conversions.odometry_msg(
            stamp,
            self.odom_frame,
            self.base_frame,
            odometry,
            pose_covariance=self.covariance.pose,
            twist_covariance=self.covariance.current_twist,
        )
        self.odom_pub.publish(msg)
        if self.tf is not None:
            self.tf.sendTransform(conversions.odometry_transform(msg))

    def shutdown(self):
        """rospy's shutdown hook: the drives get a zero-speed command before the handle is closed.

        Nothing is logged here: a log message goes out on /rosout while rospy closes its publishers.
        """
        with self.lock:
            self.core.shutdown(rospy.get_time())


def spin_together(drivers, rate: float, on_failure=None, after_cycles=None) -> None:
    """The loop of one or several drivers at rate [Hz] of rospy time, one cycle each per instant,
    then after_cycles() if given (a fleet_driver sends the instant's commands on the fleet topics).

    A driver whose handle is closed leaves the loop; one whose cycle raises is handed to
    on_failure (a fleet_driver stops that robot and drives on) or, without it, stops the loop.
    """
    drivers = list(drivers)
    ticker = rospy.Rate(rate)
    last = None
    while drivers and not rospy.is_shutdown():
        now = rospy.Time.now()
        if now == last:
            # On simulated time a late cycle's rate.sleep() returns at once, before /clock moved:
            # one cycle per instant, not two identical ones.
            try:
                rospy.sleep(0.5 / rate)
            except rospy.ROSTimeMovedBackwardsException:
                last = None
            except rospy.ROSInterruptException:
                break
            continue
        last = now
        for driver in list(drivers):
            try:
                alive = driver.cycle(now)
            except Exception:
                if on_failure is None:
                    raise
                on_failure(driver)
                alive = False
            if not alive:
                drivers.remove(driver)
        if after_cycles is not None:
            after_cycles()
        try:
            ticker.sleep()
        except rospy.ROSTimeMovedBackwardsException:
            rospy.logwarn("%s: time moved backwards; odometry integration restarts", rospy.get_name())
        except rospy.ROSInterruptException:
            break


def main():
    rospy.init_node("base_driver")
    try:
        node = BaseDriverNode()
    except (ConfigError, ThorvaldBaseError) as e:
        rospy.logfatal("base_driver: refusing to start: %s", e)
        sys.exit(EXIT_REFUSED)
    rospy.on_shutdown(node.shutdown)
    # The loop in a thread of its own. rospy runs the shutdown hooks (node.shutdown, which takes the
    # lock a cycle holds) inside its SIGINT handler, in the main thread: a Ctrl-C that came while the
    # main thread's own cycle held the lock waited for it forever (one start in about ten in the
    # rostest bad_config, a node still running 30 s after SIGINT).
    failed = []

    def loop():
        try:
            node.spin()
        except Exception:  # as an uncaught exception in the main thread did: the traceback, exit 1
            failed.append(traceback.format_exc())
        finally:
            rospy.signal_shutdown("the loop ended")

    threading.Thread(target=loop, name="base_driver loop", daemon=True).start()
    rospy.spin()
    if failed:
        sys.stderr.write(failed[0])
        sys.exit(1)
