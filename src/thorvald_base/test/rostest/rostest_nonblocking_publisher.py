#!/usr/bin/env python3
"""NonBlockingPublisher (thorvald_base.publishing) with a reader that stops reading.

The simulator publishes /clock and its robots' topics with it, so that one reader behind a dropped
network link cannot stop the simulation. Here one publisher has two readers: a rospy subscriber,
and a TCPROS subscriber of the test's own making that connects with a small receive buffer and
then reads nothing. About 10 MB go out, more than the kernel buffers between publisher and stalled
reader hold. The publisher must not block; the rospy subscriber gets every message; the stalled
reader, once it reads, finds whole messages only (a message the socket took part of is finished
with the next publish, before anything else), in order, some missed, and then the new ones; a
reader that goes away is removed. A reader whose socket another rospy thread has just closed (rospy
closes dead connections when a new reader arrives, and closes the socket before it forgets it) is
removed too, whether it was written to before or is new: publish() does not raise.
"""

import io
import socket
import struct
import threading
import time
import unittest
from xmlrpc.client import ServerProxy

import rospy
import rostest
from rosgraph.network import encode_ros_handshake_header
from std_msgs.msg import String

from thorvald_base.publishing import NonBlockingPublisher

TOPIC = "/nonblocking"
SIZE = 65536  # [bytes] per message
COUNT = 160  # messages while the reader stalls: 10.5 MB, the kernel holds at most about 4 MB of them
PERIOD = 0.02  # [s] between messages: the rospy subscriber keeps up with 3 MB/s
STALLED_RCVBUF = 4096  # [bytes]


def payload(i: int) -> str:
    return f"{i:08d}".ljust(SIZE, "x")


def index(data: str) -> int:
    return int(data[:8])


class StalledReader:
    """A TCPROS subscriber of the test's own: the handshake, then frames only when asked to read."""

    def __init__(self, topic: str, callerid: str = "/stalled_reader"):
        code, msg, protocol = ServerProxy(rospy.get_node_uri()).requestTopic(callerid, topic, [["TCPROS"]])
        assert code == 1, msg
        _, host, port = protocol
        self.sock = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, STALLED_RCVBUF)
        self.sock.connect((host, port))
        header = {"callerid": callerid, "topic": topic, "type": String._type, "md5sum": String._md5sum}
        self.sock.sendall(encode_ros_handshake_header(header))
        (length,) = struct.unpack("<I", self.exact(4))
        reply = self.exact(length)
        assert b"error=" not in reply, reply

    def exact(self, n: int) -> bytes:
        buf = io.BytesIO()
        while buf.tell() < n:
            chunk = self.sock.recv(n - buf.tell())
            if not chunk:
                raise EOFError("the publisher closed the connection")
            buf.write(chunk)
        return buf.getvalue()

    def frames(self, quiet: float, out: list) -> None:
        """Appends the messages that arrive to out until none has for quiet [s]."""
        self.sock.settimeout(quiet)
        while True:
            try:
                (length,) = struct.unpack("<I", self.exact(4))
            except socket.timeout:
                return
            self.sock.settimeout(10.0)  # a message begun arrives whole
            out.append(String().deserialize(self.exact(length)).data)
            self.sock.settimeout(quiet)


class TestNonBlockingPublisher(unittest.TestCase):
    def test_stalled_reader(self):
        received = []
        pub = NonBlockingPublisher(TOPIC, String)
        sub = rospy.Subscriber(TOPIC, String, lambda m: received.append(index(m.data)), buff_size=1 << 22)
        stalled = StalledReader(TOPIC)
        deadline = time.monotonic() + 20
        while pub.get_num_connections() < 2 and time.monotonic() < deadline:
            time.sleep(0.05)
        self.assertEqual(pub.get_num_connections(), 2)

        def publish(first, last):
            for i in range(first, last):
                pub.publish(String(payload(i)))
                time.sleep(PERIOD)

        writer = threading.Thread(target=publish, args=(0, COUNT), daemon=True)
        writer.start()
        writer.join(60.0)
        self.assertFalse(writer.is_alive(), "publish() blocked on the reader that does not read")
        self.wait_for(received, COUNT)
        self.assertEqual(received, list(range(COUNT)), "the reading subscriber missed messages")

        # it reads again (a message the socket took part of is finished with the next publish)
        got = []
        reader = threading.Thread(target=stalled.frames, args=(3.0, got), daemon=True)
        reader.start()
        seen = -1
        while len(got) != seen:  # it has read all there is (the rest of a message, if any, comes next)
            seen = len(got)
            time.sleep(1.0)
        publish(COUNT, COUNT + 5)
        reader.join(60.0)
        indexes = [index(d) for d in got]
        for data in got:
            self.assertEqual(data, payload(index(data)), "a message arrived damaged")
        self.assertEqual(indexes, sorted(set(indexes)), "out of order or repeated")
        self.assertEqual(indexes[0], 0)
        self.assertEqual(indexes[-5:], list(range(COUNT, COUNT + 5)), "reading again, it missed new messages")
        old = [i for i in indexes if i < COUNT]
        self.assertLess(len(old), COUNT, "nothing was missed: the buffers never filled, the test proves nothing")
        rospy.loginfo("stalled reader: %d of %d messages while it stalled, the last %d", len(old), COUNT, old[-1])
        self.wait_for(received, COUNT + 5)

        # a reader that goes away is removed; the others go on
        stalled.sock.close()
        deadline = time.monotonic() + 10
        i = COUNT + 5
        while pub.get_num_connections() > 1 and time.monotonic() < deadline:
            publish(i, i + 1)
            i += 1
        self.assertEqual(pub.get_num_connections(), 1, "the closed reader was not removed")
        self.wait_for(received, i)
        self.assertEqual(received, list(range(i)))
        sub.unregister()

    def test_socket_closed_by_another_thread(self):
        topic = "/closing"
        received = []
        pub = NonBlockingPublisher(topic, String)
        sub = rospy.Subscriber(topic, String, lambda m: received.append(int(m.data)))
        old = StalledReader(topic, "/old_reader")  # written to before its socket is closed
        self.wait_connections(pub, 2)
        pub.publish(String("0"))
        new = StalledReader(topic, "/new_reader")  # its socket closed before its first message
        self.wait_connections(pub, 3)
        closing = [c for c in pub.impl.connections if c.endpoint_id in ("/old_reader", "/new_reader")]
        self.assertEqual(len(closing), 2)
        for c in closing:  # the first half of TCPROSTransport.close, as another thread runs it
            c.socket.close()
        for i in range(1, 4):
            pub.publish(String(str(i)))  # raised OSError (EBADF) for the new reader: the simulator died of it
        self.assertEqual(pub.get_num_connections(), 1, "the closed readers were not removed")
        self.wait_for(received, 4)
        self.assertEqual(received, [0, 1, 2, 3])
        for reader in (old, new):
            reader.sock.close()
        sub.unregister()

    def wait_connections(self, pub, n):
        deadline = time.monotonic() + 20
        while pub.get_num_connections() < n and time.monotonic() < deadline:
            time.sleep(0.05)
        self.assertEqual(pub.get_num_connections(), n)

    def wait_for(self, received, n):
        deadline = time.monotonic() + 20
        while len(received) < n and time.monotonic() < deadline:
            time.sleep(0.05)


if __name__ == "__main__":
    rospy.init_node("nonblocking_publisher_test")
    rostest.rosrun("thorvald_base", "nonblocking_publisher", TestNonBlockingPublisher)
