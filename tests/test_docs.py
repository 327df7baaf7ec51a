"""The documentation holds: README.md, docs/*.md and every package's src/<pkg>/README.md.

Every relative link and image resolves, an anchor to a heading of its page (GitHub's slugs); every
``rosrun PKG EXE`` the pages show (in code blocks and inline code) names an executable of that
package or of a system package listed here; every ``roslaunch PKG FILE.launch`` names one launch
file of that package, and every ``name:=value`` it passes is an ``<arg>`` that file declares (or a
file it includes with ``pass_all_args``) without a fixed ``value``; every ``rostest PKG FILE.test``
exists. README.md stays a short guide that links every page. No ROS master, no ROS import: the
launch files are read as XML.
"""

import os
import re
import xml.etree.ElementTree as ET
from pathlib import Path
from typing import Dict, Iterator, List, Optional, Set, Tuple

import pytest

WS = Path(__file__).resolve().parent.parent
SRC = WS / "src"
README = WS / "README.md"
DOCS = WS / "docs"

# Executables of system (Debian) packages the pages may run with rosrun: the package alone does not
# tell whether a name exists, so each is listed.
SYSTEM_EXECUTABLES: Dict[str, Set[str]] = {
    "rviz": {"rviz"},
    "rostopic": {"rostopic"},
    "rosservice": {"rosservice"},
    "rosbag": {"record", "play"},
    "robot_state_publisher": {"robot_state_publisher"},
    "joint_state_publisher": {"joint_state_publisher"},
    "joint_state_publisher_gui": {"joint_state_publisher_gui"},
    "tf": {"tf_echo", "tf_monitor", "view_frames"},
}
README_MAX_LINES = 300
WORLD_KEYS_BEGIN = "<!-- world-keys:begin -->"
WORLD_KEYS_END = "<!-- world-keys:end -->"

FENCE = re.compile(r"^(```|~~~)")
HEADING = re.compile(r"^(#{1,6})\s+(.*?)\s*#*\s*$")
INLINE_CODE = re.compile(r"`([^`]+)`")
# [text](target) and ![alt](target), with an optional "title"
LINK = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
# a command line: an optional shell prompt and environment assignments, the tool, its two words, the rest
COMMAND = re.compile(r"^\s*(?:\$\s+)?(?:[A-Z_][A-Z0-9_]*=\S*\s+)*(rosrun|roslaunch|rostest)\s+(\S+)\s+(\S+)(.*)")
SCHEME = re.compile(r"^[a-zA-Z][a-zA-Z0-9+.-]*:")


def pages() -> List[Path]:
    return [README, *sorted(DOCS.glob("*.md")), *sorted(SRC.glob("*/README.md"))]


def packages() -> Dict[str, Path]:
    """Package name (package.xml's <name>) -> its folder, for every package of the workspace."""
    found = {}
    for xml in sorted(SRC.glob("*/package.xml")):
        name = ET.parse(xml).getroot().findtext("name")
        found[name.strip()] = xml.parent
    return found


def outside_code_blocks(text: str) -> str:
    """The text with every fenced code block blanked, line for line (so line numbers hold)."""
    kept, in_block = [], False
    for line in text.split("\n"):
        fence = bool(FENCE.match(line.strip()))
        in_block ^= fence
        kept.append("" if fence or in_block else line)
    return "\n".join(kept)


def slug(heading: str) -> str:
    """GitHub's anchor of a heading: the rendered text, lower case, punctuation dropped, spaces to '-'."""
    text = re.sub(r"!\[[^\]]*\]\([^)]*\)", "", heading)
    text = re.sub(r"\[([^\]]*)\]\([^)]*\)", r"\1", text)
    text = text.replace("`", "").replace("*", "").strip().lower()
    return "".join(c for c in text if c.isalnum() or c in "-_ ").replace(" ", "-")


def anchors(path: Path) -> Set[str]:
    prose = outside_code_blocks(path.read_text(encoding="utf-8"))
    seen: Dict[str, int] = {}
    found = set()
    for line in prose.split("\n"):
        m = HEADING.match(line)
        if not m:
            continue
        base = slug(m.group(2))
        n = seen.get(base, 0)
        seen[base] = n + 1
        found.add(base if n == 0 else f"{base}-{n}")
    return found


def links(text: str) -> Iterator[Tuple[int, str]]:
    """(line number, target) of every link and image outside code."""
    prose = outside_code_blocks(text)
    prose = INLINE_CODE.sub(lambda m: " " * len(m.group(0)), prose)
    for m in LINK.finditer(prose):
        yield prose.count("\n", 0, m.start()) + 1, m.group(1)


