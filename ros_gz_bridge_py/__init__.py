"""ros_gz_bridge_py: the ROS 2 <-> Gazebo bridge in Python, with its own Gazebo Transport peer.

Importing this package is cheap; the rclpy-facing classes load on first use:
``from ros_gz_bridge_py import Bridge``.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

__version__ = "0.1.0"
__all__ = ["Bridge", "__version__"]

if TYPE_CHECKING:
    from ros_gz_bridge_py.core.bridge import Bridge


def __getattr__(name: str) -> Any:
    if name == "Bridge":
        from ros_gz_bridge_py.core.bridge import Bridge  # noqa: PLC0415 - keeps `import` free of rclpy

        return Bridge
    msg = f"module {__name__!r} has no attribute {name!r}"
    raise AttributeError(msg)
