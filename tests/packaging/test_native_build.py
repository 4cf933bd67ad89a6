"""The native extension is optional at build time (docs/native.md §1): where the C compiler
fails, the package still builds, without it (and runs on the Python path:
test_native_path.py); where it works, the extension is built."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from testing.gzpeer import ROOT

pytestmark = [pytest.mark.slow]


def build(tmp: Path, env: dict[str, str]) -> list[Path]:
    """The extensions setup.py's ``build_ext`` (what ``pip install`` runs) builds from the
    sources; the build must succeed either way."""
    out = tmp / "lib"
    done = subprocess.run(
        [sys.executable, "setup.py", "-q", "build_ext", "--build-lib", str(out),
         "--build-temp", str(tmp / "temp")],
        cwd=ROOT, capture_output=True, text=True, timeout=600, check=False, env=env,
    )  # fmt: skip
    assert done.returncode == 0, done.stdout[-3000:] + done.stderr[-3000:]
    return sorted(out.glob("ros_gz_bridge_py/native/_native*.so"))


def test_a_failing_compiler_builds_the_package_without_the_extension(tmp_path: Path) -> None:
    assert build(tmp_path, {**os.environ, "CC": "false", "LDSHARED": "false"}) == []


def test_a_working_compiler_builds_the_extension(tmp_path: Path) -> None:
    assert build(tmp_path, dict(os.environ))
