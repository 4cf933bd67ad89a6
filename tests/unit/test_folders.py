"""Tests and benchmarks apart, and no folder round a circle (CONVENTIONS.md, "Where tests,
benchmarks and their helpers go").

``tests/`` and ``benchmarks/`` never import each other, ``testing/`` (what both use) imports
neither, and no module imports another of its own folder round a circle. Every import counts
for the first two, type-checking ones too; for circles only imports that run.
"""

from __future__ import annotations

from pathlib import Path

from tests.unit.import_graph import REPO, circles, imports, module_name, python_files

#: Each folder and the top-level packages it must not import.
APART = {
    "tests": ("benchmarks",),
    "benchmarks": ("tests",),
    "testing": ("tests", "benchmarks"),
}


def _crossings(folder: str, refused: tuple[str, ...]) -> list[str]:
    found = []
    for path in python_files(REPO / folder):
        for item in imports(path):
            top = item.module.split(".")[0]
            if top in refused:
                found.append(f"{path.relative_to(REPO)}:{item.line} imports {item.module}")
    return found


def test_tests_benchmarks_and_testing_keep_apart() -> None:
    crossings = [line for folder, refused in APART.items() for line in _crossings(folder, refused)]
    assert crossings == [], "move what both need to testing/:\n" + "\n".join(crossings)


def test_no_folder_imports_itself_round_a_circle() -> None:
    found = circles()
    assert found == [], "modules of one folder that import each other: " + repr(found)


def test_the_checks_see_a_circle_and_a_crossing(tmp_path: Path) -> None:
    """A circle through a package's ``__init__`` and a relative import, a type-only import that
    closes no circle, and an import of ``tests`` from ``benchmarks``."""
    package = tmp_path / "benchmarks"
    package.mkdir()
    (package / "__init__.py").write_text("from benchmarks.a import A\n")
    (package / "a.py").write_text("from . import b\nA = 1\n")
    (package / "b.py").write_text(
        "from typing import TYPE_CHECKING\nimport tests.gz\n"
        "if TYPE_CHECKING:\n    from benchmarks.c import C\n"
        "def late():\n    from benchmarks import A\n"
    )
    (package / "c.py").write_text("from benchmarks.b import late\nC = 1\n")
    assert circles(tmp_path) == [["benchmarks", "benchmarks.a", "benchmarks.b"]]
    assert [item.module for item in imports(package / "b.py", tmp_path)] == [
        "typing",
        "tests.gz",
        "benchmarks.c",
        "benchmarks",
    ]
    assert module_name(package / "__init__.py", tmp_path) == "benchmarks"
