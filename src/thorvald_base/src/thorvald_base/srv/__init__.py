"""Alias of thorvald_msgs.srv for code written for the original (see thorvald_base.msg)."""

from thorvald_msgs.srv import *  # noqa: F403
