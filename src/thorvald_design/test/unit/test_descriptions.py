"""A study's worker keeps a candidate's descriptions across its runs (thorvald_design.design.description_of)
while the robot file is unchanged, and makes them again once it changes."""

import os
import shutil

import pytest

from thorvald_design.design import description_of
from thorvald_model.description import generate_urdf

SRC = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", ".."))
STD = os.path.join(SRC, "thorvald_model", "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")


@pytest.mark.slow  # three descriptions generated (xacro: about 0.2 s each)
def test_a_description_is_kept_while_its_file_is_unchanged_and_made_again_after(tmp_path):
    path = str(tmp_path / "robot.yaml")
    shutil.copy(STD, path)
    first = description_of(path, tf_prefix="r/")
    assert first == generate_urdf(path, tf_prefix="r/")
    assert description_of(path, tf_prefix="r/") is first  # kept, not made again
    assert description_of(path, tf_prefix="") != first  # other arguments: another description
    with open(path, encoding="utf-8") as f:
        text = f.read()
    assert "r_wheel: 0.2" in text
    with open(path, "w", encoding="utf-8") as f:
        f.write(text.replace("r_wheel: 0.2", "r_wheel: 0.25", 1))
    changed = description_of(path, tf_prefix="r/")
    assert changed != first and changed == generate_urdf(path, tf_prefix="r/")


def test_an_unreadable_file_gives_generate_urdfs_own_error(tmp_path):
    missing = str(tmp_path / "missing.yaml")
    with pytest.raises(Exception) as kept:
        description_of(missing)
    with pytest.raises(Exception) as direct:
        generate_urdf(missing)
    assert type(kept.value) is type(direct.value) and str(kept.value) == str(direct.value)
