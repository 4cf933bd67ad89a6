"""The imports of the repository's Python files, read with ``ast`` (nothing is imported).

``tests/unit/test_layers.py`` holds the package's layers with it, ``tests/unit/test_folders.py``
the separation of ``tests/``, ``benchmarks/`` and ``testing/`` and the folders without circles.
"""

from __future__ import annotations

import ast
import os
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]
#: Folders of the repository that hold no code of ours.
_SKIPPED = {"build", "__pycache__"}


@dataclass(frozen=True)
class Import:
    """One imported module: ``import module`` or ``from module import names``."""

    line: int
    module: str
    names: tuple[str, ...] = ()
    #: Under ``if TYPE_CHECKING:``: read by type checkers, never run.
    type_only: bool = False


def module_name(path: Path, root: Path = REPO) -> str:
    """``a/b/c.py`` -> ``a.b.c``; ``a/b/__init__.py`` -> ``a.b``."""
    parts = list(path.relative_to(root).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def imports(path: Path, root: Path = REPO) -> list[Import]:
    """Every import of ``path``, relative ones made absolute, in the order they are written."""
    tree = ast.parse(path.read_text(encoding="utf-8"), str(path))
    type_only = {
        id(node)
        for block in ast.walk(tree)
        if isinstance(block, ast.If) and getattr(block.test, "id", "") == "TYPE_CHECKING"
        for node in ast.walk(block)
    }
    name = module_name(path, root)
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            module = node.module or ""
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                module = ".".join([*base, module] if module else base)
            names = tuple(alias.name for alias in node.names)
            found.append(Import(node.lineno, module, names, id(node) in type_only))
        elif isinstance(node, ast.Import):
            found += [Import(node.lineno, a.name, (), id(node) in type_only) for a in node.names]
    return sorted(found, key=lambda item: item.line)


def python_files(root: Path = REPO) -> Iterator[Path]:
    """The Python files of the repository (not the virtual environment, builds or caches)."""
    for folder, subfolders, files in os.walk(root):
        subfolders[:] = sorted(d for d in subfolders if not d.startswith(".") and d not in _SKIPPED)
        yield from (Path(folder, name) for name in sorted(files) if name.endswith(".py"))


def targets(item: Import, modules: set[str]) -> list[str]:
    """The modules of ``modules`` that ``item`` runs: ``from pkg import sub`` runs ``pkg.sub``
    where that is a module, else ``pkg``."""
    named = [f"{item.module}.{name}" for name in item.names]
    found = [module for module in named if module in modules]
    if len(found) < len(named) or not named:
        found.append(item.module)
    return [module for module in found if module in modules]


def circles(root: Path = REPO) -> list[list[str]]:
    """Groups of modules of one folder that import each other, directly or round a circle,
    with imports that run (those under ``if TYPE_CHECKING:`` do not)."""
    paths = {module_name(path, root): path for path in python_files(root)}
    graph = {
        name: {
            target
            for item in imports(path, root)
            if not item.type_only
            for target in targets(item, set(paths))
            if target != name and paths[target].parent == path.parent
        }
        for name, path in paths.items()
    }
    reach = {name: _reachable(graph, name) for name in graph}
    groups = {
        frozenset({name, *(other for other in reach[name] if name in reach[other])})
        for name in graph
        if name in reach[name]
    }
    return sorted(sorted(group) for group in groups)


def _reachable(graph: dict[str, set[str]], start: str) -> set[str]:
    """The modules ``start`` imports, directly or through others."""
    seen: set[str] = set()
    todo = [start]
    while todo:
        for target in graph[todo.pop()] - seen:
            seen.add(target)
            todo.append(target)
    return seen
