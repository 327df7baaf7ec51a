"""Pluginlib-like loading: by name, module:Class, errors, and a calculator from a second package."""

import os
import re
import sys
import textwrap

import pytest
import rospkg
from base_test_helpers import WORKSPACE_SRC, four_ws

from thorvald_base.errors import (
    PluginDescriptionError,
    PluginImportError,
    PluginNotFoundError,
    PluginTypeError,
)
from thorvald_base.kinematics import PltfClc1WD, PltfClc2WDiff, PltfClcStd, Twist
from thorvald_base.plugins import CalculatorLoader, load_calculator, parse_plugin_file
from thorvald_testing.packages import plugin_package

BUILT_IN = ["pltf_clc_1wd::PltfClc1WD", "pltf_clc_2wdiff::PltfClc2WDiff", "pltf_clc_std::PltfClcStd"]


@pytest.fixture
def loader():
    return CalculatorLoader(rospkg.RosPack(ros_paths=[WORKSPACE_SRC]))


def test_built_in_calculators_load_by_name(loader):
    assert loader.known_names() == BUILT_IN
    assert type(loader.create("pltf_clc_std::PltfClcStd")) is PltfClcStd
    assert type(loader.create("pltf_clc_2wdiff::PltfClc2WDiff")) is PltfClc2WDiff
    assert type(loader.create("pltf_clc_1wd::PltfClc1WD", estimator="paper", seed=1)) is PltfClc1WD
    assert loader.plugins["pltf_clc_std::PltfClcStd"].package == "thorvald_base"


def test_module_colon_class_loads_directly(loader):
    assert type(loader.create("thorvald_base.kinematics.std:PltfClcStd")) is PltfClcStd


def test_unknown_name_lists_known_names(loader):
    with pytest.raises(PluginNotFoundError) as e:
        loader.create("pltf_clc_foo::PltfClcFoo")
    for name in BUILT_IN:
        assert name in str(e.value)


def test_import_errors_name_module_and_class(loader):
    with pytest.raises(PluginImportError, match=re.escape("cannot import module 'no_such_module_xyz'")):
        loader.create("no_such_module_xyz:Calc")
    with pytest.raises(PluginImportError, match="has no class 'NoSuchCalc'"):
        loader.create("thorvald_base.kinematics.std:NoSuchCalc")


def test_wrong_base_class(loader):
    with pytest.raises(PluginTypeError, match=re.escape("not a subclass of thorvald_base.kinematics.BaseCalculator")):
        loader.create("collections:OrderedDict")


def test_malformed_description_file(tmp_path):
    bad = tmp_path / "plugins.xml"
    bad.write_text('<library><class name="a::B"/></library>')
    with pytest.raises(PluginDescriptionError, match=re.escape("python.module:Class")):
        parse_plugin_file(str(bad))
    bad.write_text("<library>")
    with pytest.raises(PluginDescriptionError, match="cannot read"):
        parse_plugin_file(str(bad))


def make_second_package(tmp_path, monkeypatch, base="thorvald_base.kinematics.std:PltfClcStd"):
    """A catkin package 'my_calcs' exporting two calculators for thorvald_base from its package.xml."""
    plugin_package(
        tmp_path / "ws" / "src" / "my_calcs",
        "my_calcs",
        "my_plugins.xml",
        """\
        <class_libraries>
          <library path="my_calcs">
            <class name="my_calcs::Halved" type="my_calcs_module:Halved">
              <description>The standard calculator at half speed.</description>
            </class>
            <class name="my_calcs::NotACalculator" type="my_calcs_module:NotACalculator">
              <description>Exported by mistake.</description>
            </class>
          </library>
        </class_libraries>
        """,
    )
    lib = tmp_path / "pylib"
    lib.mkdir()
    (lib / "my_calcs_module.py").write_text(
        textwrap.dedent(
            """\
            from thorvald_base.kinematics import PltfClcStd, Twist


            class Halved(PltfClcStd):
                def calculate_command(self, twist):
                    return super().calculate_command(Twist(twist.vx / 2, twist.vy / 2, twist.wz / 2))


            class NotACalculator:
                pass
            """
        )
    )
    monkeypatch.syspath_prepend(str(lib))
    monkeypatch.delitem(sys.modules, "my_calcs_module", raising=False)
    return rospkg.RosPack(ros_paths=[str(tmp_path / "ws" / "src"), WORKSPACE_SRC])


def test_calculator_of_a_second_package_loads_by_name(tmp_path, monkeypatch):
    rospack = make_second_package(tmp_path, monkeypatch)
    loader = CalculatorLoader(rospack)
    assert loader.known_names() == sorted([*BUILT_IN, "my_calcs::Halved", "my_calcs::NotACalculator"])
    plugin = loader.plugins["my_calcs::Halved"]
    assert plugin.package == "my_calcs"
    assert plugin.source == os.path.join(str(tmp_path), "ws", "src", "my_calcs", "my_plugins.xml")
    calc = loader.create("my_calcs::Halved")
    assert type(calc).__name__ == "Halved" and isinstance(calc, PltfClcStd)
    config = four_ws()
    calc.initialize(config.drives)
    # Straight ahead at 1 m/s, halved by the plugin: every wheel 0.5 m/s.
    assert [c.speed for c in calc.calculate_command(Twist(1.0, 0.0, 0.0)).commands] == [0.5] * 4
    with pytest.raises(PluginTypeError, match="my_calcs::NotACalculator"):
        loader.create("my_calcs::NotACalculator")


def test_load_calculator_uses_the_robot_files_name(tmp_path, monkeypatch):
    rospack = make_second_package(tmp_path, monkeypatch)
    from dataclasses import replace  # noqa: PLC0415

    config = replace(four_ws(), base_calculator="my_calcs::Halved")
    calc = load_calculator(config, rospack=rospack)
    assert type(calc).__name__ == "Halved"
    assert calc.layout is not None
