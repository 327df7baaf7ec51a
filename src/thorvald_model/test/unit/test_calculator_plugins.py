"""The calculator plugins as the configuration level loads them (thorvald_model.plugins): check_config
refuses every file base_driver refuses, a calculator that cannot be loaded is a problem of the file,
and no module of this package imports the packages above it (thorvald_base among them)."""

import importlib
import json
import os
import subprocess
import sys
import textwrap

import pytest
import rospkg
import yaml
from model_test_helpers import PKG, four_drives, std_drive

from thorvald_model import ConfigError, parse_robot_config
from thorvald_model.check_config import main
from thorvald_model.errors import PluginImportError, PluginNotFoundError, PluginTypeError
from thorvald_model.plugins import CALCULATORS, PluginLoader, calculator_loader, calculator_problems
from thorvald_testing.packages import plugin_package
from thorvald_testing.sources import imported_names

WORKSPACE_SRC = os.path.dirname(PKG)
# The workspace's packages above thorvald_model: each depends on it, so none may be imported by it.
ABOVE = ("thorvald_base", "thorvald_bringup", "thorvald_sim", "thorvald_teleop", "thorvald_testing")


def one_steered_on_casters():
    robot = {"base_calculator": "pltf_clc_std::PltfClcStd", "motor_drives": {"drive0": std_drive(1, 0.5, 0.0)}}
    robot["passive_wheels"] = {"passive0": {"type": "caster", "x": -0.5, "y": 0.3}}
    return robot


def diff_with_a_steered_drive():
    return {
        "base_calculator": "pltf_clc_2wdiff::PltfClc2WDiff",
        "motor_drives": {
            "drive0": std_drive(1, 0.0, -0.3, type=1),  # a type-1 pair shares one controller node
            "drive1": std_drive(1, 0.0, 0.3, type=1),
            "drive2": std_drive(2, 0.6, 0.0),
        },
        "passive_wheels": {"passive0": {"type": "caster", "x": -0.6, "y": 0.0}},
    }


def one_wheel_on_the_axle():
    return {
        "base_calculator": "pltf_clc_1wd::PltfClc1WD",
        "motor_drives": {"drive0": std_drive(1, -0.4, 0.0)},
        "passive_wheels": {
            "passive0": {"type": "fixed", "x": -0.4, "y": 0.35},
            "passive1": {"type": "fixed", "x": -0.4, "y": -0.35},
        },
    }


def one_wheel_on_four():
    return {"base_calculator": "pltf_clc_1wd::PltfClc1WD", "motor_drives": four_drives()}


# Each layout breaks no rule every calculator shares (the loader takes it) and one rule of its own
# calculator: (robot, key path, words of the rule).
REFUSED = {
    "std, one steered drive on casters": (
        one_steered_on_casters,
        "base_calculator",
        ["a single steered drive on casters", "'pltf_clc_1wd::PltfClc1WD'"],
    ),
    "differential, a steered drive beside the pair": (
        diff_with_a_steered_drive,
        "base_calculator",
        ["serves exactly two type-1 drives; this robot has 3 drives, 2 of type 1"],
    ),
    "one-wheel, four steered drives": (one_wheel_on_four, "base_calculator", ["exactly one type-0 (steered) drive"]),
    "one-wheel, the drive on the fixed wheels' axle": (one_wheel_on_the_axle, "motor_drives.drive0", ["axle line"]),
}


def write(tmp_path, robot, name="robot.yaml"):
    path = tmp_path / name
    path.write_text(yaml.safe_dump(robot))
    return str(path)


@pytest.mark.parametrize("case", sorted(REFUSED))
def test_check_config_refuses_what_the_calculator_refuses(case, tmp_path, capsys):
    make, key, words = REFUSED[case]
    path = write(tmp_path, make())
    assert main([path]) == 2
    err = capsys.readouterr().err
    line = next(line for line in err.splitlines() if f"{path}: {key}: " in line)
    for word in words:
        assert word in line, (word, err)
    # base_driver loads the calculator the same way and refuses the file with the same problems
    from thorvald_base.plugins import load_calculator  # noqa: PLC0415  (the test, not the package, uses it)

    config = parse_robot_config(make(), path)
    with pytest.raises(ConfigError) as refused:
        load_calculator(config)
    assert refused.value.problems == tuple(calculator_problems(config))
    assert str(refused.value) in err


def test_a_layout_the_calculator_serves_passes(tmp_path, capsys):
    robot = one_wheel_on_the_axle()
    robot["motor_drives"]["drive0"]["x"] = 0.6  # ahead of the fixed wheels' axle (x = -0.4)
    assert main([write(tmp_path, robot)]) == 0
    assert "calculator  pltf_clc_1wd::PltfClc1WD" in capsys.readouterr().out


