"""The stamped command stream base_driver follows in lockstep (thorvald_base.stamped_commands)."""

from thorvald_base.stamped_commands import StampedCommands

GO, STOP = (1.0, 0.0, 0.1), (0.0, 0.0, 0.0)


def test_a_cycle_takes_the_command_stamped_at_or_before_it_once_a_later_one_came():
    s = StampedCommands()
    assert not s.active and not s.begun(0.0)
    s.add(1.0, STOP)  # a source 20 Hz ahead of the instants it commands
    assert s.active
    assert not s.begun(0.98)  # nothing holds yet before its first stamp: cmd_vel does
    assert s.begun(1.0) and not s.known(1.0)  # at 1.0 the next command may still change what holds
    s.add(1.05, GO)
    assert s.known(1.0) and s.at(1.0) == STOP
    assert s.known(1.04) and s.at(1.04) == STOP
    assert not s.known(1.05)
    s.add(1.10, GO)
    assert s.at(1.06) == GO
    assert s.stamps == [1.10]  # the passed ones dropped


def test_stamps_a_nanosecond_apart_are_one_instant():
    # 1.05 s as a rospy.Time truncated to whole nanoseconds is 1.049999999 s
    s = StampedCommands()
    s.add(1.049999999, GO)
    s.add(1.1, STOP)
    assert s.begun(1.05) and s.at(1.05) == GO
    assert not s.known(1.099999999)


def test_an_earlier_stamp_starts_a_new_stream_and_clear_lets_it_go():
    s = StampedCommands()
    s.add(5.0, GO)
    s.add(5.05, GO)
    assert s.at(5.0) == GO
    s.add(0.5, STOP)  # simulated time reset, or the source started again
    assert s.stamps == [0.5] and not s.begun(0.4)
    s.clear()
    assert not s.active and s.at(1.0) is None
