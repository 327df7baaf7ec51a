#!/usr/bin/env python3
"""A lidar sees the crop rows of the shipped crop_rows world: driving between two rows, the nearest
returns on each side agree with the row spacing.

The geometry (crop_rows.yaml, test/data/row_lidar.xacro): lettuce rows along +x from x = 4 m, 0.75 m
apart, one at y = 0 and one at y = 0.75 m; heads every 0.35 m, balls of radius R = 0.12 m centred
0.13 m up, each moved up to 2 cm along and across its row, 5 % missing. The robot spawns at the
origin heading +x and drives at 0.5 m/s straddling the row at y = 0; the lidar is 0.9 m ahead of
base_link and 0.375 m to its left, half-way between the two rows, its scan plane through the heads'
centres. So, in the lidar's frame, the heads of the row on its left are 0.375 m away across the
rows, those of the row on its right too, and the next rows a row spacing (0.75 m) farther on each
side: beams pass between heads (0.35 m apart, 0.24 m wide) to them. A beam that crosses a row's
line dx from a head's centre (|dx| < R) meets the head sqrt(R^2 - dx^2) short of the line; beams
are spread evenly along the row, so dx is uniform over the head and the median hit is
R sqrt(3)/2 = 0.104 m short of it: the nearest row's returns at 0.375 - 0.104 = 0.271 m, the next
row's 0.75 m farther, the same on both sides. The heads are balls of eight facets around (their
faces R cos(22.5 deg) from the centre), a head's jitter moves it 2 cm at most, and the lidar's
noise is 0.01 m: 3 cm on a median of many returns.

Measured on every scan taken with the lidar at least 1 m into the rows: on each side, the returns
within 40 degrees of the side (+90 or -90 degrees) and 0.6 m along the rows, their distance across
the rows; the median of those below 0.6 m (the nearest row) and of those between 0.8 and 1.3 m (the
next row).
"""

import math
import threading
import unittest

import numpy as np
import rospy
import rostest
from sensor_msgs.msg import LaserScan
from sim_testing import Commander, Latest, planar, sim_sleep

ROBOT = "/thorvald_001"
SPACING = 0.75  # [m] between the rows
HALF = SPACING / 2  # [m] the lidar's distance across from each row's centre line
R = 0.12  # [m] of a head
SHORT = R * math.sqrt(3) / 2  # [m] the median hit's distance short of the row's line (docstring)
ROWS_START = 4.0  # [m] x where the rows begin
LIDAR_X = 0.9  # [m] ahead of base_link
# The heads' facets, the jitter and the noise, on a median of many returns: 3 cm
TOLERANCE = 0.03


class Scans:
    """Scans with the ground-truth pose of the moment they came (both on simulated time)."""

    def __init__(self, truth):
        self.truth = truth
        self.lock = threading.Lock()
        self.taken = []
        rospy.Subscriber(ROBOT + "/row_lidar/scan", LaserScan, self.on, queue_size=50)

    def on(self, scan):
        odom = self.truth.get()
        if odom is None:
            return
        with self.lock:
            self.taken.append((scan, planar(odom)))

    def get(self):
        with self.lock:
            return list(self.taken)


def across(scan, side):
    """Distances across the rows [m] of the returns within 40 degrees of side (+1 left, -1 right)
    and 0.6 m along the rows."""
    ranges = np.asarray(scan.ranges, dtype=float)
    angles = scan.angle_min + scan.angle_increment * np.arange(len(ranges))
    ok = np.isfinite(ranges) & (ranges >= scan.range_min) & (ranges < scan.range_max)
    ok &= np.abs(angles - side * math.pi / 2) < math.radians(40)
    x, y = ranges * np.cos(angles), ranges * np.sin(angles)
    ok &= np.abs(x) < 0.6
    return np.abs(y[ok])


class CropRowsLidarTest(unittest.TestCase):
    def test_the_nearest_returns_on_each_side_agree_with_the_row_spacing(self):
        truth = Latest(ROBOT + "/odometry/gazebo")
        truth.wait()
        scans = Scans(truth)
        nav = Commander(ROBOT + "/nav_vel")
        nav.wait_for_subscriber()
        nav.send(vx=0.5)
        sim_sleep(14.0)  # base_link from x 0 to about 7 m: the lidar 3.9 m into the rows
        nav.stop()
        taken = [(s, pose) for s, pose in scans.get() if pose[0] + LIDAR_X > ROWS_START + 1.0]
        self.assertGreater(len(taken), 40, "scans inside the rows")
        # the robot kept to its row: the figures assume the lidar half-way between the rows
        _, y, yaw = taken[-1][1]
        self.assertLess(abs(y), 0.03)
        self.assertLess(abs(yaw), 0.02)
        self.assertEqual(taken[-1][0].header.frame_id, "thorvald_001/row_lidar_link")

        near, far = {}, {}
        for side, name in ((1, "left"), (-1, "right")):
            d = np.concatenate([across(s, side) for s, _ in taken])
            near[name] = float(np.median(d[d < 0.6]))
            far[name] = float(np.median(d[(d > 0.8) & (d < 1.3)]))
            rospy.loginfo("%s: %d returns, nearest row %.3f m, next row %.3f m", name, len(d), near[name], far[name])
            # the nearest row: half a spacing, less the median hit's distance short of the line
            self.assertAlmostEqual(near[name], HALF - SHORT, delta=TOLERANCE, msg=name)
            # the next row a row spacing farther
            self.assertAlmostEqual(far[name] - near[name], SPACING, delta=TOLERANCE, msg=name)
        # the lidar is half-way between the rows: both sides read the same
        self.assertAlmostEqual(near["left"], near["right"], delta=0.02)


if __name__ == "__main__":
    rospy.init_node("crop_rows_lidar_test")
    rostest.rosrun("thorvald_sim", "crop_rows_lidar", CropRowsLidarTest)
