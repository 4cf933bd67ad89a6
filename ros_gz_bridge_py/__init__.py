"""ros_gz_bridge_py: the ROS 2 <-> Gazebo bridge in Python, with its own Gazebo Transport peer.

Importing this package is cheap; the rclpy-facing classes load on first use:
``from ros_gz_bridge_py import Bridge, BridgeOptions``.
"""

from __future__ import annotations

import sys
from typing import TYPE_CHECKING, Any

# Before any module of the package loads: an older Python would otherwise stop at the first
# 3.11-only name, far from the cause. pip refuses such a Python already (requires-python), but
# colcon (on Humble: Ubuntu 22.04, Python 3.10) runs setup.py, which does not check it.
if sys.version_info < (3, 11):  # noqa: UP036 - the one place that runs on older Pythons
    _found = ".".join(map(str, sys.version_info[:3]))
    msg = (
        f"ros_gz_bridge_py needs Python 3.11 or newer and ROS 2 Jazzy's rclpy; this is Python "
        f"{_found}. Run it from a Python 3.11+ venv with `pip install '.[ros]'` (the "
        "ros-jazzy-* wheels) in a shell where no other ROS distribution is sourced, or under a "
        "sourced Jazzy install (README.md, Install)."
    )
    raise ImportError(msg)

__version__ = "0.1.0"
__all__ = ["Bridge", "BridgeOptions", "__version__"]

if TYPE_CHECKING:
    from ros_gz_bridge_py.core.bridge import Bridge, BridgeOptions


def __getattr__(name: str) -> Any:
    if name in ("Bridge", "BridgeOptions"):
        from ros_gz_bridge_py.core import bridge  # noqa: PLC0415 - keeps `import` free of rclpy

        return getattr(bridge, name)
    msg = f"module {__name__!r} has no attribute {name!r}"
    raise AttributeError(msg)
