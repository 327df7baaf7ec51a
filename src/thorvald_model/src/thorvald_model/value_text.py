"""A value as a message shows it: its ``repr()``, cut to a length, at a cost bounded by that length.

A message names the value it refuses, but that value may be anything a file or a ROS parameter
tree holds: a list of a million numbers, a string of megabytes, or a graph that YAML aliases share
so that it stands for 10^9 leaves while taking a few kilobytes. ``repr()`` walks all of it before
anything can be cut, so here the text is built piece by piece and the walk stops as soon as the
text is longer than the limit: a value whose repr fits is shown exactly as ``repr()`` shows it,
any other as the first characters of its repr and ``...``. A dict, list or tuple of a subclass is
shown as the plain one; an integer too long to show as the length of its decimal digits.

Why not :mod:`reprlib`: it bounds each container and the depth, not the whole (six levels of six
items is 46656 items visited), sorts a whole dict to show four keys, calls ``repr()`` on
subclasses and on whole bytes, and shortens values that fit (strings past 30 characters, dicts past
four keys) that messages show whole.

Pure Python.
"""

from typing import Any, Iterator, Set, Tuple

VALUE_TEXT = 200  # [characters] of a value in a message: a line stays readable, a list of numbers whole
# Plain values whose repr() is short whatever they hold (a float is at most 24 characters).
_PLAIN = (type(None), bool, float, complex)
_DIGITS_PER_BIT = 0.30103  # log10(2): an integer of n bits has about 0.3 n decimal digits
_MAX_DIGITS = 4000  # of an integer converted to decimal to be shown (a few microseconds' work)
_CUT = object()  # a piece that says the text stops here, short of the whole repr


def value_text(value: Any, limit: int = VALUE_TEXT) -> str:
    """``repr(value)`` if it has at most ``limit`` characters, else its first ``limit - 3`` and ``...``."""
    return value_text_whole(value, limit)[0]


def value_text_whole(value: Any, limit: int = VALUE_TEXT) -> Tuple[str, bool]:
    """(the text :func:`value_text` gives, whether it is the whole ``repr(value)``).

    At most about ``limit`` items of the value are visited (each adds at least one character to
    the text), and a string or bytes is sliced before it is converted.
    """
    pieces = []
    length = 0
    for piece in _pieces(value, limit + 1, set()):
        if piece is _CUT:
            return "".join(pieces)[: max(limit - 3, 0)] + "...", False
        pieces.append(piece)
        length += len(piece)
        if length > limit:
            return "".join(pieces)[: max(limit - 3, 0)] + "...", False
    return "".join(pieces), True


def _pieces(value: Any, room: int, path: Set[int]) -> Iterator[str]:
    """The text of repr(value) in pieces; ``room``: characters past which nobody reads on; ``path``:
    the ids of the containers being shown around this value (one met again is shown as repr shows
    a structure that contains itself)."""
    if isinstance(value, _PLAIN):
        yield repr(value)
    elif isinstance(value, int):
        if value.bit_length() * _DIGITS_PER_BIT > _MAX_DIGITS:
            # converting it to decimal costs time quadratic in its length (and Python 3.11 refuses
            # past 4300 digits); its length says enough
            yield f"<an integer of about {int(value.bit_length() * _DIGITS_PER_BIT) + 1} digits>"
            yield _CUT
        else:
            yield repr(value)
    elif isinstance(value, (str, bytes, bytearray)):
        yield repr(value[:room])
    elif id(value) in path:
        yield "{...}" if isinstance(value, dict) else "[...]"
    elif isinstance(value, dict):
        path.add(id(value))
        yield "{"
        for n, (k, v) in enumerate(value.items()):
            if n:
                yield ", "
            yield from _pieces(k, room, path)
            yield ": "
            yield from _pieces(v, room, path)
        yield "}"
        path.discard(id(value))
    elif isinstance(value, (list, tuple)):
        path.add(id(value))
        yield "[" if isinstance(value, list) else "("
        for n, item in enumerate(value):
            if n:
                yield ", "
            yield from _pieces(item, room, path)
        yield "]" if isinstance(value, list) else ("," if len(value) == 1 else "") + ")"
        path.discard(id(value))
    elif isinstance(value, (set, frozenset)):
        if not value:
            yield f"{type(value).__name__}()"
            return
        yield "{" if isinstance(value, set) else "frozenset({"
        for n, item in enumerate(value):
            if n:
                yield ", "
            yield from _pieces(item, room, path)
        yield "}" if isinstance(value, set) else "})"
    else:
        # anything else (a date from YAML, a caller's own object) is shown by its own repr, cut
        yield repr(value)


__all__ = ["VALUE_TEXT", "value_text", "value_text_whole"]
