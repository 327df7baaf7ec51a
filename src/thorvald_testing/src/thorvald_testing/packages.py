"""A catkin package of a user's, made in a test's folder: what the plugin tests export calculators from."""

import textwrap
from pathlib import Path

PACKAGE_XML = """\
<?xml version="1.0"?>
<package format="3">
  <name>{name}</name>
  <version>0.0.1</version>
  <description>Calculators of another package.</description>
  <maintainer email="a@example.org">A</maintainer>
  <license>BSD</license>
  <buildtool_depend>catkin</buildtool_depend>
  <exec_depend>thorvald_base</exec_depend>
  <export>
    <thorvald_base plugin="${{prefix}}/{plugins}"/>
  </export>
</package>
"""


def plugin_package(folder: Path, name: str, plugins: str, plugins_xml: str) -> Path:
    """A catkin package ``name`` in ``folder`` (made) whose package.xml exports the calculator plugin
    description ``plugins`` (a file of the package, written with ``plugins_xml``) for thorvald_base, as a
    user's package does; its folder."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "package.xml").write_text(PACKAGE_XML.format(name=name, plugins=plugins))
    (folder / plugins).write_text(textwrap.dedent(plugins_xml))
    return folder
