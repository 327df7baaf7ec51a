"""thorvald_base.rate_grid: the instants of a rate on a stepped simulated clock."""

import math

import pytest

from thorvald_base.rate_grid import RateGrid


def instants(grid, steps, dt):
    return [k for k in steps if grid.due(k * dt)]


@pytest.mark.parametrize("rate, physics", [(40.0, 240.0), (100.0, 240.0), (30.0, 1000.0), (7.0, 240.0), (80.0, 240.0)])
def test_a_grid_gives_its_rate_per_simulated_second(rate, physics):
    dt = 1.0 / physics
    grid = RateGrid(rate, dt)
    served = instants(grid, range(int(10 * physics)), dt)
    assert len(served) == pytest.approx(10 * rate, abs=1)


def test_100_hz_on_240_hz_steps_is_100_hz_not_every_third_step():
    # 240 / 100 = 2.4 steps a period: the instants are 2 or 3 steps apart, 100 of them a second (a
    # "next = now + period" timer fires every 3rd step: 80 Hz)
    dt = 1.0 / 240
    served = instants(RateGrid(100.0, dt), range(1, 241), dt)
    assert len(served) == 100
    assert set(b - a for a, b in zip(served, served[1:])) == {2, 3}


def test_the_instants_are_the_periods_multiples_whenever_it_began():
    # 10 Hz at 240 Hz physics: the steps nearest 0.1, 0.2, ... s (steps 24, 48, ...), whether first asked
    # at step 0, 5 or 17; step 0 is itself a multiple
    dt = 1.0 / 240
    for first in (5, 17):
        assert instants(RateGrid(10.0, dt), range(first, 100), dt) == [24, 48, 72, 96]
    assert instants(RateGrid(10.0, dt), range(0, 30), dt) == [0, 24]


def test_the_step_nearest_a_multiple_serves_it():
    # 100 Hz at 240 Hz: 0.01 s is 2.4 steps; step 2 (8.3 ms) is within half a step (2.1 ms) of it
    dt = 1.0 / 240
    grid = RateGrid(100.0, dt)
    assert [grid.due(k * dt) for k in range(4)] == [True, False, True, False]
    assert grid.index == 1 and grid.time() == pytest.approx(0.01)


def test_a_missed_multiple_is_not_made_up():
    grid = RateGrid(10.0, 1.0 / 240)
    assert grid.due(0.0)
    assert not grid.due(0.05)
    assert grid.due(5.05)  # 5 s without asking: served once, late, for the multiple at 5.0 s
    assert grid.index == 50
    assert not grid.due(5.06)  # no burst of the 49 missed
    assert grid.due(5.1) and grid.index == 51


def test_after_a_pause_it_starts_again_at_the_next_multiple():
    dt = 1.0 / 240
    grid = RateGrid(10.0, dt)
    assert grid.due(0.0)
    grid.pause()
    assert not grid.due(5.05)  # nobody asked meanwhile: nothing is owed
    assert grid.due(5.1) and grid.index == 51


def test_exact_instants_without_a_step_as_base_driver_cycles_in_lockstep():
    # base_driver at 50 Hz on the simulator's ticks every 12.5 ms: a cycle at the first tick at or
    # after each multiple of 20 ms
    grid = RateGrid(50.0)
    ticks = [k * 0.0125 for k in range(17)]
    cycles = [t for t in ticks if grid.due(t)]
    assert cycles == pytest.approx([0.0, 0.025, 0.05, 0.0625, 0.0875, 0.1, 0.125, 0.15, 0.1625, 0.1875, 0.2])
    # a tick a hair before a multiple (a float's error) does not serve it
    grid = RateGrid(50.0)
    assert grid.due(0.0) and not grid.due(0.02 - 1e-6) and grid.due(0.02)


def test_rate_zero_is_every_step_with_the_steps_index():
    dt = 1.0 / 240
    grid = RateGrid(0.0, dt)
    assert all(grid.due(k * dt) for k in range(5))
    assert grid.index == 4


@pytest.mark.parametrize("rate, step", [(-1.0, 0.0), (math.nan, 0.0), (math.inf, 0.0), (0.0, 0.0), (10.0, -1.0)])
def test_bad_rates_and_steps_are_refused(rate, step):
    with pytest.raises(ValueError):
        RateGrid(rate, step)
