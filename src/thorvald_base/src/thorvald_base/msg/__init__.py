"""The original kept its messages in thorvald_base; ours are in thorvald_msgs. This alias keeps
``from thorvald_base.msg import BaseState`` in code written for the original working (the type
names on the wire are thorvald_msgs/...)."""

from thorvald_msgs.msg import *  # noqa: F403
