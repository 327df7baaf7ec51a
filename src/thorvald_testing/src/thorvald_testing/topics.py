"""What rostest nodes share to read topics (rospy: import it only in a node that has a master).

:class:`Latest` keeps a topic's newest message and waits for one with a deadline, so a test never
sleeps on the wall clock to let a message arrive.
"""

import threading
import time

import rospy

STARTUP = 60.0  # [s] of wall time for a first message on a busy machine


class Latest:
    """The newest message of a topic, and how many came (rospy's subscriber options passed on)."""

    def __init__(self, topic, msg_type, queue_size=10, **subscriber_options):
        self.topic = topic
        self._lock = threading.Lock()
        self.msg = None
        self.count = 0
        self.sub = rospy.Subscriber(topic, msg_type, self._on, queue_size=queue_size, **subscriber_options)

    def _on(self, msg):
        with self._lock:
            self.msg = msg
            self.count += 1

    def get(self):
        with self._lock:
            return self.msg

    def wait(self, timeout=STARTUP):
        """The newest message, once there is one; AssertionError after timeout [s] of wall time."""
        return self.after(None, timeout)

    def after(self, stamp, timeout=STARTUP):
        """The newest message stamped at or after stamp (a rospy.Time; None: any), once there is one."""
        deadline = time.time() + timeout
        while time.time() < deadline and not rospy.is_shutdown():
            msg = self.get()
            if msg is not None and (stamp is None or msg.header.stamp >= stamp):
                return msg
            time.sleep(0.02)
        since = "" if stamp is None else f" stamped after {stamp.to_sec():.2f} s"
        raise AssertionError(f"nothing on {self.topic}{since} within {timeout:.0f} s")


class TfPublishers:
    """Which nodes publish each child frame on /tf and /tf_static (their callerids), from now on."""

    def __init__(self):
        from tf2_msgs.msg import TFMessage  # noqa: PLC0415  (message types: only where a node reads /tf)

        self._lock = threading.Lock()
        self.by_child = {}  # child frame -> set of (topic, callerid)
        self.subs = [
            rospy.Subscriber(topic, TFMessage, self._on, callback_args=topic, queue_size=1000)
            for topic in ("/tf", "/tf_static")
        ]

    def _on(self, msg, topic):
        caller = msg._connection_header["callerid"]
        with self._lock:
            for t in msg.transforms:
                self.by_child.setdefault(t.child_frame_id.lstrip("/"), set()).add((topic, caller))

    def shared(self):
        """{child frame: its publishers} of every frame more than one node (or topic) has published."""
        with self._lock:
            return {child: sorted(who) for child, who in self.by_child.items() if len(who) > 1}

    def children(self):
        with self._lock:
            return set(self.by_child)
