"""The machinery of a validated YAML file, shared by the robot configuration and the simulator's worlds.

A file is a mapping of top-level keys; a section is a mapping of entries numbered from 0 without
gaps (``drive0``, ``drive1``, ...); an entry is a mapping of :class:`Key` values, each with a type,
a default, a rule and aliases. Nothing stops at the first mistake: every :class:`Problem` found
is collected with its dotted key path, the value and the rule, and the caller raises them together
in one :class:`ConfigError`. Every file is read within bounds of depth and size, aliases expanded
(:func:`read_yaml_file`), so no document can exhaust the memory of what reads it. Pure Python
(PyYAML only).
"""

import difflib
import math
import re
import sys
from dataclasses import dataclass, field, fields
from typing import Any, Callable, Iterable, List, Mapping, Optional, Sequence, Tuple

import yaml

from .errors import MISSING, ConfigError, Problem, YamlBoundError
from .value_text import value_text, value_text_whole

REQUIRED = object()


@dataclass(frozen=True)
class Key:
    """One key of a section entry: its type, default, rule and aliases."""

    name: str
    kind: type  # float, int, bool, str, or tuple (of strings: one or a list of them)
    default: Any = REQUIRED
    check: Optional[Callable[[Any], bool]] = None
    rule: str = ""
    aliases: Tuple[str, ...] = ()
    attr: Optional[str] = None  # dataclass field, when it differs from name
    runtime: bool = False  # may change while the robot runs (base_driver's set_drive_params)


_KEY = "thorvald_key"


def key(default: Any = REQUIRED, check=None, rule: str = "", aliases: Tuple[str, ...] = (), runtime: bool = False):
    """A field of a value type that is a key of the file: its default, rule and aliases are the
    field's metadata, so the schema is read off the type (:func:`keys_of`) and a new key is one line.

    The default lives in the schema only: the dataclass still takes every value when it is built.
    """
    spec = dict(default=default, check=check, rule=rule, aliases=tuple(aliases), runtime=runtime)
    return field(metadata={_KEY: spec})


def keys_of(cls: type) -> Tuple[Key, ...]:
    """The keys of a value type made with :func:`key`, in field order; the field's type is the key's."""
    return tuple(Key(f.name, f.type, **f.metadata[_KEY]) for f in fields(cls) if _KEY in f.metadata)


def positive(v):
    return v > 0


def non_negative(v):
    return v >= 0


def one_of(*choices):
    return lambda v: v in choices


def in_range(lo, hi):
    return lambda v: lo <= v <= hi


POSITIVE = dict(check=positive, rule="must be > 0")

# How alike (difflib's ratio) an unknown key must be to a known one to be taken for its typing
# mistake: r_wheeel for r_wheel (0.93), motor_drive for motor_drives (0.96). Less alike keys are
# the user's own, kept where a file allows it (:class:`Kept`).
CLOSE_KEY = 0.8
KEPT_RULE = "unknown key, kept as it is for the user's own files (nothing here reads it)"


@dataclass(frozen=True)
class Kept:
    """An unknown key kept with its value: where it was (the key path as parts) and what it held."""

    path: Tuple[str, ...]
    value: Any

    def problem(self) -> Problem:
        """The warning that says it was kept."""
        return Problem(".".join(self.path), short(self.value), KEPT_RULE)


NON_NEGATIVE = dict(check=non_negative, rule="must be >= 0")


# Bounds of any YAML document read here, whatever it holds. The deepest file of ours is 5 levels
# (a world's objects: file, section, entry, key, rgba list) and the largest holds about 500 values
# (the nine-drive robot); the bounds are 20 and 200 times that. Depth: the composer, and any code
# that walks what it built (copying, dumping, showing), takes about 3 Python frames a level, well
# within Python's 1000. Size: values are counted with aliases expanded (an alias of a list of 10
# holds 11), so a document that stands for 10^9 values in a few kilobytes ("billion laughs") is
# refused while it is composed, before any of it is built or walked.
MAX_YAML_DEPTH = 100  # [levels] of nesting, with aliases expanded
MAX_YAML_NODES = 100_000  # [values] (scalars, lists and mappings, mapping keys included), aliases expanded
# [characters] of an integer: Python 3.11 refuses to convert longer decimal ones, and 3.8 takes time
# quadratic in the length to do it
MAX_YAML_INT = 4300