def broken_links(path: Path, root: Path = WS) -> List[str]:
    """What is wrong with each link of a page (root: what names are shown relative to)."""
    problems = []
    for line, target in links(path.read_text(encoding="utf-8")):
        if SCHEME.match(target):
            continue  # http(s), mailto: not this test's business
        file_part, _, anchor = target.partition("#")
        dest = (path.parent / file_part).resolve() if file_part else path
        where = f"{os.path.relpath(path, root)}:{line}: {target}"
        if not dest.exists():
            problems.append(f"{where}: {file_part} does not exist")
        elif anchor and dest.suffix == ".md" and anchor not in anchors(dest):
            problems.append(f"{where}: no heading '#{anchor}' in {os.path.relpath(dest, root)}")
        elif anchor and dest.suffix != ".md":
            problems.append(f"{where}: an anchor into a file that is not a page")
    return problems


def tokens(text: str) -> List[str]:
    """Shell-like words: spaces inside quotes and $( ... ) stay in their word."""
    words, word, quote, depth = [], "", "", 0
    i = 0
    while i < len(text):
        c = text[i]
        if quote:
            word += c
            quote = "" if c == quote else quote
        elif c in "'\"":
            word += c
            quote = c
        elif text.startswith("$(", i):
            word += "$("
            depth += 1
            i += 1
        elif c == ")" and depth:
            word += c
            depth -= 1
        elif c.isspace() and not depth:
            if word:
                words.append(word)
            word = ""
        else:
            word += c
        i += 1
    if word:
        words.append(word)
    return words


def snippets(text: str) -> Iterator[Tuple[int, str]]:
    """(line number, code) of every command line of a fenced block (backslash continuations joined)
    and every inline code span (its line breaks as spaces)."""
    prose = outside_code_blocks(text)
    for m in INLINE_CODE.finditer(prose):
        yield prose.count("\n", 0, m.start()) + 1, m.group(1).replace("\n", " ")
    lines = text.split("\n")
    in_block, pending, start = False, "", 0
    for number, line in enumerate(lines, 1):
        if FENCE.match(line.strip()):
            in_block = not in_block
            continue
        if not in_block:
            continue
        if not pending:
            start = number
        if line.rstrip().endswith("\\"):
            pending += line.rstrip()[:-1] + " "
            continue
        yield start, pending + line
        pending = ""


PACKAGE_NAME = re.compile(r"[a-z][a-z0-9_]*")  # REP 144: what a word must be to name a package


def is_placeholder(word: str) -> bool:
    return word.isupper() or word.startswith("-") or "$" in word or "<" in word


def launch_files(package_dir: Path, name: str) -> List[Path]:
    """Every file of that name in the package, as roslaunch looks for it."""
    return sorted(Path(root) / name for root, _, files in os.walk(package_dir) if name in files)


def declared_args(launch: Path, pkgs: Dict[str, Path], seen: Optional[Set[Path]] = None) -> Set[str]:
    """The <arg> names a command line may set: declared without a fixed value, in the file or (through
    pass_all_args) in a file it includes."""
    seen = set() if seen is None else seen
    if launch in seen:
        return set()
    seen.add(launch)
    names = set()

    def walk(element: ET.Element) -> None:
        for child in element:
            if child.tag == "arg" and child.get("value") is None:
                names.add(child.get("name"))
            if child.tag == "include":
                if child.get("pass_all_args", "false").lower() in ("true", "1"):
                    included = resolve_find(child.get("file", ""), pkgs)
                    if included is not None:
                        names.update(declared_args(included, pkgs, seen))
                continue  # an include's own <arg>s set the included file's, they declare nothing here
            walk(child)

    walk(ET.parse(launch).getroot())
    return names


def resolve_find(path: str, pkgs: Dict[str, Path]) -> Optional[Path]:
    m = re.fullmatch(r"\$\(find ([\w-]+)\)(/.*)", path.strip())
    if m is None or m.group(1) not in pkgs:
        return None
    return pkgs[m.group(1)] / m.group(2).lstrip("/")


def executable(package_dir: Path, name: str) -> bool:
    candidates = (package_dir / "nodes" / name, package_dir / "scripts" / name, package_dir / name)
    return any(c.is_file() and os.access(c, os.X_OK) for c in candidates)


