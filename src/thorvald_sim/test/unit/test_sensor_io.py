"""The simulator's sensor messages (thorvald_sim.sensor_io) that are serialised our way."""

import io
import math

import numpy as np
import rospy
from sensor_msgs.msg import LaserScan

from thorvald_sim.sensor_io import FastLaserScan


def scan(cls, ranges, intensities):
    msg = cls()
    msg.header.seq, msg.header.stamp, msg.header.frame_id = 7, rospy.Time(12, 345678901), "robot_1/front_lidar"
    msg.angle_min, msg.angle_max, msg.angle_increment = -2.356, 2.356, 0.0043633
    msg.time_increment, msg.scan_time, msg.range_min, msg.range_max = 0.0, 0.0, 0.1, 30.0
    msg.ranges, msg.intensities = ranges, intensities
    return msg


def serialised(msg):
    buff = io.BytesIO()
    msg.serialize(buff)
    return buff.getvalue()


def test_a_fast_laser_scan_serialises_to_genpys_bytes():
    ranges = np.random.default_rng(3).uniform(0.1, 30.0, 720).astype(np.float32)
    ranges[[0, 5, 719]] = np.inf  # no return
    zeros = np.zeros(720, dtype=np.float32)
    fast = serialised(scan(FastLaserScan, ranges, zeros))
    assert fast == serialised(scan(LaserScan, ranges.tolist(), zeros.tolist()))
    # and a reader decodes it as a plain LaserScan
    back = LaserScan().deserialize(fast)
    assert back.header.frame_id == "robot_1/front_lidar" and back.header.stamp == rospy.Time(12, 345678901)
    assert len(back.ranges) == 720 and math.isinf(back.ranges[5]) and back.ranges[1] == ranges[1]
    assert back.range_max == 30.0 and list(back.intensities) == [0.0] * 720


def test_a_fast_laser_scan_of_no_beams():
    empty = np.zeros(0, dtype=np.float32)
    assert serialised(scan(FastLaserScan, empty, empty)) == serialised(scan(LaserScan, [], []))