class _Bounded:
    """What BoundedLoader adds to a YAML loader: the composer counts each node's depth and size
    with aliases expanded as it goes, and a scalar the constructor cannot convert is a YAML error
    at its place, not a Python exception."""

    def compose_document(self):
        self.bounded_depth = 0  # [levels] above the node being composed
        self.bounded_measures = {}  # id(node): (values, levels) with aliases expanded
        try:
            return super().compose_document()
        finally:
            self.bounded_measures = {}

    def compose_node(self, parent, index):
        event = self.peek_event()
        if isinstance(event, yaml.AliasEvent):
            node = super().compose_node(parent, index)
            measure = self.bounded_measures.get(id(node))
            if measure is None:
                raise YamlBoundError(
                    None,
                    None,
                    f"the alias *{event.anchor} is inside the node it names (a value that holds itself)",
                    event.start_mark,
                )
        else:
            if self.bounded_depth >= MAX_YAML_DEPTH:
                raise YamlBoundError(None, None, _depth_rule(), event.start_mark)
            self.bounded_depth += 1
            node = super().compose_node(parent, index)
            self.bounded_depth -= 1
            if isinstance(node, yaml.ScalarNode):
                children = ()
            elif isinstance(node, yaml.MappingNode):
                children = [n for pair in node.value for n in pair]
            else:
                children = node.value
            if children:
                measures = [self.bounded_measures[id(child)] for child in children]
                measure = (1 + sum(m[0] for m in measures), 1 + max(m[1] for m in measures))
            else:
                measure = (1, 1)
            self.bounded_measures[id(node)] = measure
        if measure[0] > MAX_YAML_NODES:
            rule = f"the document holds more than {MAX_YAML_NODES} values with its aliases expanded, counted up to here"
            raise YamlBoundError(None, None, f"{rule} ({_BOUND_WHY})", event.start_mark)
        if self.bounded_depth + measure[1] > MAX_YAML_DEPTH:
            raise YamlBoundError(None, None, _depth_rule(), event.start_mark)
        return node

    def construct_object(self, node, deep=False):
        try:
            return super().construct_object(node, deep)
        except (ValueError, LookupError, AttributeError, TypeError, OverflowError) as e:
            # PyYAML's safe constructors raise these on a malformed tagged scalar (!!int x, !!bool x,
            # !!timestamp 2001-13-45); say which value and where, and for a date why (datetime's
            # words, "month must be in 1..12"; int()'s and float()'s only repeat the value)
            kind = str(node.tag).rsplit(":", 1)[-1]
            reason = f" ({e})" if kind == "timestamp" and isinstance(e, ValueError) else ""
            problem = f"{value_text(node.value, 60)} is not a valid !!{kind} value{reason}"
            raise yaml.constructor.ConstructorError(None, None, problem, node.start_mark) from None

    def construct_yaml_int(self, node):
        if isinstance(node, yaml.ScalarNode) and len(node.value) > MAX_YAML_INT:
            problem = f"an integer of {len(node.value)} characters: at most {MAX_YAML_INT} (as Python converts)"
            raise yaml.constructor.ConstructorError(None, None, problem, node.start_mark)
        return super().construct_yaml_int(node)


_BOUND_WHY = "a bound of every YAML file read here; ours are at most 5 levels deep and hold about 500 values"


def _depth_rule() -> str:
    return f"the document is nested deeper than {MAX_YAML_DEPTH} levels with its aliases expanded ({_BOUND_WHY})"


class BoundedLoader(_Bounded, yaml.SafeLoader):
    """yaml.SafeLoader within :data:`MAX_YAML_DEPTH` and :data:`MAX_YAML_NODES` (aliases expanded)."""


