#!/usr/bin/env python3
"""Users' own launch files and model extras, written for the original with Gazebo, brought up on
thorvald_sim: the tf tree they rely on (users_tf_tree_*.test).

Their files include model.launch and start no robot_state_publisher, run base_driver with
enable_odom_tf false and spawn with spawn_model's arguments. So every link of the description, and
every frame a sensor publishes, must be reachable from odom: the links through model.launch's
robot_state_publisher, odom -> base_link from the simulator's ground truth. The check that the tree
is right, not merely there: the scan's points (and a depth camera's cloud), carried into odom through
it, lie on the yard's walls (inner faces at x = -3.9 and 7.9, y = -2.9 and 4.9; the ground z = 0),
standing and after driving; and a client that reads scans in base_link, as the course's did, sees
the wall ahead where it is.

Parameters: ~ns (the robot's namespace), ~odom (its odom frame), ~base (its base_link frame),
~scan (a LaserScan topic), ~cloud (a PointCloud2 topic, optional).
"""

import math
import threading
import time
import unittest
import xml.etree.ElementTree as ET

import numpy as np
import rospy
import rostest
import tf2_ros
import yaml
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from sensor_msgs import point_cloud2
from sensor_msgs.msg import LaserScan, PointCloud2

from thorvald_testing.topics import Latest, TfPublishers

STARTUP = 120.0  # [s] wall: the simulator, the model and the spawn on a busy machine
WALLS_X = (-3.9, 7.9)  # [m] the yard's inner faces in odom (the robot spawns at the origin)
WALLS_Y = (-2.9, 4.9)
ON_WALL = 0.06  # [m]: lidar noise 0.01 m (sigma), a 0.01 m range resolution, the points' time skew
SPEED = 0.5  # [m/s] the drive
ROBOT = (0.9, 0.7)  # [m] half the robot's length and width in base_link, wheels and legs included
DRIVE = 3.0  # [s] simulated


def matrix(transform):
    """4 x 4 matrix of a geometry_msgs/TransformStamped."""
    t, q = transform.transform.translation, transform.transform.rotation
    x, y, z, w = q.x, q.y, q.z, q.w
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w), t.x],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w), t.y],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y), t.z],
            [0.0, 0.0, 0.0, 1.0],
        ]
    )


def scan_points(scan):
    """The scan's finite readings as points (n x 3) in its own frame."""
    ranges = np.asarray(scan.ranges, dtype=float)
    angles = scan.angle_min + scan.angle_increment * np.arange(len(ranges))
    ok = np.isfinite(ranges) & (ranges >= scan.range_min) & (ranges <= scan.range_max)
    r, a = ranges[ok], angles[ok]
    return np.column_stack([r * np.cos(a), r * np.sin(a), np.zeros_like(r)])


def to_frame(points, m):
    return points @ m[:3, :3].T + m[:3, 3]


def distance_to_walls(points):
    """Each point's distance [m] to the nearest of the yard's inner wall faces."""
    x, y = points[:, 0], points[:, 1]
    return np.min(np.abs(np.column_stack([x - WALLS_X[0], x - WALLS_X[1], y - WALLS_Y[0], y - WALLS_Y[1]])), axis=1)


