import glob
import os

import pytest

PKG = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
EXAMPLE_ROBOTS = sorted(glob.glob(os.path.join(PKG, "config", "*", "*.yaml")))
FIGURE5 = os.path.join(PKG, "test", "data", "paper_figure5.yaml")


def std_drive(node, x, y, **extra):
    d = {"node": node, "x": x, "y": y, "type": 0}
    d.update(extra)
    return d


def four_drives():
    """The paper's Figure 5 layout with the default module parameters."""
    return {
        "drive0": std_drive(1, -0.547, -0.30),
        "drive1": std_drive(2, 0.547, -0.30),
        "drive2": std_drive(3, -0.547, 0.30),
        "drive3": std_drive(4, 0.547, 0.30),
    }


@pytest.fixture
def robot():
    """A valid 4WD4WS robot as a plain dict, for tests to break one rule at a time."""
    return {"base_calculator": "pltf_clc_std::PltfClcStd", "motor_drives": four_drives()}
