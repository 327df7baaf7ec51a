"""Reads a drive recorded by odometry_report.launch (or any bag with the same topics) into a Recording.

Topics are found by their ending, so a robot in any namespace works: ``.../odometry/gazebo``,
``.../odometry/base_raw``, ``.../base_state``, and the commands: ``.../cmd_vel_stamped`` (each at
the instant in its stamp: the same in every run), else ``.../twist_mux/cmd_vel`` (what base_driver
got, when rosbag received it) or ``.../nav_vel`` (what was sent); and, when recorded, RTK-GNSS
``.../gps/fix`` with the IMU's ``.../imu/data`` (the antenna over base_link, the reference heading
0). Messages are decoded with the definitions stored in the bag, so a bag from another machine
reads without its message packages.
"""

import rosbag

from thorvald_base.bag_topics import topics_by_ending
from thorvald_base.conversions import quaternion_yaw

from .errors import ReportError
from .odometry_report import Path, Recording, gnss_path

ENDINGS = {
    "fix": "gps/fix",
    "imu": "imu/data",
    "truth": "odometry/gazebo",
    "odometry": "odometry/base_raw",
    "states": "base_state",
    "stamped": "cmd_vel_stamped",
    "commands": "twist_mux/cmd_vel",
    "sent": "nav_vel",
}


def _topics(bag, path):
    names = sorted(bag.get_type_and_topic_info().topics)
    return topics_by_ending(names, ENDINGS, path, ReportError), names


def read_recording(path: str, robot: str = "") -> Recording:
    try:
        bag = rosbag.Bag(path)
    except (OSError, rosbag.ROSBagException) as e:
        raise ReportError(f"{path}: cannot read the bag: {e}") from None
    with bag:
        topics, names = _topics(bag, path)
        missing = [ENDINGS[k] for k in ("truth", "odometry", "states") if k not in topics]
        if not any(k in topics for k in ("stamped", "commands", "sent")):
            missing.append(f"{ENDINGS['stamped']}, {ENDINGS['commands']} or {ENDINGS['sent']}")
        if missing:
            raise ReportError(f"{path}: no topic ending in {', '.join(missing)} (the bag has: {', '.join(names)})")
        command_topic = topics.get("stamped", topics.get("commands", topics.get("sent")))
        rec = Recording([], Path(), Path(), [], robot=robot, source=path)
        wanted = [topics["truth"], topics["odometry"], topics["states"], command_topic]
        wanted += [topics[k] for k in ("fix", "imu") if k in topics]
        fixes, yaws = [], []
        for topic, msg, stamp in bag.read_messages(topics=wanted):
            if hasattr(msg, "header") and topic != command_topic:  # a publisher's count: the lost show
                rec.sequences.setdefault(topic, []).append(msg.header.seq)
            if topic == topics.get("fix"):
                if msg.status.status >= 0:  # a fix (STATUS_NO_FIX is -1)
                    fixes.append((msg.header.stamp.to_sec(), msg.latitude, msg.longitude))
            elif topic == topics.get("imu"):
                yaws.append((msg.header.stamp.to_sec(), quaternion_yaw(msg.orientation)))
            elif topic == command_topic:
                if hasattr(msg, "header"):  # stamped: the instant it holds from, published ahead of it
                    stamp, msg = msg.header.stamp, msg.twist
                rec.commands.append((stamp.to_sec(), msg.linear.x, msg.linear.y, msg.angular.z))
            elif topic == topics["states"]:
                rec.states.append((msg.header.stamp.to_sec(), tuple(msg.steer_pos), tuple(msg.prop_speed)))
            else:
                series = rec.truth if topic == topics["truth"] else rec.odometry
                p, v = msg.pose.pose, msg.twist.twist
                pose = (p.position.x, p.position.y, quaternion_yaw(p.orientation))
                series.append(msg.header.stamp.to_sec(), pose, (v.linear.x, v.linear.y, v.angular.z))
    rec.gnss = gnss_path(sorted(fixes), sorted(yaws))
    for series in (rec.truth, rec.odometry):
        _sort(series)
    rec.commands.sort()
    rec.states.sort(key=lambda s: s[0])
    return rec


def _sort(series: Path) -> None:
    order = sorted(range(len(series.t)), key=series.t.__getitem__)
    for name in ("t", "x", "y", "yaw", "vx", "vy", "wz"):
        values = getattr(series, name)
        values[:] = [values[i] for i in order]
