"""The simulator's fleet topics: every robot's drive states, currents and commands in one message per
instant (thorvald_msgs/BaseStateBatch, DriveCurrentsBatch), for a fleet_driver that drives many robots.

Per robot the simulator offers ``drive_states`` and ``drive_currents`` and follows ``drive_commands``
(:mod:`thorvald_sim.node.robot_io`); a fleet_driver of N robots would exchange 2N + N messages per
instant with it, each costing both processes a publish, a write, a wake-up and a read however small it
is. On the fleet topics the same messages go as one per instant:

=============================  ====================================================================
``~fleet/drive_states``        every robot's drive states due at the instant, while somebody reads it
``~fleet/drive_currents``      every robot's drive currents due at the instant, likewise
``~fleet/drive_commands``      followed: each entry as if it came on its own topic (``topics[i]``,
                               e.g. ``/robot_1/drive_commands``: the robot spawned to follow it;
                               an entry no robot follows is dropped, as a message nobody reads)
=============================  ====================================================================

Each entry names the per-robot topic it stands for, so it means exactly what it means there: the
same stamps, the same lockstep (a robot's drive states on the fleet topic count as published to its
reader; its command entry as its answer). The per-robot topics stay, each published only while read.
"""

import rospy

from thorvald_base import conversions
from thorvald_base.publishing import NonBlockingPublisher
from thorvald_msgs.msg import BaseStateBatch, DriveCurrentsBatch

from .robot_io import WARN_PERIOD

QUEUE = 256  # command messages queued: in lockstep each robot's answer comes alone, none may be dropped


class FleetTopics:
    """The simulator node's fleet topics; robots: the node's RobotIO by name (read under the node's lock)."""

    def __init__(self, robots, lock):
        self.robots = robots
        self.lock = lock
        self.states = NonBlockingPublisher(rospy.resolve_name("~fleet/drive_states"), BaseStateBatch)
        self.currents = NonBlockingPublisher(rospy.resolve_name("~fleet/drive_currents"), DriveCurrentsBatch)
        self.sub = rospy.Subscriber(
            rospy.resolve_name("~fleet/drive_commands"), BaseStateBatch, self.on_commands, queue_size=QUEUE
        )

    def read(self):
        """(drive states, drive currents): whether somebody reads each fleet topic."""
        return self.states.get_num_connections() > 0, self.currents.get_num_connections() > 0

    def publish(self, stamp, states, currents) -> None:
        """The instant's batches: the currents first (as each robot's are), then the states; states and
        currents: lists of (per-robot topic, message), or None while nobody reads them."""
        if currents:
            self.currents.publish(conversions.batch_msg(DriveCurrentsBatch, stamp, currents))
        if states:
            self.states.publish(conversions.batch_msg(BaseStateBatch, stamp, states))

    def on_commands(self, msg) -> None:
        try:
            entries = conversions.batch_entries(msg)
        except ValueError as e:
            rospy.logwarn_throttle(WARN_PERIOD, "simulator: %s: %s: refused", self.sub.resolved_name, e)
            return
        with self.lock:
            following = {io.sub.resolved_name: io for io in self.robots.values()}
        unknown = []
        for topic, command in entries:
            io = following.get(topic)
            if io is None:
                unknown.append(topic)
            else:
                io.on_command(command)
        if unknown:  # as a message on a topic nobody follows: a fleet_driver starts before its robots spawn
            rospy.logdebug_throttle(
                WARN_PERIOD, "simulator: %s: no robot follows %s: ignored", self.sub.resolved_name,
                ", ".join(sorted(unknown)),
            )  # fmt: skip
