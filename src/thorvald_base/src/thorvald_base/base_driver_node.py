"""The ``base_driver`` node (paper section 3.1; the original's ROS interface, notes section 2).

Private parameters: the robot configuration (``base_calculator``, ``motor_drives``, ...), loaded
from the robot's YAML by base_bringup.launch, and the node's own:

=============================  ===============================================================
``~robot_model``               path of the YAML, named in configuration errors (optional)
``~simple_sim``                simulate the drives (true) or drive the real base over CAN
``~tf_prefix``                 prefix of frame and joint names, concatenated (``robot_1/``)
``~enable_odom_tf``            broadcast odom -> base_link (default true)
``~odom_frame_id``             default ``odom``
``~passthrough_gazebo_odometry``  republish ``odometry/gazebo`` (a simulator's ground truth) on
                               ``odometry/base_raw`` once it arrives (default false)
``~rate``                      control loop rate [Hz] (default 50)
``~command_timeout``           a command older than this stops the wheels [s] (default 0.5)
``~twist_covariance``          36 values; default diagonal 0.001 x 5, 0.03 for the yaw rate
``~estimator``                 odometry: ``lsq`` (default) or ``paper``
``~projection``                unrealisable twists on a fixed axle: ``axle`` (default) or ``lsq``
``~can_interface_type/name``   the CAN line of a real base
=============================  ===============================================================
"""

import math
import sys
import threading

import rospy
import tf2_ros
from geometry_msgs.msg import TransformStamped, Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState
from std_srvs.srv import SetBool, SetBoolResponse, Trigger, TriggerResponse

from thorvald_model import ConfigError, parse_robot_config
from thorvald_msgs.msg import (
    BaseState,
    BatteryArray,
    BatteryData,
    Controller,
    ControllerArray,
    MotorVars,
    StatusFlag,
)
from thorvald_msgs.srv import DriveParams, DriveParamsResponse

from .base import BaseDriverCore, SimulatedBase
from .errors import ThorvaldBaseError
from .plugins import load_calculator

NODE_PARAMS = (
    "robot_model",
    "simple_sim",
    "tf_prefix",
    "enable_odom_tf",
    "odom_frame_id",
    "passthrough_gazebo_odometry",
    "rate",
    "command_timeout",
    "twist_covariance",
    "estimator",
    "projection",
    "can_interface_type",
    "can_interface_name",
    "joint_states_remap_to",
)
DEFAULT_TWIST_COVARIANCE = [0.0] * 36
for _i, _v in enumerate((0.001, 0.001, 0.001, 0.001, 0.001, 0.03)):
    DEFAULT_TWIST_COVARIANCE[_i * 7] = _v
MOVING = 0.005  # [m/s], [rad/s]: faster than this, the pose covariance grows (the original's rule)
WARN_PERIOD = 5.0  # [s] between repeats of one warning


def set_yaw(quaternion, yaw):
    """Fills a geometry_msgs/Quaternion with a rotation of yaw [rad] about z."""
    quaternion.x, quaternion.y = 0.0, 0.0
    quaternion.z, quaternion.w = math.sin(yaw / 2.0), math.cos(yaw / 2.0)


