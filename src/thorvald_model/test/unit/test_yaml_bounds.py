"""Any YAML file is read within bounds (depth, size with aliases expanded) and refused with one
clean ConfigError past them; a value is turned to text for a message at a cost bounded by the text,
whatever it holds (a shared alias graph standing for 10^9 values included)."""

import os
import subprocess
import sys
import tempfile
import tracemalloc

import pytest
import yaml
from model_test_helpers import EXAMPLE_ROBOTS, four_drives

from thorvald_model import ConfigError, load_robot_config, parse_robot_config
from thorvald_model.datum import load_datum
from thorvald_model.errors import Problem, YamlBoundError
from thorvald_model.schema import (
    MAX_YAML_DEPTH,
    MAX_YAML_INT,
    MAX_YAML_NODES,
    BoundedCLoader,
    BoundedLoader,
    load_yaml,
    read_yaml_file,
    short,
)
from thorvald_model.value_text import VALUE_TEXT, value_text, value_text_whole

STD = EXAMPLE_ROBOTS[0]


def python_load(text):
    return yaml.load(text, Loader=BoundedLoader)


# load_yaml: libyaml's parser with the counting composer (PyYAML's alone without libyaml)
LOADERS = [pytest.param(load_yaml, id="load_yaml"), pytest.param(python_load, id="BoundedLoader")]


def nested(levels):
    """A document of that many levels: lists in lists, the innermost empty (a list is a level)."""
    return "[" * levels + "]" * levels


def bomb(levels=9, fan=10):
    """ "Billion laughs": level a holds fan scalars, each next level fan aliases of the one before,
    so level i stands for fan^i scalars; 9 levels of 10: 10^9 scalars in about 400 bytes."""
    names = "abcdefghijklmnopqrstuvwxyz"[:levels]
    lines = [f"  a: &a [{', '.join(['lol'] * fan)}]"]
    for prev, name in zip(names, names[1:]):
        lines.append(f"  {name}: &{name} [{', '.join(['*' + prev] * fan)}]")
    return "lol:\n" + "\n".join(lines) + "\n"


def shared_graph(levels=9, fan=10):
    """The bomb's value built in Python: one list of fan references at each level (10^9 leaves)."""
    value = [0] * fan
    for _ in range(levels - 1):
        value = [value] * fan
    return value


def refusal(path, what="robot configuration"):
    """The one line a file past a bound gets from read_yaml_file."""
    with pytest.raises(ConfigError) as info:
        read_yaml_file(str(path), what)
    text = str(info.value)
    assert "\n" not in text and text.startswith(f"{path}: refused at line "), text
    return text


# ---- depth -----------------------------------------------------------------------------------
@pytest.mark.parametrize("load", LOADERS)
def test_depth_at_the_bound_is_read_and_one_past_it_refused(load):
    assert load(nested(MAX_YAML_DEPTH)) is not None
    with pytest.raises(YamlBoundError, match=f"nested deeper than {MAX_YAML_DEPTH} levels"):
        load(nested(MAX_YAML_DEPTH + 1))
    # a scalar is a level too: 99 lists and the 0 in the innermost
    assert load(nested(MAX_YAML_DEPTH - 1).replace("[]", "[0]")) is not None
    with pytest.raises(YamlBoundError):
        load(nested(MAX_YAML_DEPTH).replace("[]", "[0]"))


@pytest.mark.parametrize("load", LOADERS)
def test_depth_counts_aliases_expanded(load):
    # x: 60 levels of lists. y: n lists around *x. The root mapping is level 1, y's lists levels 2
    # to n + 1, so x's copy starts at level n + 2 and ends at n + 61: 100 levels for n = 39
    deep = "[" * 60 + "]" * 60

    def doc(lists):
        return f"x: &x {deep}\ny: {'[' * lists}*x{']' * lists}\n"

    assert load(doc(39))["x"] == load(deep)
    with pytest.raises(YamlBoundError, match="nested deeper"):
        load(doc(40))


@pytest.mark.slow  # 5000 levels of YAML read to the limit
@pytest.mark.parametrize("load", LOADERS)
def test_5000_levels_are_refused_without_recursion_error(load):
    with pytest.raises(YamlBoundError):
        load(nested(5000))


