"""Message conversions (thorvald_base.conversions): the message types, no ROS master."""

import math
import xml.etree.ElementTree as ET

import pytest
from base_test_helpers import EXAMPLE_ROBOTS
from genpy import Time
from sensor_msgs.msg import BatteryState

from thorvald_base import conversions
from thorvald_base.bases import BatteryInfo, ControllerInfo, Frame, IoInfo, MeasuredDrive
from thorvald_base.kinematics import DriveCommand, OdometryResult, Pose, Twist
from thorvald_model import load_robot_config
from thorvald_model.description import generate_urdf
from thorvald_msgs.msg import CANFrame

STAMP = Time(12, 500)


def robot(name):
    return load_robot_config(next(p for p in EXAMPLE_ROBOTS if p.endswith(name + ".yaml")))


def test_the_core_modes_are_the_messages_modes():
    """thorvald_base.modes holds the message constants for the pure core: the same numbers."""
    from thorvald_base import modes  # noqa: PLC0415
    from thorvald_msgs.msg import BaseState, BatteryData  # noqa: PLC0415

    for name in ("DRIVE", "HOME", "DECOUPLED", "ONLINE", "LOST_CONNECTION", "PRE_INITIATION"):
        assert getattr(modes, "MODE_" + name) == getattr(BaseState, "MODE_" + name), name
    assert (modes.BATTERY_OK, modes.BATTERY_ALARM, modes.BATTERY_LOST) == (
        BatteryData.STATE_OK,
        BatteryData.STATE_ALARM,
        BatteryData.STATE_LOST_CONNECTION,
    )


def test_joint_commands_carry_steering_limit_and_channel():
    diff = robot("thorvald_ii_2wd_diff")
    msg = conversions.command_msg(
        STAMP,
        [DriveCommand(0.0, 0.3), DriveCommand(0.0, -0.3)],
        [d.max_steering_speed for d in diff.drives],
        [d.channel for d in diff.drives],
    )
    # the two type-1 drives share node 1: channels 1 and 2; they cannot steer
    assert list(msg.channel) == [1, 2] and list(msg.steer_max_speed) == [0.0, 0.0]
    assert list(msg.prop_speed) == [0.3, -0.3] and msg.header.stamp == STAMP
    tall = robot("thorvald_ii_4wd2ws_tall")
    msg = conversions.command_msg(
        STAMP,
        [DriveCommand(0.1, 0.2)] * 4,
        [d.max_steering_speed for d in tall.drives],
        [d.channel for d in tall.drives],
    )
    # two steered drives (str_sim_v 4 rad/s, a controller each), two type-1 drives on one node
    assert list(msg.steer_max_speed) == [4.0, 4.0, 0.0, 0.0]
    assert list(msg.channel) == [1, 1, 1, 2]


def test_base_state_round_trip():
    config = robot("thorvald_ii_4wd4ws_std")
    states = [MeasuredDrive(0.1 * k, 0.5, 2.0 + k, -0.2) for k in range(4)]
    msg = conversions.state_msg(STAMP, states, homing=True, channels=[d.channel for d in config.drives])
    assert msg.drive_mode == msg.MODE_HOME and list(msg.channel) == [1, 1, 1, 1]
    assert conversions.measured_drives(msg) == states
    msg.prop_pos = msg.prop_pos[:3]
    with pytest.raises(ValueError, match="differ in length"):
        conversions.measured_drives(msg)


def test_drive_currents_round_trip():
    msg = conversions.currents_msg(STAMP, [1.5, -0.6, 0.0], [0.4, 0.0, -2.0])
    assert msg.header.stamp == STAMP
    assert conversions.drive_currents(msg) == ([1.5, -0.6, 0.0], [0.4, 0.0, -2.0])
    msg.steer_amps = msg.steer_amps[:2]
    with pytest.raises(ValueError, match="prop_amps, steer_amps = 3, 2"):
        conversions.drive_currents(msg)


