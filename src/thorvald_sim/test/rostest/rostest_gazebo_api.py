#!/usr/bin/env python3
"""The /gazebo API of the simulator as users' nodes call it, with Gazebo's semantics, on simulated
time: the standard robot thorvald_001 spawned by robot.launch at the origin heading +x on flat ground.

* a sprayer node drops static SDF marks 0.5 m behind ``thorvald_001/base_link`` (spawn_sdf_model with
  reference_frame the robot's link), driving and paused; the marks stay where they were dropped;
* a navigation-tuning trial loop teleports the robot to each trial's start (set_model_state, service
  and topic), drives it, reads ground truth (get_model_state) beside ``odometry/gazebo``, resets;
* a /gazebo/model_states and /gazebo/link_states subscriber;
* a harness pauses (time stands), unpauses, resets the simulation (time back to zero; base_driver and
  twist_mux carry on and the robot drives again);
* a URDF model pushed by apply_body_wrench, a gate's hinge set and pushed;
* every bad input: broken XML, unknown names and reference frames, duplicate names, a model of 10^6
  links, a wrench of 1e30 N, NaN poses, a teleport into the ground: ``success: false`` with the reason,
  and the simulator and the robot carry on.
"""

import math
import threading
import time
import unittest
from typing import ClassVar

import rospy
import rostest
from geometry_msgs.msg import Point, Pose, Quaternion, Twist, Vector3, Wrench
from rosgraph_msgs.msg import Clock
from sim_testing import STARTUP, Commander, Latest, planar, sim_sleep
from std_srvs.srv import Empty

from gazebo_msgs.msg import LinkStates, ModelState, ModelStates
from gazebo_msgs.srv import (
    ApplyBodyWrench,
    ApplyJointEffort,
    BodyRequest,
    DeleteModel,
    GetJointProperties,
    GetLinkProperties,
    GetLinkState,
    GetModelProperties,
    GetModelState,
    GetPhysicsProperties,
    GetWorldProperties,
    SetModelConfiguration,
    SetModelState,
    SetPhysicsProperties,
    SpawnModel,
)
from thorvald_base.conversions import quaternion_yaw

ROBOT = "thorvald_001"
BASE = "thorvald_001/base_link"

MARK = """<?xml version="1.0"?><sdf version="1.6"><model name="mark"><static>true</static>
  <link name="link"><visual name="visual"><geometry><cylinder><radius>0.05</radius><length>0.002</length>
  </cylinder></geometry></visual></link></model></sdf>"""

CRATE = """<?xml version="1.0"?><robot name="crate"><link name="crate_link">
  <inertial><mass value="10"/><inertia ixx="0.27" iyy="0.27" izz="0.27" ixy="0" ixz="0" iyz="0"/></inertial>
  <collision><geometry><box size="0.4 0.4 0.4"/></geometry></collision></link></robot>"""

GATE = """<sdf version="1.6"><model name="gate">
  <link name="post"><pose>0 0 0.5 0 0 0</pose>
    <collision name="collision"><geometry><box><size>0.1 0.1 1</size></box></geometry></collision></link>
  <link name="door"><pose>0.6 0 0.5 0 0 0</pose>
    <inertial><mass>5</mass><inertia><ixx>0.27</ixx><iyy>0.68</iyy><izz>0.42</izz></inertia></inertial>
    <collision name="collision"><geometry><box><size>1 0.05 0.8</size></box></geometry></collision></link>
  <joint name="hinge" type="revolute"><pose>-0.5 0 0 0 0 0</pose><parent>post</parent><child>door</child>
    <axis><xyz>0 0 1</xyz><limit><lower>-2</lower><upper>2</upper></limit></axis></joint>
  <joint name="to_world" type="fixed"><parent>world</parent><child>post</child></joint>
</model></sdf>"""


def pose(x=0.0, y=0.0, z=0.0, yaw=0.0):
    return Pose(Point(x, y, z), Quaternion(0.0, 0.0, math.sin(yaw / 2), math.cos(yaw / 2)))


def xyz(p):
    return p.position.x, p.position.y, p.position.z