def test_a_deep_file_gets_one_line_naming_the_file_and_the_rule(tmp_path):
    path = tmp_path / "deep.yaml"
    path.write_text("motor_drives: " + nested(5000) + "\n")
    text = refusal(path)
    # the list that opens level 101: the root mapping is level 1, its value's lists levels 2...
    # so the 100th "[" (column 14 + 100) opens level 101
    assert f"at line 1, column {14 + 100}:" in text
    assert f"nested deeper than {MAX_YAML_DEPTH} levels" in text


# ---- size with aliases expanded ----------------------------------------------------------------
@pytest.mark.slow  # reads files at the size bound
def test_size_at_the_bound_is_read_and_one_past_it_refused():
    load = load_yaml  # (BoundedLoader counts with the same code, 2.5 times slower: 2 x 2.4 s)
    # a list of n scalars is n + 1 values
    flat = "[" + ", ".join(["0"] * (MAX_YAML_NODES - 1)) + "]"
    assert len(load(flat)) == MAX_YAML_NODES - 1
    with pytest.raises(YamlBoundError, match=f"more than {MAX_YAML_NODES} values"):
        load("[" + ", ".join(["0"] * MAX_YAML_NODES) + "]")


@pytest.mark.parametrize("load", LOADERS)
def test_size_counts_aliases_expanded(load):
    # {a: A, b: [*a x k, 0 x p]} with A a list of 999 scalars (1000 values): the root 1, the keys
    # a and b 2, A 1000, b's list 1 + 1000 k + p; 4 + 1000 (k + 1) + p values
    k = 98
    p = MAX_YAML_NODES - 4 - 1000 * (k + 1)  # 996: exactly at the bound
    a = "[" + ", ".join(["1"] * 999) + "]"

    def doc(padding):
        return f"a: &a {a}\nb: [{', '.join(['*a'] * k + ['0'] * padding)}]\n"

    data = load(doc(p))
    assert len(data["b"]) == k + p and data["b"][0] is data["a"]  # aliases stay shared
    with pytest.raises(YamlBoundError, match="aliases expanded"):
        load(doc(p + 1))


@pytest.mark.parametrize("load", LOADERS)
def test_a_billion_laughs_is_refused_before_it_is_expanded_in_little_memory(load):
    text = bomb()
    tracemalloc.start()
    with pytest.raises(YamlBoundError) as info:
        load(text)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    # 10^9 values expanded would be gigabytes and minutes. Counted: level a holds 11 values (the
    # list and its 10 scalars), b 1 + 10 x 11 = 111, ... e 111111, past 10^5: refused at e, on
    # the 6th line (0-based 5), before f to i are even composed
    assert "more than 100000 values" in str(info.value)
    assert info.value.problem_mark.line == 5  # (how fast: bench/model.py, against loading a robot file)
    assert peak < 1_000_000, peak  # [bytes] measured: 15 kB (load_yaml), 24 kB (BoundedLoader)


def test_a_billion_laughs_costs_no_memory_of_the_process():
    """The peak resident memory of a process that reads the bomb (libyaml's allocations, which
    tracemalloc does not see, included) is that of one that reads a small file."""
    script = (
        "import resource, sys\n"
        "from thorvald_model.schema import read_yaml_file\n"
        "from thorvald_model import ConfigError\n"
        "try:\n    read_yaml_file(sys.argv[1])\nexcept ConfigError as e:\n    print(e, file=sys.stderr)\n"
        "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)\n"
    )

    def peak_kib(path):
        proc = subprocess.run([sys.executable, "-c", script, path], capture_output=True, text=True, timeout=60)
        assert proc.returncode == 0, proc.stderr
        return int(proc.stdout), proc.stderr

    with tempfile.TemporaryDirectory() as folder:
        path = os.path.join(folder, "bomb.yaml")
        with open(path, "w") as f:
            f.write(bomb())
        small, _ = peak_kib(STD)
        with_bomb, said = peak_kib(path)
    assert "refused at line 6" in said
    # [KiB] measured: 15752 for the small file, 15920 with the bomb (10^9 values built would be
    # gigabytes)
    assert with_bomb - small < 10_000, (small, with_bomb)


