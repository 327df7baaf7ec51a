"""What the tests read from a package's source files without importing them (pure: the ast module)."""

import ast
import builtins
import re
from typing import Dict, Iterable, List, Set, Tuple

# Python's own exception classes, by name (ValueError, BaseException, KeyboardInterrupt, ...)
BUILT_IN_EXCEPTIONS = frozenset(
    name for name, value in vars(builtins).items() if isinstance(value, type) and issubclass(value, BaseException)
)
_EXCEPTION_ENDINGS = ("Error", "Exception", "Warning")  # other packages' classes: yaml.MarkedYAMLError, ...
# a class statement's head and what its parentheses hold: a file none of whose heads names an exception
# class among its words is not parsed (most files are not: parsing every file of the workspace is slow)
_CLASS_HEAD = re.compile(r"^[ \t]*class[ \t]+(\w+)[ \t]*\((.*?)\)[ \t]*:", re.M | re.S)


def _is_exception_base(name: str, known: Set[str]) -> bool:
    return name in known or name.endswith(_EXCEPTION_ENDINGS)


def _classes(text: str, path: str) -> List[Tuple[str, Set[str]]]:
    """Each class the source defines (at any depth), with the names of its bases (``b`` of ``a.b``),
    in the order they are defined."""
    found = []
    stack = list(reversed(ast.parse(text, path).body))
    while stack:
        node = stack.pop()
        if isinstance(node, ast.ClassDef):
            found.append(
                (node.name, {b.attr if isinstance(b, ast.Attribute) else getattr(b, "id", "") for b in node.bases})
            )
        for field in ("body", "orelse", "finalbody", "handlers"):  # statements only: a class is one
            stack += reversed([n for n in getattr(node, field, ()) if isinstance(n, ast.AST)])
    return found


def _derived(classes: List[Tuple[str, Set[str]]], known: Set[str]) -> Set[str]:
    found: Set[str] = set()
    for name, bases in classes:  # in order: a base of the file's own comes first
        if any(b in found or _is_exception_base(b, known) for b in bases):
            found.add(name)
    return found


def exception_classes(path: str, known: Iterable[str] = ()) -> Set[str]:
    """Names of the classes a source file defines that derive from an exception class: a base that is
    one of Python's own, a name ending in Error, Exception or Warning, one of ``known`` (exception
    classes defined elsewhere, e.g. ``SpawnFailed`` imported from an errors module), or one of the
    file's own such classes."""
    with open(path, encoding="utf-8") as f:
        return _derived(_classes(f.read(), path), set(known) | BUILT_IN_EXCEPTIONS)


def exception_classes_of(paths: Iterable[str]) -> Dict[str, Set[str]]:
    """:func:`exception_classes` of each file, every file's classes known to the others (a class
    deriving from one of another file is found, however far down): what the workspace's errors test
    (tests/test_errors.py) looks for outside each package's errors module. The class heads are read
    first, by their words, and only the files whose heads may name an exception class are parsed."""
    texts = {}
    for path in paths:
        with open(path, encoding="utf-8") as f:
            texts[path] = f.read()
    heads = [
        (path, m.group(1), re.findall(r"\w+", m.group(2))) for path in texts for m in _CLASS_HEAD.finditer(texts[path])
    ]
    known: Set[str] = set(BUILT_IN_EXCEPTIONS)
    maybe: Set[Tuple[str, str]] = set()
    while True:  # every head whose words name a (maybe) exception class: more than are, never fewer
        more = {(path, name) for path, name, words in heads if any(_is_exception_base(w, known) for w in words)}
        if more <= maybe:
            break
        maybe |= more
        known |= {name for _, name in more}
    parsed = {path for path, _ in maybe}
    classes = {path: _classes(texts[path], path) if path in parsed else [] for path in texts}
    known = set(BUILT_IN_EXCEPTIONS)
    while True:
        found = {path: _derived(c, known) for path, c in classes.items()}
        names = set().union(*found.values())
        if names <= known:
            return found
        known |= names


_FUNCTIONS = (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda)


def _nodes(tree: ast.AST, inside_functions: bool):
    if inside_functions:
        yield from ast.walk(tree)
        return
    stack = [tree]
    while stack:  # what runs when the module is imported: everything but a function's body
        node = stack.pop()
        yield node
        stack += [c for c in ast.iter_child_nodes(node) if not isinstance(c, _FUNCTIONS)]


def imported_names(path: str, module: str, inside_functions: bool = True) -> List[str]:
    """Every module an import statement of the file names, at any depth (inside functions too, unless
    ``inside_functions`` is false: then what importing the module runs), relative imports resolved
    against the module's package; for ``from X import a`` both X and X.a (a may be a module); and
    every literal handed to importlib.import_module or __import__. The import checks read this where
    importing a module would miss an import inside a function."""
    with open(path, encoding="utf-8") as f:
        tree = ast.parse(f.read(), path)
    package = module if path.endswith("__init__.py") else module.rpartition(".")[0]
    names: List[str] = []
    for node in _nodes(tree, inside_functions):
        if isinstance(node, ast.Import):
            names += [a.name for a in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                anchor = ".".join(parts[: len(parts) - node.level + 1])
                base = f"{anchor}.{base}" if base else anchor
            names += [base] + [f"{base}.{a.name}" for a in node.names]
        elif isinstance(node, ast.Call) and node.args and isinstance(node.args[0], ast.Constant):
            func = node.func
            called = func.attr if isinstance(func, ast.Attribute) else getattr(func, "id", "")
            if called in ("import_module", "__import__") and isinstance(node.args[0].value, str):
                names.append(node.args[0].value)
    return names
