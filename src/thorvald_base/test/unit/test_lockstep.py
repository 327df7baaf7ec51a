"""thorvald_base.lockstep: base_driver's answer to each simulator instant, without ROS."""

import pytest
from base_test_helpers import four_ws

from thorvald_base.bases import MeasuredDrive
from thorvald_base.bases.simulated import SimulatedBase
from thorvald_base.bases.simulated_joints import SimulatedJointsBase
from thorvald_base.core import BaseDriverCore
from thorvald_base.errors import ParameterError
from thorvald_base.kinematics import PltfClcStd
from thorvald_base.lockstep import LockstepCycles


def lockstep(rate=50.0):
    config = four_ws()
    sent = []
    handle = SimulatedJointsBase(config, lambda commands, t: sent.append((t, commands)))
    calculator = PltfClcStd()
    calculator.initialize(config.drives)
    return LockstepCycles(BaseDriverCore(config, calculator, handle), rate), handle, sent


def test_a_cycle_at_the_first_tick_at_or_after_each_multiple_and_the_last_commands_between():
    steps, handle, sent = lockstep()
    for k in range(1, 9):  # the simulator's ticks at 80 Hz: 12.5 ms apart
        t = k * 0.0125
        handle.update([MeasuredDrive(0.0, 0.0, 0.0, 0.0)] * 4, t)
        if steps.due(t):
            result, refused = steps.cycle(t, (0.4, 0.0, 0.0))
            assert refused is None and result.time == t
        else:
            steps.answer(t)
    # the first tick is a cycle (there is nothing yet to answer it with: a simulator in lockstep would
    # wait in vain), then cycles at 25, 50, 62.5, 87.5 ms (the first ticks at or after 20, 40, 60, 80
    # ms); every other tick answered with the last commands, stamped for it: every tick gets its commands
    assert [round(t, 4) for t, _ in sent] == [0.0125, 0.025, 0.0375, 0.05, 0.0625, 0.075, 0.0875, 0.1]
    assert sent[2][1] == sent[1][1]  # an answer repeats the cycle's commands
    assert all(c.speed > 0 for c in sent[-1][1])  # driving ahead


def test_an_absurd_command_is_refused_as_base_driver_refuses_it():
    steps, handle, _ = lockstep()
    handle.update([MeasuredDrive(0.0, 0.0, 0.0, 0.0)] * 4, 0.0)
    assert steps.due(0.0)
    _, refused = steps.cycle(0.0, (float("nan"), 0.0, 0.0))
    assert refused is not None and "finite" in refused


def test_a_handle_that_cannot_answer_an_instant_is_refused():
    config = four_ws()
    calculator = PltfClcStd()
    calculator.initialize(config.drives)
    with pytest.raises(ParameterError, match="answers a simulator instant by instant"):
        LockstepCycles(BaseDriverCore(config, calculator, SimulatedBase(config)), 50.0)
