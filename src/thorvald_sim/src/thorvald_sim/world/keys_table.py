"""The world file's keys as a markdown table (:func:`keys_markdown`): one row a top-level key (the
element kinds' of the registry, and gravity, ground and description), with its entries and each key's
default and rule. ``docs/worlds.md`` holds it between its ``world-keys`` marker lines (``python -m
thorvald_sim.world --update docs/worlds.md`` writes it), and a test keeps the two the same."""

from typing import Optional, Sequence

from thorvald_model.schema import KIND_NAMES, REQUIRED, Key

from ..doc_tables import markers, with_table
from .ground import GROUND_DEFAULTS_TEXT, GROUND_KEYS
from .kind import ElementKind
from .kinds import element_kinds
from .loader import DESCRIPTION_KEY, GRAVITY_KEY
from .rules import RGBA_RULE

KEYS_TABLE = "world-keys"  # the name of its marker lines in a markdown file (docs/worlds.md)
KEYS_BEGIN, KEYS_END = markers(KEYS_TABLE)


def keys_markdown(kinds: Optional[Sequence[ElementKind]] = None) -> str:
    """The world file's keys as a markdown table: one row a top-level key (the element kinds', and
    gravity, ground and description), with its entries and each key's default and rule.

    kinds: default the registry's. The rules between keys are each kind's module's docstring's, the
    budgets :mod:`thorvald_sim.world.limits`'.
    """
    kinds = element_kinds() if kinds is None else kinds
    rows = [
        ("gravity", "a number [m/s^2]", _keys_text((GRAVITY_KEY,), {})),
        ("ground", "one mapping: the ground plane's surface and colour", _keys_text(GROUND_KEYS, GROUND_DEFAULTS_TEXT)),
    ]
    for kind in kinds:
        entries = "one mapping" if kind.single else f"`{kind.prefix}0`, `{kind.prefix}1`, ..."
        if kind.doc:
            entries += f": {kind.doc}"
        rows.append((kind.section, entries, _keys_text(kind.keys, kind.defaults)))
    rows.append(("description", "free text", _keys_text((DESCRIPTION_KEY,), {})))
    lines = ["| section | entries | keys (default): rule |", "| --- | --- | --- |"]
    lines += [f"| `{section}` | {_cell(entries)} | {keys} |" for section, entries, keys in rows]
    return "\n".join(lines) + "\n"


def with_keys_table(text: str, table: str) -> str:
    """The markdown text with the lines between its KEYS_BEGIN and KEYS_END lines replaced by table;
    ValueError if it has not both, in that order, once each."""
    return with_table(text, table, KEYS_TABLE)


def _keys_text(keys: Sequence[Key], defaults) -> str:
    return "<br>".join(_cell(_key_text(key, defaults.get(key.name))) for key in keys)


def _key_text(key: Key, default: Optional[str]) -> str:
    aliases = "".join(f", alias `{alias}`" for alias in key.aliases)
    if default is None:
        default = _default_text(key.default)
    rule = RGBA_RULE if key.name == "rgba" else key.rule or f"must be {KIND_NAMES[key.kind]}"
    return f"`{key.name}` ({default}{aliases}): {rule}"


def _default_text(default) -> str:
    if default is REQUIRED:
        return "required"
    if default is None:
        return "none"
    if isinstance(default, float):
        return f"{default:g}"
    if isinstance(default, str):
        return f"`{default}`" if default else '""'
    return str(default)


def _cell(text: str) -> str:
    """Text as it stands in a table's cell: a | would end the cell."""
    return text.replace("|", "\\|")
