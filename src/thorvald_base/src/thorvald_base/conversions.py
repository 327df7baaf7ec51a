"""Messages from and to the core's values: BaseState, DriveCurrents, JointState, Odometry, batteries,
controllers.

The one place where base_driver's values become ROS messages, shared by base_driver, the simulator
(which follows ``base_state``) and the CAN base. Message types only: no rospy, so it is tested
without a master. Stamps are ``rospy.Time``/``genpy.Time`` values the caller passes in.
"""

import math
from typing import Any, Dict, List, Sequence, Tuple

from diagnostic_msgs.msg import DiagnosticStatus, KeyValue
from geometry_msgs.msg import Quaternion, TransformStamped, Twist, TwistStamped
from nav_msgs.msg import Odometry
from sensor_msgs.msg import BatteryState, JointState
from std_msgs.msg import Header

from thorvald_msgs.msg import (
    BaseState,
    BatteryArray,
    BatteryData,
    CANFrame,
    Controller,
    ControllerArray,
    DriveCurrents,
    IOArray,
    IOData,
    MotorVars,
    StatusFlag,
)

from .bases import BatteryInfo, ControllerInfo, Frame, IoInfo, MeasuredDrive
from .kinematics import DriveCommand, OdometryResult
from .modes import BATTERY_LOST


def yaw_quaternion(yaw: float) -> Quaternion:
    """A rotation of yaw [rad] about z."""
    return Quaternion(0.0, 0.0, math.sin(yaw / 2.0), math.cos(yaw / 2.0))


def quaternion_yaw(q: Quaternion) -> float:
    """The rotation about z [rad] of a quaternion (its heading; roll and pitch are ignored)."""
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def joint_names(drives: Sequence, tf_prefix: str = "") -> List[str]:
    """``<tf_prefix>steeringN``, ``<tf_prefix>wheelN`` per drive, in drive order (the original's).

    Only joints the description moves: a drive that cannot steer (type 1) has a fixed steering
    joint, which robot_state_publisher would warn about in every message.
    """
    names = []
    for d in drives:
        if d.steerable:
            names.append(tf_prefix + d.steering_name)
        names.append(tf_prefix + d.wheel_name)
    return names


def command_msg(
    stamp, commands: Sequence[DriveCommand], max_steering_speeds: Sequence[float] = (), channels: Sequence[int] = ()
) -> BaseState:
    """Drive commands (joint_commands, drive_commands): steering and speed per drive, with each
    drive's steering speed limit [rad/s] and its motor channel."""
    msg = BaseState(drive_mode=BaseState.MODE_DRIVE)
    msg.header.stamp = stamp
    msg.steer_pos = [c.steering for c in commands]
    msg.prop_speed = [c.speed for c in commands]
    msg.steer_max_speed = list(max_steering_speeds)
    msg.channel = list(channels)
    return msg


def state_msg(stamp, states: Sequence[MeasuredDrive], homing: bool = False, channels: Sequence[int] = ()) -> BaseState:
    """Measured (or simulated) drive states (base_state, drive_states). An unheard drive's speeds are
    NaN: its last report is no measurement of how it moves now (its angles stay the last heard)."""
    msg = BaseState(drive_mode=BaseState.MODE_HOME if homing else BaseState.MODE_DRIVE)
    msg.header.stamp = stamp
    msg.prop_speed = [s.speed if s.heard else math.nan for s in states]
    msg.prop_pos = [s.wheel_angle for s in states]
    msg.steer_speed = [s.steering_speed if s.heard else math.nan for s in states]
    msg.steer_pos = [s.steering for s in states]
    msg.channel = list(channels)
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


def currents_msg(stamp, prop_amps: Sequence[float], steer_amps: Sequence[float]) -> DriveCurrents:
    """Each drive's motor currents [A], in drive order (drive_currents)."""
    msg = DriveCurrents(prop_amps=list(prop_amps), steer_amps=list(steer_amps))
    msg.header.stamp = stamp
    return msg


