"""Screenshots of robots in RViz on a virtual X display (Xvfb, software GL).

Used by ``scripts/render_robots`` (the pictures of README, our paper's Figure 10) and by the test
that checks RViz shows a generated robot. Every process started here is started in a session of
its own and stopped with its whole process group, so nothing outlives the ``with`` block.
Not part of the pure core: it runs Xvfb and roslaunch, but imports neither rospy nor messages.
"""

import contextlib
import copy
import os
import signal
import subprocess
import tempfile
import time
from dataclasses import dataclass
from typing import Dict, Iterator, List, Optional, Tuple

import numpy as np
import yaml
from PIL import Image, ImageGrab

from .config import RobotConfig
from .description import package_file
from .ports import free_port

BACKGROUND = (48, 48, 48)  # model.rviz's background colour


@dataclass(frozen=True)
class View:
    """An RViz orbit view: focal point [m], distance [m], pitch and yaw [rad]."""

    x: float
    y: float
    z: float
    distance: float
    pitch: float = 0.5
    yaw: float = 0.8


def robot_view(config: RobotConfig) -> View:
    """A three-quarter view from the front left that frames the whole robot."""
    points: List[Tuple[float, float, float]] = [(x, y, 0.0) for x, y in config.wheel_contacts()]
    points += [(d.x, d.y, 0.9 if d.tower else 0.6) for d in config.drives]
    points += [(c.x, c.y, c.z + c.space / 2) for c in config.corners]
    points += [(p.x1, p.y1, p.height) for p in config.pipes] + [(p.x2, p.y2, p.height) for p in config.pipes]
    for part in config.frame_parts:
        half = max(part.size_x, part.size_y, part.size_z, part.radius, part.length / 2) / 2
        points.append((part.x, part.y, part.z + half))
    xs, ys, zs = zip(*points)
    size = max(max(xs) - min(xs) + 0.5, max(ys) - min(ys) + 0.5, *zs)
    top = max(zs)
    return View(x=(max(xs) + min(xs)) / 2, y=(max(ys) + min(ys)) / 2, z=top * 0.4, distance=1.25 * size + 0.8)


def write_rviz_config(path: str, view: View, width: int, height: int, fixed_frame: str = "base_link") -> None:
    """model.rviz turned into a bare render window of width x height showing view."""
    with open(package_file("rviz", "model.rviz")) as f:
        cfg = yaml.safe_load(f)
    cfg = copy.deepcopy(cfg)
    cfg["Panels"] = []
    manager = cfg["Visualization Manager"]
    manager["Global Options"]["Fixed Frame"] = fixed_frame
    current = manager["Views"]["Current"]
    current["Distance"] = round(view.distance, 3)
    current["Focal Point"] = {"X": round(view.x, 3), "Y": round(view.y, 3), "Z": round(view.z, 3)}
    current["Pitch"] = view.pitch
    current["Yaw"] = view.yaw
    cfg["Window Geometry"] = {
        "Height": height,
        "Width": width,
        "Hide Left Dock": True,
        "Hide Right Dock": True,
        "X": 0,
        "Y": 0,
    }
    with open(path, "w") as f:
        yaml.safe_dump(cfg, f, default_flow_style=False)


def free_display() -> int:
    for n in range(140, 400):
        if not os.path.exists(f"/tmp/.X{n}-lock") and not os.path.exists(f"/tmp/.X11-unix/X{n}"):
            return n
    raise RuntimeError("no free X display number")


def _stop(proc: subprocess.Popen, timeout: float = 10.0) -> None:
    """SIGINT (roslaunch shuts its nodes down), then SIGKILL, to the process group of proc."""
    if proc.poll() is not None:
        return
    for sig, wait in ((signal.SIGINT, timeout), (signal.SIGTERM, 3.0), (signal.SIGKILL, 3.0)):
        with contextlib.suppress(ProcessLookupError):
            os.killpg(proc.pid, sig)
        try:
            proc.wait(wait)
            return
        except subprocess.TimeoutExpired:
            continue