@pytest.mark.parametrize("load", LOADERS)
def test_an_alias_inside_the_node_it_names_is_refused(load):
    # PyYAML would build a list that holds itself, which every walk over it follows for ever
    with pytest.raises(YamlBoundError, match=r"the alias \*a is inside the node it names"):
        load("a: &a [1, *a]\n")


@pytest.mark.parametrize("load", LOADERS)
def test_the_bounds_leave_ordinary_documents_as_safe_load_reads_them(load):
    for path in EXAMPLE_ROBOTS:
        with open(path, "rb") as f:
            text = f.read()
        assert load(text) == yaml.safe_load(text)
    merged = "base: &b {x: 1, y: 2}\nthis: {<<: *b, y: 3}\n"
    assert load(merged) == yaml.safe_load(merged) == {"base": {"x": 1, "y": 2}, "this": {"x": 1, "y": 3}}


# ---- scalars PyYAML's constructors cannot convert: a YAML error at their place ----------------
@pytest.mark.parametrize(
    "text, says",
    [
        ("a: !!int x", "'x' is not a valid !!int value"),
        ("a: !!int ''", "'' is not a valid !!int value"),
        ("a: !!bool maybe", "'maybe' is not a valid !!bool value"),
        ("a: 2001-13-45", "'2001-13-45' is not a valid !!timestamp value (month must be in 1..12)"),
        ("a: !!timestamp x", "'x' is not a valid !!timestamp value"),
        (
            "a: " + "1" * (MAX_YAML_INT + 1),
            f"an integer of {MAX_YAML_INT + 1} characters: at most {MAX_YAML_INT} (as Python converts)",
        ),
    ],
)
def test_a_value_the_constructor_cannot_convert_is_not_valid_yaml(tmp_path, text, says):
    path = tmp_path / "robot.yaml"
    path.write_text(text + "\n")
    with pytest.raises(ConfigError) as info:
        read_yaml_file(str(path))
    assert str(info.value) == f"{path}: not valid YAML at line 1, column 4: {says}"


def test_an_integer_at_the_length_bound_is_read():
    assert load_yaml("a: " + "1" * MAX_YAML_INT)["a"] % 10 == 1


def test_a_number_past_every_float_is_a_problem_not_a_traceback(tmp_path):
    # 0x and 400 f's: 1600 bits, about 10^481, past the largest float (about 1.8e308)
    path = tmp_path / "robot.yaml"
    drives = yaml.safe_dump({"motor_drives": four_drives()})
    path.write_text(drives.replace("node: 1\n", "node: 1\n    r_wheel: 0x" + "f" * 400 + "\n", 1))
    with pytest.raises(ConfigError) as info:
        load_robot_config(str(path))
    (problem,) = info.value.problems
    assert problem.path == "motor_drives.drive0.r_wheel" and problem.rule == "must be a finite number"
    # 16^400 - 1 has 482 digits, shown as its first 197 and "..." (a value's text is at most 200)
    assert f"r_wheel: {str(16**400 - 1)[:197]}...: must be a finite number" in str(info.value)


# ---- the C parser and PyYAML's words ----------------------------------------------------------
@pytest.mark.skipif(BoundedCLoader is None, reason="PyYAML without libyaml")
def test_what_libyaml_refuses_is_worded_by_pyyaml(tmp_path):
    broken = tmp_path / "broken.yaml"
    broken.write_text("a: [1, 2\n")
    with pytest.raises(ConfigError) as info:
        read_yaml_file(str(broken))
    assert str(info.value).endswith("not valid YAML at line 2, column 1: expected ',' or ']', but got '<stream end>'")
    latin1 = tmp_path / "latin1.yaml"
    latin1.write_bytes("a: Ås\n".encode("latin-1"))
    with pytest.raises(ConfigError) as info:
        read_yaml_file(str(latin1))
    assert str(info.value).endswith("not a text file: byte 0xc5 at offset 3 is not UTF-8 (invalid continuation byte)")


def test_a_pipe_is_read_and_worded_as_a_file(tmp_path):
    read, write = os.pipe()
    os.write(write, "a: Ås\n".encode("latin-1"))
    os.close(write)
    with os.fdopen(read, "rb") as f:
        with pytest.raises(yaml.reader.ReaderError) as info:
            load_yaml(f)
    assert (info.value.character, info.value.position, info.value.encoding) == (0xC5, 3, "utf-8")


