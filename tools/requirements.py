"""Print the pinned requirements pyproject.toml declares, one a line, for ``pip install -r``.

usage: python tools/requirements.py [--extras-only] [EXTRA ...]

The package's dependencies and those of each EXTRA (``--extras-only``: the extras' alone),
without the package itself: the set-up installs them first, and the package (whose native
extension compiles) beside the interface packages' build (Makefile, ``setup-demo``).
pyproject.toml stays the one place the pins are written.
"""

from __future__ import annotations

import sys
import tomllib
from pathlib import Path

PYPROJECT = Path(__file__).resolve().parents[1] / "pyproject.toml"


def requirements(extras: list[str], *, extras_only: bool = False) -> list[str]:
    project = tomllib.loads(PYPROJECT.read_text())["project"]
    optional = project["optional-dependencies"]
    unknown = [extra for extra in extras if extra not in optional]
    if unknown:
        msg = f"no extra {', '.join(unknown)} in {PYPROJECT} (it has {', '.join(optional)})"
        raise SystemExit(msg)
    found = [] if extras_only else list(project["dependencies"])
    for extra in extras:
        found += optional[extra]
    return found


def main(argv: list[str]) -> int:
    extras_only = "--extras-only" in argv
    extras = [arg for arg in argv if arg != "--extras-only"]
    print("\n".join(requirements(extras, extras_only=extras_only)))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
