#!/usr/bin/env python3
"""The simulated sensors of a user's sensor xacro (test/data/sensors_probe.xacro on the standard
robot), each against figures its geometry gives, on simulated time.

The world: flat ground; the robot at the origin, heading +x; a wall whose face is 3 m ahead of the
front lidar (lidar at x 0.9 m, 1 m up; face at x 3.9 m), a post of radius 0.1 m 2 m from the lidar at
+30 degrees (its near side 1.9 m away), a red box 0.6 m wide whose face is 2 m behind the camera
(camera at x -0.9 m, 0.8 m up, looking back; face at x -2.9 m). Datum: [53.268642, -0.524509, 0]
(the world's x points east). ``~only_rates``: the rates test alone (sim_sensor_rates.test, at a
real-time factor of 1).
"""

import math
import threading
import time
import unittest

import numpy as np
import rospy
import rostest
from rosgraph_msgs.msg import Log
from sensor_msgs.msg import CameraInfo, Image, Imu, LaserScan, NavSatFix, PointCloud2
from sim_testing import Commander, Latest, planar, sim_sleep

from thorvald_msgs.srv import SpawnRobot, SpawnRobotRequest

ROBOT = "/thorvald_001"
WGS84_A = 6378137.0
WGS84_E2 = 2 / 298.257223563 - (1 / 298.257223563) ** 2
LIDAR_STDDEV = 0.01


class Counter:
    """Messages of a topic and their stamps."""

    def __init__(self, topic, msg_type):
        self.stamps = []
        self.lock = threading.Lock()
        self.sub = rospy.Subscriber(topic, msg_type, self.on, queue_size=100)

    def on(self, msg):
        with self.lock:
            self.stamps.append(msg.header.stamp.to_sec())

    def between(self, start, end):
        with self.lock:
            return [s for s in self.stamps if start <= s < end]


def mean_of(latest, pick, samples, period=0.1):
    """The mean of pick(msg) over samples messages, period [s] of simulated time apart."""
    values = []
    for _ in range(samples):
        values.append(pick(latest.get()))
        sim_sleep(period)
    return np.mean(values, axis=0)


class SimSensorRatesTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.said = []  # every /rosout message from the start
        cls.rosout = rospy.Subscriber("/rosout", Log, lambda m: cls.said.append(m.msg), queue_size=1000)
        cls.scan = Latest(ROBOT + "/scan", LaserScan)
        cls.scan.wait()
        # the obstacles are spawned by nodes of their own: wait until each is in the world
        for name in ("wall", "post", "red_box"):
            Latest(f"/obstacles/{name}/odometry/gazebo").wait()
        sim_sleep(0.5)

    def test_rates_held_on_simulated_time(self):
        # 40 Hz lidar and 100 Hz IMU: 80 and 200 messages in 2 simulated seconds, stamped at their instants
        lidar, imu = Counter(ROBOT + "/scan", LaserScan), Counter(ROBOT + "/imu/data", Imu)
        sim_sleep(1.0)
        start = rospy.get_time()
        sim_sleep(2.2)
        self.assertAlmostEqual(len(lidar.between(start, start + 2.0)), 80, delta=1)
        self.assertAlmostEqual(len(imu.between(start, start + 2.0)), 200, delta=1)
        stamps = lidar.between(start, start + 2.0)
        self.assertLess(np.max(np.abs(np.diff(stamps) - 0.025)), 0.005)


