"""The executables say what they need when this environment's rclpy will not do, before an
import of rclpy fails: none at all (a real interpreter without it), or another distribution's
(recognised by the path of a ROS install; no Humble install is here to import)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from ros_gz_bridge_py.app.rclpy_check import install_distro, rclpy_problem
from testing.gzpeer import ROOT

#: The interpreter this venv was made from: the same Python, without the venv's packages.
BASE_PYTHON = Path(sys.base_prefix) / "bin" / f"python{sys.version_info[0]}.{sys.version_info[1]}"


def test_the_venv_rclpy_is_accepted() -> None:
    assert rclpy_problem() is None


@pytest.mark.parametrize("program", ["parameter_bridge", "image_bridge", "bridge_types"])
def test_without_rclpy_the_executables_say_what_is_needed(program: str) -> None:
    if sys.prefix == sys.base_prefix or not BASE_PYTHON.exists():
        pytest.skip("no interpreter outside a venv to run without rclpy")
    has_rclpy = subprocess.run(
        [str(BASE_PYTHON), "-c", "import rclpy"], capture_output=True, check=False
    )
    if has_rclpy.returncode == 0:
        pytest.skip(f"{BASE_PYTHON} has an rclpy of its own")
    env = {**os.environ, "PYTHONPATH": str(ROOT)}
    script = f"from ros_gz_bridge_py import cli; cli.{program}_main()"
    done = subprocess.run(
        [str(BASE_PYTHON), "-c", script],
        capture_output=True,
        text=True,
        cwd=ROOT,
        env=env,
        timeout=60,
        check=False,
    )
    assert done.returncode == 1
    assert done.stderr.startswith(f"{program}: rclpy is not importable here")
    assert "pip install '.[ros]'" in done.stderr
    assert "Traceback" not in done.stderr


@pytest.mark.parametrize(
    ("origin", "distro"),
    [
        ("/opt/ros/humble/lib/python3.10/site-packages/rclpy/__init__.py", "humble"),
        ("/opt/ros/jazzy/lib/python3.12/site-packages/rclpy/__init__.py", "jazzy"),
        ("/home/me/.venv/lib/python3.11/site-packages/rclpy/__init__.py", None),
    ],
)
def test_a_ros_install_is_told_by_its_path(origin: str, distro: str | None) -> None:
    assert install_distro(origin) == distro
