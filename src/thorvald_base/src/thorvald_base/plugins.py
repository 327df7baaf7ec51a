"""Kinematics calculators as plugins: base_driver's loading of the robot file's ``base_calculator``.

The plugin mechanism (finding the packages' exports, loading a class by name, the error for an
unknown name listing the known ones) is the configuration's: :mod:`thorvald_model.plugins`, since
the robot file names the calculator. check_config loads the calculator class through it without
importing this package; base_driver loads it through it here. One mechanism, so both refuse the
same files with the same words. A package exports calculators as the docstring of
thorvald_model.plugins shows (``<thorvald_base plugin="${prefix}/calculator_plugins.xml"/>``).

What a calculator can serve is the calculator's to declare: ``BaseCalculator.layout_rules``, a
classmethod each calculator overrides, checked after the rules every calculator shares
(thorvald_model.layout). :func:`load_calculator` applies them before it creates the calculator,
and a calculator that cannot be loaded or created is a problem of the robot file
(``base_calculator``, the value, the rule): a ConfigError, as every other problem of the file.
"""

from typing import List

from thorvald_model.errors import ConfigError, PluginError, Problem
from thorvald_model.plugins import (
    CALCULATORS,
    PluginDescription,
    PluginLoader,
    calculator_problems,
    parse_plugin_file,
)

from .kinematics.calculator import BaseCalculator

PACKAGE = CALCULATORS.export
EXPORT_ATTRIBUTE = CALCULATORS.attribute

__all__ = [
    "EXPORT_ATTRIBUTE",
    "PACKAGE",
    "CalculatorLoader",
    "PluginDescription",
    "calculator_layout_problems",
    "load_calculator",
    "parse_plugin_file",
]


class CalculatorLoader(PluginLoader):
    """Finds and creates calculator plugins (thorvald_model's PluginLoader for ``base_calculator``):
    ``create(name, **options)`` is a new, uninitialised calculator, the options going to its
    constructor (estimator, seed, projection).

    rospack: a rospkg.RosPack (pass one with your own ros_paths in tests); by default one over
    ROS_PACKAGE_PATH (the devel or install space). If thorvald_base itself is not on the package
    path (plain Python use of the source tree), its own description file is read instead.
    """

    def __init__(self, rospack=None):
        super().__init__(CALCULATORS, rospack)


def load_calculator(config, rospack=None, **options) -> BaseCalculator:
    """The robot configuration's base_calculator, created and initialised with its drives.

    A calculator that cannot be loaded or created with these options, and a layout the calculator
    declares it cannot serve (its ``layout_rules``), are a ConfigError of the robot file, worded
    as the loader words its own problems (file, key path, value, rule) and as check_config says them.
    """
    loader = CalculatorLoader(rospack)
    problems = calculator_problems(config, loader)
    if not problems:
        try:
            calc = loader.create(config.base_calculator, **options)
        except PluginError as e:
            problems = [Problem(CALCULATORS.key, config.base_calculator, e.rule)]
    if problems:
        raise ConfigError(config.source, problems)
    calc.initialize(config.drives, config.passive_wheels)
    return calc


def calculator_layout_problems(config, rospack=None) -> List[Problem]:
    """The problems of the configuration's layout for its calculator (its own rules, the shared
    ones having passed the loader); an unknown or unloadable calculator is a problem of
    ``base_calculator`` itself (thorvald_model.plugins.calculator_problems)."""
    return calculator_problems(config, CalculatorLoader(rospack))
