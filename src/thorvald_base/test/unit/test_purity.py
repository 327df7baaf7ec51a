"""The pure core imports no rospy, messages or pybullet (checked in a clean interpreter).

The rule covers every module of the workspace's Python packages, found by walking them, so a new
module is checked without being listed. The exceptions are the modules whose job is to talk to ROS
(nodes, message conversions, the message aliases) or physics (the simulator's pybullet modules);
each of them must really need it, so the list cannot grow stale.
"""

import json
import os
import subprocess
import sys

import pytest

from thorvald_testing.sources import imported_names

PACKAGES = ["thorvald_base", "thorvald_bringup", "thorvald_design", "thorvald_model", "thorvald_sim", "thorvald_teleop"]
# The modules whose job is ROS or physics, and why; everything else must be pure.
NOT_PURE = {
    "thorvald_base.base_driver_node": "a node",
    "thorvald_base.twist_mux_node": "a node",
    "thorvald_base.fleet_driver_node": "a node",
    "thorvald_base.state_publisher": "fleet_driver's /tf publisher",
    "thorvald_base.node_names": "where a node's names are (rospy's resolution)",
    "thorvald_base.verification_node": "a node",
    "thorvald_base.balance_node": "a node",
    "thorvald_model.place_robot": "a node",
    "thorvald_sim.node.simulator": "a node",
    "thorvald_sim.spawn.spawn_robot": "a node",
    "thorvald_sim.node.sensor_io": "the simulator node's sensor topics",
    "thorvald_sim.node.robot_io": "the simulator node's robot topics and tf",
    "thorvald_sim.node.services": "the simulator node's services",
    "thorvald_sim.node.fleet_topics": "the simulator node's fleet topics",
    "thorvald_sim.gazebo.api": "the simulator node's Gazebo API: services, topics, messages",
    "thorvald_sim.gazebo.bodies": "the Gazebo API in a world's bodies (pybullet)",
    "thorvald_teleop.joy_node": "a node",
    "thorvald_teleop.teleop_node": "a node",
    "thorvald_teleop.keyboard_node": "a node",
    "thorvald_base.conversions": "the one module that builds messages",
    "thorvald_base.publishing": "a rospy publisher for fast streams",
    "thorvald_base.msg": "aliases of thorvald_msgs for code written for the original",
    "thorvald_base.srv": "aliases of thorvald_msgs for code written for the original",
    "thorvald_bringup.report_bag": "reads a rosbag, whose messages are genpy's",
    "thorvald_bringup.record_node": "a node: record_drive, a bag recorder that drops nothing",
    "thorvald_base.calibration_cli": "calibrate_odometry reads a rosbag, whose messages are genpy's",
    "thorvald_sim.bullet": "pybullet itself, imported without its build-time line",
    "thorvald_sim.physics.scene": "the simulator's physics (pybullet)",
    "thorvald_sim.physics.robot": "the simulator's physics (pybullet)",
    "thorvald_sim.physics.simulation": "the simulator's physics (pybullet)",
    "thorvald_sim.physics.workers": "the simulator's physics in worker processes (pybullet, through Simulation)",
    "thorvald_sim.physics.engine": "the simulator's physics, in the node or a worker (pybullet, through Simulation)",
    "thorvald_sim.tools.runner": "drives a robot in the simulator without ROS (pybullet)",
    "thorvald_sim.tools.run_robot": "the runner's command line (pybullet)",
    "thorvald_design.lab": "drives a design study's candidate in the simulator (pybullet)",
}
# Modules that import ROS only when a function runs, on purpose; every other module (the base
# handles among them) imports none even inside a function.
CALL_TIME_ROS = {
    "thorvald_sim.can.emulator_node": "the emulator runs without ROS too; with a master it offers services",
    "thorvald_bringup.odometry_report_cli": "a command that reads the recorded bag (genpy) after the drive",
    "thorvald_bringup.calibration_drive_cli": "a command that calibrates from the recorded bag (genpy) after the drive",
    "thorvald_sim.sensors.kinds.model": "the sensor kinds' models call pybullet; their block readers never load it",
    "thorvald_sim.world.bodies": "the world kinds' scene builders call pybullet; their values and parsers do not",
    "thorvald_sim.models.build": "a model is built in pybullet; its readers and values never load it",
    "thorvald_design.runs": "a study's run (in a worker process) drives its candidate in the simulator",
}
FORBIDDEN = ["rospy", "genpy", "pybullet", "thorvald_msgs", "geometry_msgs", "nav_msgs", "sensor_msgs", "tf2_ros"]