BoundedLoader.add_constructor("tag:yaml.org,2002:int", _Bounded.construct_yaml_int)

if yaml.__with_libyaml__:

    class BoundedCLoader(
        _Bounded, yaml.composer.Composer, yaml.cyaml.CParser, yaml.constructor.SafeConstructor, yaml.resolver.Resolver
    ):
        """BoundedLoader with libyaml's scanner and parser: 4 to 5 times as fast (the nine-drive robot
        file in 3 ms instead of 13; the C loader whole takes 2, but its composer, in C, cannot
        count, so libyaml's events go to PyYAML's composer, counted as in BoundedLoader)."""

        def __init__(self, stream):
            yaml.cyaml.CParser.__init__(self, stream)
            yaml.composer.Composer.__init__(self)
            yaml.constructor.SafeConstructor.__init__(self)
            yaml.resolver.Resolver.__init__(self)

    BoundedCLoader.add_constructor("tag:yaml.org,2002:int", _Bounded.construct_yaml_int)
else:  # PyYAML without libyaml: the pure-Python loader alone
    BoundedCLoader = None


def load_yaml(stream: Any) -> Any:
    """The document of a YAML stream (bytes, text or a file), as yaml.safe_load gives it, within the
    bounds (:class:`YamlBoundError` past them). What libyaml refuses is read again by PyYAML's own
    reader and parser, so a malformed file is worded as PyYAML words it (the byte and the encoding
    of a file that is not text, PyYAML's line and column)."""
    if BoundedCLoader is None:
        return yaml.load(stream, Loader=BoundedLoader)
    if hasattr(stream, "read") and not (hasattr(stream, "seekable") and stream.seekable()):
        stream = stream.read()  # a pipe: kept, so that it can be read again
    start = stream.tell() if hasattr(stream, "seek") else None
    try:
        return yaml.load(stream, Loader=BoundedCLoader)
    except (yaml.reader.ReaderError, yaml.scanner.ScannerError, yaml.parser.ParserError):
        if start is not None:
            stream.seek(start)
        return yaml.load(stream, Loader=BoundedLoader)


