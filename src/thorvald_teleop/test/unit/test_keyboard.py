"""The keyboard teleoperation's state machine and key map (thorvald_teleop.keyboard), driven with fake times."""

import pytest

from thorvald_teleop.keyboard import (
    HELP,
    IGNORED,
    MOTION,
    MOTION_KEYS,
    QUIT,
    SPEED,
    STOP,
    ZERO,
    KeyboardTeleop,
    Velocity,
    split_keys,
)

RATE = 20.0
PERIOD = 1.0 / RATE


def teleop(**kw):
    args = {"speed": 0.5, "turn": 0.5, "rate": RATE, "key_timeout": 0.6}
    args.update(kw)
    return KeyboardTeleop(**args)


def run(t, start, end, keys=(), step=0.01):
    """Polls ``t`` like the node does, every ``step`` s from ``start`` to ``end``, pressing ``keys`` ({time: key})
    on the way; returns the publications as [(time, Velocity)]."""
    out = []
    pending = sorted(keys.items()) if keys else []
    n = round((end - start) / step)
    for i in range(n + 1):
        now = start + i * step
        while pending and pending[0][0] <= now + 1e-9:
            t.on_key(pending.pop(0)[1], now)
        v = t.due(now)
        if v is not None:
            out.append((round(now, 6), v))
    return out


@pytest.mark.parametrize(
    "keys, expected",
    [
        ("wi", Velocity(0.5, 0.0, 0.0)),
        ("s,", Velocity(-0.5, 0.0, 0.0)),
        ("aj", Velocity(0.0, 0.5, 0.0)),
        ("dl", Velocity(0.0, -0.5, 0.0)),
        ("qu", Velocity(0.0, 0.0, 0.4)),
        ("eo", Velocity(0.0, 0.0, -0.4)),
        (["\x1b[A", "\x1bOA"], Velocity(0.5, 0.0, 0.0)),
        (["\x1b[B", "\x1bOB"], Velocity(-0.5, 0.0, 0.0)),
        (["\x1b[D", "\x1bOD"], Velocity(0.0, 0.0, 0.4)),
        (["\x1b[C", "\x1bOC"], Velocity(0.0, 0.0, -0.4)),
    ],
)
def test_each_motion_key_gives_its_motion_at_once(keys, expected):
    for key in list(keys) + [k.upper() for k in keys if len(k) == 1 and k.isalpha()]:
        t = teleop(speed=0.5, turn=0.4)
        assert t.due(0.0) is None  # idle: nothing
        assert t.on_key(key, 1.0) == MOTION
        assert t.due(1.0) == expected, key


def test_motion_is_published_at_the_rate_while_the_key_repeats():
    t = teleop()
    # key repeat at 30 Hz for 2 s
    keys = {round(0.1 + i / 30.0, 6): "w" for i in range(60)}
    out = run(t, 0.0, 2.0, keys)
    times = [when for when, _ in out]
    assert all(v == Velocity(0.5, 0, 0) for _, v in out)
    assert times[0] == pytest.approx(0.1)
    gaps = [b - a for a, b in zip(times, times[1:])]
    assert all(g == pytest.approx(PERIOD, abs=0.011) for g in gaps), gaps
    assert len(out) == pytest.approx(1.9 * RATE, abs=2)


def test_a_key_not_repeated_stops_with_one_zero_then_silence():
    t = teleop()
    out = run(t, 0.0, 3.0, {0.5: "w"})
    assert out[0] == (0.5, Velocity(0.5, 0, 0))
    zeros = [(when, v) for when, v in out if v == ZERO]
    assert len(zeros) == 1 and out[-1] == zeros[0]
    assert zeros[0][0] == pytest.approx(0.5 + 0.6, abs=0.011)
    # the motion until then, at the rate
    assert len(out) - 1 == pytest.approx(0.6 * RATE, abs=1)
    assert t.next_deadline(3.0) is None


def test_the_key_timeout_is_counted_from_the_last_repeat():
    t = teleop(key_timeout=0.3)
    out = run(t, 0.0, 2.0, {0.0: "w", 0.25: "w", 0.5: "w"})
    (stop,) = [when for when, v in out if v == ZERO]
    assert stop == pytest.approx(0.8, abs=0.011)


def test_the_stop_keys_stop_at_once_with_one_zero():
    for key in (" ", "k", "K"):
        t = teleop()
        out = run(t, 0.0, 2.0, {0.0: "w", 0.2: "w", 0.3: key})
        assert out[-1] == (0.3, ZERO)
        assert [v for _, v in out].count(ZERO) == 1


def test_the_stop_key_when_idle_still_gives_one_zero():
    t = teleop()
    assert t.on_key(" ", 0.0) == STOP
    assert run(t, 0.0, 1.0) == [(0.0, ZERO)]


def test_a_new_motion_key_replaces_the_motion_at_once():
    t = teleop()
    out = run(t, 0.0, 0.5, {0.0: "w", 0.12: "q"})
    assert (0.12, Velocity(0, 0, 0.5)) in out
    assert all(v == Velocity(0.5, 0, 0) for when, v in out if when < 0.12)
    assert all(v == Velocity(0, 0, 0.5) for when, v in out if when >= 0.12)
    assert ZERO not in [v for _, v in out]