def test_joint_states_give_wheel_angular_speed():
    config = robot("thorvald_ii_4wd4ws_std")
    names = conversions.joint_names(config.drives, "robot_1/")
    assert names[:2] == ["robot_1/steering0", "robot_1/wheel0"] and len(names) == 8
    states = [MeasuredDrive(0.3, 0.5, 1.0, 0.1)] * 4
    msg = conversions.drive_joint_state_msg(STAMP, names, config.drives, states)
    # wheel angular speed = rim speed / r_wheel = 0.5 / 0.2
    assert list(msg.position[:2]) == [0.3, 1.0] and list(msg.velocity[:2]) == [0.1, 2.5]


def test_joint_states_name_only_joints_the_description_moves():
    """A type-1 drive's steering joint is fixed in the description: robot_state_publisher warns for
    every joint_states message that names it, so base_driver leaves it out."""
    config = robot("thorvald_ii_2wd_diff")
    names = conversions.joint_names(config.drives, "r/")
    assert names == ["r/wheel0", "r/wheel1"]
    urdf = ET.fromstring(generate_urdf(config.source, tf_prefix="r/"))
    moving = {j.get("name") for j in urdf.findall("joint") if j.get("type") != "fixed"}
    assert set(names) <= moving
    states = [MeasuredDrive(0.0, 0.4, 1.5, 0.0), MeasuredDrive(0.0, -0.4, -1.5, 0.0)]
    msg = conversions.drive_joint_state_msg(STAMP, names, config.drives, states)
    # wheel angle, then rim speed / r_wheel per wheel
    r = config.drives[0].r_wheel
    assert list(msg.name) == names
    assert list(msg.position) == [1.5, -1.5] and list(msg.velocity) == [0.4 / r, -0.4 / r]


def test_odometry_and_its_transform():
    odom = OdometryResult(Twist(0.5, 0.1, 0.2), Pose(1.0, -2.0, 2.5), 0.0, 0.02)
    msg = conversions.odometry_msg(
        STAMP, "odom", "r/base_link", odom, pose_covariance=[0.0] * 36, twist_covariance=[1.0] * 36
    )
    assert (msg.header.frame_id, msg.child_frame_id) == ("odom", "r/base_link")
    assert conversions.quaternion_yaw(msg.pose.pose.orientation) == pytest.approx(2.5)
    q = msg.pose.pose.orientation
    assert math.hypot(math.hypot(q.x, q.y), math.hypot(q.z, q.w)) == pytest.approx(1.0)
    assert (msg.twist.twist.linear.x, msg.twist.twist.linear.y, msg.twist.twist.angular.z) == (0.5, 0.1, 0.2)
    tf = conversions.odometry_transform(msg)
    assert (tf.header.frame_id, tf.child_frame_id) == ("odom", "r/base_link")
    assert (tf.transform.translation.x, tf.transform.translation.y) == (1.0, -2.0)
    assert tf.transform.rotation == q


def test_a_full_pose_for_ground_truth():
    msg = conversions.pose_odometry_msg(
        STAMP,
        "r/odom",
        "r/base_link",
        position=(1.0, 2.0, 0.3),
        orientation=(0.0, 0.0, 0.0, 1.0),
        linear=(0.5, 0.0, 0.1),
        angular=(0.0, 0.2, 0.3),
    )
    assert (msg.pose.pose.position.z, msg.twist.twist.linear.z, msg.twist.twist.angular.y) == (0.3, 0.1, 0.2)
    assert msg.pose.pose.orientation.w == 1.0 and len(msg.pose.covariance) == 36


