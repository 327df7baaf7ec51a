"""The simulation loop's pure parts with a clock of the test's own: pacing, lockstep, parameters, the
robots' commands and the wait for robots that lag."""

import threading

import pytest

from thorvald_sim.errors import ParameterError, ThorvaldSimError
from thorvald_sim.node.commands import APPLY, HOLD, STREAM_ALIVE, CommandSlot
from thorvald_sim.node.lockstep import STARTUP_SPAN, STARTUP_TIMEOUT, Lockstep
from thorvald_sim.node.pacing import FollowerWait, Pacer
from thorvald_sim.node.params import SimulatorParams


class FakeClock:
    """Wall time [s] that moves only when told (or when something sleeps on it)."""

    def __init__(self):
        self.now = 100.0
        self.slept = []

    def __call__(self):
        return self.now

    def sleep(self, seconds):
        self.slept.append(seconds)
        self.now += seconds


# ---- pacing --------------------------------------------------------------------------------------
def test_pacing_keeps_the_real_time_factor():
    clock = FakeClock()
    pacer = Pacer(2.0, clock=clock, sleep=clock.sleep)
    dt = 1.0 / 240
    for k in range(1, 481):  # 2 simulated seconds, each step costing 1 ms of wall time
        clock.now += 0.001
        pacer.stepped(k * dt)
    # at 2 x real time, 2 simulated seconds take 1 wall second (the first step is the anchor)
    assert clock.now - 100.0 == pytest.approx(1.0 - 1.0 / 480 + 0.001, abs=1e-9)


def test_a_stall_is_followed_by_no_burst():
    clock = FakeClock()
    pacer = Pacer(1.0, clock=clock, sleep=clock.sleep)
    dt = 0.01
    pacer.stepped(dt)
    for k in range(2, 11):
        pacer.stepped(k * dt)  # on pace: each step waits 10 ms
    assert clock.slept[-1] == pytest.approx(0.01)
    clock.now += 3.0  # a 3 s stall (a busy machine)
    pacer.stepped(11 * dt)  # behind by 2.99 s: a new anchor, not a race
    assert pacer.restarts == 1
    waits = []
    for k in range(12, 20):
        before = len(clock.slept)
        pacer.stepped(k * dt)
        waits.append(clock.slept[-1] if len(clock.slept) > before else 0.0)
    # the step after the stall takes the new anchor (no wait), then the pace of real time again: no
    # steps at full speed to make up the 3 s
    assert waits == pytest.approx([0.0] + [0.01] * 7)


def test_a_small_lag_is_made_up_but_not_a_large_one():
    clock = FakeClock()
    pacer = Pacer(1.0, catch_up=0.05, clock=clock, sleep=clock.sleep)
    pacer.stepped(0.0)
    clock.now += 0.04  # 40 ms late at the next step: within catch_up, the pace holds its anchor
    pacer.stepped(0.0 + 0.001)
    assert pacer.restarts == 0 and pacer.anchor is not None


def test_as_fast_as_possible_never_waits_and_a_pause_drops_the_anchor():
    clock = FakeClock()
    fast = Pacer(0.0, clock=clock, sleep=clock.sleep)
    assert all(fast.stepped(k * 0.01) == 0.0 for k in range(100)) and clock.slept == []
    paced = Pacer(1.0, clock=clock, sleep=clock.sleep)
    paced.stepped(1.0)
    paced.paused()
    assert paced.anchor is None
    clock.now += 60.0  # paused a minute: no burst after it either
    assert paced.stepped(1.01) == 0.0 and paced.restarts == 0


@pytest.mark.parametrize("factor", [-1.0, float("nan"), float("inf")])
def test_a_bad_factor_is_refused(factor):
    with pytest.raises(ValueError):
        Pacer(factor)


# ---- lockstep ------------------------------------------------------------------------------------
def lockstep(timeout=2.0):
    """A Lockstep whose waits advance the test's clock instead of the wall's."""
    clock = FakeClock()

    def wait(condition, seconds):
        clock.now += seconds

    return Lockstep(timeout, clock=clock, wait=wait), clock


