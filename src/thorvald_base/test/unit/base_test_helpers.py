"""Robots for the kinematics tests: every example robot file, plus small inline ones."""

import glob
import math
import os

import pytest

from thorvald_model import load_robot_config, parse_robot_config

HERE = os.path.dirname(os.path.abspath(__file__))
WORKSPACE_SRC = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
EXAMPLE_ROBOTS = sorted(glob.glob(os.path.join(WORKSPACE_SRC, "thorvald_model", "config", "*", "*.yaml")))


def drive(node, x, y, type_=0, **extra):
    d = {"node": node, "x": x, "y": y, "type": type_}
    d.update(extra)
    return d


def four_ws(x=0.549, y=0.449, **extra):
    """The 4WD4WS layout of the original files: drive0 rear right, 1 front right, 2 front left, 3 rear left."""
    return parse_robot_config(
        {
            "motor_drives": {
                "drive0": drive(1, -x, -y, **extra),
                "drive1": drive(2, x, -y, **extra),
                "drive2": drive(3, x, y, **extra),
                "drive3": drive(4, -x, y, **extra),
            }
        },
        "inline-4wd4ws",
    )


def four_wd_two_ws():
    """Figure 10 (b): two steered drives in front, two type-1 drives on the rear axle x = -0.5."""
    return parse_robot_config(
        {
            "motor_drives": {
                "drive0": drive(1, 0.5, -0.4),
                "drive1": drive(2, 0.5, 0.4),
                "drive2": drive(3, -0.5, -0.4, 1),
                "drive3": drive(3, -0.5, 0.4, 1),
            }
        },
        "inline-4wd2ws",
    )


def diff(x=0.0, b=0.3):
    return parse_robot_config(
        {
            "base_calculator": "pltf_clc_2wdiff::PltfClc2WDiff",
            "motor_drives": {"drive0": drive(1, x, -b, 1), "drive1": drive(1, x, b, 1)},
            "passive_wheels": {"passive0": {"type": "caster", "x": -0.5, "y": 0.0}},
        },
        "inline-2wd-diff",
    )


def one_wheel(length=0.8, b=0.4):
    """A tricycle: one steered drive at (length, 0), fixed wheels at (0, +-b) rolling along x."""
    return parse_robot_config(
        {
            "base_calculator": "pltf_clc_1wd::PltfClc1WD",
            "motor_drives": {"drive0": drive(1, length, 0.0)},
            "passive_wheels": {
                "passive0": {"type": "fixed", "x": 0.0, "y": b},
                "passive1": {"type": "fixed", "x": 0.0, "y": -b},
            },
        },
        "inline-1wd",
    )


def ring(n, radius=1.5):
    """n steered drives on a circle (asymmetric by a small offset), for 6 and 9 drive cases."""
    drives = {}
    for k in range(n):
        a = 2 * math.pi * k / n
        drives[f"drive{k}"] = drive(k + 1, radius * math.cos(a) + 0.1, radius * math.sin(a))
    return parse_robot_config({"motor_drives": drives}, f"inline-{n}wd{n}ws")


INLINE_ROBOTS = {
    "inline-4wd4ws": four_ws,
    "inline-4wd2ws": four_wd_two_ws,
    "inline-2wd-diff": diff,
    "inline-1wd": one_wheel,
    "inline-6wd6ws": lambda: ring(6),
    "inline-9wd9ws": lambda: ring(9),
}

ROBOT_IDS = [os.path.basename(p) for p in EXAMPLE_ROBOTS] + list(INLINE_ROBOTS)


def robot_config(robot_id):
    if robot_id in INLINE_ROBOTS:
        return INLINE_ROBOTS[robot_id]()
    return load_robot_config(EXAMPLE_ROBOTS[[os.path.basename(p) for p in EXAMPLE_ROBOTS].index(robot_id)])


@pytest.fixture(params=ROBOT_IDS)
def any_robot(request):
    return robot_config(request.param)


def constraint_rows(config):
    """(a_vx, a_vy, a_wz) with a . twist = 0 for each wheel that cannot steer.

    The wheel's lateral direction n = (-sin yaw, cos yaw) (yaw 0 for type-1 drives); its contact
    velocity (vx - wz y, vy + wz x) must have no component along n.
    """
    rows = []
    wheels = [(d.x, d.y, 0.0) for d in config.drives if d.type == 1]
    wheels += [(w.x, w.y, w.yaw) for w in config.passive_wheels if w.type == "fixed"]
    for x, y, yaw in wheels:
        nx, ny = -math.sin(yaw), math.cos(yaw)
        rows.append((nx, ny, x * ny - y * nx))
    return rows


def make_realisable(config, vx, vy, wz):
    """A realisable twist from free components: all non-steering wheels share one axle (the loader's
    rule), so one constraint; solve it for vy, or for vx when the axle lies across y."""
    rows = constraint_rows(config)
    if not rows:
        return vx, vy, wz
    a0, a1, a2 = rows[0]
    if abs(a1) >= abs(a0):
        vy = -(a0 * vx + a2 * wz) / a1
    else:
        vx = -(a1 * vy + a2 * wz) / a0
    return vx, vy, wz
