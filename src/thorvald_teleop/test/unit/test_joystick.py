"""The joystick core without ROS: js_event bytes, axis scaling, the state, when to publish, the reader."""

import errno
import os

import pytest
from hypothesis import given
from hypothesis import strategies as st

from thorvald_teleop import joystick
from thorvald_teleop.joystick import (
    JS_EVENT_AXIS,
    JS_EVENT_BUTTON,
    JS_EVENT_INIT,
    DeviceUnavailable,
    JoystickReader,
    JoystickState,
    JsEvent,
    PublishSchedule,
    check_settings,
    pack_event,
    parse_events,
    scale_axis,
)

INIT_BUTTON = JS_EVENT_BUTTON | JS_EVENT_INIT
INIT_AXIS = JS_EVENT_AXIS | JS_EVENT_INIT


# js_event bytes


def test_an_event_is_8_little_endian_bytes_time_value_type_number():
    # time 1000 ms, value -32767 (0x8001), type axis|init, number 1
    data = b"\xe8\x03\x00\x00\x01\x80\x82\x01"
    events, rest = parse_events(data)
    assert events == [JsEvent(1000, -32767, 0x82, 1)]
    assert rest == b""
    assert pack_event(1000, -32767, 0x82, 1) == data
    e = events[0]
    assert e.is_axis and e.is_init and not e.is_button


def test_several_events_and_a_partial_one():
    data = pack_event(1, 1, JS_EVENT_BUTTON, 3) + pack_event(2, -5, JS_EVENT_AXIS, 0) + b"\x07\x00\x00"
    events, rest = parse_events(data)
    assert events == [JsEvent(1, 1, JS_EVENT_BUTTON, 3), JsEvent(2, -5, JS_EVENT_AXIS, 0)]
    assert rest == b"\x07\x00\x00"
    assert events[0].is_button and not events[0].is_init and not events[0].is_axis
    # the rest completes with the next read
    more, rest = parse_events(rest + b"\x00\x00\x00\x81\x02")
    assert more == [JsEvent(7, 0, INIT_BUTTON, 2)] and rest == b""


@given(st.integers(0, 2**32 - 1), st.integers(-32768, 32767), st.sampled_from([1, 2, 0x81, 0x82]), st.integers(0, 255))
def test_pack_and_parse_round_trip(time, value, type_, number):
    assert parse_events(pack_event(time, value, type_, number)) == ([JsEvent(time, value, type_, number)], b"")


# axis scaling


def test_axes_are_negated_and_scaled_to_one():
    # the joy package's sign: the kernel's -32767 (stick up, or left) reads +1
    assert scale_axis(-32767, 0.0) == 1.0
    assert scale_axis(32767, 0.0) == -1.0
    assert scale_axis(16384, 0.0) == pytest.approx(-16384 / 32767)
    assert scale_axis(32767, 0.05) == -1.0
    assert scale_axis(-32767, 0.05) == 1.0
    assert scale_axis(-32768, 0.0) == 1.0  # clamped (-32768 / 32767 is a little more than 1)
    assert scale_axis(-32768, 0.05) == 1.0


def test_the_deadzone_reads_zero_and_the_rest_is_rescaled():
    dz = 0.05 * 32767  # 1638.35
    assert scale_axis(0, 0.05) == 0.0
    assert scale_axis(1638, 0.05) == 0.0
    assert scale_axis(-1638, 0.05) == 0.0
    assert scale_axis(1639, 0.05) == pytest.approx(-(1639 - dz) / (32767 - dz))
    assert abs(scale_axis(1639, 0.05)) < 1e-4  # continuous at the edge of the deadzone
    # halfway between the deadzone and the end reads one half
    assert scale_axis(-round((dz + 32767) / 2), 0.05) == pytest.approx(0.5, abs=1e-4)
    assert scale_axis(16384, 0.05) == pytest.approx(-0.4737, abs=1e-4)


@given(st.integers(-32768, 32766), st.floats(0.0, 0.9))
def test_scaling_is_continuous_monotonic_and_bounded(value, deadzone):
    a, b = scale_axis(value, deadzone), scale_axis(value + 1, deadzone)
    assert -1.0 <= a <= 1.0
    assert b <= a  # negated: a larger raw value never reads more
    assert a - b <= 1.0 / (32767 * (1 - deadzone)) + 1e-9


def test_settings_are_corrected_as_the_joy_package_does():
    assert check_settings(0.05, 0.0, 0.001) == (joystick.Settings(0.05, 0.0, 0.001), [])
    settings, warnings = check_settings(3276.7, -1.0, -0.5)
    assert settings.deadzone == pytest.approx(0.1)  # raw units, divided by 32767
    assert settings.autorepeat_rate == 0.0 and settings.coalesce_interval == 0.0
    assert len(warnings) == 3
    assert check_settings(0.95, 0, 0.001)[0].deadzone == 0.9
    assert check_settings(-0.1, 0, 0.001)[0].deadzone == 0.0
    settings, warnings = check_settings(0.05, 2000.0, 0.001)  # faster than the coalesce interval
    assert settings.autorepeat_rate == 2000.0 and "does not make sense" in warnings[0]


