"""A rospy publisher for fast streams that must never wait for a reader nor cost a thread per reader.

rospy offers two ways to publish, and a fast loop that talks to many readers (the simulator's
``/clock`` to every node and its per-robot topics, many times real time) can afford neither:

- ``queue_size=N`` gives every reader a writer thread: each message wakes all of them and the
  publishing thread yields the interpreter once per reader (rospy's ``QueuedConnection`` sleeps 0
  after queueing), which cost the simulator more than its physics;
- ``queue_size=None`` writes in the publishing thread, but blocks it on a reader whose socket is
  full, e.g. one behind a dropped network link: the whole simulation stopped for every robot.

``BlockingPublisher`` is the second, made for what a lockstep run records: a reader that falls
behind holds the publisher back (through TCP) instead of missing messages, so nothing published is
lost; in lockstep the world waits anyway, and a run then repeats to the bit under any load.

``NonBlockingPublisher`` writes in the publishing thread on non-blocking sockets. A reader whose
socket is full (its kernel buffers hold everything it has not read yet: on a dropped link after
some seconds) misses the messages published meanwhile, with a throttled warning, and gets the next
ones as soon as it reads again; every other reader goes on, nobody is disconnected. A message the
socket took only part of is finished before anything else goes to that reader, so the stream stays
whole. A reader that went away is removed as rospy does.
"""

import warnings

import rospy
from rospy.exceptions import TransportTerminated

WARN_PERIOD = 5.0  # [s] between repeats of the warning of one publisher


class BlockingPublisher(rospy.Publisher):
    """``rospy.Publisher`` written in the caller's thread, waiting for every reader: nothing is lost."""

    def __init__(self, name, data_class, **kwargs):
        with warnings.catch_warnings():  # rospy warns of queue_size=None; waiting for the reader is the point
            warnings.simplefilter("ignore", SyntaxWarning)
            super().__init__(name, data_class, queue_size=None, **kwargs)


def recorded_publisher(lockstep: bool, otherwise=None):
    """The publisher class of a stream a run records: blocking in lockstep (nothing lost), else
    ``otherwise`` (NonBlockingPublisher by default)."""
    return BlockingPublisher if lockstep else (otherwise or NonBlockingPublisher)


class NonBlockingPublisher(rospy.Publisher):
    """``rospy.Publisher`` written in the caller's thread; a reader that cannot take a message misses it."""

    def __init__(self, name, data_class, **kwargs):
        with warnings.catch_warnings():  # rospy warns of queue_size=None; synchronous is the point, made safe here
            warnings.simplefilter("ignore", SyntaxWarning)
            super().__init__(name, data_class, queue_size=None, **kwargs)
        self._adopted = None  # the connection list last seen (rospy replaces the list on every change)

    def publish(self, *args, **kwargs):
        connections = self.impl.connections
        if connections is not self._adopted:
            for connection in connections:
                if not isinstance(connection.write_data, _NonBlockingWriter):
                    connection.write_data = _NonBlockingWriter(connection, self.resolved_name)
            self._adopted = connections
        return super().publish(*args, **kwargs)


class _NonBlockingWriter:
    """Takes the place of one connection's ``write_data`` (rospy calls it under the publisher's lock)."""

    def __init__(self, connection, topic: str):
        self.connection = connection
        self.topic = topic
        self.rest = b""  # what the socket has not taken yet of a message it took part of
        self.missed = 0  # messages this reader missed
        # Made non-blocking at the first write, where a failure removes the reader: not here, in publish().
        # Another rospy thread may be closing the connection meanwhile (a new reader's arrival closes the
        # dead ones, _TopicImpl.add_connection), and TCPROSTransport.close closes the socket before it
        # forgets it: raised from here, that closed socket killed the simulator when spawn_robot nodes left.
        self.nonblocking = False

    def __call__(self, data) -> bool:
        c = self.connection
        sock = c.socket  # once: another thread's close() sets it to None
        if c.done or sock is None:
            raise TransportTerminated("connection closed")
        try:
            if not self.nonblocking:
                sock.setblocking(False)
                self.nonblocking = True
            if self.rest:
                self.rest = self.rest[sock.send(self.rest) :]
                if self.rest:
                    raise BlockingIOError
            sent = sock.send(data)
        except BlockingIOError:
            self.missed += 1
            rospy.logwarn_throttle(
                WARN_PERIOD,
                "%s: the reader %s is not reading (its socket is full): %d messages missed so far",
                self.topic,
                c.endpoint_id,
                self.missed,
            )
            return True
        except OSError as e:  # the reader went away: rospy's publish() removes the connection
            c.close()
            raise TransportTerminated(str(e)) from None
        self.rest = bytes(data[sent:])
        c.stat_bytes += sent
        c.stat_num_msg += 1
        return True