def batch_msg(kind, stamp, entries):
    """Several robots' messages in one (kind: BaseStateBatch or DriveCurrentsBatch, the simulator's
    fleet topics); entries: (the per-robot topic a message stands for, the message)."""
    msg = kind(topics=[topic for topic, _ in entries], messages=[m for _, m in entries])
    msg.header.stamp = stamp
    return msg


def batch_entries(msg) -> List[Tuple[str, Any]]:
    """(per-robot topic, message) of each entry of a batch; ValueError when its topics and messages
    differ in number."""
    if len(msg.topics) != len(msg.messages):
        raise ValueError(f"{len(msg.topics)} topics for {len(msg.messages)} messages")
    return list(zip(msg.topics, msg.messages))


def drive_currents(msg: DriveCurrents) -> Tuple[List[float], List[float]]:
    """(propulsion, steering) motor currents [A] per drive a DriveCurrents carries."""
    n, m = len(msg.prop_amps), len(msg.steer_amps)
    if n != m:
        raise ValueError(f"DriveCurrents arrays differ in length: prop_amps, steer_amps = {n}, {m}")
    return list(msg.prop_amps), list(msg.steer_amps)


def joint_state_msg(stamp, names: Sequence[str], positions: Sequence[float], velocities: Sequence[float]) -> JointState:
    msg = JointState(name=list(names), position=list(positions), velocity=list(velocities))
    msg.header.stamp = stamp
    return msg


def drive_joint_state_msg(stamp, names: Sequence[str], drives: Sequence, states: Sequence[MeasuredDrive]) -> JointState:
    """joint_states of the drives: per drive the steering (angle, rate) then the wheel (angle, angular
    speed); names as :func:`joint_names` gives them (no steering for a drive that cannot steer)."""
    positions, velocities = [], []
    for d, s in zip(drives, states):
        if d.steerable:
            positions.append(s.steering)
            velocities.append(s.steering_speed)
        positions.append(s.wheel_angle)
        velocities.append(s.speed / d.r_wheel)
    return joint_state_msg(stamp, names, positions, velocities)


def odometry_msg(
    stamp, odom_frame: str, base_frame: str, odometry: OdometryResult, *, pose_covariance, twist_covariance
) -> Odometry:
    """odometry/base_raw: the planar pose in odom_frame, the twist in base_frame."""
    p, t = odometry.pose, odometry.twist
    q = yaw_quaternion(p.yaw)
    return pose_odometry_msg(
        stamp,
        odom_frame,
        base_frame,
        position=(p.x, p.y, 0.0),
        orientation=(q.x, q.y, q.z, q.w),
        linear=(t.vx, t.vy, 0.0),
        angular=(0.0, 0.0, t.wz),
        pose_covariance=pose_covariance,
        twist_covariance=twist_covariance,
    )


def pose_odometry_msg(
    stamp,
    frame: str,
    child_frame: str,
    *,
    position,
    orientation,
    linear,
    angular,
    pose_covariance=None,
    twist_covariance=None,
) -> Odometry:
    """An Odometry of a full pose (position [m], quaternion x y z w) in frame and a twist (linear
    [m/s], angular [rad/s]) in child_frame: a simulator's ground truth on any ground."""
    msg = Odometry()
    msg.header.stamp = stamp
    msg.header.frame_id = frame
    msg.child_frame_id = child_frame
    pose = msg.pose.pose
    pose.position.x, pose.position.y, pose.position.z = position
    pose.orientation = Quaternion(*orientation)
    twist = msg.twist.twist
    twist.linear.x, twist.linear.y, twist.linear.z = linear
    twist.angular.x, twist.angular.y, twist.angular.z = angular
    if pose_covariance is not None:
        msg.pose.covariance = list(pose_covariance)
    if twist_covariance is not None:
        msg.twist.covariance = list(twist_covariance)
    return msg


def twist_msg(twist: Sequence[float]) -> Twist:
    """A planar twist (vx [m/s], vy [m/s], wz [rad/s]) as a Twist."""
    msg = Twist()
    msg.linear.x, msg.linear.y, msg.angular.z = twist
    return msg


def twist_stamped_msg(stamp, twist: Sequence[float]) -> TwistStamped:
    """A planar twist stamped with the instant it holds from."""
    msg = TwistStamped()
    msg.header.stamp = stamp
    msg.twist = twist_msg(twist)
    return msg