def refusal(tmp_path, capsys, calculator):
    """check_config's one problem line for a robot naming this calculator (exit status 2)."""
    robot = {"base_calculator": calculator, "motor_drives": four_drives()}
    path = write(tmp_path, robot)
    assert main([path]) == 2
    err = capsys.readouterr().err
    (line,) = [line.strip() for line in err.splitlines() if f"{path}: base_calculator: " in line]
    assert err.startswith(f"{path}: invalid robot configuration (1 problem):"), err
    assert "Traceback" not in err
    return line[len(f"{path}: base_calculator: ") :]


def test_an_unknown_calculator_is_refused_with_the_known_ones(tmp_path, capsys):
    line = refusal(tmp_path, capsys, "pltf_clc_foo::PltfClcFoo")
    assert line == (
        "'pltf_clc_foo::PltfClcFoo': must name a calculator plugin: known calculators are pltf_clc_1wd::PltfClc1WD, "
        "pltf_clc_2wdiff::PltfClc2WDiff, pltf_clc_std::PltfClcStd (or give a 'python.module:Class')"
    )


def test_a_module_that_cannot_be_imported_is_refused(tmp_path, capsys, monkeypatch):
    line = refusal(tmp_path, capsys, "no_such_module_xyz:Calc")
    module = "no_such_module_xyz"
    assert line == f"'{module}:Calc': cannot import module '{module}': No module named '{module}'"
    line = refusal(tmp_path, capsys, "thorvald_base.kinematics.std:NoSuchCalc")
    assert line.endswith(": module 'thorvald_base.kinematics.std' has no class 'NoSuchCalc'")
    line = refusal(tmp_path, capsys, "collections:OrderedDict")
    assert line.endswith(": collections.OrderedDict is not a subclass of thorvald_base.kinematics.BaseCalculator")
    # a module that fails as it is imported: the error it raised is the reason
    lib = tmp_path / "lib"
    lib.mkdir()
    (lib / "broken_calc_module.py").write_text("raise RuntimeError('needs a licence file')\n")
    monkeypatch.syspath_prepend(str(lib))
    line = refusal(tmp_path, capsys, "broken_calc_module:Calc")
    assert line.endswith(": cannot import module 'broken_calc_module': RuntimeError: needs a licence file")


def test_the_errors_carry_the_rule_and_name_the_calculator():
    loader = calculator_loader()
    with pytest.raises(PluginNotFoundError) as e:
        loader.class_for("nowhere::Nothing")
    assert str(e.value).startswith("unknown base_calculator 'nowhere::Nothing': known calculators are ")
    assert e.value.known == ("pltf_clc_1wd::PltfClc1WD", "pltf_clc_2wdiff::PltfClc2WDiff", "pltf_clc_std::PltfClcStd")
    with pytest.raises(PluginImportError) as e:
        loader.class_for("no_such_module_xyz:Calc")
    assert str(e.value) == "calculator 'no_such_module_xyz:Calc': " + e.value.rule
    with pytest.raises(PluginTypeError):
        loader.class_for("collections:OrderedDict")
    with pytest.raises(PluginImportError, match=r"is not of the form 'python\.module:Class'"):
        loader.class_for("no_class_named:")


def test_an_exported_calculator_whose_module_is_missing_names_the_export(tmp_path):
    """A second package exports a calculator whose module is not there: the problem says which
    package exports it as what."""
    plugin_package(
        tmp_path / "ws" / "my_calcs",
        "my_calcs",
        "plugins.xml",
        '<library><class name="my_calcs::Gone" type="my_calcs_gone_module:Gone"><description/></class></library>',
    )
    loader = calculator_loader(rospkg.RosPack(ros_paths=[str(tmp_path / "ws"), WORKSPACE_SRC]))
    config = parse_robot_config({"base_calculator": "my_calcs::Gone", "motor_drives": four_drives()}, "robot.yaml")
    (problem,) = calculator_problems(config, loader)
    assert (problem.path, problem.value) == ("base_calculator", "my_calcs::Gone")
    assert problem.rule == (
        "cannot import module 'my_calcs_gone_module': No module named 'my_calcs_gone_module' "
        "(exported by my_calcs as 'my_calcs_gone_module:Gone')"
    )


@pytest.mark.slow  # a fresh interpreter
def test_without_the_calculators_package_every_file_is_refused_never_passed(tmp_path):
    """thorvald_model alone (thorvald_base not importable): the example robot's calculator cannot be
    loaded, so check_config refuses the file (it used to pass it on the shared rules alone)."""
    path = os.path.join(PKG, "config", "thorvald_ii_4wd4ws_std", "thorvald_ii_4wd4ws_std.yaml")
    script = (
        "import sys; sys.modules['thorvald_base'] = None\n"  # an import of thorvald_base fails
        "from thorvald_model.check_config import main\n"
        "sys.exit(main(sys.argv[1:]))\n"
    )
    proc = subprocess.run([sys.executable, "-c", script, path], capture_output=True, text=True, timeout=60)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    assert f"{path}: base_calculator: 'pltf_clc_std::PltfClcStd': cannot import module 'thorvald_base." in proc.stderr
    assert "Traceback" not in proc.stderr


