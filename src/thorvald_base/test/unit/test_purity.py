"""The pure core (kinematics, twist_mux logic, configuration loader) imports no rospy, messages or
pybullet (checked in a clean interpreter)."""

import os
import subprocess
import sys

CORE = [
    "thorvald_base.errors",
    "thorvald_base.plugins",
    "thorvald_base.kinematics_cli",
    "thorvald_base.kinematics",
    "thorvald_base.kinematics.types",
    "thorvald_base.kinematics.geometry",
    "thorvald_base.kinematics.calculator",
    "thorvald_base.kinematics.odometry",
    "thorvald_base.kinematics.drive",
    "thorvald_base.kinematics.std",
    "thorvald_base.kinematics.diff",
    "thorvald_base.kinematics.one_wheel",
    "thorvald_base.mux",
    "thorvald_model.config",
    "thorvald_model.layout",
    "thorvald_model.check_config",
]
FORBIDDEN = ["rospy", "genpy", "pybullet", "thorvald_msgs", "geometry_msgs", "nav_msgs", "sensor_msgs"]

SCRIPT = """
import importlib, pkgutil, sys
import thorvald_base.kinematics as k
mods = {core!r} + [k.__name__ + "." + m.name for m in pkgutil.iter_modules(k.__path__)]
for m in mods:
    importlib.import_module(m)
# The loader really searches the workspace (rospkg is fine: it is not rospy).
from thorvald_base.plugins import CalculatorLoader
assert "pltf_clc_std::PltfClcStd" in CalculatorLoader().known_names()
bad = sorted(m for m in sys.modules if m.split(".")[0] in {forbidden!r})
print(",".join(bad))
"""


def test_core_imports_nothing_of_ros_runtime():
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join(p for p in sys.path if p)
    out = subprocess.run(
        [sys.executable, "-c", SCRIPT.format(core=CORE, forbidden=set(FORBIDDEN))],
        capture_output=True,
        text=True,
        env=env,
        timeout=60,
    )
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == ""