# the state


def init_burst(buttons=(0, 0, 0, 1, 0), axes=(0, 0, -32767, 0, 0, 32767)):
    """The initial-state events a device gives when it opens."""
    events = [JsEvent(0, v, INIT_BUTTON, i) for i, v in enumerate(buttons)]
    return events + [JsEvent(0, v, INIT_AXIS, i) for i, v in enumerate(axes)]


def test_initial_events_size_the_arrays_and_set_the_buttons():
    state = JoystickState(0.05)
    assert all(state.apply(e) for e in init_burst())
    assert state.buttons == [0, 0, 0, 1, 0]
    # as the joy package: the axes' initial values are not taken (they may be stale), only their number
    assert state.axes == [0.0] * 6
    assert state.neutral() == ([0.0] * 6, [0] * 5)


def test_default_trig_val_takes_the_initial_axis_values():
    state = JoystickState(0.05, default_trig_val=True)
    for e in init_burst():
        state.apply(e)
    assert state.axes == [0.0, 0.0, 1.0, 0.0, 0.0, -1.0]


def test_events_change_the_state_and_grow_the_arrays():
    state = JoystickState(0.0)
    for e in init_burst():
        state.apply(e)
    state.apply(JsEvent(10, 1, JS_EVENT_BUTTON, 0))
    state.apply(JsEvent(11, -32767, JS_EVENT_AXIS, 1))
    state.apply(JsEvent(12, 0, JS_EVENT_BUTTON, 3))
    assert state.buttons == [1, 0, 0, 0, 0]
    assert state.axes == [0.0, 1.0, 0.0, 0.0, 0.0, 0.0]
    state.apply(JsEvent(13, 7, JS_EVENT_BUTTON, 8))  # any non-zero value is pressed
    state.apply(JsEvent(14, 32767, JS_EVENT_AXIS, 7))
    assert state.buttons == [1, 0, 0, 0, 0, 0, 0, 0, 1]
    assert state.axes == [0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0]
    assert not state.apply(JsEvent(15, 1, 0x04, 0))  # unknown type: ignored
    assert len(state.buttons) == 9
    state.reset()
    assert (state.axes, state.buttons) == ([], [])


# when to publish


def replay(timed_events, coalesce=0.01, autorepeat=0.0, until=None):
    """Feeds (time, event) pairs as the node does; returns the (time, axes, buttons) published."""
    state, schedule, out = JoystickState(0.0), PublishSchedule(coalesce, autorepeat), []

    def publish(now):
        out.append((now, list(state.axes), list(state.buttons)))
        schedule.published(now)

    for now, event in timed_events:
        due = schedule.next_time()
        while due is not None and due <= now:  # what falls due before this event
            publish(due)
            due = schedule.next_time()
        state.apply(event)
        if schedule.on_event(event, now):
            publish(now)
    due = schedule.next_time()
    while due is not None and due <= (until if until is not None else timed_events[-1][0] + 1.0):
        publish(due)
        due = schedule.next_time()
    return out


def test_the_initial_burst_is_one_message():
    out = replay([(0.0, e) for e in init_burst()])
    assert out == [(0.01, [0.0] * 6, [0, 0, 0, 1, 0])]


def test_axis_events_within_the_interval_are_one_message():
    t0 = [(0.0, e) for e in init_burst()]
    moves = [
        (1.0, JsEvent(0, -32767, JS_EVENT_AXIS, 1)),
        (1.004, JsEvent(0, 32767, JS_EVENT_AXIS, 0)),
        (1.009, JsEvent(0, -16000, JS_EVENT_AXIS, 1)),  # the timer is not restarted by later events
        (1.02, JsEvent(0, 0, JS_EVENT_AXIS, 0)),
    ]
    out = replay(t0 + moves)
    assert [round(t, 3) for t, _, _ in out] == [0.01, 1.01, 1.03]
    assert out[1][1][:2] == [-1.0, pytest.approx(16000 / 32767)]
    assert out[2][1][:2] == [0.0, pytest.approx(16000 / 32767)]


def test_a_button_change_is_published_at_once_with_waiting_axis_changes():
    out = replay(
        [(0.0, e) for e in init_burst()]
        + [
            (1.0, JsEvent(0, -32767, JS_EVENT_AXIS, 1)),
            (1.001, JsEvent(0, 1, JS_EVENT_BUTTON, 0)),  # press and release read together: two messages
            (1.001, JsEvent(0, 0, JS_EVENT_BUTTON, 0)),
        ]
    )
    assert [(round(t, 3), a[1], b[0]) for t, a, b in out[1:]] == [(1.001, 1.0, 1), (1.001, 1.0, 0)]