def test_each_robot_answers_an_instant_before_the_next():
    steps, clock = lockstep()
    assert steps.published("r1", 0.0125) and steps.published("r2", 0.0125)  # both join with their first states
    assert steps.waiting() == ["r1", "r2"]
    steps.answered("r1", 0.0125)
    assert steps.waiting() == ["r2"]
    steps.answered("r2", 0.0125)
    assert steps.wait() == [] and clock.now == 100.0  # nothing to wait for: no time passes


def test_an_older_command_does_not_answer_a_newer_instant():
    steps, _ = lockstep()
    steps.published("r1", 0.05)
    steps.answered("r1", 0.0375)
    assert steps.waiting() == ["r1"]
    steps.answered("r1", 0.05 - 1e-10)  # a stamp's nanoseconds: the same instant
    assert steps.waiting() == []


def test_a_robot_that_never_answers_is_released_after_its_timeout_and_the_others_go_on():
    steps, clock = lockstep(timeout=2.0)
    for name in ("silent", "r2"):
        steps.published(name, 0.0125)  # joined at the start
        steps.answered(name, 0.0125)
    steps.published("silent", 1.1)  # past its first second in lockstep
    steps.published("r2", 1.1)
    steps.answered("r2", 1.1)
    assert steps.wait() == ["silent"]
    assert clock.now - 100.0 == pytest.approx(2.0)
    # let go: the world no longer waits for it, while r2 is still awaited each instant
    steps.published("silent", 1.2)
    steps.published("r2", 1.2)
    assert steps.waiting() == ["r2"]
    # its next command brings it back
    assert steps.answered("silent", 1.2)
    steps.published("silent", 1.3)
    assert "silent" in steps.waiting()


def test_a_robot_in_its_first_second_in_lockstep_has_the_startup_timeout():
    """A driver just started answers its first instants while its process still imports and connects:
    it has STARTUP_TIMEOUT for those of its first STARTUP_SPAN of simulated time, then TIMEOUT; one that
    joins again later starts a span of its own."""
    steps, clock = lockstep(timeout=2.0)
    steps.published("old", 0.0125)
    steps.answered("old", 0.0125)
    steps.published("old", 1.5)  # an instant after its first second: 2 s
    steps.published("new", 1.5)  # joins here: 10 s
    assert steps.allowed("old") == 2.0 and steps.allowed("new") == STARTUP_TIMEOUT
    assert steps.wait() == ["old", "new"]  # both silent: old let go at 2 s, new at 10 s
    assert clock.now - 100.0 == pytest.approx(STARTUP_TIMEOUT)
    steps.answered("new", 1.5)
    steps.published("new", 1.5 + STARTUP_SPAN)  # its span over
    assert steps.allowed("new") == 2.0
    assert steps.answered("old", 2.6)  # joins again: a span of its own
    steps.published("old", 2.6)
    assert steps.allowed("old") == STARTUP_TIMEOUT


def test_the_others_are_let_go_at_their_own_timeouts():
    steps, clock = lockstep(timeout=2.0)
    steps.published("old", 0.0125)
    steps.answered("old", 0.0125)
    steps.published("old", 1.5)
    steps.published("new", 1.5)
    # the new one answers after 5 s: the old one was let go at 2 s, the wait ends with the answer
    original = steps._wait

    def wait(condition, seconds):
        original(condition, seconds)
        if clock.now - 100.0 >= 5.0 and steps.waiting() == ["new"]:
            steps.answered("new", 1.5)

    steps._wait = wait
    assert steps.wait() == ["old"]
    assert clock.now - 100.0 == pytest.approx(5.0, abs=0.11)


def test_a_wait_ends_when_the_answer_comes_from_another_thread():
    steps = Lockstep(timeout=30.0)
    steps.published("r1", 1.0)
    threading.Timer(0.05, steps.answered, args=("r1", 1.0)).start()
    assert steps.wait() == []


def test_a_forgotten_robot_is_not_waited_for():
    steps, _ = lockstep()
    steps.published("deleted", 1.0)
    steps.forget("deleted")
    assert steps.waiting() == [] and steps.wait() == []