def test_batteries_and_controllers():
    msg = conversions.battery_array_msg(
        STAMP, [BatteryInfo(1, 1, 80.0, 95.0, 47.5, 3.0, alarms=("over_voltage_protection", "bms_fail"))]
    )
    b = msg.batteries[0]
    assert (b.battery_id, b.battery_state, b.battery_alarms.bms_fail, b.battery_alarms.short_circuit_discharge) == (
        1,
        1,
        True,
        False,
    )
    with pytest.raises(ValueError, match="unknown battery alarm 'melting'"):
        conversions.battery_array_msg(STAMP, [BatteryInfo(1, 1, 80.0, 95.0, 47.5, 3.0, alarms=("melting",))])
    info = ControllerInfo(
        "drive0", "t", "v", 1, 3, status_flags=(("stall", True),), motor_vars=(("propulsion", 0.5, 1.0, 2.0, 0.1),)
    )
    c = conversions.controller_array_msg(STAMP, [info]).controllers[0]
    assert (c.name, c.can_id, c.controller_mode) == ("drive0", 1, 3)
    assert (c.status_flags[0].status_name, c.status_flags[0].status_value) == ("stall", True)
    assert (c.motor_vars[0].type, c.motor_vars[0].motor_amps) == ("propulsion", 2.0)


def test_relayed_frames_both_ways():
    msg = conversions.frame_msg(Time(3, 0), Frame(0x185, bytes([1, 2, 3])))
    assert (msg.id, msg.length, bytes(bytearray(msg.data))) == (0x185, 3, bytes([1, 2, 3, 0, 0, 0, 0, 0]))
    assert msg.header.stamp == Time(3, 0)
    # what code written for the original publishes: id, length, data only
    frame = conversions.frame_of(CANFrame(id=20, length=2, data=[9, 8, 7, 0, 0, 0, 0, 0]))
    assert (frame.id, frame.data, frame.is_extended) == (20, bytes([9, 8]), False)
    assert conversions.frame_of(CANFrame(id=0x18FF1234, length=8, data=[0] * 8, is_extended=True)).is_extended
    with pytest.raises(ValueError, match=r"length 9: a CAN frame carries 0..8 bytes"):
        conversions.frame_of(CANFrame(id=1, length=9, data=[0] * 8))
    with pytest.raises(ValueError, match=r"id 0x800: above 0x7FF for a 11-bit frame"):
        conversions.frame_of(CANFrame(id=0x800, length=0, data=[0] * 8))


def test_battery_state_and_io_messages():
    b = BatteryInfo(1, 1, 87.0, 96.0, 50.1, -12.5, capacity=100.0, temperatures=(21.0, 25.0), alarms=("bms_fail",))
    msg = conversions.battery_state_msg(Time(1, 0), "robot/base_link", b)
    assert (msg.voltage, msg.current, msg.capacity, msg.temperature) == pytest.approx((50.1, -12.5, 100.0, 25.0))
    assert msg.percentage == pytest.approx(0.87) and msg.present
    assert msg.power_supply_status == BatteryState.POWER_SUPPLY_STATUS_DISCHARGING
    assert msg.power_supply_health == BatteryState.POWER_SUPPLY_HEALTH_UNSPEC_FAILURE
    gone = conversions.battery_state_msg(Time(1, 0), "", BatteryInfo(1, 2, 0.0, 0.0, 0.0, 0.0))
    assert not gone.present and math.isnan(gone.capacity)
    io = conversions.io_array_msg(Time(2, 0), [IoInfo(3, 0, (True, False), (12.0, 5.0, 0.0), True)])
    assert io.ios[0].id == 3 and list(io.ios[0].relay_states) == [True, False] and io.ios[0].online


def test_an_unheard_drives_speeds_are_nan_in_base_state_and_its_angles_the_last_heard():
    heard = MeasuredDrive(0.1, 0.3, 2.0, 0.05)
    silent = MeasuredDrive(0.2, 0.3, 4.0, 0.05, heard=False)
    msg = conversions.state_msg(Time(1, 0), [heard, silent])
    assert msg.prop_speed[0] == 0.3 and math.isnan(msg.prop_speed[1])
    assert msg.steer_speed[0] == 0.05 and math.isnan(msg.steer_speed[1])
    assert list(msg.steer_pos) == [0.1, 0.2] and list(msg.prop_pos) == [2.0, 4.0]