# ---- robot and datum files: their loaders give the clean error --------------------------------
def test_a_robot_file_with_a_bomb_under_an_unknown_key_is_refused(tmp_path):
    path = tmp_path / "robot.yaml"
    with open(STD) as f:
        path.write_text(f.read() + bomb())
    with pytest.raises(ConfigError) as info:
        load_robot_config(str(path))
    text = str(info.value)
    assert "\n" not in text and text.startswith(f"{path}: refused at line ") and "aliases expanded" in text


def test_a_datum_file_nested_too_deep_is_refused(tmp_path):
    path = tmp_path / "datum.yaml"
    path.write_text("datum: " + nested(MAX_YAML_DEPTH + 1) + "\n")
    with pytest.raises(ConfigError) as info:
        load_datum(str(path))
    assert str(info.value).startswith(f"{path}: refused at line 1, column ") and "nested deeper" in str(info.value)


# ---- a value as text: bounded, exact when it fits -------------------------------------------------
FITTING = [
    *(None, True, -3, 1.5, float("nan"), "it's", b"\x00x", 10**150),
    *([], (), (1,), {}, set(), frozenset(), {1}, frozenset({2}), [[[]]]),
    {"a": [1, 2.5, (3, "x")], 2: None, (1, 2): {"k": []}},
]


@pytest.mark.parametrize("value", FITTING)
def test_a_value_that_fits_is_shown_as_repr_shows_it(value):
    assert value_text_whole(value) == (repr(value), True)


def test_a_structure_that_holds_itself_is_shown_as_repr_shows_it():
    a = [1]
    a.append(a)
    d = {}
    d["d"] = d
    assert value_text(a) == repr(a) == "[1, [...]]" and value_text(d) == repr(d) == "{'d': {...}}"


def test_a_huge_shared_value_is_shown_cut_in_little_memory():
    value = shared_graph()  # 10^9 leaves, 81 list slots in memory
    tracemalloc.start()
    text, whole = value_text_whole(value)
    problem_text = Problem("lol", value, "some rule").format("robot.yaml")
    shortened = short(value)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    assert not whole and len(text) == VALUE_TEXT and text.startswith("[[[[[[[[[0, 0, 0") and text.endswith("...")
    assert problem_text == f"robot.yaml: lol: {text}: some rule"
    assert isinstance(shortened, str) and len(shortened) == 60 and shortened.endswith("...")
    assert peak < 200_000, peak  # [bytes]


def test_long_strings_bytes_and_integers_are_cut_before_they_are_converted():
    assert value_text("x" * 10**7, 20) == "'" + "x" * 16 + "..."
    assert value_text(b"y" * 10**7, 20) == "b'" + "y" * 15 + "..."
    # 10^100000: a decimal conversion quadratic in its length (and refused by Python 3.11)
    assert value_text(10**100000, 60) == "<an integer of about 100001 digits>..."
    deep = []
    for _ in range(100000):  # deeper than Python's recursion limit
        deep = [deep]
    assert value_text(deep, 30) == "[" * 27 + "..."


# ---- the configuration as a ROS parameter tree (base_driver's path): parse_robot_config --------
def test_a_parameter_tree_with_a_huge_shared_value_gets_bounded_messages():
    tree = {"base_calculator": "pltf_clc_std::PltfClcStd", "motor_drives": four_drives(), "lol": shared_graph()}
    config = parse_robot_config(tree, "/base_driver parameters")  # an unknown key of the user's: kept
    (warning,) = config.warnings
    line = warning.format(config.source)
    assert line.startswith("/base_driver parameters: lol: '[[[[[[[[[0, 0,") and len(line) < 300
    # the same value where a number must be: a problem, shown cut
    tree["motor_drives"]["drive0"]["r_wheel"] = shared_graph()
    with pytest.raises(ConfigError) as info:
        parse_robot_config(tree, "/base_driver parameters")
    assert "motor_drives.drive0.r_wheel: [[[[[[[[[0," in str(info.value) and len(str(info.value)) < 1000
    # a section that is not a mapping at all
    with pytest.raises(ConfigError) as info:
        parse_robot_config({"motor_drives": shared_graph()}, "/base_driver parameters")
    assert len(str(info.value)) < 1000
