"""Every command that reads a robot file answers a file it cannot read with one line and exit status 2.

Kinds: not UTF-8 text, a directory, a missing path, a file without read permission. Entry points:
check_config, kinematics, generate_urdf, the xacro wrapper and the main job (tools/demo), each run
as a user runs it. base_driver's answer (its non-zero status, a fatal log, no traceback) is checked
by the rostest thorvald_base/test/rostest/bad_config.test on a master of its own.

root reads files without read permission, so as root the commands run with the two capabilities
that let root pass file permissions dropped (setpriv, util-linux), the way a normal user runs them.
"""

import os
import shutil
import subprocess

import pytest

pytestmark = pytest.mark.slow  # a process per case: the commands as a user types them

WS = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
XACRO = os.path.join(WS, "src", "thorvald_model", "urdf", "thorvald_model.xacro")
STANDARD = os.path.join(WS, "src", "thorvald_model", "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")

ENTRY_POINTS = {
    "check_config": lambda path: ["rosrun", "thorvald_model", "check_config", path],
    "kinematics": lambda path: ["rosrun", "thorvald_base", "kinematics", path, "--twist", "0.5", "0", "0"],
    "generate_urdf": lambda path: ["rosrun", "thorvald_model", "generate_urdf", path],
    "xacro": lambda path: ["rosrun", "thorvald_model", "xacro", XACRO, "robot_config:=" + path],
    "demo": lambda path: [os.path.join(WS, "tools", "demo"), path],
}
# what the line says for each kind
REASONS = {
    "not_utf8": "not a text file: byte 0xc5 at offset",
    "directory": "cannot read the robot configuration: Is a directory",
    "missing": "cannot read the robot configuration: No such file or directory",
    "no_permission": "cannot read the robot configuration: Permission denied",
}


def without_file_override():
    """A command prefix under which root, too, is refused files it has no permission to read."""
    if os.geteuid() != 0:
        return []
    setpriv = shutil.which("setpriv")
    assert setpriv, "setpriv (util-linux) is needed to check unreadable files as root"
    caps = "-dac_override,-dac_read_search"
    return [setpriv, "--inh-caps=" + caps, "--bounding-set=" + caps]


def make(kind, folder):
    path = os.path.join(folder, "robot.yaml")
    if kind == "not_utf8":
        with open(STANDARD, encoding="utf-8") as f:
            text = f.read()
        with open(path, "wb") as f:  # the file of a Latin-1 editor: "Å" is one byte, 0xc5
            f.write(("# Ås, Norway\n" + text).encode("latin-1"))
    elif kind == "directory":
        os.mkdir(path)
    elif kind == "no_permission":
        shutil.copy(STANDARD, path)
        os.chmod(path, 0)
    return path


@pytest.mark.parametrize("kind", sorted(REASONS))
@pytest.mark.parametrize("entry_point", sorted(ENTRY_POINTS))
def test_one_line_naming_the_file_and_the_reason_and_exit_status_2(tmp_path, entry_point, kind):
    path = make(kind, str(tmp_path))
    proc = subprocess.run(
        without_file_override() + ENTRY_POINTS[entry_point](path),
        cwd=str(tmp_path),
        capture_output=True,
        text=True,
        timeout=120,
    )
    lines = [line for line in proc.stderr.splitlines() if line.strip()]
    assert proc.returncode == 2, proc.stdout + proc.stderr
    assert len(lines) == 1, proc.stderr
    assert path in lines[0] and REASONS[kind] in lines[0], lines[0]
    assert proc.stdout == "", proc.stdout


def test_the_main_job_takes_a_relative_path_from_where_it_was_typed(tmp_path):
    (tmp_path / "mine.yaml").mkdir()
    proc = subprocess.run(
        [os.path.join(WS, "tools", "demo"), "mine.yaml"], cwd=str(tmp_path), capture_output=True, text=True, timeout=60
    )
    assert proc.returncode == 2
    assert proc.stderr.strip() == f"{tmp_path / 'mine.yaml'}: cannot read the robot configuration: Is a directory"
