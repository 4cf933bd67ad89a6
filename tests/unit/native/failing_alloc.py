"""The failing-allocation shim (``failing_alloc.c``): built with cc into ``.build/`` and
preloaded into a subprocess, which then makes its malloc and realloc fail for one size, so that
a test can make one chosen allocation of the native extension fail without a hook in it."""

from __future__ import annotations

import ctypes
import hashlib
import json
import os
import shutil
import subprocess
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[3]
#: What a bytes object of n bytes asks of PyObject_Malloc beyond n (its header and final NUL).
BYTES_OVERHEAD = 33
SOURCE = Path(__file__).with_suffix(".c")


def shim() -> Path:
    """The built shim, compiled once per version of its source (skips without a compiler)."""
    compiler = shutil.which("cc")
    if compiler is None:
        pytest.skip("no C compiler to build the failing-allocation shim")
    digest = hashlib.sha256(SOURCE.read_bytes()).hexdigest()[:16]
    target = ROOT / ".build" / "failing_alloc" / f"failing_alloc-{digest}.so"
    if not target.exists():
        target.parent.mkdir(parents=True, exist_ok=True)
        partial = target.with_name(f"{target.name}.{os.getpid()}")
        command = [compiler, "-shared", "-fPIC", "-O2", "-o", str(partial), str(SOURCE)]
        subprocess.run(command, check=True, capture_output=True, text=True)
        partial.replace(target)
    return target


def environment() -> dict[str, str]:
    """Our environment, for a subprocess with the shim preloaded (and this checkout's package
    the one imported)."""
    preload = " ".join(filter(None, [str(shim()), os.environ.get("LD_PRELOAD", "")]))
    return {**os.environ, "LD_PRELOAD": preload, "PYTHONPATH": str(ROOT)}


def fail_size(size: int, spared: int = 0) -> None:
    """In a process the shim is preloaded into: from now on every malloc or realloc of
    ``size`` bytes fails (0: none), but for the first ``spared`` of them."""
    process = ctypes.CDLL(None)
    ctypes.c_ulong.in_dll(process, "failing_alloc_spared").value = spared
    ctypes.c_size_t.in_dll(process, "failing_alloc_size").value = size


def failures() -> int:
    """In a process the shim is preloaded into: the allocations it made fail so far."""
    return int(ctypes.c_ulong.in_dll(ctypes.CDLL(None), "failing_alloc_failures").value)


def while_failing(size: int, run: Callable[[], dict[str, Any]], spared: int = 0) -> dict[str, Any]:
    """In a process the shim is preloaded into: ``run()``'s report, made while allocations of
    ``size`` bytes fail (but the first ``spared``), with the failures the shim made meanwhile
    (``"failures"``)."""
    before = failures()
    fail_size(size, spared)
    try:
        report = run()
    finally:
        fail_size(0)
    report["failures"] = failures() - before
    return report


def side(script: Path, *arguments: int | str) -> dict[str, Any]:
    """What ``script`` reports (JSON on its output), run with the shim preloaded."""
    result = subprocess.run(
        [sys.executable, str(script), *map(str, arguments)],
        env=environment(),
        capture_output=True,
        text=True,
        timeout=120,
        check=False,
    )
    assert result.returncode == 0, result.stdout[-2000:] + result.stderr[-3000:]
    report: dict[str, Any] = json.loads(result.stdout)
    return report
