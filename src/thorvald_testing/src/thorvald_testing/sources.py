"""What the tests read from a package's source files without importing them (pure: the ast module)."""

import ast
from typing import List, Set


def exception_classes(path: str) -> Set[str]:
    """Names of the classes a source file defines that derive from an exception class (a base named
    Exception or ending in Error, or one of the file's own such classes): what each package's test of
    its one errors module looks for elsewhere."""
    with open(path, encoding="utf-8") as f:
        tree = ast.parse(f.read(), path)
    found: Set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.ClassDef):
            bases = {b.attr if isinstance(b, ast.Attribute) else getattr(b, "id", "") for b in node.bases}
            if any(b == "Exception" or b.endswith("Error") or b in found for b in bases):
                found.add(node.name)
    return found


def imported_names(path: str, module: str) -> List[str]:
    """Every module an import statement of the file names, at any depth (inside functions too),
    relative imports resolved against the module's package; for ``from X import a`` both X and X.a
    (a may be a module); and every literal handed to importlib.import_module or __import__. The
    import checks read this where importing a module would miss an import inside a function."""
    with open(path, encoding="utf-8") as f:
        tree = ast.parse(f.read(), path)
    package = module if path.endswith("__init__.py") else module.rpartition(".")[0]
    names: List[str] = []
    for node in ast.walk(tree):
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
