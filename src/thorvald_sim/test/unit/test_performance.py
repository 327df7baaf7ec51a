"""The simulator's own measure of how it runs (its /diagnostics): windows of wall time, the
real-time factor reached and CPU per simulated second, and the solver's part counted by Simulation."""

import time

import pybullet as p
import pytest

from thorvald_sim.physics.simulation import Performance, PerformanceMeter, Simulation, performance_report
from thorvald_sim.world import parse_world


def test_the_meter_reports_each_window_of_at_least_its_period():
    meter = PerformanceMeter(period=1.0)
    assert meter.due(10.0)  # the first sample is always due: it opens the first window
    assert meter.sample(10.0, 0.0, 2.0, 1.0) is None
    assert meter.sample(10.6, 3.0, 2.3, 1.1) is None  # 0.6 s of wall time: too short
    # 1.5 s of wall time from the window's start: 6 simulated seconds, 0.9 s of CPU, 0.3 s of it the solver
    perf = meter.sample(11.5, 6.0, 2.9, 1.3)
    assert perf == Performance(
        wall=pytest.approx(1.5), simulated=6.0, cpu=pytest.approx(0.9), solver_cpu=pytest.approx(0.3)
    )
    assert perf.real_time_factor == pytest.approx(4.0)  # 6 s simulated in 1.5 s
    assert perf.per_simulated_second(perf.cpu) == pytest.approx(0.15)  # 0.9 s / 6 s
    assert perf.per_simulated_second(perf.solver_cpu) == pytest.approx(0.05)
    assert not meter.due(12.4) and meter.due(12.5)  # the next window starts where this one ended
    assert meter.sample(12.0, 8.0, 3.0, 1.4) is None


def test_a_paused_window_reports_no_progress_and_no_division_by_zero():
    meter = PerformanceMeter(period=1.0)
    meter.sample(0.0, 5.0, 1.0, 0.5)
    perf = meter.sample(2.0, 5.0, 1.01, 0.5)
    assert perf.real_time_factor == 0.0
    assert perf.per_simulated_second(perf.cpu) == 0.0


def test_the_simulation_counts_the_cpu_its_solver_takes():
    client = p.connect(p.DIRECT)
    try:
        sim = Simulation(client, parse_world({"ground": {"lateral_friction": 0.9}}, "flat"))
        for k in range(40):  # something to collide: a stack of boxes on the ground
            box = p.createCollisionShape(p.GEOM_BOX, halfExtents=(0.2, 0.2, 0.2), physicsClientId=client)
            p.createMultiBody(1.0, box, basePosition=(0.1 * (k % 5), 0.0, 0.2 + 0.41 * k), physicsClientId=client)
        cpu = time.thread_time()
        for _ in range(240):
            sim.step()
        cpu = time.thread_time() - cpu
        assert sim.steps == 240 and sim.time == pytest.approx(1.0)
        # the solver's part of the steps: most of them (the loop around it is a few microseconds a step)
        assert 0.0 < sim.solver_cpu <= cpu
        assert sim.solver_cpu > 0.5 * cpu
    finally:
        p.disconnect(client)


def test_the_report_warns_when_the_factor_asked_is_not_held():
    perf = Performance(wall=2.0, simulated=1.6, cpu=1.0, solver_cpu=0.4)
    level, message, values = performance_report(
        perf, robots=3, asked=1.0, paused=False, physics_rate=240.0, simulated_now=12.5
    )
    assert (level, message) == (1, "3 robots, 0.80 x real time (asked for 1 x: the machine cannot keep up)")
    assert values["CPU per simulated second [s]"] == "0.62500" and values["CPU share [cores]"] == "0.500"
    assert values["solver CPU per simulated second [s]"] == "0.25000" and values["simulated time [s]"] == "12.500"
    # 0.8 holds half of real time; as fast as possible holds any; paused says so
    assert performance_report(perf, robots=1, asked=0.5, paused=False, physics_rate=240.0, simulated_now=0.0)[:2] == (
        0,
        "1 robot, 0.80 x real time",
    )
    fast = performance_report(perf, robots=1, asked=0.0, paused=False, physics_rate=240.0, simulated_now=0.0)
    assert fast[0] == 0 and fast[2]["real-time factor asked"] == "as fast as possible"
    assert performance_report(perf, robots=1, asked=1.0, paused=True, physics_rate=240.0, simulated_now=0.0)[:2] == (
        0,
        "paused",
    )