class UsersTfTree(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.ns = rospy.get_param("~ns")
        cls.odom = rospy.get_param("~odom")
        cls.base = rospy.get_param("~base")
        cls.buffer = tf2_ros.Buffer(rospy.Duration(30.0))
        cls.listener = tf2_ros.TransformListener(cls.buffer)
        cls.tf_publishers = TfPublishers()
        cls.scan = Latest(rospy.get_param("~scan"), LaserScan, queue_size=1, buff_size=2**24)
        cloud = rospy.get_param("~cloud", "")
        cls.cloud = Latest(cloud, PointCloud2, queue_size=1, buff_size=2**24) if cloud else None
        cls.truth = Latest(cls.ns + "odometry/gazebo", Odometry, queue_size=1)
        cls.nav = rospy.Publisher(cls.ns + "nav_vel", Twist, queue_size=1)
        deadline = time.time() + STARTUP
        while time.time() < deadline and (cls.truth.get() is None or cls.scan.get() is None):
            time.sleep(0.1)
        assert cls.truth.get() is not None, f"no {cls.ns}odometry/gazebo after {STARTUP:g} s: the robot is not up"
        assert cls.scan.get() is not None, f"no {cls.scan.sub.resolved_name} after {STARTUP:g} s"
        description = ET.fromstring(rospy.get_param(cls.ns + "robot_description"))
        cls.links = [link.get("name") for link in description.iter("link")]

    def lookup(self, target, source, stamp=None, timeout=10.0):
        return self.buffer.lookup_transform(target, source, stamp or rospy.Time(0), rospy.Duration(timeout))

    def test_1_every_link_hangs_from_odom(self):
        self.assertIn(self.base, self.links)
        missing = []
        for link in self.links:
            try:
                self.lookup(self.odom, link)
            except tf2_ros.TransformException as e:
                missing.append(f"{link}: {e}")
        self.assertEqual(missing, [], "links without a transform from " + self.odom)
        # odom -> base_link, and no frame named with a leading or a doubled slash
        frames = yaml.safe_load(self.buffer.all_frames_as_yaml())
        names = set(frames) | {f["parent"] for f in frames.values()}
        self.assertEqual([n for n in names if n.startswith("/") or "//" in n], [])
        self.assertEqual(frames[self.base]["parent"], self.odom)
        # one publisher per transform: model.launch's robot_state_publisher, the simulator's odom -> base_link
        self.assertEqual(self.tf_publishers.shared(), {})
        self.assertIn(self.base, self.tf_publishers.children())

    def test_2_every_sensor_frame_hangs_from_odom_and_its_readings_lie_on_the_walls(self):
        scan = self.scan.get()
        self.assertFalse(scan.header.frame_id.startswith("/"), scan.header.frame_id)
        self.assertIn(scan.header.frame_id, self.links)
        self.check_scan_on_walls(scan)
        if self.cloud is not None:
            cloud = self.cloud.wait(timeout=STARTUP)
            self.assertFalse(cloud.header.frame_id.startswith("/"), cloud.header.frame_id)
            self.assertIn(cloud.header.frame_id, self.links)
            m = matrix(self.lookup(self.odom, cloud.header.frame_id, cloud.header.stamp))
            xyz = np.array(list(point_cloud2.read_points(cloud, ("x", "y", "z"), skip_nans=True)))
            self.assertGreater(len(xyz), 1000, "the depth camera sees nothing")
            points = to_frame(xyz[:: max(1, len(xyz) // 3000)], m)
            off = np.minimum(distance_to_walls(points), np.abs(points[:, 2]))  # a wall or the ground
            self.assertLess(
                np.percentile(off, 99), ON_WALL, f"cloud off the walls and ground: {points[off > ON_WALL][:5]}"
            )

    def check_scan_on_walls(self, scan):
        """Every reading not on the robot itself (the lidar sees its own legs, as Gazebo's did) lies on a wall."""
        own = to_frame(scan_points(scan), matrix(self.lookup(self.base, scan.header.frame_id, scan.header.stamp)))
        m = matrix(self.lookup(self.odom, scan.header.frame_id, scan.header.stamp))
        points = to_frame(scan_points(scan), m)[(np.abs(own[:, 0]) > ROBOT[0]) | (np.abs(own[:, 1]) > ROBOT[1])]
        self.assertGreater(len(points), 100, "the lidar sees no wall")
        off = distance_to_walls(points)
        self.assertLess(np.max(off), ON_WALL, f"scan points off the walls (odom): {points[off > ON_WALL][:5]}")
        return points

    def test_3_after_driving_the_tree_still_puts_the_scan_on_the_walls(self):
        start = self.truth.get().pose.pose.position
        stop = threading.Event()

        def stream():
            msg = Twist()
            msg.linear.x, msg.angular.z = SPEED, 0.2
            while not stop.is_set():
                self.nav.publish(msg)
                time.sleep(0.05)

        threading.Thread(target=stream, daemon=True).start()
        try:
            end = rospy.get_time() + DRIVE
            while rospy.get_time() < end and not rospy.is_shutdown():
                time.sleep(0.02)
            scan = self.scan.after(rospy.Time.from_sec(end - 0.5))  # a scan taken while it drives
            self.check_scan_on_walls(scan)
        finally:
            stop.set()
        now = self.truth.get().pose.pose.position
        moved = math.hypot(now.x - start.x, now.y - start.y)
        self.assertGreater(moved, 0.5 * SPEED * DRIVE, "the robot did not drive")
        # odom -> base_link is the simulator's ground truth: odometry/gazebo's pose at its stamp
        truth = self.truth.get()
        tf = self.lookup(self.odom, self.base, truth.header.stamp)
        self.assertAlmostEqual(tf.transform.translation.x, truth.pose.pose.position.x, places=6)
        self.assertAlmostEqual(tf.transform.translation.y, truth.pose.pose.position.y, places=6)

    def test_4_a_client_reading_scans_in_base_link_sees_the_wall_ahead(self):
        """The course's client: each scan into base_link, the nearest reading straight ahead."""
        scan = self.scan.after(rospy.Time.from_sec(rospy.get_time()))
        m = matrix(self.lookup(self.base, scan.header.frame_id, scan.header.stamp))
        points = to_frame(scan_points(scan), m)
        ahead = points[np.abs(points[:, 1]) < 0.2]
        self.assertGreater(len(ahead), 0)
        # the wall ahead, seen from base_link: where ground truth puts the robot in the yard, the
        # first inner face along its heading
        truth = self.truth.after(scan.header.stamp, timeout=30.0).pose.pose
        yaw = 2 * math.atan2(truth.orientation.z, truth.orientation.w)
        c, s = math.cos(yaw), math.sin(yaw)
        hits = []
        if abs(c) > 1e-6:
            hits.append(((WALLS_X[1] if c > 0 else WALLS_X[0]) - truth.position.x) / c)
        if abs(s) > 1e-6:
            hits.append(((WALLS_Y[1] if s > 0 else WALLS_Y[0]) - truth.position.y) / s)
        self.assertAlmostEqual(float(np.min(ahead[:, 0])), min(hits), delta=0.25)


if __name__ == "__main__":
    rospy.init_node("users_tf_tree")
    rostest.rosrun("thorvald_bringup", "users_tf_tree", UsersTfTree)
