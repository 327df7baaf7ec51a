#!/usr/bin/env python3
"""base_driver over SLCAN to the emulated devices of the standard robot (another process).

Commands reach the wheels and come back as measured states; a motor controller silenced mid-drive
stops every wheel once it has been silent for 2 s and is reported, odometry rests on the other
three drives and says so, and control resumes when it is heard again; the relay works both ways
with an implement on the hub's second port, refuses a frame to a base controller's command id, and
is muted by the service; the main IO board's relays switch
by the original's service names (setRl1, setRl2) without an io section in the robot file; the
adapter unplugged and plugged back: base_driver survives, reports, and drives again.
"""

import os
import time
import unittest

import can
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from driver_testing import STARTUP_TIMEOUT, Topic, driver_service, driver_stream, twist
from nav_msgs.msg import Odometry
from std_srvs.srv import SetBool, Trigger

from thorvald_msgs.msg import BaseState, CANFrame, ControllerArray, IOArray

SPEED = 0.5  # [m/s]
LOST_AFTER = 2.0  # [s] the rule: a device silent this long is lost
CYCLE = 0.02  # [s] base_driver at 50 Hz
RAMP = SPEED / 1.5  # [s] the wheels' ramp down at prp_sim_a


def all_at(speed, tol=0.02):
    return lambda m: len(m.prop_speed) == 4 and all(abs(v - speed) < tol for v in m.prop_speed)


def emulator_service(name, srv_type):
    rospy.wait_for_service("can_emulator/" + name, timeout=STARTUP_TIMEOUT)
    return rospy.ServiceProxy("can_emulator/" + name, srv_type)


class CanSlcanTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.state = Topic("base_state", BaseState)
        cls.odom = Topic("odometry/base_raw", Odometry)
        cls.controllers = Topic("motor_controller_data", ControllerArray)
        cls.diagnostics = Topic("/diagnostics", DiagnosticArray)
        cls.device_r = Topic("can_frames_device_r", CANFrame)
        cls.device_t = rospy.Publisher("can_frames_device_t", CANFrame, queue_size=10)
        cls.cmd = driver_stream(cls.state)
        cls.links = rospy.get_param("can_links")

    def test_1_drives_follow_commands_over_the_bus(self):
        online = self.controllers.wait_for(
            # online, and each has sent its script version (once a second)
            lambda m: len(m.controllers) == 4 and all(c.controller_mode == 3 and c.version for c in m.controllers),
            timeout=STARTUP_TIMEOUT,
            since=0,
        )
        self.assertIsNotNone(online, "the four motor controllers never reported online")
        self.assertEqual({c.type for c in online.controllers}, {"RoboteqFbl2360"})
        self.assertEqual({c.version for c in online.controllers}, {"2.1.0"})
        self.cmd.send(twist(SPEED))
        self.assertIsNotNone(self.state.wait_for(all_at(SPEED), timeout=10.0), "the wheels never reached 0.5 m/s")
        # odometry from the speeds and steering counts the controllers report
        odom = self.odom.wait_for(lambda m: abs(m.twist.twist.linear.x - SPEED) < 0.01, timeout=5.0)
        self.assertIsNotNone(odom, "odometry did not follow the command")
        self.assertAlmostEqual(odom.twist.twist.angular.z, 0.0, delta=0.01)
        self.cmd.send(twist(0.3, 0.0, 0.4))
        turning = self.odom.wait_for(
            lambda m: abs(m.twist.twist.linear.x - 0.3) < 0.01 and abs(m.twist.twist.angular.z - 0.4) < 0.01,
            timeout=10.0,
        )
        self.assertIsNotNone(turning, "odometry did not follow a turning command")

    def test_2_a_silent_controller_stops_the_wheels_and_control_resumes(self):
        self.cmd.send(twist(SPEED))
        self.assertIsNotNone(self.state.wait_for(all_at(SPEED), timeout=10.0))
        silence = emulator_service("drive1/silence", SetBool)
        silenced = time.time()
        silence(True)
        stopped = self.state.wait_for(lambda m: abs(m.prop_speed[0]) < 0.01, timeout=10.0)
        took = time.time() - silenced
        self.assertIsNotNone(stopped, "the wheels did not stop")
        # drive0 still reports: it slows once drive1 has been silent 2 s (one cycle, the ramp, slack)
        self.assertGreater(took, LOST_AFTER - 0.2)
        self.assertLess(took, LOST_AFTER + CYCLE + RAMP + 1.0)
        report = self.controllers.wait_for(lambda m: any(c.controller_mode == 4 for c in m.controllers))
        self.assertEqual([c.name for c in report.controllers if c.controller_mode == 4], ["drive1"])
        diag = self.diagnostics.wait_for(
            lambda m: any("drive1" in s.name and s.level == DiagnosticStatus.ERROR for s in m.status)
        )
        self.assertIsNotNone(diag, "/diagnostics did not report the lost controller")
        # Odometry from the three drives heard: the robot stands, and so does odometry (drive1's last
        # 0.5 m/s, held, would read 0.125 m/s over four drives); its twist covariance says so
        still = self.odom.wait_for(lambda m: abs(m.twist.twist.linear.x) < 1e-3, timeout=5.0)
        self.assertIsNotNone(still, "odometry kept moving with drive1 silent and the wheels stopped")
        later = self.odom.wait_for(lambda m: m.header.stamp.to_sec() > still.header.stamp.to_sec() + 1.0)
        self.assertAlmostEqual(later.pose.pose.position.x, still.pose.pose.position.x, delta=1e-3)
        self.assertAlmostEqual(later.twist.covariance[0], 0.001 * 4 / 3, delta=1e-9)
        degraded = self.diagnostics.wait_for(
            lambda m: any(
                s.name.endswith("odometry") and s.level == DiagnosticStatus.WARN and "drive1 unheard" in s.message
                for s in m.status
            )
        )
        self.assertIsNotNone(degraded, "/diagnostics did not say odometry rests on three drives")
        silence(False)
        self.assertIsNotNone(self.state.wait_for(all_at(SPEED), timeout=10.0), "control did not resume")
        whole = self.odom.wait_for(lambda m: abs(m.twist.twist.linear.x - SPEED) < 0.01, timeout=5.0)
        self.assertIsNotNone(whole, "odometry did not follow the drives heard again")
        self.assertAlmostEqual(whole.twist.covariance[0], 0.001, delta=1e-9)

    def test_3_relay_both_ways_guard_and_mute(self):
        implement = can.Bus(interface="slcan", channel=os.path.join(self.links, "port1"), sleep_after_open=0)
        try:
            implement.send(can.Message(arbitration_id=0x123, data=[1, 2, 3], is_extended_id=False))
            got = self.device_r.wait_for(lambda m: m.id == 0x123, timeout=5.0, since=0)
            self.assertIsNotNone(got, "an implement's frame did not come out on can_frames_device_r")
            self.assertEqual(bytes(bytearray(got.data))[: got.length], bytes([1, 2, 3]))

            def relayed(can_id, payload, timeout=3.0):
                self.device_t.publish(
                    CANFrame(id=can_id, length=len(payload), data=list(payload) + [0] * (8 - len(payload)))
                )
                deadline = time.time() + timeout
                while time.time() < deadline:
                    msg = implement.recv(0.1)
                    if msg is not None and msg.arbitration_id == can_id and bytes(msg.data) == bytes(payload):
                        return True
                return False

            deadline = time.time() + STARTUP_TIMEOUT
            while not self.device_t.get_num_connections() and time.time() < deadline:
                time.sleep(0.05)
            self.assertTrue(relayed(0x124, b"\x07\x08"), "a frame on can_frames_device_t did not reach the implement")
            # drive0's command id, with a payload base_driver itself never sends
            self.assertFalse(relayed(0x201, b"\xab" * 8, timeout=1.5), "a relayed frame to a base controller went out")
            mute = driver_service("mute_extra_can_device_commands", SetBool)
            mute(True)
            self.assertFalse(relayed(0x125, b"\x01", timeout=1.5), "a frame went out while muted")
            mute(False)
            self.assertTrue(relayed(0x126, b"\x02"), "relaying did not resume after unmuting")
        finally:
            implement.shutdown()

    def test_3b_the_main_board_relays_by_the_original_names(self):
        """The robot file has no io section: the main enclosure PCB (id 0) is on the bus all the same,
        and setRl1 / setRl2 (the original's names) switch its relays 0 and 1, as io0_rl0 / io0_rl1."""
        io = Topic("io_data", IOArray)

        def relays(expected):
            msg = io.wait_for(
                lambda m: any(b.id == 0 and b.online and list(b.relay_states) == expected for b in m.ios),
                timeout=5.0,
            )
            return msg is not None

        self.assertTrue(relays([False, False]), "the main board never reported online with its relays off")
        set_rl1, set_rl2 = driver_service("setRl1", SetBool), driver_service("setRl2", SetBool)
        self.assertTrue(set_rl1(True).success)
        self.assertTrue(relays([True, False]), "setRl1 did not switch the main board's first relay on")
        self.assertTrue(set_rl2(True).success)
        self.assertTrue(relays([True, True]), "setRl2 did not switch the main board's second relay on")
        self.assertTrue(set_rl1(False).success)
        self.assertTrue(relays([False, True]), "setRl1 did not switch it off again")
        self.assertTrue(driver_service("io0_rl1", SetBool)(False).success)
        self.assertTrue(relays([False, False]), "io0_rl1 did not switch the second relay off")

    def test_4_the_adapter_unplugged_and_back(self):
        self.cmd.send(twist(SPEED))
        self.assertIsNotNone(self.state.wait_for(all_at(SPEED), timeout=10.0))
        emulator_service("port0/drop", Trigger)()
        closed = self.diagnostics.wait_for(
            lambda m: any(s.name.endswith("CAN bus") and s.level == DiagnosticStatus.ERROR for s in m.status),
            timeout=10.0,
        )
        self.assertIsNotNone(closed, "/diagnostics did not report the bus going away")
        back = self.diagnostics.wait_for(
            lambda m: any(
                s.name.endswith("CAN bus")
                and s.level == DiagnosticStatus.OK
                and dict((v.key, v.value) for v in s.values).get("bus reopened", "0") != "0"
                for s in m.status
            ),
            timeout=20.0,
        )
        self.assertIsNotNone(back, "base_driver did not reopen the bus")
        self.assertIsNotNone(self.state.wait_for(all_at(SPEED), timeout=10.0), "no control after reconnecting")


if __name__ == "__main__":
    rospy.init_node("can_slcan_test")
    rostest.rosrun("thorvald_base", "can_slcan", CanSlcanTest)