class Gazebo:
    """The /gazebo services by name."""

    TYPES: ClassVar[dict] = {
        "spawn_urdf_model": SpawnModel, "spawn_sdf_model": SpawnModel, "delete_model": DeleteModel,
        "get_model_state": GetModelState, "set_model_state": SetModelState, "get_link_state": GetLinkState,
        "get_model_properties": GetModelProperties, "get_world_properties": GetWorldProperties,
        "get_link_properties": GetLinkProperties, "get_joint_properties": GetJointProperties,
        "get_physics_properties": GetPhysicsProperties, "set_physics_properties": SetPhysicsProperties,
        "set_model_configuration": SetModelConfiguration, "apply_body_wrench": ApplyBodyWrench,
        "clear_body_wrenches": BodyRequest, "apply_joint_effort": ApplyJointEffort,
        "pause_physics": Empty, "unpause_physics": Empty, "reset_simulation": Empty, "reset_world": Empty,
    }  # fmt: skip

    def __init__(self):
        for name, kind in self.TYPES.items():
            rospy.wait_for_service("/gazebo/" + name, STARTUP)
            setattr(self, name, rospy.ServiceProxy("/gazebo/" + name, kind))

    def truth(self, name=ROBOT, frame="world"):
        res = self.get_model_state(name, frame)
        assert res.success, res.status_message
        return res


class Collect:
    """Every message of a topic, kept."""

    def __init__(self, topic, kind):
        self.messages, self.lock = [], threading.Lock()
        self.sub = rospy.Subscriber(topic, kind, self.on, queue_size=50)

    def on(self, msg):
        with self.lock:
            self.messages.append(msg)

    def last(self, timeout=30.0):
        deadline = time.time() + timeout
        while time.time() < deadline:
            with self.lock:
                if self.messages:
                    return self.messages[-1]
            time.sleep(0.01)
        raise AssertionError(f"nothing on {self.sub.resolved_name}")


class GazeboApiTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.gz = Gazebo()
        cls.truth = Latest(f"/{ROBOT}/odometry/gazebo")
        cls.truth.wait()
        cls.cmd = Commander(f"/{ROBOT}/nav_vel")
        cls.cmd.wait_for_subscriber()
        sim_sleep(1.0)

    def setUp(self):
        self.gz.unpause_physics()

    def assert_refused(self, res, *words):
        self.assertFalse(res.success, res.status_message)
        for word in words:
            self.assertIn(word, res.status_message)

    def assert_carries_on(self):
        """The simulator steps and the robot stands where it stood."""
        before = self.gz.truth()
        t = rospy.get_time()
        sim_sleep(0.3)
        self.assertGreater(rospy.get_time(), t + 0.25)
        after = self.gz.truth()
        self.assertLess(math.dist(xyz(before.pose), xyz(after.pose)), 0.02)

    # ---- the world ------------------------------------------------------------------------------
    def test_01_world_and_model_properties_name_what_gazebo_would(self):
        world = self.gz.get_world_properties()
        self.assertTrue(world.success)
        self.assertEqual(world.model_names[:2], ["ground_plane", ROBOT])
        self.assertGreater(world.sim_time, 0.5)
        props = self.gz.get_model_properties(ROBOT)
        self.assertTrue(props.success, props.status_message)
        self.assertEqual(props.body_names[0], BASE)
        self.assertFalse(props.is_static)
        self.assertTrue(any("steering" in j or "wheel" in j for j in props.joint_names), props.joint_names)
        link = self.gz.get_link_properties(f"{ROBOT}::{BASE}")
        self.assertTrue(link.success, link.status_message)
        self.assertGreater(link.mass, 10.0)
        self.assertTrue(self.gz.get_link_state(BASE, "").success)  # a link's own name, as Gazebo finds it
        physics = self.gz.get_physics_properties()
        self.assertAlmostEqual(physics.time_step, 1 / 240.0)
        self.assertAlmostEqual(physics.gravity.z, -9.81)

    # ---- a sprayer's marks ------------------------------------------------------------------------
    def test_02_sprayer_marks_land_where_the_robot_drops_them_and_stay(self):
        self.cmd.send(0.4, 0.0, 0.1)
        sim_sleep(2.0)
        # paused: the mark lands exactly at the link's frame composed with the request's pose
        self.gz.pause_physics()
        robot = self.gz.get_link_state(BASE, "world").link_state.pose
        res = self.gz.spawn_sdf_model("mark_0", MARK, "", pose(-0.5, 0.0, -0.4), BASE)
        self.assertTrue(res.success, res.status_message)
        mark = self.gz.truth("mark_0").pose
        yaw = quaternion_yaw(robot.orientation)
        r = robot.position
        expect = (r.x - 0.5 * math.cos(yaw), r.y - 0.5 * math.sin(yaw), r.z - 0.4)
        for got, want in zip(xyz(mark), expect):
            self.assertAlmostEqual(got, want, places=6)
        self.assertAlmostEqual(quaternion_yaw(mark.orientation), yaw, places=6)
        relative = self.gz.get_model_state("mark_0", BASE)
        self.assertTrue(relative.success)
        self.assertAlmostEqual(relative.pose.position.x, -0.5, places=6)
        self.assertEqual(relative.header.frame_id, BASE)
        self.gz.unpause_physics()
        # driving: a mark a second, each behind the robot as it was; none moves after
        dropped = {}
        for k in range(1, 4):
            sim_sleep(1.0)
            res = self.gz.spawn_sdf_model(f"mark_{k}", MARK, "", pose(-0.5, 0.0, -0.4), BASE)
            self.assertTrue(res.success, res.status_message)
            dropped[k] = xyz(self.gz.truth(f"mark_{k}").pose)
        self.cmd.send()
        sim_sleep(1.0)
        for k, where in dropped.items():
            self.assertEqual(xyz(self.gz.truth(f"mark_{k}").pose), where)
        self.assertGreater(math.dist(dropped[1], dropped[3]), 0.5)  # the robot moved between them
        for k in range(4):
            self.assertTrue(self.gz.delete_model(f"mark_{k}").success)

    # ---- a trial loop ------------------------------------------------------------------------------
    def test_03_trial_loop_teleports_drives_reads_ground_truth_and_resets(self):
        height = self.gz.truth().pose.position.z  # standing (the robot was spawned at the origin)
        set_topic = rospy.Publisher("/gazebo/set_model_state", ModelState, queue_size=1)
        starts = [(5.0, 2.0, math.pi / 2), (-4.0, 3.0, -2.5), (2.0, -6.0, 0.3)]
        for k, (x, y, yaw) in enumerate(starts):
            state = ModelState(ROBOT, pose(x, y, height + 0.02, yaw), Twist(), "world")
            if k == 1:  # the topic, as some loops do it
                deadline = time.time() + 10
                while set_topic.get_num_connections() == 0 and time.time() < deadline:
                    time.sleep(0.05)
                set_topic.publish(state)
                deadline = time.time() + 10
                while math.dist(xyz(self.gz.truth().pose)[:2], (x, y)) > 0.05 and time.time() < deadline:
                    time.sleep(0.02)
            else:
                res = self.gz.set_model_state(state)
                self.assertTrue(res.success, res.status_message)
            sim_sleep(1.0)
            got = self.gz.truth()
            self.assertAlmostEqual(got.pose.position.x, x, delta=0.02)
            self.assertAlmostEqual(got.pose.position.y, y, delta=0.02)
            self.assertAlmostEqual(got.pose.position.z, height, delta=0.01)  # standing on its wheels
            turn = math.remainder(quaternion_yaw(got.pose.orientation) - yaw, math.tau)
            self.assertAlmostEqual(turn, 0.0, delta=0.01)
            odom = planar(self.truth.get())  # odometry/gazebo follows the teleport
            self.assertAlmostEqual(odom[0], x, delta=0.02)
            self.assertAlmostEqual(odom[1], y, delta=0.02)
            # a trial: 2 s at 0.5 m/s ahead
            self.cmd.send(0.5)
            sim_sleep(2.0)
            self.cmd.send()
            sim_sleep(1.0)
            end = self.gz.truth().pose
            dx, dy = end.position.x - x, end.position.y - y
            along = dx * math.cos(yaw) + dy * math.sin(yaw)
            self.assertGreater(along, 0.7)
            self.assertLess(abs(-dx * math.sin(yaw) + dy * math.cos(yaw)), 0.05)
            self.gz.reset_world()
            sim_sleep(0.5)
            back = self.gz.truth().pose
            self.assertLess(math.dist(xyz(back)[:2], (0.0, 0.0)), 0.02)  # where it was spawned

    def test_04_model_and_link_states_follow_the_world(self):
        models = Collect("/gazebo/model_states", ModelStates)
        links = Collect("/gazebo/link_states", LinkStates)
        sim_sleep(0.5)
        msg = models.last()
        self.assertEqual(msg.name[:2], ["ground_plane", ROBOT])
        truth = self.gz.truth().pose
        self.assertLess(math.dist(xyz(msg.pose[1]), xyz(truth)), 0.01)
        names = links.last().name
        self.assertIn(f"{ROBOT}::{BASE}", names)
        self.assertIn("ground_plane::link", names)
        models.sub.unregister()
        links.sub.unregister()

    # ---- models pushed -----------------------------------------------------------------------------
    def test_05_a_crate_pushed_by_a_wrench_and_a_gate_swung(self):
        res = self.gz.spawn_urdf_model("crate", CRATE, "", pose(0.0, 5.0, 0.3), "world")
        self.assertTrue(res.success, res.status_message)
        sim_sleep(1.0)
        start = xyz(self.gz.truth("crate").pose)
        self.assertAlmostEqual(start[2], 0.2, delta=0.01)
        # 300 N along y for 1 s: the crate slides off along +y
        push = Wrench(Vector3(0, 300, 0), Vector3())
        res = self.gz.apply_body_wrench("crate::crate_link", "", Point(), push, rospy.Time(0), rospy.Duration(1.0))
        self.assertTrue(res.success, res.status_message)
        sim_sleep(2.0)
        moved = xyz(self.gz.truth("crate").pose)
        self.assertGreater(moved[1] - start[1], 0.5)
        self.assertLess(abs(moved[0] - start[0]), 0.1)
        self.gz.clear_body_wrenches("crate::crate_link")  # an empty answer, as Gazebo's
        res = self.gz.spawn_sdf_model("gate", GATE, "", pose(-3.0, 5.0, 0.0), "")
        self.assertTrue(res.success, res.status_message)
        res = self.gz.set_model_configuration("gate", "", ["hinge"], [0.5])
        self.assertTrue(res.success, res.status_message)
        joint = self.gz.get_joint_properties("gate::hinge")
        self.assertTrue(joint.success, joint.status_message)
        self.assertAlmostEqual(joint.position[0], 0.5, delta=0.01)
        res = self.gz.apply_joint_effort("hinge", 5.0, rospy.Time(0), rospy.Duration(0.5))
        self.assertTrue(res.success, res.status_message)
        sim_sleep(0.6)
        self.assertGreater(self.gz.get_joint_properties("gate::hinge").position[0], 0.6)
        for name in ("crate", "gate"):
            self.assertTrue(self.gz.delete_model(name).success)

    # ---- bad input ---------------------------------------------------------------------------------
    def test_06_every_bad_input_is_refused_with_its_reason_and_nothing_stops(self):
        gz = self.gz
        self.assert_refused(gz.spawn_sdf_model("broken", "<sdf version='1.6'><model name='b'><link", "", pose(), ""))
        self.assert_refused(gz.spawn_urdf_model("broken", "<robot name='x'><link name='a'></robot>", "", pose(), ""))
        self.assert_refused(gz.spawn_sdf_model("m", MARK, "", pose(), "nosuch_frame"), "nosuch_frame")
        self.assert_refused(gz.spawn_sdf_model(ROBOT, MARK, "", pose(), ""), "exists")
        huge = "<sdf version='1.6'><model name='huge'>" + "<link name='l'/>" * 10**6 + "</model></sdf>"
        self.assert_refused(gz.spawn_sdf_model("huge", huge, "", pose(), ""))
        self.assert_refused(gz.spawn_sdf_model("nan", MARK, "", pose(math.nan), ""), "finite")
        self.assert_refused(gz.set_model_state(ModelState(ROBOT, pose(math.nan), Twist(), "")), "finite")
        self.assert_refused(gz.set_model_state(ModelState("nosuch", pose(), Twist(), "")), "nosuch")
        self.assert_refused(gz.set_model_state(ModelState(ROBOT, pose(), Twist(), "nosuch")), "nosuch")
        self.assert_refused(gz.set_model_state(ModelState(ROBOT, pose(0, 0, -1.0), Twist(), "")), "inside the ground")
        wrench = Wrench(Vector3(1e30, 0, 0), Vector3())
        second = rospy.Duration(1)
        self.assert_refused(
            gz.apply_body_wrench(f"{ROBOT}::{BASE}", "", Point(), wrench, rospy.Time(0), second), "1e+07"
        )
        self.assert_refused(gz.apply_body_wrench("nosuch::link", "", Point(), Wrench(), rospy.Time(0), second))
        self.assert_refused(gz.get_model_state("nosuch", ""), "does not exist")
        self.assert_refused(gz.get_link_state("nosuch", ""))
        self.assert_refused(gz.get_joint_properties("nosuch"))
        self.assert_refused(gz.delete_model("nosuch"), "does not exist")
        self.assert_refused(gz.delete_model("ground_plane"))
        self.assert_refused(gz.apply_joint_effort("nosuch", 1.0, rospy.Time(0), rospy.Duration(1)))
        self.assertEqual(gz.get_world_properties().model_names, ["ground_plane", ROBOT])
        self.assert_carries_on()
        self.cmd.send(0.3)  # and the robot still drives
        start = self.gz.truth().pose
        sim_sleep(1.5)
        self.cmd.send()
        sim_sleep(0.5)
        self.assertGreater(math.dist(xyz(self.gz.truth().pose), xyz(start)), 0.2)

    # ---- pause, resets --------------------------------------------------------------------------------
    def test_07_pause_stops_time_and_unpause_starts_it(self):
        self.gz.pause_physics()
        self.assertTrue(self.gz.get_physics_properties().pause)
        t = rospy.get_time()
        time.sleep(0.5)  # wall time: nothing must happen while paused
        self.assertEqual(rospy.get_time(), t)
        self.gz.unpause_physics()
        self.assertFalse(self.gz.get_physics_properties().pause)
        sim_sleep(0.2)

    def test_08_physics_properties_set_gravity_and_refuse_another_step(self):
        props = self.gz.get_physics_properties()
        self.assertAlmostEqual(props.max_update_rate, 480.0)  # real-time factor 2 at 240 Hz
        wrong = self.gz.set_physics_properties(0.001, 480.0, Vector3(0, 0, -9.81), props.ode_config)
        self.assert_refused(wrong, "time step")
        ok = self.gz.set_physics_properties(props.time_step, 480.0, Vector3(0, 0, -5.0), props.ode_config)
        self.assertTrue(ok.success, ok.status_message)
        self.assertAlmostEqual(self.gz.get_physics_properties().gravity.z, -5.0)
        ok = self.gz.set_physics_properties(props.time_step, 480.0, Vector3(0, 0, -9.81), props.ode_config)
        self.assertTrue(ok.success, ok.status_message)
        self.assert_carries_on()

    def test_09_reset_simulation_sets_time_back_and_the_nodes_carry_on(self):
        self.cmd.send(0.4)
        sim_sleep(1.0)
        before = rospy.get_time()
        self.assertGreater(before, 5.0)
        clock = Collect("/clock", Clock)  # every tick, so the jump back is seen however late we look
        clock.last()
        self.gz.reset_simulation()
        deadline = time.time() + 30
        while time.time() < deadline:
            with clock.lock:
                jumped = [m.clock.to_sec() for m in clock.messages if m.clock.to_sec() < before - 1.0]
            if jumped:
                break
            time.sleep(0.01)
        clock.sub.unregister()
        self.assertTrue(jumped, f"/clock never went back from {before:.2f} s")
        self.assertLess(min(jumped), 0.1)  # back to zero
        self.assertLess(math.dist(xyz(self.gz.truth().pose)[:2], (0.0, 0.0)), 0.1)  # at its spawn pose
        # the command stream carries on (a navigation stack's), and the robot drives again
        sim_sleep(2.0)
        self.assertGreater(self.gz.truth().pose.position.x, 0.3)
        odom = Latest(f"/{ROBOT}/odometry/base_raw")
        odom.wait()
        self.assertLess(odom.get().header.stamp.to_sec(), 5.0)  # base_driver publishes on the new time
        self.cmd.send()
        sim_sleep(1.0)


if __name__ == "__main__":
    rospy.init_node("gazebo_api_test")
    rostest.rosrun("thorvald_sim", "gazebo_api", GazeboApiTest)
