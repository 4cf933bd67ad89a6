"""pip reads the package's metadata without a deprecation warning from setuptools (which
builds it with the newest setuptools it finds, >= 77, where the license once warned), and the
license and the Python it needs are in it. The other end, colcon with setuptools 68.1.2, is
test_colcon.py's."""

from __future__ import annotations

import configparser
import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

from ros_gz_bridge_py.demo import topics
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


def test_the_demo_finds_its_configuration_where_a_wheel_installs_it() -> None:
    """``python -m ros_gz_bridge_py.demo`` from an installed wheel, away from the source tree."""
    data_files = configparser.ConfigParser()
    data_files.read(ROOT / "setup.cfg")
    installed = data_files["options.data_files"]["share/ros_gz_bridge_py/config"]
    assert installed.strip() == "config/*.yaml"
    name = topics.CONFIG_FILE.name
    assert (ROOT / "config" / name).is_file()
    expected = Path(sys.prefix) / "share/ros_gz_bridge_py/config" / name
    assert expected == topics.INSTALLED_CONFIG_FILE
