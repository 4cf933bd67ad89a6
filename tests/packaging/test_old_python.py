"""An interpreter older than 3.11 (Humble's 3.10) gets one clear error naming what is needed,
from a real older interpreter importing the package as ``ros2 run`` and ``python -m`` do.

Skipped where no older Python is installed (pyenv's, or a ``python3.X`` on PATH).
"""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

from testing.gzpeer import ROOT

OLDER = ("3.10", "3.9", "3.8")


def older_python() -> Path | None:
    """A Python interpreter older than 3.11, if this machine has one."""
    pyenv = shutil.which("pyenv")
    if pyenv is not None:
        done = subprocess.run([pyenv, "root"], capture_output=True, text=True, check=False)
        root = Path(done.stdout.strip())
        for minor in OLDER:
            for python in sorted(root.glob(f"versions/{minor}.*/bin/python{minor}")):
                return python
    for minor in OLDER:
        found = shutil.which(f"python{minor}")
        if found is not None and ".pyenv/shims" not in found:
            return Path(found)
    return None


@pytest.mark.parametrize(
    "command",
    [
        ["-c", "import ros_gz_bridge_py.cli"],
        ["-m", "ros_gz_bridge_py.app.parameter_bridge", "/a@std_msgs/msg/String@gz.msgs.StringMsg"],
    ],
)
def test_an_older_python_is_told_what_it_needs(command: list[str]) -> None:
    python = older_python()
    if python is None:
        pytest.skip("no Python older than 3.11 installed here")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    done = subprocess.run(
        [str(python), *command],
        capture_output=True,
        text=True,
        cwd=ROOT,
        env=env,
        timeout=60,
        check=False,
    )
    assert done.returncode == 1
    last = done.stderr.strip().splitlines()[-1]
    assert last.startswith("ImportError: ros_gz_bridge_py needs Python 3.11 or newer")
    assert "ROS 2 Jazzy's rclpy" in last
    assert "pip install '.[ros]'" in last
