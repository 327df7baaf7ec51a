"""The world file's keys are documented once: the table rendered from the registry of element
kinds (:func:`thorvald_sim.world.keys_table.keys_markdown`), which docs/worlds.md holds between its
``world-keys`` marker lines (``python -m thorvald_sim.world --update docs/worlds.md`` writes it)."""

import os

import pytest

from thorvald_sim.world import BUILT_IN, top_level_keys
from thorvald_sim.world.__main__ import main
from thorvald_sim.world.ground import GROUND_KEYS
from thorvald_sim.world.keys_table import KEYS_BEGIN, KEYS_END, keys_markdown, with_keys_table
from thorvald_sim.world.loader import GRAVITY_KEY

WORLDS_MD = os.path.join(os.path.dirname(os.path.abspath(__file__)), *[".."] * 4, "docs", "worlds.md")


def rows():
    """The table's rows as (section, entries, [key cells])."""
    lines = keys_markdown().splitlines()
    assert lines[:2] == ["| section | entries | keys (default): rule |", "| --- | --- | --- |"]
    cells = [line.split(" | ") for line in lines[2:]]
    assert all(len(c) == 3 and c[0].startswith("| `") and c[2].endswith(" |") for c in cells)
    return [(c[0][3:-1], c[1], c[2][:-2].split("<br>")) for c in cells]


def test_one_row_a_top_level_key_in_the_files_order():
    assert [section for section, _, _ in rows()] == list(top_level_keys())


def test_every_key_of_every_section_with_its_default_and_rule():
    table = {section: (entries, cells) for section, entries, cells in rows()}
    for kind in BUILT_IN:
        entries, cells = table[kind.section]
        assert entries.startswith("one mapping" if kind.single else f"`{kind.prefix}0`, `{kind.prefix}1`, ...")
        assert [cell.split("`")[1] for cell in cells] == [key.name for key in kind.keys], kind.section
    assert [cell.split("`")[1] for cell in table["ground"][1]] == [key.name for key in GROUND_KEYS]
    assert table["gravity"][1] == [f"`gravity` ({GRAVITY_KEY.default}): must be > 0"]
    rows_cells = {cell.split("`")[1]: cell for cell in table["rows"][1]}
    assert rows_cells["gap_probability"] == "`gap_probability` (0, alias `gaps`): must be in [0, 1]"
    assert rows_cells["length"] == "`length` (required): must be in (0, 10000] [m]"
    assert rows_cells["plant"] == "`plant` (`cylinder`): must be one of cylinder, sphere"
    assert rows_cells["rgba"].startswith("`rgba` (leaf green [0.25, 0.55, 0.2, 1]): must be a list of 3 or 4 numbers")
    objects = {cell.split("`")[1]: cell for cell in table["objects"][1]}
    assert objects["size_x"] == "`size_x` (required for a box): must be in (0, 10000] [m]"


def test_the_table_goes_between_the_marker_lines():
    text = f"# Worlds\n\n{KEYS_BEGIN}\nan old table\n{KEYS_END}\n\nmore\n"
    assert with_keys_table(text, "| new |\n") == f"# Worlds\n\n{KEYS_BEGIN}\n| new |\n{KEYS_END}\n\nmore\n"
    for broken in ("no markers\n", f"{KEYS_END}\n{KEYS_BEGIN}\n", f"{KEYS_BEGIN}\n{KEYS_BEGIN}\n{KEYS_END}\n"):
        with pytest.raises(ValueError, match="once each and in that order"):
            with_keys_table(broken, "| new |\n")


def test_update_writes_the_table_into_a_file(tmp_path, capsys):
    path = tmp_path / "worlds.md"
    path.write_text(f"text\n{KEYS_BEGIN}\n{KEYS_END}\n")
    assert main(["--update", str(path)]) == 0
    assert path.read_text() == f"text\n{KEYS_BEGIN}\n{keys_markdown()}{KEYS_END}\n"
    assert main([]) == 0
    assert capsys.readouterr().out == keys_markdown()
    path.write_text("no markers\n")
    assert main(["--update", str(path)]) == 2
    assert capsys.readouterr().err.startswith(f"{path}: needs the lines ")


def test_docs_worlds_md_holds_exactly_the_table():
    with open(WORLDS_MD) as f:
        text = f.read()
    assert with_keys_table(text, keys_markdown()) == text, (
        "docs/worlds.md's keys table is not the registry's: python -m thorvald_sim.world --update docs/worlds.md"
    )