def test_the_calculators_package_is_found_without_the_package_path(tmp_path):
    """Plain Python use of the source tree (thorvald_base importable, not on the package path): its
    own description file, found next to its sources without importing it."""
    loader = calculator_loader(rospkg.RosPack(ros_paths=[str(tmp_path)]))
    (plugin,) = [p for p in loader.plugins.values() if p.name == "pltf_clc_std::PltfClcStd"]
    assert plugin.source == os.path.join(WORKSPACE_SRC, "thorvald_base", "calculator_plugins.xml")
    assert loader.class_for("pltf_clc_std::PltfClcStd").__name__ == "PltfClcStd"


def test_the_calculator_kind_is_the_calculators_package():
    """CALCULATORS names thorvald_base's pieces by string: they must be the real ones."""
    from thorvald_base.kinematics.calculator import BaseCalculator  # noqa: PLC0415
    from thorvald_base.plugins import CalculatorLoader  # noqa: PLC0415

    module, _, name = CALCULATORS.base_class.partition(":")
    assert getattr(importlib.import_module(module), name) is BaseCalculator
    assert os.path.isfile(os.path.join(WORKSPACE_SRC, CALCULATORS.export, CALCULATORS.own_description))
    export = f'<{CALCULATORS.export} {CALCULATORS.attribute}="${{prefix}}/{CALCULATORS.own_description}"/>'
    with open(os.path.join(WORKSPACE_SRC, CALCULATORS.export, "package.xml")) as f:
        assert export in f.read()
    assert isinstance(CalculatorLoader(), PluginLoader) and CalculatorLoader().kind is CALCULATORS


# ---- no upward imports ---------------------------------------------------------------------------
def model_modules():
    """(module name, source file) of every module of thorvald_model: its source tree walked (the
    devel space's __init__.py is catkin's, which runs this one)."""
    root = os.path.join(PKG, "src")
    out = []
    for folder, _, files in os.walk(os.path.join(root, "thorvald_model")):
        for name in sorted(files):
            if name.endswith(".py"):
                path = os.path.join(folder, name)
                module = os.path.relpath(path, root)[: -len(".py")].replace(os.sep, ".")
                out.append((module[: -len(".__init__")] if module.endswith(".__init__") else module, path))
    return out


def test_the_source_scan_sees_an_upward_import(tmp_path):
    source = tmp_path / "m.py"
    source.write_text(
        "import importlib\n"
        "def f():\n"
        "    from thorvald_base.plugins import load_calculator\n"
        "    return importlib.import_module('thorvald_sim.world')\n"
    )
    names = imported_names(str(source), "thorvald_model.m")
    assert names == [
        "importlib",
        "thorvald_base.plugins",
        "thorvald_base.plugins.load_calculator",
        "thorvald_sim.world",
    ]


def test_no_module_imports_a_package_above_it_in_its_source():
    modules = dict(model_modules())
    # the walk finds the package and its modules, subpackages' too
    assert len(modules) > 20 and {"thorvald_model", "thorvald_model.plugins", "thorvald_model.check_config"} <= set(
        modules
    )
    assert {m.split(".")[0] for m in modules} == {"thorvald_model"}
    upward = {}
    for module, path in modules.items():
        bad = sorted({n for n in imported_names(path, module) if n.split(".")[0] in ABOVE})
        if bad:
            upward[module] = bad
    assert upward == {}


@pytest.mark.slow  # a fresh interpreter a module
def test_importing_every_module_in_a_clean_interpreter_loads_no_package_above_it():
    script = textwrap.dedent(
        """\
        import importlib, json, pkgutil, sys
        import thorvald_model
        walk = pkgutil.walk_packages(thorvald_model.__path__, "thorvald_model.")
        names = ["thorvald_model"] + [m.name for m in walk]
        for name in names:
            importlib.import_module(name)
        print(json.dumps({"modules": names, "loaded": sorted({m.split(".")[0] for m in sys.modules})}))
        """
    )
    env = dict(os.environ, PYTHONPATH=os.pathsep.join(p for p in sys.path if p))
    proc = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, timeout=120)
    assert proc.returncode == 0, proc.stderr
    found = json.loads(proc.stdout.strip().splitlines()[-1])
    assert "thorvald_model.check_config" in found["modules"] and "thorvald_model.plugins" in found["modules"]
    assert sorted(set(found["loaded"]) & set(ABOVE)) == []
