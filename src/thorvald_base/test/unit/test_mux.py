"""The twist multiplexer's decisions, with twist_mux's semantics, on a plain clock [s]."""

import pytest

from thorvald_base.errors import ParameterError
from thorvald_base.mux import Source, TwistMux, parse_sources

JOY = Source("joystick", "teleop_joy/cmd_vel", 0.5, 100)
NAV = Source("navigation", "nav_vel", 0.5, 10)
JOY_LOCK = Source("joystick_lock", "teleop_joy/joy_priority", 0.0, 50)


def test_highest_priority_live_input_wins():
    mux = TwistMux([JOY, NAV])
    assert mux.on_input("navigation", 0.0)  # alone: relayed
    assert mux.on_input("joystick", 0.1)
    assert not mux.on_input("navigation", 0.2)  # joystick is live (0.1 s old) and higher
    assert mux.selected(0.2) == "joystick"


def test_lower_priority_passes_once_the_higher_one_times_out():
    mux = TwistMux([JOY, NAV])
    mux.on_input("joystick", 0.0)
    assert not mux.on_input("navigation", 0.5)  # 0.5 s old is not older than the 0.5 s timeout
    assert mux.on_input("navigation", 0.51)


def test_after_time_moved_backwards_an_input_heard_before_is_expired():
    mux = TwistMux([JOY, NAV])
    mux.on_input("joystick", 100.0)
    assert mux.selected(100.2) == "joystick"
    assert mux.selected(0.1) is None  # a simulation reset: the joystick was heard 99.9 s "ahead"
    assert mux.on_input("navigation", 0.2)
    assert mux.on_input("joystick", 0.3) and mux.selected(0.4) == "joystick"


def test_inputs_with_a_timeout_start_expired():
    mux = TwistMux([JOY, NAV])
    assert mux.selected(0.0) is None
    assert mux.on_input("navigation", 0.0)


def test_timeout_zero_never_expires_even_before_the_first_message():
    forever = Source("forever", "x", 0.0, 200)
    mux = TwistMux([forever, NAV])
    assert not mux.on_input("navigation", 0.0)  # as twist_mux: a timeout-0 input always counts as live
    assert mux.on_input("forever", 1000.0)
    assert not mux.masked("forever", 1e9)


def test_lock_masks_inputs_below_its_priority():
    mux = TwistMux([JOY, NAV], [JOY_LOCK])
    assert mux.on_input("navigation", 0.0)  # lock never heard from, timeout 0: open
    mux.on_lock("joystick_lock", True, 0.1)
    assert not mux.on_input("navigation", 0.2)  # 10 < 50: masked, though joystick is silent
    assert mux.selected(0.2) is None
    assert mux.on_input("joystick", 0.3)  # 100 >= 50
    mux.on_lock("joystick_lock", False, 1.0)
    assert mux.on_input("navigation", 1.1)


def test_lock_masks_only_lower_priorities_equal_passes():
    mux = TwistMux([Source("a", "a", 0.5, 50)], [Source("l", "l", 0.0, 50)])
    mux.on_lock("l", True, 0.0)
    assert mux.on_input("a", 0.1)


def test_lock_with_a_timeout_is_locked_until_its_first_message():
    lock = Source("heartbeat", "safety_ok", 1.0, 255)
    mux = TwistMux([JOY, NAV], [lock])
    assert not mux.on_input("joystick", 0.0)  # never heard from: locked
    mux.on_lock("heartbeat", False, 0.5)
    assert mux.on_input("joystick", 0.6)
    assert not mux.on_input("joystick", 1.6)  # the lock's last message is 1.1 s old: locked again
    assert mux.status(1.6)["locks"][0]["locked"]


def test_status_reports_ages_and_masks():
    mux = TwistMux([JOY, NAV], [JOY_LOCK])
    mux.on_input("navigation", 2.0)
    status = mux.status(2.25)
    assert status["selected"] == "navigation"
    assert status["lock_priority"] == -1
    nav = next(s for s in status["inputs"] if s["name"] == "navigation")
    joy = next(s for s in status["inputs"] if s["name"] == "joystick")
    assert nav["age"] == pytest.approx(0.25) and not nav["masked"]
    assert joy["age"] is None and joy["masked"]


def test_parse_sources_reads_both_twist_mux_formats():
    as_list = [{"name": "navigation", "topic": "nav_vel", "timeout": 0.5, "priority": 10}]
    as_map = {"navigation": {"topic": "nav_vel", "timeout": 0.5, "priority": 10}}
    assert parse_sources(as_list, "~topics") == parse_sources(as_map, "~topics") == [NAV]
    assert parse_sources(None, "~locks") == []


def test_parse_sources_reports_every_problem():
    bad = [
        {"name": "a", "topic": "", "timeout": -1, "priority": 300},
        {"name": "b", "topic": "b", "timeout": 0.5, "priority": 1, "prio": 3},
        {"name": "c", "topic": "c", "timeout": 0.5, "priority": 1},
        {"name": "c", "topic": "d", "timeout": 0.5, "priority": 2},
    ]
    with pytest.raises(ParameterError) as info:
        parse_sources(bad, "~topics")
    text = str(info.value)
    assert "~topics.a.topic: '': must be a topic name" in text
    assert "~topics.a.timeout: -1: must be a number of seconds >= 0" in text
    assert "~topics.a.priority: 300: must be an integer in 0..255" in text
    assert "~topics.b: unknown key(s) prio" in text
    assert "~topics: name 'c' appears more than once" in text


def test_parse_sources_refuses_a_scalar():
    with pytest.raises(ParameterError, match="~locks: 'x': must be a list"):
        parse_sources("x", "~locks")