# Imports the pure modules in a fresh interpreter and prints which forbidden top-level modules that
# pulled in: all of them in one interpreter (what they pulled in together is what any of them pulled
# in), each on its own only if that found something (to name it).
SCRIPT = """
import json, os, subprocess, sys
from concurrent.futures import ThreadPoolExecutor
pure, forbidden = {pure!r}, {forbidden!r}
probe = "import importlib, sys; [importlib.import_module(m) for m in sys.argv[1].split(',')]; " \\
        "print(','.join(sorted({{m.split('.')[0] for m in sys.modules}} & set(sys.argv[2].split(',')))))"
def probe_many(names):
    out = subprocess.run([sys.executable, "-c", probe, ",".join(names), ",".join(forbidden)],
                         capture_output=True, text=True)
    if out.returncode != 0:
        return "import failed: " + out.stderr.strip().splitlines()[-1]
    return out.stdout.strip()
together = probe_many(pure)
found = dict.fromkeys(pure, "")
if together:
    with ThreadPoolExecutor(os.cpu_count() or 2) as pool:  # each thread waits for its interpreter
        found.update(zip(pure, pool.map(lambda m: probe_many([m]), pure)))
print(json.dumps(found))
"""


def workspace_modules():
    """Every module of PACKAGES (found by walking them, so a new one is checked unlisted) and its file."""
    import importlib  # noqa: PLC0415
    import pkgutil  # noqa: PLC0415

    modules = {}
    for name in PACKAGES:
        pkg = importlib.import_module(name)
        modules[name] = pkg.__file__
        for info in pkgutil.walk_packages(pkg.__path__, name + "."):
            modules[info.name] = importlib.util.find_spec(info.name).origin
    return modules


def imported_forbidden(pure):
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p)
    out = subprocess.run(
        [sys.executable, "-c", SCRIPT.format(pure=sorted(pure), forbidden=FORBIDDEN)],
        capture_output=True,
        text=True,
        env=env,
        timeout=300,
    )
    assert out.returncode == 0, out.stderr
    return json.loads(out.stdout)


def forbidden_on_import(module, modules):
    """The forbidden top-level modules that importing ``module`` runs an import of, read from the
    sources: its own module-level imports (not those inside functions), its packages' __init__, and
    the same of every module of ours they import, however deep."""
    found, seen, todo = set(), set(), [module]
    while todo:
        name = todo.pop()
        parts = name.split(".")
        for owner in (".".join(parts[:i]) for i in range(1, len(parts) + 1)):  # a.b.c imports a and a.b
            if owner in seen or owner not in modules:
                continue
            seen.add(owner)
            path = modules[owner]
            if not path or not path.endswith(".py"):
                continue
            for imported in imported_names(path, owner, inside_functions=False):
                if imported.split(".")[0] in FORBIDDEN:
                    found.add(imported.split(".")[0])
                elif imported in modules:
                    todo.append(imported)
    return found


@pytest.mark.slow  # the pure modules imported together in a fresh interpreter: about 3 s
def test_every_module_but_the_ros_ones_imports_nothing_of_the_ros_runtime():
    modules = workspace_modules()
    # the walk really finds the core, new subpackages included
    for core in ("thorvald_base.core", "thorvald_base.bases.handle", "thorvald_base.kinematics.geometry"):
        assert core in modules, sorted(modules)
    # (a compiled extension of ours, thorvald_sim._scan, is C: it imports nothing and may not be built
    # beside the sources the interpreter finds first)
    found = imported_forbidden([m for m, path in modules.items() if m not in NOT_PURE and path.endswith(".py")])
    impure = {m: f for m, f in found.items() if f}
    assert impure == {}, "these modules import the ROS runtime (or fail to import): " + repr(impure)
    # each module listed as not pure imports the ROS runtime or pybullet when it is imported, so the
    # list cannot grow stale: read from the sources (importing each in an interpreter of its own took
    # 16 s of the suite)
    needless = sorted(m for m in NOT_PURE if m not in modules or not forbidden_on_import(m, modules))
    assert needless == [], f"listed as not pure but pure (or missing): {needless}"


def test_the_plugin_loader_searches_the_workspace():
    # rospkg is fine (it is not rospy): the loader finds the workspace's exports
    from thorvald_base.plugins import CalculatorLoader  # noqa: PLC0415

    assert "pltf_clc_std::PltfClcStd" in CalculatorLoader().known_names()


@pytest.mark.slow  # a fresh interpreter per core, importing every module
def test_no_pure_module_imports_the_ros_runtime_even_inside_a_function():
    """An import inside a function escapes the import-time check above: the source is read instead.
    Importing a module of NOT_PURE (e.g. conversions) counts as importing what it imports; the
    modules of CALL_TIME_ROS, and only they, do it on purpose."""
    offenders = {}
    checked = 0
    for module, path in workspace_modules().items():
        if module in NOT_PURE or not path or not path.endswith(".py"):
            continue
        checked += 1
        bad = sorted({n for n in imported_names(path, module) if n.split(".")[0] in FORBIDDEN or n in NOT_PURE})
        if bad:
            offenders[module] = bad
    assert checked > 40
    assert sorted(offenders) == sorted(CALL_TIME_ROS), {m: b for m, b in offenders.items() if m not in CALL_TIME_ROS}
    assert not any(m.startswith("thorvald_base.bases") for m in CALL_TIME_ROS)