class SimSensorsTest(SimSensorRatesTest):
    """Everything, the rates too (a real-time factor of 0 in sim_sensors.test)."""

    def test_lidar_reads_the_wall_the_post_and_nothing(self):
        scan = self.scan.get()
        self.assertEqual(scan.header.frame_id, "thorvald_001/front_lidar")  # frameName in the robot's namespace
        self.assertEqual(len(scan.ranges), 1081)
        ahead = round((0.0 - scan.angle_min) / scan.angle_increment)
        post = round((math.radians(30) - scan.angle_min) / scan.angle_increment)
        left = round((math.radians(120) - scan.angle_min) / scan.angle_increment)
        ranges = mean_of(self.scan, lambda m: np.asarray(m.ranges), 10, 0.05)
        # 10 scans, noise 0.01: the mean within 3 standard deviations (0.01 / sqrt(10)), plus 2 mm of mount
        self.assertAlmostEqual(ranges[ahead], 3.0, delta=3 * LIDAR_STDDEV / math.sqrt(10) + 0.003)
        self.assertAlmostEqual(ranges[post], 1.9, delta=0.015)
        self.assertTrue(math.isinf(scan.ranges[left]), f"beam at +120 degrees reads {scan.ranges[left]}")

    def test_3d_lidar_rings(self):
        clouds = Latest(ROBOT + "/velodyne_points", PointCloud2)
        clouds.wait()
        sim_sleep(0.3)  # a cloud of the world with every obstacle in it
        cloud = clouds.get()
        self.assertEqual(cloud.header.frame_id, "thorvald_001/velodyne")
        self.assertEqual([f.name for f in cloud.fields], ["x", "y", "z", "intensity", "ring", "time"])
        dtype = np.dtype(
            {"names": ["x", "y", "z", "ring"], "formats": ["<f4", "<f4", "<f4", "<u2"], "offsets": [0, 4, 8, 16],
             "itemsize": cloud.point_step}
        )  # fmt: skip
        points = np.frombuffer(cloud.data, dtype=dtype)
        # the top ring (+15 degrees) from 1.6 m up hits the wall's face (x 3.9 m, 3 m high) ahead at
        # 1.6 + 3.9 tan(15 deg) = 2.645 m: in the sensor frame z = 3.9 tan(15 deg) = 1.045 m
        top = points[(points["ring"] == 15) & (np.abs(points["y"]) < 0.2) & (points["x"] > 0)]
        self.assertGreater(len(top), 0)
        self.assertAlmostEqual(float(np.median(top["x"])), 3.9, delta=0.05)
        self.assertAlmostEqual(float(np.median(top["z"])), 3.9 * math.tan(math.radians(15)), delta=0.05)

    def test_camera_sees_the_red_box_and_depth_reads_its_distance(self):
        image = Latest(ROBOT + "/rgbd/rgb/image_raw", Image).wait()
        info = Latest(ROBOT + "/rgbd/rgb/camera_info", CameraInfo).wait()
        depth = Latest(ROBOT + "/rgbd/depth/image_raw", Image).wait()
        self.assertEqual(image.header.frame_id, "thorvald_001/camera_optical")
        self.assertEqual((image.width, image.height, image.encoding), (160, 120, "rgb8"))
        rgb = np.frombuffer(image.data, np.uint8).reshape(120, 160, 3)
        f = info.K[0]
        self.assertAlmostEqual(f, 160 / (2 * math.tan(0.5)), places=3)
        # the box's half width 0.3 m at 2 m: 0.15 f pixels either side of the centre
        half = 0.3 / 2.0 * f
        centre = rgb[60, 80]
        self.assertTrue(centre[0] > 150 and centre[1] < 60 and centre[2] < 60, f"centre pixel {centre}")
        inside, outside = rgb[60, int(80 + 0.7 * half)], rgb[60, int(80 + 1.4 * half)]
        self.assertTrue(inside[0] > 150 and inside[1] < 60, f"pixel inside the box {inside}")
        self.assertFalse(outside[0] > 150 and outside[1] < 60, f"pixel outside the box {outside}")
        d = np.frombuffer(depth.data, "<f4").reshape(120, 160)
        self.assertEqual(depth.encoding, "32FC1")
        self.assertAlmostEqual(float(d[60, 80]), 2.0, delta=0.02)
        # the cloud: organised as the image, the centre point 2 m ahead on the optical axis (z forward),
        # red packed as gazebo_ros's rgb (r << 16 | g << 8 | b)
        cloud = Latest(ROBOT + "/rgbd/depth/points", PointCloud2).wait()
        self.assertEqual((cloud.width, cloud.height, cloud.header.frame_id), (160, 120, "thorvald_001/camera_optical"))
        self.assertEqual([(f.name, f.offset) for f in cloud.fields], [("x", 0), ("y", 4), ("z", 8), ("rgb", 16)])
        dtype = np.dtype({"names": ["x", "y", "z", "rgb"], "formats": ["<f4", "<f4", "<f4", "<u4"],
                          "offsets": [0, 4, 8, 16], "itemsize": cloud.point_step})  # fmt: skip
        points = np.frombuffer(cloud.data, dtype=dtype).reshape(120, 160)
        c = points[60, 80]
        self.assertAlmostEqual(float(c["z"]), 2.0, delta=0.02)
        self.assertLess(abs(float(c["x"])), 0.02)
        r, g, b = (int(c["rgb"]) >> 16) & 0xFF, (int(c["rgb"]) >> 8) & 0xFF, int(c["rgb"]) & 0xFF
        self.assertTrue(r > 150 and g < 60 and b < 60, f"centre point's colour {(r, g, b)}")
        # 0.7 of the box's half width (0.3 m) right of the centre: x = 0.21 m (the optical frame's x is right)
        self.assertAlmostEqual(float(points[60, int(80 + 0.7 * half)]["x"]), 0.7 * 0.3, delta=0.02)

    def test_unknown_plugins_are_logged_and_a_broken_block_refuses_that_sensor_only(self):
        said = self.said
        urdf = """<robot name="odd"><link name="odd_base">
          <inertial><mass value="0"/><inertia ixx="0" iyy="0" izz="0" ixy="0" ixz="0" iyz="0"/></inertial></link>
          <gazebo reference="odd_base"><sensor type="contact" name="bumper">
            <plugin name="bumper_plugin" filename="libContactPlugin.so"/></sensor>
          <sensor type="ray" name="broken_lidar"><update_rate>10</update_rate>
            <ray><scan><horizontal><min_angle>0</min_angle><max_angle>1</max_angle></horizontal></scan>
            <range><min>0.1</min><max>10</max></range></ray>
            <plugin name="l" filename="libgazebo_ros_laser.so"><topicName>scan</topicName></plugin></sensor>
          <sensor type="imu" name="odd_imu"><plugin name="i" filename="libgazebo_ros_imu_sensor.so">
            <topicName>imu</topicName><frameName>odd_base</frameName><updateRateHZ>20</updateRateHZ></plugin></sensor>
          </gazebo></robot>"""
        spawn = rospy.ServiceProxy("/simulator/spawn_robot", SpawnRobot)
        response = spawn(SpawnRobotRequest(model_name="odd", robot_namespace="/odd", robot_description=urdf,
                                           x=-10.0, y=-10.0, publish_tf=0))  # fmt: skip
        self.assertTrue(response.success, response.message)
        Latest("/odd/imu", Imu).wait(30)  # the good sensor works
        deadline = time.time() + 10
        while time.time() < deadline and not any("bumper" in m for m in said):
            time.sleep(0.1)
        self.assertTrue(any("bumper" in m and "not simulated" in m and "odd_base" in m for m in said), said)
        refused = [m for m in said if "broken_lidar" in m and "refused" in m]
        self.assertTrue(refused and "horizontal/samples" in refused[0] and "odd_base" in refused[0], said)

    def test_z_imu_at_rest_then_spinning(self):
        imu = Latest(ROBOT + "/imu/data", Imu)
        imu.wait()
        acc = mean_of(imu, lambda m: (m.linear_acceleration.x, m.linear_acceleration.y, m.linear_acceleration.z), 5)
        gyro = mean_of(imu, lambda m: (m.angular_velocity.x, m.angular_velocity.y, m.angular_velocity.z), 5)
        np.testing.assert_allclose(acc, (0.0, 0.0, 9.81), atol=0.05)
        np.testing.assert_allclose(gyro, (0.0, 0.0, 0.0), atol=0.01)
        truth = Latest(ROBOT + "/odometry/gazebo")
        truth.wait()
        nav = Commander(ROBOT + "/nav_vel")
        nav.wait_for_subscriber()
        nav.send(wz=0.5)
        sim_sleep(4.0)
        rate = mean_of(imu, lambda m: m.angular_velocity.z, 5, 0.05)
        msg, odom = imu.get(), truth.get()
        nav.stop()
        self.assertAlmostEqual(rate, 0.5, delta=0.02)
        q = msg.orientation
        yaw = math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))
        # ground truth's odom frame is the spawn pose (yaw 0), so its yaw is the world's; taken at the
        # IMU message's instant (the two latest messages may be 0.1 s apart: 0.05 rad at this spin)
        dt = (msg.header.stamp - odom.header.stamp).to_sec()
        yaw_truth = planar(odom)[2] + odom.twist.twist.angular.z * dt
        self.assertAlmostEqual(math.remainder(yaw - yaw_truth, 2 * math.pi), 0.0, delta=0.05)

    def test_zz_gnss_moves_with_the_robot_in_hectors_axes_from_the_datum(self):
        fix = Latest(ROBOT + "/gps/fix", NavSatFix)
        fix.wait()
        truth = Latest(ROBOT + "/odometry/gazebo")
        truth.wait()
        nav = Commander(ROBOT + "/nav_vel")
        nav.wait_for_subscriber()
        sim_sleep(2.0)  # the spin of the test before settles

        def position():
            return mean_of(fix, lambda m: (m.latitude, m.longitude), 10, 0.1)

        lat0, lon0 = position()
        self.assertEqual(fix.get().header.frame_id, "thorvald_001/gnss_link")
        # the reference is the datum file's; the antenna is within a few metres of the world's origin
        self.assertAlmostEqual(lat0, 53.268642, delta=5e-5)
        self.assertAlmostEqual(lon0, -0.524509, delta=1e-4)
        start = planar(truth.get())
        # drive along the world's +y (north with the datum's heading 0) for about 10 m, wherever the
        # spin left the robot's heading: the command is in base_link, so turn it into the world's y
        heading = start[2]
        nav.send(vx=0.5 * math.sin(heading), vy=0.5 * math.cos(heading))
        sim_sleep(20.0)
        nav.stop()
        sim_sleep(1.0)
        end = planar(truth.get())
        lat1, lon1 = position()
        lat = math.radians(53.268642)
        temp = 1.0 / (1.0 - WGS84_E2 * math.sin(lat) ** 2)
        radius_north = WGS84_A * math.sqrt(temp) * (1 - WGS84_E2) * temp
        radius_east = WGS84_A * math.sqrt(temp) * math.cos(lat)
        north = math.radians(lat1 - lat0) * radius_north
        east = math.radians(lon1 - lon0) * radius_east
        moved_x, moved_y = end[0] - start[0], end[1] - start[1]
        self.assertGreater(moved_y, 9.0)
        # 10 fixes of 2 cm noise averaged at each end: within 3 cm; the antenna turned with the robot too
        self.assertAlmostEqual(north, moved_y, delta=0.05)
        self.assertAlmostEqual(east, moved_x, delta=0.05)


if __name__ == "__main__":
    rospy.init_node("sim_sensors_test")
    only_rates = rospy.get_param("~only_rates", False)
    rostest.rosrun("thorvald_sim", "sim_sensors", SimSensorRatesTest if only_rates else SimSensorsTest)