class BaseDriverNode:
    def __init__(self):
        params = rospy.get_param("~", {})
        source = params.get("robot_model") or rospy.resolve_name("~") + " parameters"
        self.config = parse_robot_config(params, source, ignore=NODE_PARAMS)
        self.tf_prefix = str(params.get("tf_prefix", ""))
        self.odom_frame = str(params.get("odom_frame_id", "odom"))
        self.base_frame = self.tf_prefix + "base_link"
        self.enable_tf = bool(params.get("enable_odom_tf", True))
        self.rate = float(params.get("rate", 50.0))
        if not self.rate > 0:
            raise ThorvaldBaseError(f"~rate: {self.rate!r}: must be > 0 [Hz]")
        cov = params.get("twist_covariance", DEFAULT_TWIST_COVARIANCE)
        if not isinstance(cov, list) or len(cov) != 36 or not all(isinstance(v, (int, float)) for v in cov):
            raise ThorvaldBaseError(f"~twist_covariance: {cov!r}: must be a list of 36 numbers (row-major 6x6)")
        self.twist_cov = [float(v) for v in cov]
        self.pose_cov = list(self.twist_cov)

        if not params.get("simple_sim", False):
            raise ThorvaldBaseError(
                "~simple_sim: false: the CAN base is not available yet; set simple_sim:=true to simulate the drives"
            )
        handle = SimulatedBase(self.config)
        calculator = load_calculator(
            self.config,
            estimator=str(params.get("estimator", "lsq")),
            projection=str(params.get("projection", "axle")),
        )
        self.core = BaseDriverCore(
            self.config, calculator, handle, command_timeout=float(params.get("command_timeout", 0.5))
        )
        self.lock = threading.Lock()
        self.joint_names = []
        for d in self.config.drives:
            self.joint_names += [self.tf_prefix + d.steering_name, self.tf_prefix + d.wheel_name]

        self.odom_pub = rospy.Publisher("odometry/base_raw", Odometry, queue_size=10)
        self.joint_pub = rospy.Publisher("joint_states", JointState, queue_size=10)
        self.state_pub = rospy.Publisher("base_state", BaseState, queue_size=10)
        self.command_pub = rospy.Publisher("joint_commands", BaseState, queue_size=10)
        self.battery_pub = rospy.Publisher("battery_data", BatteryArray, queue_size=1)
        self.controller_pub = rospy.Publisher("motor_controller_data", ControllerArray, queue_size=1)
        self.tf = tf2_ros.TransformBroadcaster() if self.enable_tf else None
        self.gazebo_odom = None
        if params.get("passthrough_gazebo_odometry", False):
            rospy.Subscriber("odometry/gazebo", Odometry, self.on_gazebo_odometry, queue_size=10)
        rospy.Subscriber("cmd_vel", Twist, self.on_cmd_vel, queue_size=1)
        rospy.Service("~home_steering", Trigger, self.srv_home_steering)
        rospy.Service("~reset_base_odom", Trigger, self.srv_reset_odom)
        rospy.Service("~safety_stop", SetBool, self.srv_safety_stop)
        rospy.Service("~set_drive_params", DriveParams, self.srv_set_drive_params)
        self._last_status_publish = None
        rospy.loginfo(
            "base_driver: %d drives, calculator %s, simulated base, %.0f Hz, odom tf %s",
            len(self.config.drives),
            self.config.base_calculator,
            self.rate,
            "on" if self.enable_tf else "off",
        )

    # ---- callbacks: message -> core -> message -----------------------------------------------
    def on_cmd_vel(self, msg):
        with self.lock:
            refused = self.core.set_command(msg.linear.x, msg.linear.y, msg.angular.z, rospy.get_time())
        if refused:
            rospy.logwarn_throttle(WARN_PERIOD, "base_driver: %s", refused)

    def on_gazebo_odometry(self, msg):
        if self.gazebo_odom is None:
            rospy.logwarn("Switching to using Gazebo odometry for odometry/base_raw (passthrough_gazebo_odometry)")
        msg.header.frame_id = self.odom_frame
        self.gazebo_odom = msg
        self.odom_pub.publish(msg)

    def srv_home_steering(self, _req):
        with self.lock:
            message = self.core.home_steering()
        return TriggerResponse(True, message)

    def srv_reset_odom(self, _req):
        with self.lock:
            self.core.reset_odometry()
            self.pose_cov = list(self.twist_cov)
        return TriggerResponse(True, "odometry pose reset to zero")

    def srv_safety_stop(self, req):
        with self.lock:
            message = self.core.safety_stop(req.data)
        rospy.logwarn("base_driver: %s", message)
        return SetBoolResponse(True, message)

    def srv_set_drive_params(self, req):
        changes = [(p.index, p.type, p.value) for p in req.params]
        with self.lock:
            applied, problems = self.core.set_drive_params(changes)
        for problem in problems:
            rospy.logwarn("base_driver: set_drive_params: %s", problem)
        message = f"{applied} of {len(changes)} parameter(s) applied" + ("; " + "; ".join(problems) if problems else "")
        return DriveParamsResponse(applied, message)

    # ---- the loop ----------------------------------------------------------------------------
    def spin(self):
        rate = rospy.Rate(self.rate)
        while not rospy.is_shutdown():
            now = rospy.Time.now()
            with self.lock:
                result = self.core.step(now.to_sec())
            self.publish(result, now)
            if result.twist_changed:
                rospy.logwarn_throttle(
                    WARN_PERIOD, "base_driver: this robot cannot realise the commanded twist; driving the closest one"
                )
            try:
                rate.sleep()
            except rospy.ROSTimeMovedBackwardsException:
                rospy.logwarn("base_driver: time moved backwards; odometry integration restarts")
            except rospy.ROSInterruptException:
                break

    def publish(self, result, stamp):
        commands = BaseState(drive_mode=BaseState.MODE_DRIVE)
        commands.header.stamp = stamp
        commands.steer_pos = [c.steering for c in result.commands]
        commands.prop_speed = [c.speed for c in result.commands]
        commands.channel = [1] * len(result.commands)
        self.command_pub.publish(commands)

        state = BaseState(drive_mode=BaseState.MODE_HOME if result.stopped_by == "homing" else BaseState.MODE_DRIVE)
        state.header.stamp = stamp
        state.prop_speed = [s.speed for s in result.states]
        state.prop_pos = [s.wheel_angle for s in result.states]
        state.steer_speed = [s.steering_speed for s in result.states]
        state.steer_pos = [s.steering for s in result.states]
        self.state_pub.publish(state)

        joints = JointState(name=self.joint_names)
        joints.header.stamp = stamp
        # core.config, not self.config: set_drive_params may have changed r_wheel since start-up
        for d, s in zip(self.core.config.drives, result.states):
            joints.position += [s.steering, s.wheel_angle]
            joints.velocity += [s.steering_speed, s.speed / d.r_wheel]
        self.joint_pub.publish(joints)

        if self.gazebo_odom is None:
            self.publish_odometry(result.odometry, stamp)

        if self._last_status_publish is None or (stamp - self._last_status_publish).to_sec() >= 1.0:
            self._last_status_publish = stamp
            self.publish_status(result.time, stamp)

    def publish_odometry(self, odom, stamp):
        if not odom.valid:
            rospy.logwarn_throttle(WARN_PERIOD, "base_driver: odometry calculation failed (non-finite drive states)")
            return
        t, p = odom.twist, odom.pose
        if abs(t.vx) > MOVING or abs(t.vy) > MOVING or abs(t.wz) > MOVING:
            # Rate-independent growth: the twist covariance per second of motion.
            self.pose_cov = [a + b * odom.dt for a, b in zip(self.pose_cov, self.twist_cov)]
        msg = Odometry()
        msg.header.stamp = stamp
        msg.header.frame_id = self.odom_frame
        msg.child_frame_id = self.base_frame
        msg.pose.pose.position.x, msg.pose.pose.position.y = p.x, p.y
        set_yaw(msg.pose.pose.orientation, p.yaw)
        msg.pose.covariance = self.pose_cov
        msg.twist.twist.linear.x, msg.twist.twist.linear.y, msg.twist.twist.angular.z = t.vx, t.vy, t.wz
        msg.twist.covariance = self.twist_cov
        self.odom_pub.publish(msg)
        if self.tf is not None:
            tf = TransformStamped()
            tf.header = msg.header
            tf.child_frame_id = self.base_frame
            tf.transform.translation.x, tf.transform.translation.y = p.x, p.y
            set_yaw(tf.transform.rotation, p.yaw)
            self.tf.sendTransform(tf)

    def publish_status(self, time, stamp):
        handle = self.core.handle
        batteries = handle.batteries(time)
        if batteries:
            msg = BatteryArray()
            msg.header.stamp = stamp
            for b in batteries:
                data = BatteryData(
                    battery_id=b.id,
                    battery_state=b.state,
                    state_of_charge=b.state_of_charge,
                    state_of_health=b.state_of_health,
                    battery_voltage=b.voltage,
                    battery_current=b.current,
                    charge_fet_on=b.charge_fet_on,
                    discharge_fet_on=b.discharge_fet_on,
                    cycle_count=b.cycle_count,
                    battery_capacity=b.capacity,
                    temperatures=list(b.temperatures),
                )
                for alarm in b.alarms:
                    setattr(data.battery_alarms, alarm, True)
                msg.batteries.append(data)
            self.battery_pub.publish(msg)
        controllers = handle.controllers(time)
        if controllers:
            msg = ControllerArray()
            msg.header.stamp = stamp
            for c in controllers:
                msg.controllers.append(
                    Controller(
                        name=c.name,
                        type=c.type,
                        version=c.version,
                        can_id=c.can_id,
                        controller_mode=c.mode,
                        battery_volts=c.battery_volts,
                        battery_amps=c.battery_amps,
                        temps=list(c.temps),
                        status_flags=[StatusFlag(n, v) for n, v in c.status_flags],
                        motor_vars=[MotorVars(*v) for v in c.motor_vars],
                    )
                )
            self.controller_pub.publish(msg)

    def shutdown(self):
        with self.lock:
            self.core.safety_stop(True)
            self.core.handle.close()


def main():
    rospy.init_node("base_driver")
    try:
        node = BaseDriverNode()
    except ConfigError as e:
        rospy.logfatal("base_driver: refusing to start: %s", e)
        sys.exit(1)
    except ThorvaldBaseError as e:
        rospy.logfatal("base_driver: refusing to start: %s", e)
        sys.exit(1)
    rospy.on_shutdown(node.shutdown)
    node.spin()
