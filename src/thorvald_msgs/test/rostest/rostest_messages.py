#!/usr/bin/env python3
"""Publishes each thorvald_msgs message on a real master and checks what arrives is what was sent."""

import threading
import unittest

import rospy
import rostest

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


def round_trip(topic, msg_type, msg, timeout=10.0):
    received = []
    done = threading.Event()

    def callback(m):
        received.append(m)
        done.set()

    sub = rospy.Subscriber(topic, msg_type, callback)
    pub = rospy.Publisher(topic, msg_type, queue_size=1, latch=True)
    pub.publish(msg)
    done.wait(timeout)
    sub.unregister()
    pub.unregister()
    return received[0] if received else None


class MessagesRoundTrip(unittest.TestCase):
    def test_can_frame(self):
        sent = CANFrame(id=0x185, length=3, data=[1, 2, 255, 0, 0, 0, 0, 0], is_extended=False)
        got = round_trip("can_frames_device_t", CANFrame, sent)
        self.assertIsNotNone(got)
        self.assertEqual(got.id, 0x185)
        self.assertEqual(got.length, 3)
        self.assertEqual(list(bytearray(got.data)), [1, 2, 255, 0, 0, 0, 0, 0])

    def test_base_state(self):
        sent = BaseState(drive_mode=BaseState.MODE_DRIVE, prop_speed=[0.5, -0.5], steer_pos=[0.1, -3.0])
        sent.header.stamp = rospy.Time(12, 5)
        got = round_trip("base_state", BaseState, sent)
        self.assertIsNotNone(got)
        self.assertEqual(list(got.prop_speed), [0.5, -0.5])
        self.assertEqual(list(got.steer_pos), [0.1, -3.0])
        self.assertEqual(got.header.stamp, rospy.Time(12, 5))

    def test_battery_array(self):
        bat = BatteryData(battery_id=1, state_of_charge=87.0, temperatures=[21.0, 22.5])
        bat.battery_alarms.short_circuit_discharge = True
        got = round_trip("battery_data", BatteryArray, BatteryArray(batteries=[bat]))
        self.assertIsNotNone(got)
        self.assertEqual(got.batteries[0].battery_id, 1)
        self.assertTrue(got.batteries[0].battery_alarms.short_circuit_discharge)
        self.assertFalse(got.batteries[0].battery_alarms.bms_fail)
        self.assertEqual(list(got.batteries[0].temperatures), [21.0, 22.5])

    def test_controller_array(self):
        ctrl = Controller(
            name="drive0",
            can_id=1,
            status_flags=[StatusFlag("stall detected", True)],
            motor_vars=[MotorVars(type="propulsion", speed=1.0), MotorVars(type="steering", position=0.3)],
        )
        got = round_trip("motor_controller_data", ControllerArray, ControllerArray(controllers=[ctrl]))
        self.assertIsNotNone(got)
        self.assertEqual(got.controllers[0].status_flags[0].status_name, "stall detected")
        self.assertEqual(got.controllers[0].motor_vars[1].position, 0.3)

    def test_drive_currents(self):
        sent = DriveCurrents(prop_amps=[1.5, -0.84], steer_amps=[0.4, 0.0])
        sent.header.stamp = rospy.Time(3, 25)
        got = round_trip("drive_currents", DriveCurrents, sent)
        self.assertIsNotNone(got)
        self.assertEqual(list(got.prop_amps), [1.5, -0.84])
        self.assertEqual(list(got.steer_amps), [0.4, 0.0])
        self.assertEqual(got.header.stamp, rospy.Time(3, 25))

    def test_io_array(self):
        got = round_trip("io_data", IOArray, IOArray(ios=[IOData(id=0, type=0, relay_states=[True, False])]))
        self.assertIsNotNone(got)
        self.assertEqual(list(got.ios[0].relay_states), [True, False])


if __name__ == "__main__":
    rospy.init_node("messages_round_trip")
    rostest.rosrun("thorvald_msgs", "messages_round_trip", MessagesRoundTrip)