def bad_commands(path: Path, pkgs: Dict[str, Path], root: Path = WS) -> List[str]:
    """What is wrong with each rosrun, roslaunch and rostest command of a page."""
    problems = []
    for line, code in snippets(path.read_text(encoding="utf-8")):
        m = COMMAND.match(code)
        if m is None:
            continue
        tool, pkg, target, rest = m.groups()
        where = f"{os.path.relpath(path, root)}:{line}: {tool} {pkg} {target}"
        if not PACKAGE_NAME.fullmatch(pkg) or (tool != "rosrun" and is_placeholder(target)):
            continue  # a placeholder (PKG, -p) or words about the tool, not a command
        if tool == "rosrun":
            if pkg in SYSTEM_EXECUTABLES:
                if target not in SYSTEM_EXECUTABLES[pkg]:
                    problems.append(f"{where}: {target} is not a listed executable of {pkg}")
            elif pkg not in pkgs:
                problems.append(f"{where}: no package {pkg} in the workspace or the known system packages")
            elif not executable(pkgs[pkg], target):
                problems.append(f"{where}: no executable {target} in {pkg}'s nodes/, scripts/ or folder")
            continue
        if pkg not in pkgs:
            problems.append(f"{where}: no package {pkg} in the workspace")
            continue
        found = launch_files(pkgs[pkg], target)
        if len(found) != 1:
            problems.append(f"{where}: {len(found)} files named {target} in {pkg} ({tool} needs exactly one)")
            continue
        if tool == "rostest":
            continue
        allowed = declared_args(found[0], pkgs)
        for word in tokens(rest):
            if word.startswith("#") or word in ("&&", "||", "|", ";", "&"):
                break
            name, assign, _ = word.partition(":=")
            if assign and not name.startswith("_") and name not in allowed:
                problems.append(f"{where}: {found[0].name} declares no settable <arg name={name!r}>")
    return problems


MODULE_NAME = re.compile(r"thorvald_[a-z_]+(?:\.[A-Za-z_][A-Za-z0-9_]*)+")


def defines(module: Path, name: str) -> bool:
    """Whether a module's text defines or imports the name (a class, a function, an assignment, or an
    import, one line or a parenthesised list)."""
    text = module.read_text(encoding="utf-8") if module.is_file() else ""
    patterns = (
        rf"^\s*(?:class|def)\s+{name}\b",
        rf"^{name}\s*[:=]",
        rf"^\s*(?:from\s+\S+\s+)?import\b[^\n]*\b{name}\b",
        rf"^\s+{name},?\s*$",
    )
    return any(re.search(p, text, re.M) for p in patterns)


def missing_module_name(dotted: str) -> Optional[str]:
    """Why a dotted name of ours (``thorvald_base.can.slcan.BufferedSlcanBus``) does not exist in the
    source, or None: each part a package folder, a module, or a name the module defines."""
    first, *parts = dotted.split(".")
    here = SRC / first / "src" / first
    if not here.is_dir():
        return f"no Python package {first}"
    module = here / "__init__.py"
    for part in parts:
        if here.is_dir() and (here / part).is_dir():
            here = here / part
            module = here / "__init__.py"
        elif here.is_dir() and (here / f"{part}.py").is_file():
            here = module = here / f"{part}.py"
        elif part.startswith("_") and (SRC / first / "csrc" / f"{part[1:]}.c").is_file():
            return None  # a C extension catkin_make builds (thorvald_sim._scan)
        elif defines(module, part):
            return None  # an attribute: what follows it is the object's, not the source tree's
        else:
            return f"{part} is neither a module nor defined in {os.path.relpath(module, WS)}"
    return None


PAGES = pages()


def page_id(path: Path) -> str:
    return str(path.relative_to(WS))


@pytest.mark.parametrize("page", PAGES, ids=page_id)
def test_links_and_images_resolve(page):
    assert broken_links(page) == []


@pytest.mark.parametrize("page", PAGES, ids=page_id)
def test_commands_name_what_exists(page):
    assert bad_commands(page, packages()) == []


@pytest.mark.parametrize("page", PAGES, ids=page_id)
def test_module_names_exist(page):
    prose = outside_code_blocks(page.read_text(encoding="utf-8"))
    names = {m.group(1) for m in INLINE_CODE.finditer(prose) if MODULE_NAME.fullmatch(m.group(1))}
    assert {n: missing_module_name(n) for n in sorted(names) if missing_module_name(n)} == {}


def test_readme_is_a_short_guide_that_links_every_page():
    text = README.read_text(encoding="utf-8")
    assert len(text.rstrip("\n").split("\n")) <= README_MAX_LINES
    targets = {(WS / t.partition("#")[0]).resolve() for _, t in links(text) if not SCHEME.match(t)}
    unlinked = [page_id(p) for p in PAGES[1:] if p.resolve() not in targets]
    assert unlinked == []
    # the two commands stay at the very top
    assert text.split("\n")[4:8] == [
        "```sh",
        "make demo    # installs everything it needs (apt, .venv, catkin build), then runs the main job",
        "make test    # installs everything it needs, then runs every test (ruff, pytest, rostest)",
        "```",
    ]


