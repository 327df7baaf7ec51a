"""``catkin_make install`` gives a working workspace, as catkin users expect.

Builds the install space of src/ into a temporary folder (build, devel and install spaces of its
own, testing off) from an environment that holds no ROS workspace, then, with only
``install/setup.bash`` sourced: the Python packages and package files come from the install space,
check_config and generate_urdf work on an installed example robot, the kinematics tool loads a
calculator plugin through the installed plugin description, base_bringup.launch brings up the
installed base_driver, which publishes odometry, every module of the source tree imports from the
install space, and the installed base_driver drives the installed CAN device emulator over SLCAN.
"""

import json
import os
import shlex
import signal
import subprocess
import time

import pytest

from thorvald_testing import free_port

pytestmark = [pytest.mark.ros, pytest.mark.slow, pytest.mark.long(35)]

WS = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
VENV_PYTHON = os.path.join(WS, ".venv", "bin", "python")
STARTUP = 90.0  # [s] for roslaunch, the master and base_driver on a busy machine


def clean_env():
    """The environment of a new shell: no ROS workspace, no PYTHONPATH; the virtual environment first."""
    return {
        "HOME": os.environ.get("HOME", "/root"),
        "PATH": os.pathsep.join([os.path.dirname(VENV_PYTHON), "/usr/local/bin", "/usr/bin", "/bin"]),
        "LANG": "C.UTF-8",
    }


@pytest.fixture(scope="module")
def install(tmp_path_factory):
    root = tmp_path_factory.mktemp("install_space")
    cmd = [
        "catkin_make",
        "-C",
        WS,
        "--source",
        os.path.join(WS, "src"),
        "--build",
        str(root / "build"),
        "-DCATKIN_DEVEL_PREFIX=" + str(root / "devel"),
        "-DCMAKE_INSTALL_PREFIX=" + str(root / "install"),
        "-DPYTHON_EXECUTABLE=" + VENV_PYTHON,
        "-DCATKIN_ENABLE_TESTING=OFF",
        "install",
        "-j2",
    ]
    proc = subprocess.run(cmd, env=clean_env(), capture_output=True, text=True, timeout=900)
    assert proc.returncode == 0, proc.stdout[-3000:] + proc.stderr[-3000:]
    return str(root / "install")


def in_install(install, script, timeout=120, check=True):
    """Runs a bash script with only the install space sourced; returns the completed process."""
    proc = subprocess.run(
        ["bash", "-c", f"source {shlex.quote(install)}/setup.bash && {script}"],
        env=clean_env(),
        capture_output=True,
        text=True,
        timeout=timeout,
    )
    if check:
        assert proc.returncode == 0, f"{script}\n{proc.stdout}\n{proc.stderr}"
    return proc


class InstallLaunch:
    """A bash script run in the background with only the install space sourced, in a session of its
    own; ended with SIGINT (roslaunch's own shutdown). ``output`` holds what it printed."""

    def __init__(self, install, script):
        self.install = install
        self.proc = subprocess.Popen(
            ["bash", "-c", f"source {shlex.quote(install)}/setup.bash && {script}"],
            # unbuffered: a node roslaunch has to kill at the end still leaves its log lines here
            # (one CI run lost base_driver's start-up line when its stop took over 15 s)
            env=dict(clean_env(), PYTHONUNBUFFERED="1"),
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
            start_new_session=True,
        )
        self.output = ""

    def wait_for(self, master, command, predicate):
        """The output of command (run in the install space) once predicate holds, or None at STARTUP."""
        deadline = time.time() + STARTUP
        while time.time() < deadline and self.proc.poll() is None:
            proc = in_install(self.install, f"{master} && timeout 15 {command}", check=False)
            if proc.returncode == 0 and predicate(proc.stdout):
                return proc.stdout
            time.sleep(0.5)
        return None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGINT)
        self.output, _ = self.proc.communicate(timeout=60)


def example(install, name):
    return os.path.join(install, "share", "thorvald_model", "config", name, name + ".yaml")


