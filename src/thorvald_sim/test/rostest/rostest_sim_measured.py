#!/usr/bin/env python3
"""Measured drives: base_driver's odometry from the simulated joints' encoders against ground truth.

On tarmac, 10 m at 1 m/s: odometry's distance within 2 % of ground truth's. On ice (friction 0.1)
the robot starts from rest at 1 m/s: its wheels ramp up at their controllers' 1.5 m/s^2, the robot
can accelerate at mu g = 0.98 m/s^2 at most, so ground truth falls behind odometry: the slip is real.
(Until the wheels' friction was really 1.0, they had 0.5 and the ice 0.05: about 0.5 m against 1 m.)
At speed, base_driver's motor controllers report the simulated motors' currents (drive_currents).
"""

import time
import unittest

import numpy as np
import rospy
import rostest
from sim_testing import STARTUP, Commander, Latest, delta, planar, sim_sleep

from thorvald_msgs.msg import BaseState, ControllerArray, DriveCurrents


class SimMeasuredTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.truth = {r: Latest(f"/{r}/odometry/gazebo") for r in ("tarmac", "ice")}
        cls.odometry = {r: Latest(f"/{r}/odometry/base_raw") for r in ("tarmac", "ice")}
        cls.nav = {r: Commander(f"/{r}/nav_vel") for r in ("tarmac", "ice")}
        cls.measured = Latest("/tarmac/drive_states", BaseState)
        cls.controllers = Latest("/tarmac/motor_controller_data", ControllerArray)
        for r in ("tarmac", "ice"):
            cls.truth[r].wait()
            cls.odometry[r].wait()
            cls.nav[r].wait_for_subscriber()
        sim_sleep(1.0)

    def drive(self, robot, seconds, settle=0.0):
        """The motion by ground truth and by odometry: sampled settle s after the stop (both topics at
        rest, so it does not matter which of them reached this node last), or while still moving
        (settle 0: each sample as fresh as its topic's delivery)."""
        truth0, odom0 = planar(self.truth[robot].get()), planar(self.odometry[robot].get())
        self.nav[robot].send(1.0)
        sent = rospy.get_time()
        sim_sleep(seconds)
        if settle:
            self.nav[robot].send()
            sim_sleep(settle)
        last, odom = self.truth[robot].get(), self.odometry[robot].get()
        truth1, odom1 = planar(last), planar(odom)
        self.nav[robot].send()
        self.elapsed = last.header.stamp.to_sec() - sent  # simulated s from the command to the truth sample
        self.lag = last.header.stamp.to_sec() - odom.header.stamp.to_sec()  # the odometry sample's age behind it
        return delta(truth0, truth1), delta(odom0, odom1)

    def test_odometry_follows_ground_truth_over_10_m_of_tarmac(self):
        # at speed, the drive states are the simulator's: base_driver reads its wheels' measured rim speed
        self.nav["tarmac"].send(1.0)
        sent = rospy.get_time()
        sim_sleep(2.0)
        self.assertAlmostEqual(self.measured.get().prop_speed[0], 1.0, delta=0.05)
        # and its motor controllers (1 Hz) the simulated motors' currents: at 1 m/s on tarmac every wheel
        # pushes, at least its motor's no-load current (0.6 A) forward
        status = self.controllers.after(rospy.Time.from_sec(sent + 1.0))
        prop = [c.motor_vars[0] for c in status.controllers]
        rospy.loginfo("tarmac: propulsion currents %s A", ", ".join(f"{v.motor_amps:.3f}" for v in prop))
        self.assertEqual(len(prop), 4)
        for v in prop:
            self.assertEqual(v.type, "propulsion")
            self.assertAlmostEqual(v.speed, 1.0, delta=0.1)
            self.assertGreater(v.motor_amps, 0.0)
        self.nav["tarmac"].send()
        sim_sleep(1.5)
        # compared at rest: sampled while moving at 1 m/s, 0.1 s between the deliveries of the two
        # topics on a busy machine read as 0.1 m (one CI run: 10.14 m against 9.89 m)
        truth, odom = self.drive("tarmac", 10.0, settle=1.5)
        rospy.loginfo("tarmac: ground truth %.4f m, odometry %.4f m", truth[0], odom[0])
        self.assertGreater(truth[0], 9.0)  # about 10 m (a busy machine may start it late)
        self.assertAlmostEqual(odom[0], truth[0], delta=0.02 * truth[0])

    def test_the_currents_come_at_their_own_rate_and_the_states_at_theirs(self):
        # drive_currents at ~drive_current_rate (10 Hz: base_driver reports them at 1 Hz), drive_states at 80 Hz
        stamps = {"drive_currents": [], "drive_states": []}  # (stamp, seq) as delivered
        subs = [
            rospy.Subscriber(
                f"/tarmac/{topic}",
                msg_type,
                lambda m, t=topic: stamps[t].append((m.header.stamp.to_sec(), m.header.seq)),
            )
            for topic, msg_type in (("drive_currents", DriveCurrents), ("drive_states", BaseState))
        ]
        # The window is the stamps' own, not the test's clock: it opens 0.2 s after the first message of
        # both topics and is counted once each has delivered one stamped after it. One topic's messages
        # come in order, so none inside it is still on its way (a window on the test's clock, which
        # lags a simulator running ahead of real time, counted 158 of 160 drive states twice).
        deadline = time.time() + STARTUP
        while not all(stamps.values()):
            self.assertLess(time.time(), deadline, "no drive_currents and drive_states")
            time.sleep(0.05)
        start = max(times[0][0] for times in stamps.values()) + 0.2
        while not all(times[-1][0] >= start + 2.1 for times in stamps.values()):
            self.assertLess(time.time(), deadline, f"no messages stamped after {start + 2.1:.2f} s")
            time.sleep(0.05)
        for sub in subs:
            sub.unregister()
        for topic, rate in (("drive_currents", 10.0), ("drive_states", 80.0)):
            within = [(t, seq) for t, seq in stamps[topic] if start <= t < start + 2.0]
            # What the simulator published is counted by the messages' sequence numbers: a reader that
            # does not keep up misses messages (the simulator never waits for one), and this test's
            # reader on a loaded machine missed 6 of 160 drive states in one CI run at 3x real time.
            published = within[-1][1] - within[0][1] + 1
            missed = published - len(within)
            rospy.loginfo("%s: %d published in 2 s of stamps, %d missed by this reader", topic, published, missed)
            self.assertAlmostEqual(published, 2.0 * rate, delta=1, msg=topic)
            # the period between messages the reader got, per message published between them
            periods = [(t1 - t0) / (s1 - s0) for (t0, s0), (t1, s1) in zip(within, within[1:])]
            self.assertAlmostEqual(float(np.median(periods)), 1.0 / rate, delta=0.2 / rate, msg=topic)
            self.assertLess(missed, 0.25 * published, msg=f"{topic}: this reader missed most messages")

    def test_on_ice_ground_truth_falls_behind_odometry(self):
        truth, odom = self.drive("ice", 1.5)
        rospy.loginfo("ice: ground truth %.4f m, odometry %.4f m", truth[0], odom[0])
        # odometry counts the wheels' turns: 1 m/s reached at 1.5 m/s^2 after 0.67 s, 1.17 m in 1.5 s
        # (less the command's way through twist_mux and base_driver's cycle); the robot accelerates at
        # most mu g = 0.98 m/s^2, reaching 1 m/s after 1.02 s: at most 0.51 + 0.48 = 0.99 m in 1.5 s,
        # 0.18 m behind its wheels (0.94 m against 1.13 m of odometry here; 0.09 m behind in a CI run on
        # a loaded machine, where the command reached the wheels later in the 1.5 s). The bound is taken
        # at the truth sample's own stamp: a loaded machine samples it later than 1.5 s after the
        # command (a CI run read 0.992 m against a bound taken at 1.5 s).
        t, a = self.elapsed, 0.1 * 9.81
        bound = a * t * t / 2 if t < 1.0 / a else 0.5 / a + (t - 1.0 / a)
        rospy.loginfo("ice: %.3f s of simulated time from the command, at most %.4f m at mu g", t, bound)
        self.assertGreater(odom[0], 0.5)  # it drove
        self.assertLess(truth[0], bound)
        # at one instant: the odometry sample may be older than the truth sample on a loaded machine
        # (its delivery came first); its wheels turned at 1 m/s meanwhile (a CI run read 0.031 m apart
        # uncorrected)
        rospy.loginfo("ice: odometry sampled %.3f s before ground truth", self.lag)
        self.assertGreater(odom[0] + 1.0 * self.lag - truth[0], 0.05)


if __name__ == "__main__":
    rospy.init_node("sim_measured_test")
    rostest.rosrun("thorvald_sim", "sim_measured", SimMeasuredTest)
