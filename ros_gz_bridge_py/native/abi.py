"""Whether the libraries in the process lay out the structures the native loops declare by hand.

The loops call libzmq and rcl/rmw without their headers (docs/native.md §5, §7): pump.c
declares ``zmq_msg_t`` as the 64 bytes of libzmq 4.2 and later (4.0 had 32, early 4.1 48), and
ros_pump.c declares ``rmw_message_info_t`` with the 16-byte ``rmw_gid_t`` of Iron and later
(Humble and before: 24 bytes, so every field after the GID would be read at the wrong place).
Where the loaded libraries are known to differ, the loop is not used: the channel takes the
Python path, and the bridge logs once why. The versions are read from what is loaded: libzmq's
through pyzmq (``zmq_version``), rclpy's from its package metadata, else ``ROS_DISTRO``.
"""

from __future__ import annotations

import functools
import importlib.metadata
import logging
import os

_LOG = logging.getLogger("ros_gz_bridge_py.native")

#: The first libzmq whose zmq_msg_t is certainly 64 bytes.
ZMQ_MSG_64 = (4, 2, 0)
#: The last rclpy major version of a distribution with 24-byte GIDs (Humble's rclpy is 3.x).
RCLPY_24_BYTE_GID = 3
#: Distributions whose rmw_gid_t holds 24 bytes.
DISTROS_24_BYTE_GID = frozenset({"ardent", "bouncy", "crystal", "dashing", "eloquent", "foxy",
                                 "galactic", "humble"})  # fmt: skip


def zmq_problem(version: tuple[int, ...]) -> str:
    """Why libzmq ``version`` does not fit pump.c ("" when it does)."""
    if tuple(version[:3]) >= ZMQ_MSG_64:
        return ""
    shown = ".".join(map(str, version))
    return (
        f"libzmq {shown} is loaded, whose zmq_msg_t may not be the 64 bytes the native loop "
        "declares; install libzmq 4.2 or later (pyzmq's wheels bundle one)"
    )


def rmw_problem(rclpy_version: str | None, distro: str | None) -> str:
    """Why the rmw of rclpy ``rclpy_version`` (or, unknown, of ``distro``) does not fit
    ros_pump.c ("" when it does, or when neither is known)."""
    if rclpy_version:
        major = rclpy_version.split(".")[0]
        if major.isdigit() and int(major) <= RCLPY_24_BYTE_GID:
            return (
                f"rclpy {rclpy_version} is loaded, a distribution whose rmw_gid_t holds 24 "
                "bytes where the native loop declares Jazzy's 16"
            )
        return ""
    if distro and distro.lower() in DISTROS_24_BYTE_GID:
        return (
            f"ROS_DISTRO is {distro}, whose rmw_gid_t holds 24 bytes where the native loop "
            "declares Jazzy's 16"
        )
    return ""


def _rclpy_version() -> str | None:
    try:
        return importlib.metadata.version("rclpy")
    except importlib.metadata.PackageNotFoundError:
        return None


@functools.cache
def zmq_layout_fits() -> bool:
    """Whether the loaded libzmq fits the Gazebo -> ROS loop; logged once where not."""
    import zmq  # noqa: PLC0415 - only where a native loop is considered

    problem = zmq_problem(zmq.zmq_version_info())
    if problem:
        _LOG.warning("Every channel takes the Python path: %s", problem)
    return not problem


@functools.cache
def rmw_layout_fits() -> bool:
    """Whether the loaded rmw fits the ROS -> Gazebo loop; logged once where not."""
    problem = rmw_problem(_rclpy_version(), os.environ.get("ROS_DISTRO"))
    if problem:
        _LOG.warning("ROS -> Gazebo channels convert in Python: %s", problem)
    return not problem
