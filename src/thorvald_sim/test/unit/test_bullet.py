"""pybullet imported through thorvald_sim.bullet prints nothing: its build-time line is not ours to
print before every tool's output."""

import subprocess
import sys

import pytest


@pytest.mark.slow  # a fresh interpreter, the only place pybullet is imported for the first time
def test_importing_pybullet_prints_nothing():
    code = "from thorvald_sim.bullet import pybullet; pybullet.connect(pybullet.DIRECT); print('done')"
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout == "done\n" and proc.stderr == ""
    plain = subprocess.run([sys.executable, "-c", "import pybullet"], capture_output=True, text=True, timeout=60)
    assert "build time" in plain.stderr  # what it quiets: pybullet's own line, there without it