def transform_msg(stamp, parent: str, child: str, transform) -> TransformStamped:
    """parent -> child as a TransformStamped; transform: ((x, y, z), (qx, qy, qz, qw))."""
    (x, y, z), (qx, qy, qz, qw) = transform
    t = TransformStamped()
    t.header.stamp = stamp
    t.header.frame_id = parent
    t.child_frame_id = child
    t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = x, y, z
    r = t.transform.rotation
    r.x, r.y, r.z, r.w = qx, qy, qz, qw
    return t


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
                drive_direction=c.drive_direction,
                home_speed=c.home_speed,
                home_count=c.home_count,
                controller_mode=c.mode,
                battery_volts=c.battery_volts,
                battery_amps=c.battery_amps,
                temps=list(c.temps),
                status_flags=[StatusFlag(n, v) for n, v in c.status_flags],
                motor_vars=[MotorVars(*v) for v in c.motor_vars],
            )
        )
    return msg


def battery_state_msg(stamp, frame_id: str, b: BatteryInfo) -> BatteryState:
    """sensor_msgs/BatteryState of one battery (voltage, current, charge as a fraction, health)."""
    msg = BatteryState()
    msg.header.stamp = stamp
    msg.header.frame_id = frame_id
    msg.voltage = b.voltage
    msg.current = b.current
    msg.charge = math.nan
    msg.capacity = b.capacity if b.capacity > 0 else math.nan
    msg.design_capacity = math.nan
    msg.percentage = b.state_of_charge / 100.0
    msg.temperature = max(b.temperatures) if b.temperatures else math.nan
    msg.power_supply_technology = BatteryState.POWER_SUPPLY_TECHNOLOGY_LION
    msg.present = b.state != BATTERY_LOST
    if b.state == BATTERY_LOST:
        msg.power_supply_status = BatteryState.POWER_SUPPLY_STATUS_UNKNOWN
        msg.power_supply_health = BatteryState.POWER_SUPPLY_HEALTH_UNKNOWN
    else:
        msg.power_supply_status = (
            BatteryState.POWER_SUPPLY_STATUS_CHARGING if b.current > 0 else BatteryState.POWER_SUPPLY_STATUS_DISCHARGING
        )
        msg.power_supply_health = (
            BatteryState.POWER_SUPPLY_HEALTH_GOOD if not b.alarms else BatteryState.POWER_SUPPLY_HEALTH_UNSPEC_FAILURE
        )
    msg.location = f"battery {b.id}"
    return msg


def io_array_msg(stamp, boards: Sequence[IoInfo]) -> IOArray:
    msg = IOArray()
    msg.header.stamp = stamp
    msg.ios = [IOData(b.id, b.type, list(b.relays), list(b.analog), b.online) for b in boards]
    return msg


def frame_msg(stamp, frame: Frame) -> CANFrame:
    data = bytes(frame.data[:8])
    return CANFrame(
        header=Header(stamp=stamp),
        id=frame.id,
        length=len(data),
        data=data + bytes(8 - len(data)),
        is_extended=frame.is_extended,
        is_remote=frame.is_remote,
    )


def frame_of(msg: CANFrame) -> Frame:
    """A relayed CANFrame as the handle takes it; ValueError when it cannot be a CAN frame."""
    if not 0 <= msg.length <= 8:
        raise ValueError(f"length {msg.length}: a CAN frame carries 0..8 bytes")
    limit = 0x1FFFFFFF if msg.is_extended else 0x7FF
    if not 0 <= msg.id <= limit:
        raise ValueError(f"id 0x{msg.id:X}: above 0x{limit:X} for a {'29' if msg.is_extended else '11'}-bit frame")
    return Frame(msg.id, bytes(bytearray(msg.data))[: msg.length], msg.is_extended, msg.is_remote)


def diagnostic_status(name: str, hardware_id: str, level: int, message: str, values: Dict[str, str]):
    return DiagnosticStatus(
        level=level,
        name=name,
        message=message,
        hardware_id=hardware_id,
        values=[KeyValue(k, str(v)) for k, v in values.items()],
    )
