#!/usr/bin/env python3
"""The Figure 7 robot in the simulator: ground truth (odometry/gazebo) against the motion that
base_driver's drive states describe (its odometry of base_state).

Forward 0.5 m/s for 4 s: distance within 2 %. Spin in place at 0.5 rad/s for 4 s: turn within 3 %,
centre within 0.05 m. A 45 degree crab: direction within 2 degrees, distance within 2 %. Run in
sequence on one robot; each compares the motion from just before the command to after the robot
has stopped. Where the two differ most is the start of a command that slews the steering while
the wheels already drive (base_driver's drives, as the original's): odometry's model of wheels
that disagree and the physics of them resolve differently.

The simulator's /diagnostics: one robot, the real-time factor asked for (3) reached and never
exceeded, and its CPU per simulated second with the solver's part.
"""

import math
import unittest

import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from sim_testing import Commander, Latest, drive, sim_sleep


class SimDriveTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.truth = Latest("odometry/gazebo")
        cls.odometry = Latest("odometry/base_raw")
        cls.nav = Commander("nav_vel")
        cls.truth.wait()
        cls.odometry.wait()
        cls.nav.wait_for_subscriber()
        sim_sleep(1.0)  # settled on its wheels

    def test_1_forward(self):
        truth, odom = drive(self.nav, (0.5, 0.0, 0.0), 4.0, self.truth, self.odometry)
        rospy.loginfo("forward: ground truth %.4f m, odometry %.4f m", truth[0], odom[0])
        # it drove (0.5 m/s for 4 s, ramping at 1.5 m/s^2: 1.92 m, less the command's late start on a busy machine)
        self.assertGreater(odom[0], 1.5)
        self.assertAlmostEqual(truth[0], odom[0], delta=0.02 * odom[0])
        self.assertAlmostEqual(truth[1], 0.0, delta=0.02)  # straight ahead
        self.assertAlmostEqual(truth[2], 0.0, delta=0.02)

    def test_2_spin_in_place(self):
        truth, odom = drive(self.nav, (0.0, 0.0, 0.5), 4.0, self.truth, self.odometry, settle=1.5)
        rospy.loginfo(
            "spin: ground truth turned %.4f rad, moved %.4f m; odometry %.4f rad", truth[2], truth[0], odom[2]
        )
        self.assertGreater(odom[2], 1.5)  # it spun: 0.5 rad/s for 4 s, less the slew and a late start
        self.assertAlmostEqual(truth[2], odom[2], delta=0.03 * odom[2])
        self.assertLess(truth[0], 0.05, "the centre of the spin moved")

    def test_3_crab_45_degrees(self):
        v = 0.5 / math.sqrt(2.0)
        truth, odom = drive(self.nav, (v, v, 0.0), 4.0, self.truth, self.odometry, settle=1.5)
        rospy.loginfo("crab: ground truth %.4f m at %.4f rad; odometry %.4f m at %.4f rad", *truth[:2], *odom[:2])
        self.assertAlmostEqual(truth[1], math.pi / 4, delta=math.radians(2))
        self.assertAlmostEqual(truth[0], odom[0], delta=0.02 * odom[0])
        self.assertAlmostEqual(truth[2], 0.0, delta=0.02)

    def test_4_the_simulator_reports_how_it_runs_on_diagnostics(self):
        statuses = []

        def on_diagnostics(msg):
            statuses.extend(s for s in msg.status if s.name == "/simulator: simulation")

        sub = rospy.Subscriber("/diagnostics", DiagnosticArray, on_diagnostics)
        try:
            deadline = rospy.Time.now() + rospy.Duration(30.0)  # at least 10 s of wall time at 3x
            while len(statuses) < 3 and rospy.Time.now() < deadline:
                sim_sleep(0.5)
        finally:
            sub.unregister()
        self.assertGreaterEqual(len(statuses), 3, "the simulator published no /diagnostics once a wall second")
        status = statuses[-1]
        values = {kv.key: kv.value for kv in status.values}
        rospy.loginfo("simulator: %s %s", status.message, values)
        self.assertEqual(values["robots"], "1")
        self.assertEqual(values["real-time factor asked"], "3")
        rtf = float(values["real-time factor"])
        self.assertLess(rtf, 3.3)  # paced on the wall clock: never faster than asked
        self.assertGreater(rtf, 0.5)
        # below 90 % of the pace asked for it says so
        self.assertEqual(status.level, DiagnosticStatus.WARN if rtf < 2.7 else DiagnosticStatus.OK, status.message)
        cpu, solver = (
            float(values["CPU per simulated second [s]"]),
            float(values["solver CPU per simulated second [s]"]),
        )
        self.assertGreater(solver, 0.0)
        self.assertLess(solver, cpu)  # the solver is a part of the process's CPU
        self.assertLess(cpu, 1.0)  # one robot: far less than a core per simulated second here


if __name__ == "__main__":
    rospy.init_node("sim_drive_test")
    rostest.rosrun("thorvald_sim", "sim_drive", SimDriveTest)