# ---- parameters ----------------------------------------------------------------------------------
def test_parameters_are_read_once_with_their_defaults():
    asked = []

    def get(name, default):
        asked.append(name)
        return {"real_time_factor": 0, "seed": 7, "world": "slope"}.get(name, default)

    params = SimulatorParams.read(get)
    assert params == SimulatorParams(real_time_factor=0.0, seed=7, world="slope")
    assert params.clock_rate == 80.0 and params.publish_tf is True
    assert len(asked) == len(set(asked)) == 23  # every parameter, each once
    assert (params.drive_state_rate, params.drive_current_rate) == (80.0, 10.0)
    assert (params.physics, params.physics_rate, params.solver_iterations) == ("default", 240.0, 50)


def test_the_physics_preset_gives_the_rate_and_iterations_unless_they_are_given():
    fleet = SimulatorParams.read(lambda n, d: "fleet" if n == "physics" else d)
    assert (fleet.physics, fleet.physics_rate, fleet.solver_iterations) == ("fleet", 120.0, 50)
    given = {"physics": "fleet", "physics_rate": 200, "solver_iterations": 30}
    mixed = SimulatorParams.read(given.get)
    assert (mixed.physics_rate, mixed.solver_iterations) == (200.0, 30)


@pytest.mark.parametrize(
    "name, value, rule",
    [
        ("physics_rate", 0, "must be > 0"),
        ("physics_rate", "fast", "must be a number"),
        ("physics_rate", True, "must be a number"),
        ("clock_rate", float("nan"), "must be > 0"),
        ("drive_current_rate", 0, "must be > 0"),
        ("real_time_factor", -1, "must be >= 0"),
        ("seed", 1.5, "must be a whole number"),
        ("seed", True, "must be a whole number"),
        ("physics", "fast", "must be one of default, fleet"),
        ("physics", ["fleet"], "must be one of default, fleet"),
        ("solver_iterations", 0, "must be a whole number in 1..1000"),
        ("solver_iterations", 12.5, "must be a whole number in 1..1000"),
        ("physics_workers", 0, "must be a whole number in 1..16"),
        ("physics_workers", 17, "must be a whole number in 1..16"),
        ("physics_workers", True, "must be a whole number in 1..16"),
        ("physics_workers", 2.0, "must be a whole number in 1..16"),
        ("worker_strips", "9", "must be none or 0 increasing x [m]"),
    ],
)
def test_a_bad_parameter_is_refused_with_its_name_value_and_rule(name, value, rule):
    with pytest.raises(ParameterError) as e:
        SimulatorParams.read(lambda n, d: value if n == name else d)
    assert str(e.value).startswith(f"~{name}: {value!r}: {rule}")
    assert isinstance(e.value, ThorvaldSimError)


@pytest.mark.parametrize(
    "strips, read",
    [("", ()), ("9", (9.0,)), (9, (9.0,)), ("-3, 9.5", (-3.0, 9.5)), ([0, 10], (0.0, 10.0)), ("9 x", None),
     ("9 3", None), ([1, float("nan")], None), ([True, 3], None), ("1 2 3", None)],
)  # fmt: skip
def test_physics_workers_take_strips_of_one_less_increasing_x(strips, read):
    workers = 2 if len(read or ()) < 2 else 3
    given = {"physics_workers": workers, "worker_strips": strips}
    if read is None:
        with pytest.raises(ParameterError) as e:
            SimulatorParams.read(given.get)
        assert str(e.value).startswith(f"~worker_strips: {strips!r}: must be none or {workers - 1} increasing x [m]")
    else:
        params = SimulatorParams.read(given.get)
        assert (params.physics_workers, params.worker_strips) == (workers, read)


def test_pybullets_window_shows_one_client_so_gui_takes_one_worker():
    with pytest.raises(ParameterError) as e:
        SimulatorParams.read({"gui": True, "physics_workers": 2}.get)
    assert str(e.value) == "~physics_workers: 2: must be 1 with ~gui true (pybullet's window shows one client's world)"
    assert SimulatorParams.read({"gui": True}.get).physics_workers == 1


