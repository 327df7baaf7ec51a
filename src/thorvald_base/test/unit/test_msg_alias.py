"""Code written for the original imports its messages from thorvald_base."""


def test_original_message_imports_work():
    from thorvald_base.msg import BaseState, CANFrame  # noqa: PLC0415 (the import is what is tested)
    from thorvald_base.srv import DriveParams  # noqa: PLC0415
    from thorvald_msgs.msg import BaseState as Ours  # noqa: PLC0415

    assert BaseState is Ours
    assert CANFrame._type == "thorvald_msgs/CANFrame"
    assert DriveParams._type == "thorvald_msgs/DriveParams"
