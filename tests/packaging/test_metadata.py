"""pip reads the package's metadata without a deprecation warning from setuptools (which
builds it with the newest setuptools it finds, >= 77, where the license once warned), and the
license and the Python it needs are in it. The other end, colcon with setuptools 68.1.2, is
test_colcon.py's."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from testing.gzpeer import ROOT


def test_pip_reads_the_metadata_without_a_deprecation_warning(tmp_path: Path) -> None:
    report = tmp_path / "report.json"
    done = subprocess.run(
        [sys.executable, "-m", "pip", "install", "--dry-run", "--no-deps", "--ignore-installed",
         "--verbose", "--report", str(report), str(ROOT)],
        capture_output=True, text=True, timeout=300, check=False,
    )  # fmt: skip
    output = done.stdout + done.stderr
    if done.returncode != 0 and os.environ.get("CI", "").lower() != "true":
        pytest.skip(f"pip could not prepare the metadata here (no package index?):\n{output}")
    assert done.returncode == 0, output
    assert "deprecat" not in output.lower(), output
    (metadata,) = [entry["metadata"] for entry in json.loads(report.read_text())["install"]]
    assert metadata["license"] == "Apache-2.0"
    assert metadata["requires_python"] == ">=3.11"