@contextlib.contextmanager
def xvfb(width: int, height: int) -> Iterator[str]:
    """A virtual X display of width x height; yields its name, e.g. ':140'."""
    n = free_display()
    proc = subprocess.Popen(
        # -noreset: by default Xvfb resets when its last client leaves, and refuses connections
        # meanwhile, so an RViz started right after another one failed to open the display.
        ["Xvfb", f":{n}", "-screen", "0", f"{width}x{height}x24", "-nolisten", "tcp", "-noreset"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
        start_new_session=True,
    )
    try:
        deadline = time.monotonic() + 10
        while not os.path.exists(f"/tmp/.X11-unix/X{n}"):
            if proc.poll() is not None or time.monotonic() > deadline:
                raise RuntimeError(f"Xvfb :{n} did not start")
            time.sleep(0.1)
        yield f":{n}"
    finally:
        _stop(proc, 5.0)


@contextlib.contextmanager
def roslaunch(args: List[str], display: str, log_dir: str, port: Optional[int] = None) -> Iterator[Dict[str, str]]:
    """``roslaunch ARGS`` with a master of its own on a free port, drawing on display."""
    port = port or free_port()
    env = dict(os.environ)
    env.update(
        DISPLAY=display,
        LIBGL_ALWAYS_SOFTWARE="1",
        ROS_MASTER_URI=f"http://localhost:{port}",
        ROS_LOG_DIR=log_dir,
        ROS_HOME=log_dir,
    )
    with open(os.path.join(log_dir, "roslaunch.out"), "w") as out:
        proc = subprocess.Popen(
            ["roslaunch", "-p", str(port), *args], env=env, stdout=out, stderr=subprocess.STDOUT, start_new_session=True
        )
    try:
        yield env
    finally:
        _stop(proc)


def grab(display: str):
    """A screenshot of the whole display (PIL image)."""
    return ImageGrab.grab(xdisplay=display).convert("RGB")


def differing_pixels(a, b, threshold: int = 40) -> int:
    """Pixels whose colour differs by more than threshold (sum over RGB) between two screenshots."""
    diff = np.abs(np.asarray(a, dtype=np.int16) - np.asarray(b, dtype=np.int16)).sum(axis=2)
    return int((diff > threshold).sum())


def wait_for_render(display: str, timeout: float, settle: float = 1.5, min_changed: int = 1):
    """The screenshot once RViz has drawn something besides its background and it stopped changing.

    Returns the last screenshot even on timeout: the caller judges it.
    """
    deadline = time.monotonic() + timeout
    last = None
    stable_since = None
    while True:
        time.sleep(0.5)
        shot = grab(display)
        background = Image.new("RGB", shot.size, BACKGROUND)
        # RViz is up once a fifth of the screen is its background; the scene once more is drawn.
        same = shot.size[0] * shot.size[1] - differing_pixels(shot, background, threshold=20)
        drawn = same > shot.size[0] * shot.size[1] // 5 and differing_pixels(shot, background) >= min_changed
        if last is not None and drawn and differing_pixels(shot, last, threshold=10) == 0:
            stable_since = stable_since or time.monotonic()
            if time.monotonic() - stable_since >= settle:
                return shot
        else:
            stable_since = None
        last = shot
        if time.monotonic() > deadline:
            return shot


def crop_to_scene(image):
    """The RViz render area: the rows and columns that are mostly background, without menu,
    tool bar, dock handles and status bar."""
    width, height = image.size
    px = image.load()
    step = 4
    rows = [y for y in range(height) if step * sum(_near(px[x, y]) for x in range(0, width, step)) > width // 3]
    cols = [x for x in range(width) if step * sum(_near(px[x, y]) for y in range(0, height, step)) > height // 3]
    if not rows or not cols:
        return image
    return image.crop((cols[0], rows[0], cols[-1] + 1, rows[-1] + 1))


def _near(a, b=BACKGROUND, tol: int = 12) -> bool:
    return all(abs(int(u) - int(v)) <= tol for u, v in zip(a, b))


@contextlib.contextmanager
def rviz_session(
    robot_model: str, width: int, height: int, view: View, extra_args: Optional[List[str]] = None
) -> Iterator[str]:
    """display.launch for one robot in RViz on a fresh Xvfb; yields the display name."""
    with tempfile.TemporaryDirectory(prefix="thorvald_rviz_") as tmp:
        rviz_cfg = os.path.join(tmp, "view.rviz")
        write_rviz_config(rviz_cfg, view, width, height)
        args = [
            "thorvald_model",
            "display.launch",
            f"robot_model:={robot_model}",
            f"rviz_config:={rviz_cfg}",
            *(extra_args or []),
        ]
        with xvfb(width, height) as display, roslaunch(args, display, tmp):
            yield display
