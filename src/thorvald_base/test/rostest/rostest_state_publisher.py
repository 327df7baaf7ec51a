#!/usr/bin/env python3
"""fleet_driver's /tf of a robot's joints (thorvald_base.state_publisher) equals robot_state_publisher's.

The same robot is described as ref/ (robot_state_publisher runs on it) and as fleet/ (this test
node runs FleetStatePublisher on it, as fleet_driver does). Both get joint positions of every moving
joint at random, in one JointState each with the same stamp; every transform they publish, on /tf
and on /tf_static, must agree to 1e-6 with the prefix swapped. Then: a message stamped within
1 / publish_frequency of the last is not used, by either.
"""

import math
import random
import threading
import time
import unittest

import rospy
import rostest
from sensor_msgs.msg import JointState
from tf2_msgs.msg import TFMessage

from thorvald_base.state_publisher import FleetStatePublisher
from thorvald_model.joint_tree import JointTree

WAIT = 30.0  # [s] wall


class Collector:
    def __init__(self, topic):
        self.lock = threading.Lock()
        self.by_child = {}
        self.messages = []
        self.sub = rospy.Subscriber(topic, TFMessage, self.on, queue_size=100)

    def on(self, msg):
        with self.lock:
            self.messages.append(msg)
            for t in msg.transforms:
                self.by_child[(t.child_frame_id, t.header.stamp.to_nsec())] = t

    def find(self, child, stamp):
        with self.lock:
            return self.by_child.get((child, stamp.to_nsec()))

    def statics(self):
        with self.lock:
            return {t.child_frame_id: t for m in self.messages for t in m.transforms}


def close(a, b, tol=1e-6):
    ta, tb = a.transform, b.transform
    dq = min(
        max(abs(p - q) for p, q in zip(rots(ta), rots(tb))),
        max(abs(p + q) for p, q in zip(rots(ta), rots(tb))),
    )
    dt = max(abs(p - q) for p, q in zip(trans(ta), trans(tb)))
    return dt < tol and dq < tol, (dt, dq)


def rots(t):
    return (t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w)


def trans(t):
    return (t.translation.x, t.translation.y, t.translation.z)


def wait_for(condition, what):
    deadline = time.time() + WAIT
    while not condition():
        if time.time() > deadline:
            raise AssertionError(f"{what} within {WAIT:.0f} s")
        time.sleep(0.05)


class StatePublisherTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tf = Collector("/tf")
        cls.static = Collector("/tf_static")
        wait_for(lambda: rospy.has_param("/fleet/robot_description"), "no /fleet/robot_description")
        cls.publisher = FleetStatePublisher(50.0)
        cls.publisher.add("/fleet/")
        cls.publisher.publish_static()
        tree = JointTree(rospy.get_param("/fleet/robot_description"))
        cls.moving = sorted(n[len("fleet/") :] for n in tree.joints if tree.moving(n))
        # each joint's child link, unprefixed
        cls.child = {n: tree.joints["fleet/" + n][0][len("fleet/") :] for n in cls.moving}
        cls.pubs = {p: rospy.Publisher(f"/{p}/joint_states", JointState, queue_size=10) for p in ("ref", "fleet")}
        wait_for(lambda: all(p.get_num_connections() for p in cls.pubs.values()), "both publishers not read")
        wait_for(lambda: cls.tf.sub.get_num_connections() >= 2, "/tf not published by both")

    last_stamp = rospy.Time()

    def fresh_stamp(self):
        """Now, or 0.1 s past the last stamp any test sent, whichever is later: both publishers skip
        a message within 1 / publish_frequency of their last, and the tests run in one process."""
        stamp = max(rospy.Time.now(), StatePublisherTest.last_stamp + rospy.Duration(0.1))
        StatePublisherTest.last_stamp = stamp + rospy.Duration(0.05)  # the interval test sends up to 50 ms on
        return stamp

    def send(self, positions, stamp):
        for prefix, pub in self.pubs.items():
            msg = JointState(name=[prefix + "/" + n for n in positions], position=list(positions.values()))
            msg.header.stamp = stamp
            pub.publish(msg)

    def test_fixed_joints_agree(self):
        wait_for(lambda: any(c.startswith("fleet/") for c in self.static.statics()), "no fleet/ static transform")
        wait_for(lambda: any(c.startswith("ref/") for c in self.static.statics()), "no ref/ static transform")
        statics = self.static.statics()
        ref = {c[len("ref/") :]: t for c, t in statics.items() if c.startswith("ref/")}
        ours = {c[len("fleet/") :]: t for c, t in statics.items() if c.startswith("fleet/")}
        self.assertEqual(sorted(ref), sorted(ours))
        self.assertGreater(len(ours), 5)
        for child, t in ours.items():
            self.assertEqual(t.header.frame_id, "fleet/" + ref[child].header.frame_id[len("ref/") :])
            ok, err = close(t, ref[child])
            self.assertTrue(ok, f"{child}: {err}")

    def test_moving_joints_agree_at_random_positions(self):
        self.assertGreater(len(self.moving), 10)  # steering, wheels and suspension of six drives
        rng = random.Random(7)
        for _ in range(5):
            positions = {
                n: rng.uniform(-math.pi, math.pi) if "susp" not in n else rng.uniform(-0.05, 0.05) for n in self.moving
            }
            stamp = self.fresh_stamp()
            self.send(positions, stamp)
            for n in self.moving:
                child = self.child[n]
                wait_for(lambda c=child, s=stamp: self.tf.find("fleet/" + c, s) is not None, f"fleet/{n} at {stamp}")
                wait_for(lambda c=child, s=stamp: self.tf.find("ref/" + c, s) is not None, f"ref/{n} at {stamp}")
                ours, ref = self.tf.find("fleet/" + child, stamp), self.tf.find("ref/" + child, stamp)
                ok, err = close(ours, ref)
                self.assertTrue(ok, f"{n} at {positions[n]:.4f}: {err}")
            time.sleep(0.05)  # past 1 / publish_frequency

    def test_a_message_within_the_publish_interval_is_not_used(self):
        positions = dict.fromkeys(self.moving, 0.1)
        stamp = self.fresh_stamp()
        self.send(positions, stamp)
        child = self.child[self.moving[0]]
        wait_for(lambda: self.tf.find("fleet/" + child, stamp) is not None, "the first message used")
        soon = stamp + rospy.Duration(0.005)
        self.send(positions, soon)
        later = stamp + rospy.Duration(0.05)
        self.send(positions, later)
        wait_for(lambda: self.tf.find("fleet/" + child, later) is not None, "the message 50 ms on used")
        wait_for(lambda: self.tf.find("ref/" + child, later) is not None, "ref's message 50 ms on used")
        self.assertIsNone(self.tf.find("fleet/" + child, soon))
        self.assertIsNone(self.tf.find("ref/" + child, soon))


if __name__ == "__main__":
    rospy.init_node("state_publisher_test")
    rostest.rosrun("thorvald_base", "state_publisher", StatePublisherTest)
