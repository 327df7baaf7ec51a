"""The simulator's sensor messages (thorvald_sim.node.sensor_io) that are serialised our way."""

import io
import math

import numpy as np
import rospy
from sensor_msgs.msg import Image, LaserScan, PointCloud2

from thorvald_sim.node.sensor_io import (
    CAMERA_DTYPE,
    CAMERA_FIELDS,
    LIDAR_DTYPE,
    LIDAR_FIELDS,
    FastImage,
    FastLaserScan,
    FastPointCloud2,
    packed_rgb,
)


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


def image(cls, data, encoding, size):
    width, height, step = size
    msg = cls()
    msg.header.seq, msg.header.stamp, msg.header.frame_id = 3, rospy.Time(5, 6), "robot_1/rgbd_optical_frame"
    msg.height, msg.width, msg.encoding, msg.is_bigendian, msg.step = height, width, encoding, 0, step
    msg.data = data
    return msg


def test_a_fast_image_serialises_an_array_to_genpys_bytes():
    rng = np.random.default_rng(5)
    rgb = rng.integers(0, 256, (4, 6, 3), dtype=np.uint8)
    fast = serialised(image(FastImage, rgb, "rgb8", (6, 4, 18)))
    assert fast == serialised(image(Image, rgb.tobytes(), "rgb8", (6, 4, 18)))
    back = Image().deserialize(fast)
    assert back.encoding == "rgb8" and back.data == rgb.tobytes() and back.header.stamp == rospy.Time(5, 6)
    depth = rng.uniform(0.4, 10.0, (4, 6)).astype(np.float32)
    depth[0, 0] = np.nan
    fast = serialised(image(FastImage, depth, "32FC1", (6, 4, 24)))
    assert fast == serialised(image(Image, depth.tobytes(), "32FC1", (6, 4, 24)))
    # bytes are genpy's own way
    assert serialised(image(FastImage, b"abc", "mono8", (3, 1, 3))) == serialised(
        image(Image, b"abc", "mono8", (3, 1, 3))
    )


def cloud(cls, data, fields, size, dense):
    width, height, point_step = size
    msg = cls()
    msg.header.seq, msg.header.stamp, msg.header.frame_id = 9, rospy.Time(1, 2), "robot_1/velodyne"
    msg.height, msg.width, msg.fields, msg.is_bigendian = height, width, fields, False
    msg.point_step, msg.row_step, msg.is_dense, msg.data = point_step, point_step * width, dense, data
    return msg


def test_a_fast_point_cloud_serialises_its_points_to_genpys_bytes():
    rng = np.random.default_rng(8)
    camera = np.zeros((3, 4), dtype=CAMERA_DTYPE)  # a depth camera's organised cloud, 32 bytes a point
    camera["x"], camera["y"], camera["z"] = rng.normal(size=(3, 3, 4)).astype(np.float32)
    camera["rgb"] = rng.integers(0, 2**24, (3, 4), dtype=np.uint32)
    for dense in (False, True):  # is_dense comes after the data
        fast = serialised(cloud(FastPointCloud2, camera, CAMERA_FIELDS, (4, 3, 32), dense))
        assert fast == serialised(cloud(PointCloud2, camera.tobytes(), CAMERA_FIELDS, (4, 3, 32), dense))
        back = PointCloud2().deserialize(fast)
        assert back.is_dense == dense and back.data == camera.tobytes() and back.fields[3].name == "rgb"
    lidar = np.zeros((1, 5), dtype=LIDAR_DTYPE)  # 22 bytes a point, unaligned
    lidar["x"], lidar["ring"] = rng.normal(size=(1, 5)).astype(np.float32), np.arange(5)
    fast = serialised(cloud(FastPointCloud2, lidar, LIDAR_FIELDS, (5, 1, 22), True))
    assert fast == serialised(cloud(PointCloud2, lidar.tobytes(), LIDAR_FIELDS, (5, 1, 22), True))
    assert len(PointCloud2().deserialize(fast).data) == 5 * 22
    empty = np.zeros((1, 0), dtype=LIDAR_DTYPE)  # a 3D lidar that sees nothing
    fast = serialised(cloud(FastPointCloud2, empty, LIDAR_FIELDS, (0, 1, 22), True))
    assert fast == serialised(cloud(PointCloud2, b"", LIDAR_FIELDS, (0, 1, 22), True))


def test_a_clouds_colours_are_packed_r_g_b_from_the_rgba():
    rgba = np.array([[[10, 20, 30, 255], [255, 0, 0, 128]], [[0, 0, 255, 0], [1, 2, 3, 4]]], dtype=np.uint8)
    assert packed_rgb(rgba).tolist() == [[0x0A141E, 0xFF0000], [0x0000FF, 0x010203]]
    # into a cloud's field (strided, 32 bytes a point): the same words, the rest of the points untouched
    points = np.zeros((2, 2), dtype=CAMERA_DTYPE)
    points["x"] = 1.5
    packed_rgb(rgba, out=points["rgb"])
    assert points["rgb"].tolist() == [[0x0A141E, 0xFF0000], [0x0000FF, 0x010203]] and (points["x"] == 1.5).all()
