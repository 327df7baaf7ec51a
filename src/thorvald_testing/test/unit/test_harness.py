"""The shared harness itself (thorvald_testing): a master of one's own (roscore or a bare rosmaster),
roslaunch on it, processes stopped with their groups, and what a process costs."""

import os
import subprocess
import sys
import time

import pytest

from thorvald_testing import (
    Launch,
    Master,
    Processes,
    children,
    cmdline,
    cpu_seconds,
    group_members,
    master_is_up,
    poll,
    processes_naming,
)

pytestmark = pytest.mark.long(25)  # [s] in all: the parallel run starts it early


def gone_pid():
    """A pid nobody has: a process that has exited and been reaped."""
    proc = subprocess.Popen([sys.executable, "-c", "pass"])
    proc.wait()
    return proc.pid


def test_what_a_process_is_and_costs():
    assert "python" in cmdline(os.getpid()) and cmdline(gone_pid()) == ""
    before = cpu_seconds(os.getpid())
    end = time.process_time() + 0.2
    while time.process_time() < end:  # 0.2 s of CPU, so the clock (10 ms ticks) must move
        pass
    assert 0.1 < cpu_seconds(os.getpid()) - before < 5.0
    assert cpu_seconds(gone_pid(), missing=-1.0) == -1.0
    with pytest.raises(OSError):
        cpu_seconds(gone_pid())


def test_processes_stop_with_everything_they_started():
    with Processes() as procs:
        # a shell's background jobs ignore SIGINT: they outlive the shell unless killed
        shell = procs.start(["sh", "-c", "sleep 60 & sleep 60 & wait"])
        kids = poll(lambda: len(children(shell.pid)) == 2 and children(shell.pid), 10, "the shell's two sleeps")
        assert sorted(group_members(shell.pid)) == sorted([shell.pid, *kids])
        started = time.monotonic()
        procs.stop(shell, grace=1.0)
        assert time.monotonic() - started < 5.0
        quiet = procs.start([sys.executable, "-c", "import time; time.sleep(60)"])
    assert shell.poll() is not None and quiet.poll() is not None and procs.procs == []
    assert group_members(shell.pid) == [] and group_members(quiet.pid) == []


@pytest.mark.ros
def test_a_bare_master_and_a_launch_on_it_that_leaves_it_running(tmp_path):
    (tmp_path / "master").mkdir()
    with Master(tmp_path / "master", core_only=True) as master:
        assert master.proc.args[:2] == ["rosmaster", "--core"] and master_is_up(master.uri)
        launch_file = tmp_path / "one.launch"
        launch_file.write_text(
            '<launch><node name="talker" pkg="rostopic" type="rostopic" args="pub -r 1 /x std_msgs/Empty"/></launch>'
        )
        home = tmp_path / "launch"
        home.mkdir()
        with Launch(home, str(launch_file), env=master.env, port=master.port) as launch:
            # the node registers with the benchmark's master, not one of roslaunch's own
            poll(lambda: "/talker" in launch.run(["rosnode", "list"]).stdout, 60, lambda: "/talker\n" + launch.tail())
            assert launch.env["ROS_MASTER_URI"] == master.uri
        assert launch.left == [] and processes_naming(str(home)) == []
        assert master_is_up(master.uri)  # roslaunch left the master it did not start
    assert not master_is_up(master.uri)