def test_speed_steps_scale_linear_and_angular_and_apply_at_once():
    t = teleop(speed=0.5, turn=1.0)
    assert t.on_key("+", 0.0) == SPEED
    assert (t.speed, t.turn) == pytest.approx((0.55, 1.1))
    assert t.due(0.0) is None  # idle: a speed change publishes nothing
    t.on_key("w", 0.1)
    assert t.due(0.1) == pytest.approx(Velocity(0.55, 0, 0))
    assert t.on_key("-", 0.12) == SPEED
    assert t.due(0.12) == pytest.approx(Velocity(0.495, 0, 0))  # at once, not at the next period
    assert t.on_key("=", 0.13) == SPEED  # "+" without shift
    t.on_key("q", 0.14)
    assert t.due(0.14) == pytest.approx(Velocity(0, 0, 1.0 * 1.1 * 0.9 * 1.1))


def test_speed_steps_stay_within_the_limits():
    t = teleop(speed=0.5, turn=0.5, max_speed=1.0, max_turn=0.8)
    for _ in range(50):
        t.on_key("+", 0.0)
    assert (t.speed, t.turn) == pytest.approx((1.0, 0.8))
    for _ in range(100):
        t.on_key("-", 0.0)
    assert (t.speed, t.turn) == pytest.approx((0.05, 0.05))
    slow = teleop(speed=0.02, turn=0.01)
    slow.on_key("-", 0.0)
    assert (slow.speed, slow.turn) == pytest.approx((0.02, 0.01))  # the floor is the start when lower


def test_quit_keys_and_the_last_zero():
    for key in ("\x1b", "\x03"):
        t = teleop()
        t.on_key("w", 0.0)
        assert t.due(0.0) == Velocity(0.5, 0, 0)
        assert t.on_key(key, 0.1) == QUIT
        assert t.quit() == ZERO
        assert t.quit() is None
        assert t.due(0.2) is None
    idle = teleop()
    assert idle.quit() is None  # nothing owed
    stopped = teleop()
    stopped.on_key("w", 0.0)
    stopped.due(0.0)
    stopped.due(1.0)  # the timeout's zero, published
    assert stopped.quit() is None
    unpublished = teleop()
    unpublished.on_key("w", 0.0)
    unpublished.on_key("k", 0.1)  # its zero not yet published
    assert unpublished.quit() == ZERO


def test_other_keys_are_ignored():
    t = teleop()
    t.on_key("w", 0.0)
    for key in ("x", "1", "\r", "\x1b[5~", "é"):
        assert t.on_key(key, 0.1) == IGNORED
    assert t.due(0.1) == Velocity(0.5, 0, 0)  # the first publication; the motion goes on


def test_next_deadline_tells_when_to_poll():
    t = teleop()
    assert t.next_deadline(0.0) is None
    t.on_key("w", 1.0)
    assert t.next_deadline(1.0) == 1.0  # publish at once
    t.due(1.0)
    assert t.next_deadline(1.01) == pytest.approx(1.0 + PERIOD)
    short = teleop(key_timeout=0.02)
    short.on_key("w", 1.0)
    short.due(1.0)
    assert short.next_deadline(1.0) == pytest.approx(1.02)
    assert short.due(1.02) == ZERO
    assert short.next_deadline(1.02) is None


def test_a_late_poll_restarts_the_schedule_instead_of_bursting():
    t = teleop(key_timeout=10.0)
    t.on_key("w", 0.0)
    assert t.due(0.0) is not None
    assert t.due(0.5) is not None  # late by many periods: one publication
    assert t.due(0.51) is None
    assert t.due(0.5 + PERIOD) is not None


@pytest.mark.parametrize(
    "kw",
    [{"speed": 0}, {"turn": -1}, {"rate": 0}, {"key_timeout": 0}, {"speed": float("nan")}, {"rate": float("inf")}],
)
def test_bad_parameters_are_refused(kw):
    with pytest.raises(ValueError, match=next(iter(kw))):
        teleop(**kw)


def test_a_start_speed_above_its_limit_is_refused():
    with pytest.raises(ValueError, match="max_speed"):
        teleop(speed=3.0, max_speed=2.0)
    with pytest.raises(ValueError, match="max_turn"):
        teleop(turn=3.0, max_turn=2.0)


def test_split_keys():
    assert split_keys("wq ") == ["w", "q", " "]
    assert split_keys("\x1b") == ["\x1b"]
    assert split_keys("\x1b[A\x1b[Bw") == ["\x1b[A", "\x1b[B", "w"]
    assert split_keys("\x1bOD\x1b[5~") == ["\x1bOD", "\x1b[5~"]
    assert split_keys("w\x1b") == ["w", "\x1b"]
    assert split_keys("\x1b\x1b") == ["\x1b", "\x1b"]
    assert split_keys("") == []


def test_the_help_names_every_key():
    text = HELP.format(topic="/teleop_joy/cmd_vel", key_timeout=0.6)
    for key in [k for k in MOTION_KEYS if len(k) == 1] + ["+", "-", "space", "Esc", "Ctrl-C"]:
        assert f" {key} " in text or f" {key}\n" in text, key
    assert "/teleop_joy/cmd_vel" in text and "0.6 s" in text
