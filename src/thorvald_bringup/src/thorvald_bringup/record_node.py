"""``rosrun thorvald_bringup record_drive -O BAG TOPIC [TOPIC ...]``: rosbag record's job, losing nothing.

``rosbag record`` (roscpp) queues 100 messages a topic and drops the oldest when its thread falls
behind; beside two busy cores a drive recorded faster than real time lost drive states that way,
and the report replayed from them changed. This recorder reads every topic with no bound on its
queue: rospy reads each connection in a thread of its own and, with ``queue_size=None``, drops
nothing, so a recorder that falls behind holds its publishers back through TCP instead (in lockstep
the simulator waits for them; base_driver and the simulator publish what is recorded without a
queue of their own then: ``~lockstep``). Messages are written as they arrive (``rospy.AnyMsg``, not
decoded), stamped with the ROS time they arrived at (the simulator's clock), with the publishers'
connection headers (message definitions included), into ``BAG.active``, renamed ``BAG`` at the end
as rosbag does. The bag is the library's (``rosbag.Bag``); this node only subscribes and writes.
"""

import argparse
import os
import sys
import threading
from typing import List, Optional

import genpy
import rosbag
import rospy

NAME = "record"


def parse_args(argv: Optional[List[str]]):
    parser = argparse.ArgumentParser(prog="record_drive", description="Record topics into a bag, dropping none.")
    parser.add_argument("-O", "--output-name", required=True, help="the bag to write")
    parser.add_argument("topics", nargs="+", help="the topics to record")
    return parser.parse_args(argv)


class Recorder:
    def __init__(self, path: str, topics: List[str]):
        self.path = path if path.endswith(".bag") else path + ".bag"
        self.active = self.path + ".active"
        self.bag = rosbag.Bag(self.active, "w")
        self.lock = threading.Lock()
        self.classes = {}  # message type -> its class, for the bag's connection records
        self.subscribers = [
            rospy.Subscriber(topic, rospy.AnyMsg, self.on_message, rospy.resolve_name(topic), queue_size=None)
            for topic in topics
        ]

    def on_message(self, msg, topic: str) -> None:
        header = msg._connection_header
        kind = header["type"]
        with self.lock:
            if self.bag is None:
                return
            if kind not in self.classes:
                self.classes[kind] = genpy.message.get_message_class(kind)
            connection = {
                "topic": topic,
                "type": kind,
                "md5sum": header["md5sum"],
                "message_definition": header["message_definition"],
            }
            self.bag.write(
                topic, (kind, msg._buff, header["md5sum"], self.classes[kind]), rospy.Time.now(), raw=True,
                connection_header=connection,
            )  # fmt: skip

    def close(self) -> None:
        with self.lock:
            if self.bag is None:
                return
            for subscriber in self.subscribers:
                subscriber.unregister()
            self.bag.close()
            self.bag = None
            os.replace(self.active, self.path)


def main(argv: Optional[List[str]] = None) -> int:
    args = parse_args(rospy.myargv(sys.argv)[1:] if argv is None else argv)
    rospy.init_node(NAME, disable_signals=False)
    recorder = Recorder(args.output_name, args.topics)
    rospy.on_shutdown(recorder.close)
    rospy.spin()
    recorder.close()
    return 0


__all__ = ["Recorder", "main"]
