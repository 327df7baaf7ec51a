"""Messages from and to the core's values: BaseState, JointState, Odometry, batteries, controllers.

The one place where base_driver's values become ROS messages, shared by base_driver, the simulator
(which follows ``base_state``) and the CAN base. Message types only: no rospy, so it is tested
without a master. Stamps are ``rospy.Time``/``genpy.Time`` values the caller passes in.
"""

import math
from typing import List, Sequence

from geometry_msgs.msg import Quaternion, TransformStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState

from thorvald_msgs.msg import (
    BaseState,
    BatteryArray,
    BatteryData,
    Controller,
    ControllerArray,
    MotorVars,
    StatusFlag,
)

from .bases import BatteryInfo, ControllerInfo, MeasuredDrive
from .kinematics import DriveCommand, OdometryResult


def yaw_quaternion(yaw: float) -> Quaternion:
    """A rotation of yaw [rad] about z."""
    return Quaternion(0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))


def quaternion_yaw(q: Quaternion) -> float:
    """The rotation about z [rad] of a quaternion (its heading; roll and pitch are ignored)."""
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def joint_names(drives: Sequence, tf_prefix: str = "") -> List[str]:
    """``<tf_prefix>steeringN``, ``<tf_prefix>wheelN`` per drive, in drive order (the original's)."""
    names = []
    for d in drives:
        names += [tf_prefix + d.steering_name, tf_prefix + d.wheel_name]
    return names


def command_msg(stamp, drives: Sequence, commands: Sequence[DriveCommand]) -> BaseState:
    """joint_commands: what the drives were told, with each drive's steering limit and channel."""
    msg = BaseState(drive_mode=BaseState.MODE_DRIVE)
    msg.header.stamp = stamp
    msg.steer_pos = [c.steering for c in commands]
    msg.prop_speed = [c.speed for c in commands]
    msg.steer_max_speed = [d.max_steering_speed for d in drives]
    msg.channel = [d.channel for d in drives]
    return msg


def state_msg(stamp, drives: Sequence, states: Sequence[MeasuredDrive], homing: bool = False) -> BaseState:
    """base_state: the measured (or simulated) state of every drive."""
    msg = BaseState(drive_mode=BaseState.MODE_HOME if homing else BaseState.MODE_DRIVE)
    msg.header.stamp = stamp
    msg.prop_speed = [s.speed for s in states]
    msg.prop_pos = [s.wheel_angle for s in states]
    msg.steer_speed = [s.steering_speed for s in states]
    msg.steer_pos = [s.steering for s in states]
    msg.channel = [d.channel for d in drives]
    return msg


def measured_drives(msg: BaseState) -> List[MeasuredDrive]:
    """The drive states a BaseState carries (what a simulator following base_state reads)."""
    n = len(msg.steer_pos)
    lengths = (n, len(msg.prop_speed), len(msg.prop_pos), len(msg.steer_speed))
    if len(set(lengths)) != 1:
        raise ValueError(
            "BaseState arrays differ in length: steer_pos, prop_speed, prop_pos, steer_speed = {}, {}, {}, {}".format(
                *lengths
            )
        )
    return [
        MeasuredDrive(a, v, p, w) for a, v, p, w in zip(msg.steer_pos, msg.prop_speed, msg.prop_pos, msg.steer_speed)
    ]


def joint_state_msg(stamp, names: Sequence[str], drives: Sequence, states: Sequence[MeasuredDrive]) -> JointState:
    """joint_states: per drive the steering (angle, rate) then the wheel (angle, angular speed)."""
    msg = JointState(name=list(names))
    msg.header.stamp = stamp
    for d, s in zip(drives, states):
        msg.position += [s.steering, s.wheel_angle]
        msg.velocity += [s.steering_speed, s.speed / d.r_wheel]
    return msg


def odometry_msg(
    stamp, odom_frame: str, base_frame: str, odometry: OdometryResult, *, pose_covariance, twist_covariance
) -> Odometry:
    """odometry/base_raw: pose in odom_frame, twist in base_frame."""
    msg = Odometry()
    msg.header.stamp = stamp
    msg.header.frame_id = odom_frame
    msg.child_frame_id = base_frame
    p, t = odometry.pose, odometry.twist
    msg.pose.pose.position.x, msg.pose.pose.position.y = p.x, p.y
    msg.pose.pose.orientation = yaw_quaternion(p.yaw)
    msg.pose.covariance = list(pose_covariance)
    msg.twist.twist.linear.x, msg.twist.twist.linear.y, msg.twist.twist.angular.z = t.vx, t.vy, t.wz
    msg.twist.covariance = list(twist_covariance)
    return msg


def odometry_transform(msg: Odometry) -> TransformStamped:
    """The transform header.frame_id -> child_frame_id an Odometry message describes."""
    tf = TransformStamped()
    tf.header = msg.header
    tf.child_frame_id = msg.child_frame_id
    position = msg.pose.pose.position
    tf.transform.translation.x, tf.transform.translation.y, tf.transform.translation.z = (
        position.x,
        position.y,
        position.z,
    )
    tf.transform.rotation = msg.pose.pose.orientation
    return tf


def battery_array_msg(stamp, batteries: Sequence[BatteryInfo]) -> BatteryArray:
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
            if not hasattr(data.battery_alarms, alarm):
                raise ValueError(f"unknown battery alarm {alarm!r}")
            setattr(data.battery_alarms, alarm, True)
        msg.batteries.append(data)
    return msg


def controller_array_msg(stamp, controllers: Sequence[ControllerInfo]) -> ControllerArray:
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
    return msg
