"""The package is layered: no module imports from a layer above its own (README Architecture).

Imports made only for type checking (under ``if TYPE_CHECKING:``) are left out: they do not
run. The layers, bottom up, are the folders (and root modules) of ``ros_gz_bridge_py``.
"""

from __future__ import annotations

from pathlib import Path

from tests.unit.import_graph import REPO, imports

PACKAGE = REPO / "ros_gz_bridge_py"
#: Bottom up; a part may import its own layer and those below.
LAYERS: tuple[frozenset[str], ...] = (
    frozenset({"errors", "libc", "msgs", "watchers"}),
    frozenset({"config", "transport"}),
    frozenset({"ros"}),
    frozenset({"bulk"}),
    frozenset({"converters"}),
    frozenset({"native"}),
    frozenset({"core"}),
    frozenset({"app", "demo"}),
    frozenset({"cli", "actions", "__init__"}),
)
LEVEL = {part: level for level, parts in enumerate(LAYERS) for part in parts}


def part_of(module: str) -> str | None:
    """The top-level part of ``ros_gz_bridge_py.<part>...`` (None for other packages)."""
    names = module.split(".")
    if names[0] != "ros_gz_bridge_py":
        return None
    return names[1] if len(names) > 1 else "__init__"


def runtime_imports(path: Path, root: Path = REPO) -> list[tuple[int, str]]:
    """(line, module) of every import that runs (not under ``if TYPE_CHECKING``)."""
    return [(item.line, item.module) for item in imports(path, root) if not item.type_only]


def test_every_part_has_a_layer() -> None:
    parts = {p.stem for p in PACKAGE.glob("*.py")}
    parts |= {p.name for p in PACKAGE.iterdir() if (p / "__init__.py").is_file()}
    assert parts <= set(LEVEL), f"give these a layer: {sorted(parts - set(LEVEL))}"


def test_no_module_imports_upward() -> None:
    upward = []
    for path in sorted(PACKAGE.rglob("*.py")):
        relative = path.relative_to(PACKAGE)
        own = relative.parts[0].removesuffix(".py") if len(relative.parts) > 1 else path.stem
        for line, module in runtime_imports(path):
            target = part_of(module)
            if target is not None and LEVEL[target] > LEVEL[own]:
                upward.append(f"{relative}:{line} ({own}) imports {module} ({target})")
    assert upward == [], "imports from a higher layer:\n" + "\n".join(upward)


def test_the_check_sees_an_upward_import(tmp_path: Path) -> None:
    """The walker finds a runtime import and skips a type-checking one."""
    sample = tmp_path / "sample.py"
    sample.write_text(
        "from typing import TYPE_CHECKING\n"
        "from ros_gz_bridge_py.core.bridge import Bridge\n"
        "if TYPE_CHECKING:\n"
        "    from ros_gz_bridge_py.app import settings\n"
    )
    assert runtime_imports(sample, tmp_path) == [(1, "typing"), (2, "ros_gz_bridge_py.core.bridge")]