def test_code_and_package_files_come_from_the_install_space(install):
    out = in_install(
        install,
        "python -c 'import rospkg, thorvald_base, thorvald_model, thorvald_msgs.msg as m; r = rospkg.RosPack(); "
        "print(thorvald_base.__file__, thorvald_model.__file__, m.__file__, "
        'r.get_path("thorvald_base"), r.get_path("thorvald_model"), r.get_path("thorvald_bringup"))\'',
    ).stdout.split()
    assert len(out) == 6 and all(path.startswith(install + os.sep) for path in out), out
    for path in (
        "lib/thorvald_base/base_driver",
        "lib/thorvald_base/twist_mux",
        "lib/thorvald_base/kinematics",
        "lib/thorvald_model/check_config",
        "lib/thorvald_model/xacro",
        "lib/thorvald_model/state_publisher",  # model.launch's robot_state_publisher
        "share/thorvald_base/launch/base_bringup.launch",
        "share/thorvald_base/calculator_plugins.xml",
        "share/thorvald_model/urdf/thorvald_model.xacro",
        "share/thorvald_model/rviz/model.rviz",
        "share/thorvald_bringup/launch/twist_mux.launch",
        "share/thorvald_bringup/config/twist_mux.yaml",
        "lib/thorvald_sim/simulator",
        "lib/thorvald_sim/spawn_robot",
        "lib/thorvald_sim/check_world",
        "lib/thorvald_sim/check_as_built",
        "share/thorvald_sim/launch/robot.launch",
        "share/thorvald_sim/worlds/tarmac_gravel.yaml",
        "share/thorvald_model/meshes/hokuyo/hokuyo.dae",
        # the original's package names: real files in the install space, not links back to src/
        "share/thorvald_description/launch/model.launch",
        "share/thorvald_description/urdf/thorvald_model.xacro",
        "share/thorvald_description/meshes/hokuyo/hokuyo.dae",
        "share/thorvald_twist_mux/launch/twist_mux.launch",
        "share/thorvald_twist_mux/config/twist_mux.yaml",
        "share/thorvald_example_robots/config/thorvald_ii_4wd4ws_std/thorvald_ii_4wd4ws_std.yaml",
        "share/thorvald_example_robots/launch/thorvald_ii_4wd4ws_std_sim.launch",
        "share/xacro/xacro",
        "lib/xacro/xacro",
        # gazebo_ros: users' Gazebo launch files and spawn lines
        "share/gazebo_ros/launch/empty_world.launch",
        "lib/gazebo_ros/spawn_model",
    ):
        assert os.path.exists(os.path.join(install, path)), path
        assert not os.path.realpath(os.path.join(install, path)).startswith(os.path.join(WS, "src")), path


def test_check_config_and_generate_urdf(install):
    std = example(install, "thorvald_ii_4wd4ws_std")
    assert "valid robot configuration" in in_install(install, f"rosrun thorvald_model check_config {std}").stdout
    urdf = in_install(install, f"rosrun thorvald_model generate_urdf {std}").stdout
    assert '<robot name="thorvald_ii_4wd4ws_std"' in urdf
    assert urdf.count("<joint ") == 34 and "thorvald_model/urdf/thorvald_model.xacro" in urdf
    assert install in urdf  # xacro's banner names the installed model
    users = in_install(
        install,
        f"rosrun xacro xacro $(rospack find thorvald_description)/urdf/thorvald_model.xacro robot_config:={std} "
        "tf_prefix:=thorvald_001",
    ).stdout
    assert 'link name="thorvald_001/base_link"' in users and install in users


def test_kinematics_loads_a_plugin_through_the_installed_description(install):
    diff = example(install, "thorvald_ii_2wd_diff")
    out = in_install(install, f"rosrun thorvald_base kinematics {diff} --twist 0.5 0 0.4").stdout
    assert "pltf_clc_2wdiff::PltfClc2WDiff" in out
    # v = vx - wz y: the wheels at y = -+0.275 turn at 0.5 + 0.11 and 0.5 - 0.11 m/s
    assert "0.6100" in out and "0.3900" in out
    source = in_install(
        install,
        "python -c 'from thorvald_base.plugins import CalculatorLoader; "
        'print(CalculatorLoader().plugins["pltf_clc_2wdiff::PltfClc2WDiff"].source)\'',
    ).stdout.strip()
    assert source == os.path.join(install, "share", "thorvald_base", "calculator_plugins.xml")