def read_yaml_file(path: str, what: str = "robot configuration") -> Any:
    """The parsed YAML document of a file; ConfigError of one line if it cannot be read or parsed,
    or if it is past the bounds of every document read here (:data:`MAX_YAML_DEPTH`,
    :data:`MAX_YAML_NODES`: a YAML bomb is refused while it is composed, in little memory).

    Bytes go to PyYAML, which decodes them (UTF-8, or UTF-16 with a byte order mark) and says where
    decoding fails, whatever the locale.
    """
    try:
        with open(path, "rb") as f:
            return load_yaml(f)
    except OSError as e:
        raise ConfigError(path, [Problem("", MISSING, f"cannot read the {what}: {e.strerror}")], what) from None
    except yaml.reader.ReaderError as e:
        if e.encoding == "unicode":
            reason = f"character #x{e.character:04x} at offset {e.position} is not allowed in a YAML file"
        else:
            reason = f"byte 0x{e.character:02x} at offset {e.position} is not {e.encoding.upper()} ({e.reason})"
        raise ConfigError(path, [Problem("", MISSING, f"not a text file: {reason}")], what) from None
    except YamlBoundError as e:
        mark = e.problem_mark
        rule = f"refused at line {mark.line + 1}, column {mark.column + 1}: {e.problem}"
        raise ConfigError(path, [Problem("", MISSING, rule)], what) from None
    except yaml.YAMLError as e:
        mark = getattr(e, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        reason = getattr(e, "problem", None) or str(e)
        raise ConfigError(path, [Problem("", MISSING, f"not valid YAML{where}: {reason}")], what) from None


def check_top_level(
    data: Any,
    known: Sequence[str],
    problems: List[Problem],
    ignore: Iterable[str] = (),
    *,
    kept: Optional[List[Kept]] = None,
    mistakable: Optional[Sequence[str]] = None,
    source: Optional[str] = None,
    what: str = "robot configuration",
) -> Mapping:
    """The document as a mapping (empty for an empty file); a problem for each unknown top-level key.

    With a ``kept`` list, an unknown key unlike any of ``mistakable`` (default: every known key) is
    the user's own and goes there instead; one like a known key stays a problem ("did you mean").
    Raises ConfigError of source (a file of kind what) at once when the document is not a mapping
    at all (there is nothing more to check).
    """
    if data is None:
        return {}
    if not isinstance(data, Mapping):
        raise ConfigError(source, [Problem("", short(data), "the file must hold a mapping of keys")], what)
    ignore = set(ignore)
    for key in data:
        if key not in known and key not in ignore:
            if kept is not None and close_key(key, known if mistakable is None else mistakable) is None:
                kept.append(Kept((str(key),), data[key]))
            else:
                problems.append(Problem(str(key), short(data[key]), unknown_key_rule(key, known)))
    return data


_ENTRY_NAME = re.compile(r"^([a-z_]+?)(\d+)$")


def parse_section(
    raw: Any,
    key: str,
    prefix: str,
    keys: Sequence[Key],
    problems: List[Problem],
    *,
    kept: Optional[List[Kept]] = None,
) -> List[Tuple[str, int, dict]]:
    """(name, index, values) of each valid entry of a section, in index order.

    raw: the section's value (None for an absent section); key: its top-level key, e.g.
    ``motor_drives``; prefix: the entries' name, e.g. ``drive``; kept: as :func:`parse_entry`.
    """
    if raw is None:
        return []
    if not isinstance(raw, Mapping):
        problems.append(Problem(key, short(raw), f"must be a mapping of {prefix}0, {prefix}1, ..."))
        return []
    indexed = {}
    for name, entry in raw.items():
        path = f"{key}.{name}"
        m = _ENTRY_NAME.match(str(name))
        if not m or m.group(1) != prefix or (len(m.group(2)) > 1 and m.group(2).startswith("0")):
            problems.append(Problem(path, MISSING, f"entries must be named {prefix}0, {prefix}1, ..."))
            continue
        indexed[int(m.group(2))] = (str(name), parse_entry(entry, path, keys, problems, kept=kept))
    for expected, index in enumerate(sorted(indexed)):
        if index != expected:
            # The original read robot files' entries until one was missing and silently dropped the rest.
            read = ", ".join(indexed[i][0] for i in sorted(indexed) if i < expected) or "none"
            dropped = ", ".join(indexed[i][0] for i in sorted(indexed) if i > expected)
            problems.append(
                Problem(
                    f"{key}.{prefix}{expected}",
                    MISSING,
                    f"entries must be numbered from {prefix}0 without gaps: read in order (as the original "
                    f"read them), they stop after {read} at the missing {prefix}{expected}, and {dropped} "
                    "would be dropped",
                )
            )
            break
    return [(indexed[i][0], i, indexed[i][1]) for i in sorted(indexed) if indexed[i][1] is not None]


def parse_entry(
    entry: Any, path: str, keys: Sequence[Key], problems: List[Problem], *, kept: Optional[List[Kept]] = None
) -> Optional[dict]:
    """The entry's values with defaults filled in; None if a required key is missing or invalid.

    An invalid value of a key that has a default is replaced by the default after its problem is
    recorded, so the cross-field rules can still look at the rest of the entry. With a ``kept``
    list, an unknown key unlike every known one is kept there (see :func:`check_top_level`).
    """
    if not isinstance(entry, Mapping):
        problems.append(Problem(path, short(entry), "must be a mapping of keys"))
        return None
    by_name = {}
    for key in keys:
        by_name[key.name] = key
        for alias in key.aliases:
            by_name[alias] = key
    values = {}
    seen_as = {}
    for raw_key, raw_value in entry.items():
        key_path = f"{path}.{raw_key}"
        key = by_name.get(raw_key)
        if key is None:
            if kept is not None and close_key(raw_key, by_name) is None:
                kept.append(Kept((*path.split("."), str(raw_key)), raw_value))
            else:
                problems.append(Problem(key_path, raw_value, unknown_key_rule(raw_key, list(by_name))))
            continue
        if key.name in seen_as:
            problems.append(Problem(key_path, raw_value, f"'{raw_key}' is already given as '{seen_as[key.name]}'"))
            continue
        seen_as[key.name] = raw_key
        ok, value = coerce(raw_value, key.kind)
        if not ok:
            problems.append(Problem(key_path, raw_value, f"must be {KIND_NAMES[key.kind]}"))
            continue
        if key.check is not None and value is not None and not key.check(value):
            problems.append(Problem(key_path, raw_value, key.rule))
            continue
        values[key.name] = value
    complete = True
    for key in keys:
        if key.name in values:
            continue
        if key.default is not REQUIRED:
            values[key.name] = key.default
            continue
        complete = False
        if key.name not in seen_as:
            problems.append(Problem(f"{path}.{key.name}", MISSING, "is required"))
    return values if complete else None


def parse_scalar(data: Mapping, key: Key, problems: List[Problem]) -> Any:
    """A top-level key's value of data (a file's mapping), checked as an entry's key is; its default
    when absent or invalid (the problem recorded at the key's own name)."""
    if key.name not in data:
        return key.default
    found: List[Problem] = []
    values = parse_entry({key.name: data[key.name]}, "", (key,), found)
    # parse_entry names a key of the entry at "" as ".gravity"; a top-level key has no dot
    problems.extend(Problem(p.path.lstrip("."), p.value, p.rule) for p in found)
    return values[key.name] if values else key.default


KIND_NAMES = {
    float: "a finite number",
    int: "an integer",
    bool: "true or false (or 1 or 0)",
    str: "a string",
    tuple: "a string or a list of strings",
}


def coerce(value: Any, kind: type) -> Tuple[bool, Any]:
    """Converts a YAML value to kind; numbers written as strings ("-0.425") count as numbers."""
    if kind is str:
        return (True, value) if isinstance(value, str) else (False, None)
    if kind is tuple:  # one or more names: a string is a list of one; the list holds strings only
        items = [value] if isinstance(value, str) else value
        if isinstance(items, (list, tuple)) and items and all(isinstance(v, str) for v in items):
            return True, tuple(items)
        return False, None
    if kind is bool:
        if isinstance(value, bool):
            return True, value
        if isinstance(value, int) and value in (0, 1):
            return True, bool(value)
        if isinstance(value, str) and value.strip().lower() in ("true", "false", "0", "1"):
            return True, value.strip().lower() in ("true", "1")
        return False, None
    if isinstance(value, bool):
        return False, None
    if isinstance(value, str):
        try:
            value = float(value.strip())
        except ValueError:
            return False, None
    if isinstance(value, int) and abs(value) > sys.float_info.max:
        return False, None  # past every float (math.isfinite would raise OverflowError)
    if not isinstance(value, (int, float)) or not math.isfinite(value):
        return False, None
    if kind is int:
        if float(value) != int(value):
            return False, None
        return True, int(value)
    return True, float(value)


def close_key(key: Any, known: Iterable[str]) -> Optional[str]:
    """The known key that ``key`` most likely mistypes, or None."""
    close = difflib.get_close_matches(str(key), sorted(set(known)), n=1, cutoff=CLOSE_KEY)
    return close[0] if close else None


def unknown_key_rule(key: Any, known: Iterable[str]) -> str:
    known = sorted(set(known))
    close = difflib.get_close_matches(str(key), known, n=1, cutoff=0.6)
    hint = f"did you mean '{close[0]}'?" if close else "known keys: {}".format(", ".join(known))
    return f"unknown key ({hint})"


SHORT_TEXT = 60  # [characters] of a value a message shows only in part (a kept key's, a whole section's)


def short(value: Any) -> Any:
    """The value itself if its repr has at most SHORT_TEXT characters, else the start of its repr;
    bounded in time and memory whatever the value (:mod:`~thorvald_model.value_text`)."""
    text, whole = value_text_whole(value, SHORT_TEXT)
    return value if whole else text
