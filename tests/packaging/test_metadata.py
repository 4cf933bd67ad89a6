"""pip reads the package's metadata without a deprecation warning from setuptools (which
builds it with the newest setuptools it finds, >= 77, where the license once warned), and the
license and the Python it needs are in it. The other end, colcon with setuptools 68.1.2, is
test_colcon.py's."""

from __future__ import annotations

import configparser
import json
import os
import shutil
import subprocess
import sys
import tarfile
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


def test_the_source_distribution_carries_the_set_up_steps_and_the_docs(tmp_path: Path) -> None:
    """Before MANIFEST.in, an sdist held the package alone: the README's
    ``tools/setup_interfaces.sh``, the interface packages and docs/ were not in it."""
    tree = tmp_path / "tree"
    skipped = shutil.ignore_patterns(
        ".git", ".venv*", ".build", "__pycache__", "*.egg-info", "*.so", ".*_cache"
    )
    shutil.copytree(ROOT, tree, ignore=skipped)
    done = subprocess.run(
        [sys.executable, "setup.py", "-q", "sdist", "-d", str(tmp_path / "dist")],
        cwd=tree, capture_output=True, text=True, timeout=300, check=False,
    )  # fmt: skip
    assert done.returncode == 0, done.stdout + done.stderr
    (archive,) = (tmp_path / "dist").glob("*.tar.gz")
    with tarfile.open(archive) as sdist:
        names = {name.split("/", 1)[1] for name in sdist.getnames() if "/" in name}
    assert {
        "tools/setup_interfaces.sh",
        "docs/configuration.md",
        "examples/embed_bridge.py",
        "config/diff_car_bridge.yaml",
    } <= names
    assert any(name.startswith("interfaces/") and name.endswith("package.xml") for name in names)
    assert not [name for name in names if "__pycache__" in name or name.startswith("tests/")]