# ---- commands ------------------------------------------------------------------------------------
def test_each_command_is_applied_once_and_a_silent_robot_is_held_once():
    slot = CommandSlot(2, clock=FakeClock())
    assert slot.take(0.0, 0.5) == (None, None)  # nothing came yet: nothing to do, no hold
    assert slot.put([0.1, 0.2], [1.0, 1.0], [], now=1.0, stamp=1.0) == ""
    assert slot.take(1.0, 0.5) == (APPLY, ([0.1, 0.2], [1.0, 1.0], None))
    assert slot.take(1.2, 0.5) == (None, None)  # applied already; not stale yet
    assert slot.take(1.6, 0.5) == (HOLD, None)  # 0.6 s without a command: the wheels stop, once
    assert slot.take(5.0, 0.5) == (None, None)
    slot.put([0.0, 0.0], [0.5, 0.5], [1.0, 2.0], now=5.0, stamp=5.0)
    assert slot.take(5.0, 0.5) == (APPLY, ([0.0, 0.0], [0.5, 0.5], [1.0, 2.0]))


@pytest.mark.parametrize(
    ("steering", "speeds", "limits", "says"),
    [
        ([0.0], [1.0, 1.0], [], "a command for 1/2 drives ignored; the robot has 2"),
        ([0.0, 0.0, 0.0], [1.0, 1.0, 1.0], [], "a command for 3/3 drives ignored; the robot has 2"),
        ([0.0, float("nan")], [1.0, 1.0], [], "a non-finite command ignored"),
        ([0.0, 0.0], [1.0, float("inf")], [], "a non-finite command ignored"),
        ([0.0, 0.0], [1.0, 1.0], [float("nan"), 1.0], "a non-finite command ignored"),
    ],
)
def test_a_command_that_cannot_be_applied_is_refused_and_the_last_one_stays(steering, speeds, limits, says):
    slot = CommandSlot(2, clock=FakeClock())
    slot.put([0.1, 0.1], [1.0, 1.0], [], now=1.0, stamp=1.0)
    assert slot.put(steering, speeds, limits, now=1.1, stamp=1.1) == says
    assert slot.take(1.1, 0.5) == (APPLY, ([0.1, 0.1], [1.0, 1.0], None))


def test_a_robot_lags_while_its_stream_is_alive_and_behind():
    clock = FakeClock()
    slot = CommandSlot(1, clock=clock)
    assert not slot.lagging(10.0, 0.05)  # no command yet: nothing to wait for
    slot.put([0.0], [1.0], [], now=10.0, stamp=9.99)
    assert not slot.lagging(10.0, 0.05)  # 10 ms behind
    assert slot.lagging(10.1, 0.05)  # 110 ms behind, its last command just now
    clock.now += STREAM_ALIVE + 0.01
    assert not slot.lagging(10.1, 0.05)  # its stream stopped: not waited for


def test_the_wait_for_lagging_robots_ends_when_they_catch_up():
    clock = FakeClock()
    behind = iter([["r1", "r2"], ["r1"], ["r1"], []])
    ticks = []
    wait = FollowerWait(max_wait=0.5, clock=clock, sleep=clock.sleep, poll=0.001)
    assert wait.wait(lambda: next(behind), lambda: ticks.append(clock.now)) == []
    assert ticks == [100.0] and clock.slept == [0.001] * 3  # the clock published once, at the start


def test_a_robot_that_cannot_catch_up_is_given_up_on_after_the_longest_wait():
    clock = FakeClock()
    wait = FollowerWait(max_wait=0.5, clock=clock, sleep=clock.sleep, poll=0.001)
    assert wait.wait(lambda: ["slow"], lambda: None) == ["slow"]
    assert clock.now - 100.0 == pytest.approx(0.501, abs=0.0015)
    assert wait.wait(lambda: [], lambda: None) == []  # nobody lags: no wait at all
    assert wait.wait(lambda: ["slow"], lambda: None, stop=lambda: True) == []  # shutting down