def test_every_package_has_a_readme():
    assert sorted(p.name for p in packages().values() if not (p / "README.md").is_file()) == []


def test_world_keys_table_has_its_markers():
    lines = (DOCS / "worlds.md").read_text(encoding="utf-8").split("\n")
    assert lines.count(WORLD_KEYS_BEGIN) == 1
    assert lines.count(WORLD_KEYS_END) == 1
    assert lines.index(WORLD_KEYS_BEGIN) < lines.index(WORLD_KEYS_END)


# The checker itself, on pages made for it: each of these must be caught.


def test_slugs_follow_github():
    # GitHub drops punctuation and backticks, keeps '_' and '-', turns each space into '-'
    assert (
        slug("The paper's odometry experiment (`odometry_report`)") == "the-papers-odometry-experiment-odometry_report"
    )
    assert slug("`odom -> base_link`") == "odom---base_link"
    assert slug("The example: `sensors_example.xacro`") == "the-example-sensors_examplexacro"


def test_checker_catches_broken_links_and_anchors(tmp_path):
    (tmp_path / "docs").mkdir()
    (tmp_path / "docs" / "a.md").write_text("# A page\n\n## Two words\n\n## Two words\n", encoding="utf-8")
    page = tmp_path / "README.md"
    page.write_text(
        "[ok](docs/a.md#two-words) [dup](docs/a.md#two-words-1) ![img](docs/missing.png)\n"
        "[gone](docs/b.md) [bad anchor](docs/a.md#three) [self](#nowhere) `[code](not/checked.md)`\n"
        "```\n[fenced](not/checked.md)\n```\n[web](https://example.org/x)\n",
        encoding="utf-8",
    )
    problems = broken_links(page, root=tmp_path)
    assert [p.split(": ")[1] for p in problems] == ["docs/missing.png", "docs/b.md", "docs/a.md#three", "#nowhere"]


def test_checker_catches_unknown_executables_launch_files_and_args(tmp_path):
    pkg = tmp_path / "src" / "pkg_a"
    (pkg / "launch").mkdir(parents=True)
    (pkg / "nodes").mkdir()
    (pkg / "nodes" / "node_x").write_text("#!/bin/sh\n", encoding="utf-8")
    (pkg / "nodes" / "node_x").chmod(0o755)
    (pkg / "launch" / "inner.launch").write_text('<launch><arg name="deep"/></launch>', encoding="utf-8")
    (pkg / "launch" / "top.launch").write_text(
        '<launch><arg name="a" default="1"/><arg name="fixed" value="2"/>'
        '<include file="$(find pkg_a)/launch/inner.launch" pass_all_args="true"/>'
        '<include file="$(find pkg_a)/launch/inner.launch"><arg name="not_declared" value="3"/></include>'
        "</launch>",
        encoding="utf-8",
    )
    page = tmp_path / "README.md"
    page.write_text(
        "```sh\nrosrun pkg_a node_x _p:=1\nrosrun pkg_a node_y\nrosrun rviz rviz -d x\nrosrun rviz rvis\n"
        "roslaunch pkg_a top.launch a:=1 deep:=$(rospack find pkg_a)/x \\\n    fixed:=3 not_declared:=4  # c:=5\n"
        "roslaunch pkg_a nothere.launch\nrostest pkg_b x.test\n```\n"
        "and `rosrun PKG EXE`, `roslaunch pkg_a top.launch b:=1`\n",
        encoding="utf-8",
    )
    problems = bad_commands(page, {"pkg_a": pkg}, root=tmp_path)
    assert [p.split(": ", 2)[2] for p in problems] == [
        "top.launch declares no settable <arg name='b'>",
        "no executable node_y in pkg_a's nodes/, scripts/ or folder",
        "rvis is not a listed executable of rviz",
        "top.launch declares no settable <arg name='fixed'>",
        "top.launch declares no settable <arg name='not_declared'>",
        "0 files named nothere.launch in pkg_a (roslaunch needs exactly one)",
        "no package pkg_b in the workspace",
    ]


def test_checker_catches_module_names_that_do_not_exist():
    assert missing_module_name("thorvald_model.config") is None
    assert missing_module_name("thorvald_sim._scan") is None  # built from src/thorvald_sim/csrc/scan.c
    assert missing_module_name("thorvald_model.no_such_module") is not None
    assert missing_module_name("thorvald_model.config.no_such_name") is not None
    assert missing_module_name("thorvald_nothing.config") == "no Python package thorvald_nothing"