def test_base_bringup_launch(install):
    port = free_port()
    std = example(install, "thorvald_ii_4wd4ws_std")
    master = f"export ROS_MASTER_URI=http://localhost:{port}"
    script = (
        f"{master} && exec roslaunch -p {port} thorvald_base base_bringup.launch robot_model:={std} simple_sim:=true"
    )
    with InstallLaunch(install, script) as launch:
        frame = launch.wait_for(
            master, "rostopic echo -n 1 /odometry/base_raw/child_frame_id", lambda o: "base_link" in o
        )
        assert frame is not None, "no odometry from the installed base_driver"
        running = subprocess.run(["pgrep", "-af", "base_driver"], capture_output=True, text=True).stdout
        assert os.path.join(install, "lib", "thorvald_base", "base_driver") in running, running
    assert "base_driver: 4 drives" in launch.output, launch.output[-3000:]


def test_every_module_is_installed_and_imports(install):
    """Every module of the source tree, and the C module, is in the install space (a setup.py
    listing packages by hand once left thorvald_base.can out) and imports from there."""
    sources = []
    for pkg in sorted(os.listdir(os.path.join(WS, "src"))):
        top = os.path.join(WS, "src", pkg, "src")
        for folder, _, files in os.walk(top):
            for name in files:
                if name.endswith(".py"):
                    rel = os.path.relpath(os.path.join(folder, name), top)[: -len(".py")]
                    sources.append(rel.replace(os.sep, ".").replace(".__init__", ""))
    assert "thorvald_base.can.protocol" in sources and len(sources) > 60
    sources.append("thorvald_sim._scan")  # the C module (src/thorvald_sim/csrc/scan.c), built and installed by cmake
    script = (
        "import importlib, json, sys; out = {}\n"
        "for m in sys.argv[1:]:\n"
        "    try:\n"
        "        out[m] = importlib.import_module(m).__file__\n"
        "    except Exception as e:\n"
        "        out[m] = 'failed: %s: %s' % (type(e).__name__, e)\n"
        "print(json.dumps(out))\n"
    )
    proc = in_install(install, f"python -c {shlex.quote(script)} {' '.join(sorted(sources))}")
    found = json.loads(proc.stdout)
    elsewhere = {m: f for m, f in found.items() if not f.startswith(install + os.sep)}
    assert elsewhere == {}, elsewhere


def test_base_driver_drives_the_can_emulator_from_the_install_space(install, tmp_path):
    """The installed base_driver on the CAN base, over SLCAN to the installed device emulator: every
    motor controller of the standard robot comes online and odometry is published."""
    port = free_port()
    std = example(install, "thorvald_ii_4wd4ws_std")
    links = str(tmp_path / "can")
    master = f"export ROS_MASTER_URI=http://localhost:{port}"
    script = (
        # the emulator runs on its own (no master needed); base_driver restarts until its port exists
        f"{master} && (rosrun thorvald_sim can_emulator {std} --ports 1 --link-dir {links} &) && "
        f"exec roslaunch -p {port} thorvald_base base_bringup.launch robot_model:={std} simple_sim:=false "
        f"can_interface_type:=slcan can_interface_name:={links}/port0 respawn:=true respawn_delay:=1"
    )
    try:
        with InstallLaunch(install, script) as launch:
            online = launch.wait_for(
                master, "rostopic echo -n 1 /motor_controller_data", lambda o: o.count("controller_mode: 3") == 4
            )
            assert online, "the emulated motor controllers never came online for the installed base_driver"
            odom = in_install(install, f"{master} && timeout 15 rostopic echo -n 1 /odometry/base_raw/child_frame_id")
            assert "base_link" in odom.stdout
    finally:
        subprocess.run(["pkill", "-f", f"can_emulator {std} --ports 1 --link-dir {links}"], check=False)
    assert "base_driver: 4 drives" in launch.output, launch.output[-3000:]
