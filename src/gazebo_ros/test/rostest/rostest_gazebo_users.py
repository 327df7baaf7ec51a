#!/usr/bin/env python3
"""A users' Gazebo launch file (gazebo_users.test) on this workspace: empty_world.launch started
paused, the robot spawned with ``gazebo_ros spawn_model -urdf -param robot_description ... -unpause``,
a plain SDF box with ``-sdf -file``, a URDF turntable with ``-J turn 0.7 -b`` and a users' model from
GAZEBO_MODEL_PATH with ``-database``.

- the robot is where spawn_model put it (/gazebo/get_model_state), with its odometry, and drives
  on a navigation stack's velocity command (twist_mux's nav_vel): odometry and Gazebo's model
  state both see it move, the same distance in the spawn heading;
- the box rests on the ground where it was put;
- the turntable's joint is at -J's position (/gazebo/get_joint_properties);
- a users' script spawns a mark relative to the robot's base_link and turns the turntable through
  gazebo_ros.gazebo_interface;
- killing the turntable's spawn_model (its bond, -b) deletes the model.

Every wait is on simulated time or a message, bounded by a wall-clock deadline.
"""

import math
import os
import subprocess
import time
import unittest

import rospy
import rostest
from geometry_msgs.msg import Point, Pose, Quaternion, Twist
from nav_msgs.msg import Odometry

from gazebo_msgs.srv import GetJointProperties, GetModelState, GetWorldProperties
from gazebo_ros import gazebo_interface
from thorvald_testing.topics import Latest

ROBOT = "thorvald_001"
STARTUP = 120.0  # [s] wall: the simulator, the robot's nodes and the spawns on a busy machine
WALL_LIMIT = 120.0  # [s] wall, for a wait on simulated time
DATA = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "data")
SPAWN = (1.0, -1.0, 0.3)  # gazebo_users.test's -x -y -Y


def sim_sleep(seconds):
    """Waits for seconds of simulated time, within a wall-clock limit."""
    end = rospy.get_time() + seconds
    deadline = time.time() + WALL_LIMIT
    while rospy.get_time() < end:
        if time.time() > deadline or rospy.is_shutdown():
            raise AssertionError(f"simulated time stalled at {rospy.get_time():.2f} s (waiting for {end:.2f} s)")
        time.sleep(0.005)


def wait_until(predicate, what, timeout=STARTUP):
    deadline = time.time() + timeout
    while not rospy.is_shutdown() and time.time() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.05)
    raise AssertionError(f"timed out after {timeout:.0f} s waiting for {what}")


def yaw_of(q):
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


class GazeboUsersTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        for name in ("get_model_state", "get_world_properties", "get_joint_properties"):
            rospy.wait_for_service("/gazebo/" + name, timeout=STARTUP)
        cls.model_state = rospy.ServiceProxy("/gazebo/get_model_state", GetModelState)
        cls.world = rospy.ServiceProxy("/gazebo/get_world_properties", GetWorldProperties)
        cls.joint = rospy.ServiceProxy("/gazebo/get_joint_properties", GetJointProperties)
        cls.odometry = Latest(f"/{ROBOT}/odometry/base_raw", Odometry)
        cls.nav = rospy.Publisher(f"/{ROBOT}/nav_vel", Twist, queue_size=1)
        wait_until(lambda: {ROBOT, "box", "turntable", "post"} <= set(cls.world().model_names), "the spawned models")
        cls.odometry.wait(STARTUP)  # the robot's spawn unpaused the world: time goes on
        wait_until(lambda: cls.nav.get_num_connections() > 0, "twist_mux subscribing to nav_vel")

    def state(self, model, frame=""):
        response = self.model_state(model, frame)
        self.assertTrue(response.success, response.status_message)
        return response

    def test_1_the_robot_is_where_spawn_model_put_it(self):
        pose = self.state(ROBOT).pose
        x, y, yaw = SPAWN
        self.assertAlmostEqual(pose.position.x, x, delta=0.05)
        self.assertAlmostEqual(pose.position.y, y, delta=0.05)
        self.assertAlmostEqual(yaw_of(pose.orientation), yaw, delta=0.02)

    def test_2_it_drives_on_a_velocity_command(self):
        start, odom0 = self.state(ROBOT).pose.position, self.odometry.get().pose.pose.position
        command = Twist()
        command.linear.x = 0.5
        end_time = rospy.get_time() + 3.0
        while rospy.get_time() < end_time:  # 20 Hz of simulated time, as a navigation stack streams it
            self.nav.publish(command)
            sim_sleep(0.05)
        self.nav.publish(Twist())
        sim_sleep(1.0)
        end, odom1 = self.state(ROBOT).pose.position, self.odometry.get().pose.pose.position
        moved = math.hypot(end.x - start.x, end.y - start.y)
        odom_moved = math.hypot(odom1.x - odom0.x, odom1.y - odom0.y)
        rospy.loginfo("drove %.3f m (model state), %.3f m (odometry)", moved, odom_moved)
        # 0.5 m/s for 3 s, less base_driver's ramp and the command's start: well over 1 m
        self.assertGreater(moved, 1.0)
        self.assertAlmostEqual(odom_moved, moved, delta=0.05 * moved)
        heading = math.atan2(end.y - start.y, end.x - start.x)
        self.assertAlmostEqual(heading, SPAWN[2], delta=0.05)  # forward: along its spawn heading

    def test_3_the_sdf_box_rests_where_it_was_put(self):
        pose = self.state("box", "world").pose.position
        self.assertAlmostEqual(pose.x, 3.0, delta=0.02)
        self.assertAlmostEqual(pose.y, 2.0, delta=0.02)
        self.assertAlmostEqual(pose.z, 0.2, delta=0.02)  # 0.4 m a side, on the ground

    def test_3b_a_model_from_gazebos_model_path_stands_where_it_was_put_and_collides_as_its_mesh(self):
        """-database marker_post: the model's folder on GAZEBO_MODEL_PATH, its model.config's newer SDF,
        its collision an OBJ found through model://: a box dropped on the 1 m post rests on its top."""
        pose = self.state("post", "world").pose
        self.assertAlmostEqual(pose.position.x, 2.0, delta=1e-6)
        self.assertAlmostEqual(pose.position.y, -3.0, delta=1e-6)
        self.assertAlmostEqual(yaw_of(pose.orientation), 0.5, delta=1e-6)
        with open(os.path.join(DATA, "box.sdf"), encoding="utf-8") as f:
            box = f.read()
        on_top = Pose(Point(2.0, -3.0, 1.5), Quaternion(0, 0, math.sin(0.25), math.cos(0.25)))
        self.assertTrue(gazebo_interface.spawn_sdf_model_client("cap", box, "", on_top, "", "/gazebo"))
        sim_sleep(1.5)
        self.assertAlmostEqual(self.state("cap", "world").pose.position.z, 1.2, delta=0.02)  # 1 m + half of 0.4 m

    def test_3c_the_world_files_models_are_models_of_the_api(self):
        """yard.world's own models (its ground plane as the ground), where the file puts them."""
        names = set(self.world().model_names)
        self.assertTrue({"ground_plane", "yard_wall", "gate_post", "corner_post"} <= names, names)
        self.assertAlmostEqual(self.state("yard_wall", "world").pose.position.x, 6.0, delta=1e-6)
        corner = self.state("corner_post", "world").pose
        self.assertAlmostEqual(corner.position.y, 4.0, delta=1e-6)
        self.assertAlmostEqual(yaw_of(corner.orientation), 0.3, delta=1e-6)

    def test_4_the_turntable_joint_is_at_its_initial_position(self):
        response = self.joint("turn")
        self.assertTrue(response.success, response.status_message)
        self.assertAlmostEqual(response.position[0], 0.7, delta=0.02)

    def test_5_users_scripts_spawn_and_configure_through_gazebo_interface(self):
        robot = self.state(ROBOT).pose
        with open(os.path.join(DATA, "box.sdf"), encoding="utf-8") as f:
            box = f.read()
        # a sprayer's mark: 2.5 m ahead of the robot's base_link, resting on the ground
        ahead = Pose(Point(2.5, 0.0, 0.2), Quaternion(0.0, 0.0, 0.0, 1.0))
        ok = gazebo_interface.spawn_sdf_model_client("mark", box, "", ahead, f"{ROBOT}/base_link", "/gazebo")
        self.assertTrue(ok)
        mark = self.state("mark").pose.position
        yaw = yaw_of(robot.orientation)
        self.assertAlmostEqual(mark.x, robot.position.x + 2.5 * math.cos(yaw), delta=0.03)
        self.assertAlmostEqual(mark.y, robot.position.y + 2.5 * math.sin(yaw), delta=0.03)
        self.assertAlmostEqual(mark.z, 0.2, delta=0.03)
        self.assertTrue(gazebo_interface.set_model_configuration_client("turntable", "", ["turn"], [-0.5], "/gazebo"))
        self.assertAlmostEqual(self.joint("turn").position[0], -0.5, delta=0.02)

    def test_6_the_bond_deletes_the_turntable_when_its_spawn_model_ends(self):
        subprocess.run(["rosnode", "kill", "/spawn_turntable"], check=True, capture_output=True, timeout=60)
        wait_until(lambda: "turntable" not in self.world().model_names, "the turntable deleted", timeout=60)
        self.assertFalse(self.model_state("turntable", "").success)


if __name__ == "__main__":
    rospy.init_node("gazebo_users_test")
    rostest.rosrun("gazebo_ros", "gazebo_users", GazeboUsersTest)
