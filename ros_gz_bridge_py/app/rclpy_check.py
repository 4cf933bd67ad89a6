"""Before the executables import rclpy: is there one, and is it ROS 2 Jazzy's?

The bridge is written against Jazzy's rclpy (the ``ros-jazzy-*`` wheels or a sourced Jazzy).
Two set-ups fail far from their cause otherwise: no rclpy at all (a bare ``pip install .``), and
another distribution's rclpy ahead on ``PYTHONPATH`` (Humble's ``setup.bash`` sourced in the
shell of a Python 3.11 venv: its rclpy is built for 3.10 and fails to load). The check looks
the package up without importing it, so it costs nothing measurable at start-up.
"""

from __future__ import annotations

import importlib.util
import re

SUPPORTED = "jazzy"
#: A ROS install's Python path: ``/opt/ros/<distro>/lib/python3.X/site-packages/...``.
_ROS_INSTALL = re.compile(r"/opt/ros/([^/]+)/")
HOW = (
    "Install the ros-jazzy-* wheels into this Python 3.11+ environment (`pip install '.[ros]'`) "
    "in a shell where no other ROS distribution is sourced, or source a ROS 2 Jazzy install "
    "(docs/which-ros.md)."
)


def install_distro(origin: str) -> str | None:
    """The distribution of a ROS install that ``origin`` (a module's file) lies in, if any."""
    found = _ROS_INSTALL.search(origin)
    return None if found is None else found.group(1)


def rclpy_problem() -> str | None:
    """Why this environment's rclpy will not do for the bridge, or None."""
    spec = importlib.util.find_spec("rclpy")
    if spec is None:
        return f"rclpy is not importable here: the bridge needs ROS 2 Jazzy's rclpy. {HOW}"
    distro = install_distro(spec.origin or "")
    if distro is not None and distro != SUPPORTED:
        return (
            f"rclpy is imported from ROS 2 {distro.capitalize()} ({spec.origin}); the bridge "
            f"runs on ROS 2 Jazzy's rclpy only. {HOW}"
        )
    return None