def test_a_press_in_the_initial_burst_is_folded_into_the_first_message():
    out = replay([(0.0, e) for e in init_burst()] + [(0.0, JsEvent(0, 1, JS_EVENT_BUTTON, 1))])
    assert out == [(0.0, [0.0] * 6, [0, 1, 0, 1, 0])]


def test_autorepeat_repeats_the_last_state_while_nothing_changes():
    out = replay(
        [(0.0, e) for e in init_burst()] + [(0.1, JsEvent(0, 1, JS_EVENT_BUTTON, 0))],
        autorepeat=20.0,
        until=0.31,
    )
    times = [round(t, 3) for t, _, _ in out]
    assert times == [0.01, 0.06, 0.1, 0.15, 0.2, 0.25, 0.3]
    assert [b[0] for _, _, b in out] == [0, 0, 1, 1, 1, 1, 1]


def test_no_repeat_before_the_first_message_nor_when_off():
    schedule = PublishSchedule(0.001, 10.0)
    assert schedule.next_time() is None and not schedule.due(100.0)
    schedule.published(1.0)
    assert schedule.next_time() == pytest.approx(1.1)
    assert not schedule.due(1.05) and schedule.due(1.1)
    schedule.reset()
    assert schedule.next_time() is None
    off = PublishSchedule(0.001, 0.0)
    off.published(1.0)
    assert off.next_time() is None


# the reader


def test_a_missing_device_is_unavailable(tmp_path):
    reader = JoystickReader(str(tmp_path / "js0"))
    with pytest.raises(DeviceUnavailable) as e:
        reader.open()
    assert "ENOENT" in e.value.reason and str(tmp_path / "js0") in str(e.value)
    assert not reader.is_open


def test_a_fifo_without_a_writer_is_no_device_yet(tmp_path):
    path = str(tmp_path / "js0")
    os.mkfifo(path)
    reader = JoystickReader(path)
    with pytest.raises(DeviceUnavailable) as e:
        reader.open()  # opens (non-blocking), but reads end of file
    assert "end of file" in e.value.reason
    assert not reader.is_open


def fifo_writer(path):
    """A writer of a FIFO opened while nobody else reads it (a reader is needed for the open)."""
    hold = os.open(path, os.O_RDONLY | os.O_NONBLOCK)
    try:
        return os.open(path, os.O_WRONLY | os.O_NONBLOCK)
    finally:
        os.close(hold)


def test_events_are_read_as_they_come_and_end_of_file_is_an_unplug(tmp_path):
    path = str(tmp_path / "js0")
    os.mkfifo(path)
    writer = fifo_writer(path)
    with JoystickReader(path) as reader:
        reader.open()
        assert reader.is_open and reader.read_events() == []  # a writer, nothing written: no events yet
        burst = b"".join(pack_event(0, v, INIT_BUTTON, i) for i, v in enumerate([0, 1]))
        os.write(writer, burst + pack_event(5, -32767, JS_EVENT_AXIS, 1)[:5])  # half an event
        assert reader.read_events() == [JsEvent(0, 0, INIT_BUTTON, 0), JsEvent(0, 1, INIT_BUTTON, 1)]
        os.write(writer, pack_event(5, -32767, JS_EVENT_AXIS, 1)[5:] + pack_event(6, 1, JS_EVENT_BUTTON, 0))
        assert reader.read_events() == [JsEvent(5, -32767, JS_EVENT_AXIS, 1), JsEvent(6, 1, JS_EVENT_BUTTON, 0)]
        # the last events, then the writer goes away: the events first, then the unplug
        os.write(writer, pack_event(7, 0, JS_EVENT_BUTTON, 0))
        os.close(writer)
        assert reader.read_events() == [JsEvent(7, 0, JS_EVENT_BUTTON, 0)]
        with pytest.raises(DeviceUnavailable) as e:
            reader.read_events()
        assert "end of file" in e.value.reason
        assert not reader.is_open
        # plugged again
        writer = fifo_writer(path)
        reader.open()
        os.write(writer, pack_event(9, 1, INIT_BUTTON, 4))
        assert reader.read_events() == [JsEvent(9, 1, INIT_BUTTON, 4)]
        os.close(writer)


def test_enodev_is_an_unplug(tmp_path, monkeypatch):
    path = str(tmp_path / "js0")
    os.mkfifo(path)
    writer = fifo_writer(path)
    reader = JoystickReader(path)
    reader.open()

    def unplugged(fd, n):
        raise OSError(errno.ENODEV, os.strerror(errno.ENODEV))

    monkeypatch.setattr(joystick.os, "read", unplugged)
    with pytest.raises(DeviceUnavailable) as e:
        reader.read_events()
    assert "ENODEV" in e.value.reason and not reader.is_open
    os.close(writer)
