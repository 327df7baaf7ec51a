"""thorvald_sim.node.tf_watch: another publisher of a robot's odom -> base_link found in /tf's raw bytes.

The bytes are genpy's serialisation of real tf2_msgs/TFMessage values (the parser shares nothing
with it), so a wrong offset in the parser shows as wrong frames.
"""

import io

import pytest
from geometry_msgs.msg import TransformStamped
from tf2_msgs.msg import TFMessage

from thorvald_sim.errors import MalformedTf
from thorvald_sim.node.tf_watch import TfWatch, transform_frames


def tf_bytes(*pairs, x=0.25):
    msg = TFMessage()
    for parent, child in pairs:
        t = TransformStamped()
        t.header.frame_id, t.child_frame_id = parent, child
        t.header.stamp.secs, t.header.seq = 12, 7
        t.transform.translation.x = x
        t.transform.rotation.w = 1.0
        msg.transforms.append(t)
    buff = io.BytesIO()
    msg.serialize(buff)
    return buff.getvalue()


RSP = [("r1/base_link", "r1/leg0"), ("r1/leg0", "r1/wheel0_link"), ("r1/base_link", "r1/leg1")]


def test_frames_of_a_serialised_message_in_order_leading_slashes_dropped():
    assert transform_frames(tf_bytes(*RSP)) == RSP
    assert transform_frames(tf_bytes(("/odom", "/base_link"))) == [("odom", "base_link")]
    assert transform_frames(tf_bytes()) == []
    # UTF-8 names of any length, and a translation whose bytes look like a short string length (x = 0)
    assert transform_frames(tf_bytes(("wörld", "a" * 300), x=0.0)) == [("wörld", "a" * 300)]


def test_a_cut_message_is_malformed_not_misread():
    whole = tf_bytes(*RSP)
    for end in (0, 3, 10, len(whole) - 1):
        with pytest.raises(MalformedTf):
            transform_frames(whole[:end])


def watch_with(publishers, judge_after=3, stale=2.0):
    w = TfWatch("/simulator", judge_after=judge_after, stale=stale)
    w.watch("r1", "r1/base_link")
    w.publishers(["/simulator", *publishers])
    return w


def test_another_publisher_of_the_watched_child_is_a_conflict_once():
    w = watch_with(["/r1/base_driver"])
    assert w.listening()
    odom = tf_bytes(("r1/odom", "/r1/base_link"))  # a leading slash means the same frame, as in tf2
    (conflict,) = w.message("/r1/base_driver", odom, now=1.0)
    assert (conflict.robot, conflict.publisher, conflict.parent, conflict.child) == (
        "r1",
        "/r1/base_driver",
        "r1/odom",
        "r1/base_link",
    )
    assert w.message("/r1/base_driver", odom, now=1.1) == []  # said once while it goes on
    assert w.listening()  # read on, to see it stop


def test_base_link_as_a_parent_is_no_conflict_and_a_publisher_is_judged_then_not_read():
    w = watch_with(["/r1/rsp/robot_state_publisher"], judge_after=3)
    for k in range(3):
        assert w.listening(), k
        assert w.message("/r1/rsp/robot_state_publisher", tf_bytes(*RSP), now=k) == []
    assert not w.listening()  # every publisher judged: /tf need not be read
    w.publishers(["/r1/rsp/robot_state_publisher", "/r1/ekf"])  # a new publisher: read again
    assert w.listening()


def test_our_own_messages_never_conflict():
    w = watch_with([])
    assert w.message("/simulator", tf_bytes(("r1/odom", "r1/base_link")), now=0.0) == []


def test_a_new_robot_has_every_publisher_judged_again():
    w = watch_with(["/fleet_driver"], judge_after=1)
    assert w.message("/fleet_driver", tf_bytes(*RSP), now=0.0) == []
    assert not w.listening()
    w.watch("r2", "r2/base_link")
    assert w.listening()
    (conflict,) = w.message("/fleet_driver", tf_bytes(("r2/odom", "r2/base_link")), now=0.1)
    assert conflict.robot == "r2"


def test_a_silent_other_publisher_hands_the_robot_back_and_its_return_is_seen():
    w = watch_with(["/r1/base_driver"], stale=2.0)
    odom = tf_bytes(("r1/odom", "r1/base_link"))
    assert len(w.message("/r1/base_driver", odom, now=10.0)) == 1
    w.message("/r1/base_driver", odom, now=11.5)  # still publishing: the yield lasts from here
    assert w.resumed(now=13.0) == []
    (back,) = w.resumed(now=13.6)
    assert back.robot == "r1" and w.resumed(now=20.0) == []
    assert w.listening()  # a robot that had a conflict keeps /tf read
    assert len(w.message("/r1/base_driver", odom, now=21.0)) == 1  # it came back


def test_forgetting_a_robot_ends_its_watch():
    w = watch_with(["/r1/base_driver"])
    w.forget("r1")
    assert not w.listening()
    assert w.message("/r1/base_driver", tf_bytes(("r1/odom", "r1/base_link")), now=0.0) == []
