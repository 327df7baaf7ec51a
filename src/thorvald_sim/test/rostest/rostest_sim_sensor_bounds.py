#!/usr/bin/env python3
"""A robot whose sensor blocks ask for more than one reading may cost, beside a robot that drives.

``greedy`` (test/data/oversized_sensors.xacro on the standard robot) asks for a camera of
100000 x 100000 pixels, whose first frame used to abort the simulator inside pybullet's renderer,
and a lidar of 10000 x 1000 = 10^7 rays a reading, which stalled the clock; it also has an IMU.
``driver`` is the standard robot, driven through its nav_vel. With subscribers on the refused
sensors' topics from the start: the simulator stays up and /clock advances; driver moves as
commanded (0.5 m/s for 2 s, then a stop: 1 m, the ramps at 1.5 m/s^2 taking at the start what they
give at the end); greedy keeps its IMU; and /diagnostics
carries an error for each refused sensor naming the robot, the link, the element path, the value
and the rule. At a real-time factor of 2.
"""

import threading
import time
import unittest
import xmlrpc.client

import rosgraph
import rospy
import rostest
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from rosgraph_msgs.msg import Log
from sensor_msgs.msg import CameraInfo, Image, Imu, PointCloud2
from sim_testing import Commander, Latest, delta, planar

WALL = 30.0  # [s] the longest a wait for the simulator may take on a busy machine

OVERSIZED = {
    "/greedy/big_camera/image_raw": Image,
    "/greedy/big_camera/camera_info": CameraInfo,
    "/greedy/dense_points": PointCloud2,
}


def wait_until(predicate, what, timeout=WALL):
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline or rospy.is_shutdown():
            raise AssertionError(f"timed out after {timeout:.0f} s waiting for {what}")
        time.sleep(0.02)


def wait_simulated(seconds):
    """Waits for seconds of simulated time; fails if /clock stalls."""
    end = rospy.get_time() + seconds
    wait_until(lambda: rospy.get_time() >= end, f"simulated time to reach {end:.2f} s (it is {rospy.get_time():.2f} s)")


class SimSensorBoundsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.lock = threading.Lock()
        cls.said = []  # the simulator's /rosout lines (a subscriber may come after the spawn: not asserted)
        cls.statuses = {}  # the latest /diagnostics status of each name
        cls.received = {topic: 0 for topic in OVERSIZED}
        rospy.Subscriber("/rosout", Log, cls.on_log, queue_size=1000)
        rospy.Subscriber("/diagnostics", DiagnosticArray, cls.on_diagnostics, queue_size=100)
        cls.oversized = [
            rospy.Subscriber(topic, kind, cls.on_oversized, callback_args=topic, queue_size=1)
            for topic, kind in OVERSIZED.items()
        ]
        cls.truth = Latest("/driver/odometry/gazebo")
        cls.imu = Latest("/greedy/imu/data", Imu)
        cls.nav = Commander("/driver/nav_vel")
        cls.truth.wait()
        cls.imu.wait()
        cls.nav.wait_for_subscriber()

    @classmethod
    def on_log(cls, msg):
        if msg.name == "/simulator":
            with cls.lock:
                cls.said.append(msg.msg)

    @classmethod
    def on_diagnostics(cls, msg):
        with cls.lock:
            cls.statuses.update((s.name, s) for s in msg.status)

    @classmethod
    def on_oversized(cls, _msg, topic):
        with cls.lock:
            cls.received[topic] += 1

    def status(self, name):
        with self.lock:
            return self.statuses.get(name)

    def test_1_the_other_robot_drives_and_the_clock_goes_on(self):
        start = planar(self.truth.get())
        self.nav.send(0.5)
        wait_simulated(2.0)
        self.nav.send()
        wait_simulated(1.0)
        moved, direction, _ = delta(start, planar(self.truth.get()))
        rospy.loginfo("driver moved %.3f m at %.3f rad", moved, direction)
        # 0.5 m/s for 2 s, then a stop: 1 m (1.03 m here), within what a busy machine's late commands change
        self.assertAlmostEqual(moved, 1.0, delta=0.25)
        self.assertAlmostEqual(direction, 0.0, delta=0.05)

    def test_2_the_simulator_is_up_and_greedy_keeps_its_other_sensor(self):
        master = rosgraph.Master("/sim_sensor_bounds")
        code, _, pid = xmlrpc.client.ServerProxy(master.lookupNode("/simulator")).getPid("/sim_sensor_bounds")
        self.assertEqual(code, 1)
        self.assertGreater(pid, 0)
        before = self.imu.count
        wait_simulated(0.5)
        self.assertGreater(self.imu.count, before, "greedy's IMU stopped")
        published = {topic for topic, _ in rospy.get_published_topics()}
        with self.lock:
            received = dict(self.received)
        for topic in OVERSIZED:
            self.assertNotIn(topic, published, f"{topic} is published: its sensor was not refused")
            self.assertEqual(received[topic], 0, topic)

    def test_3_diagnostics_carry_each_refusal(self):
        camera = "/simulator: sensor big_camera of greedy"
        lidar = "/simulator: sensor dense_lidar of greedy"
        wait_until(lambda: self.status(camera) and self.status(lidar), "the refusals on /diagnostics")
        with self.lock:
            said = [line for line in self.said if "sensor refused" in line]
        rospy.loginfo("the simulator said: %s", said)
        for name, expected in (
            (camera, ["greedy", "greedy/big_camera_link", "sensor[@name='big_camera']/camera/image/width",
                      "100000 must be <= 8192"]),
            (lidar, ["greedy", "greedy/dense_lidar_link", "sensor[@name='dense_lidar']/ray/scan",
                     "10000 x 1000 = 10000000 must be <= 524288"]),
        ):  # fmt: skip
            status = self.status(name)
            rospy.loginfo("%s: %s", name, status.message)
            self.assertEqual(status.level, DiagnosticStatus.ERROR)
            self.assertEqual(status.hardware_id, "greedy")
            for text in expected:
                self.assertIn(text, status.message)


if __name__ == "__main__":
    rospy.init_node("sim_sensor_bounds_test")
    rostest.rosrun("thorvald_sim", "sim_sensor_bounds", SimSensorBoundsTest)
