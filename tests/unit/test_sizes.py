"""No file of the repository over 500 lines but generated data, and no module of the package
over 450 (CONVENTIONS.md, "Sizes"; issue 35). A file that grows past it is split by what each
part does: a module by responsibility, a page by the question each part answers.

The files are those git tracks (what a clone has); binary files (a NUL byte near the start:
the descriptor set, the plots) are not counted in lines.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
MAX_LINES = 500
MAX_MODULE_LINES = 450
#: Written by code, never by hand: the figures the benchmarks store between runs.
GENERATED = frozenset({"benchmarks/results.json"})


def _tracked() -> list[str]:
    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.skip("not a git checkout: the tracked files are not known")
    listing = subprocess.run(
        ["git", "ls-files", "-z"], cwd=ROOT, capture_output=True, check=True
    ).stdout
    return [name for name in listing.decode().split("\0") if name]


def _line_counts() -> dict[str, int]:
    counts = {}
    for name in _tracked():
        path = ROOT / name
        if not path.is_file():  # deleted in the work tree, not yet committed
            continue
        data = path.read_bytes()
        if b"\0" not in data[:8192]:
            counts[name] = data.count(b"\n")
    return counts


def test_no_file_is_over_500_lines_but_generated_data() -> None:
    over = {
        name: lines
        for name, lines in _line_counts().items()
        if lines > MAX_LINES and name not in GENERATED
    }
    assert not over, f"over {MAX_LINES} lines, split by what each part does: {over}"


def test_no_module_of_the_package_is_over_450_lines() -> None:
    over = {
        name: lines
        for name, lines in _line_counts().items()
        if name.startswith("ros_gz_bridge_py/") and name.endswith(".py")
        if lines > MAX_MODULE_LINES
    }
    assert not over, f"package modules over {MAX_MODULE_LINES} lines: {over}"
