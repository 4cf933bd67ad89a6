"""The foreign libraries the native loops call: their functions, and whether their structures
are laid out as the loops declare them (docs/native.md §5, §7).

The loops call libzmq and rcl/rmw without linking them or reading their headers: their
functions are the ones the libraries pyzmq and rclpy loaded, found here by the names the
extension gives (``PUMP_FUNCTIONS``, ``ROS_PUMP_FUNCTIONS``: its one list of them) and passed to
it by name (:func:`zmq_functions`, :func:`ros_functions`), and the few structures passed to them
are declared by hand. pump.c declares ``zmq_msg_t`` as the 64 bytes of libzmq 4.2 and later (4.0 had
32, early 4.1 48); ros_pump.c declares ``rmw_message_info_t`` with the 16-byte ``rmw_gid_t`` of
Iron and later (Humble and before: 24 bytes, so every field after the GID would be read at the
wrong place). Where the loaded libraries are known to differ, or a function is missing, the
loop is not used: the channel takes the Python path, and the bridge logs once why. The versions
are read from what is loaded: libzmq's through pyzmq (``zmq_version``), rclpy's from its
package metadata, else ``ROS_DISTRO``.
"""

from __future__ import annotations

import contextlib
import ctypes
import functools
import importlib.metadata
import logging
import os
from collections.abc import Iterable, Mapping
from pathlib import Path

from ros_gz_bridge_py.native import extension

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


# --- the functions ---------------------------------------------------------------------------


def loaded_libraries() -> list[str]:
    """The paths of the shared libraries this process has loaded (Linux), in load order."""
    try:
        maps = Path("/proc/self/maps").read_text()
    except OSError:
        return []
    paths = [line.rpartition(" ")[2] for line in maps.splitlines()]
    return list(dict.fromkeys(path for path in paths if ".so" in path))


def libzmq_path() -> str | None:
    """The libzmq pyzmq loaded (its wheel bundles one)."""
    import zmq  # noqa: F401, PLC0415 - loads pyzmq's libzmq, which this finds

    return next((path for path in loaded_libraries() if "/libzmq" in path), None)


#: The libraries of rcl's and rcutils' functions, by the prefix of their names (loaded by rclpy).
_ROS_LIBRARIES = {"rcl": "librcl.so", "rcutils": "librcutils.so"}


def find_functions(
    names: Iterable[str], libraries: Mapping[str, str]
) -> tuple[dict[str, int], str]:
    """The address of each function of ``names``, found in the library its name's prefix
    names (``zmq_msg_recv``: ``libraries["zmq"]``, a path or a loaded library's name); or {}
    and why not."""
    found: dict[str, int] = {}
    try:
        loaded = {prefix: ctypes.CDLL(path) for prefix, path in libraries.items()}
        for name in names:
            function = getattr(loaded[name.partition("_")[0]], name)
            found[name] = ctypes.cast(function, ctypes.c_void_p).value or 0
    except (OSError, AttributeError, KeyError) as err:
        return {}, f"a function the native loop calls cannot be found ({err})"
    missing = [name for name, address in found.items() if not address]
    return ({}, f"{', '.join(missing)} has no address") if missing else (found, "")


@functools.cache
def zmq_functions() -> dict[str, int] | None:
    """The addresses of the functions a Pump calls (``PUMP_FUNCTIONS``: libzmq's, rcl's and
    rcutils'), by name, or None (then no channel takes the native path; logged once why)."""
    native = extension()
    if native is None:
        return None
    path = libzmq_path()
    found: dict[str, int] = {}
    problem = "pyzmq's libzmq is not among the loaded libraries"
    if path is not None:
        found, problem = find_functions(native.PUMP_FUNCTIONS, {**_ROS_LIBRARIES, "zmq": path})
    if not found:
        _LOG.warning("Every channel takes the Python path: %s", problem)
    return found or None


@functools.cache
def ros_functions() -> dict[str, int] | None:
    """The addresses of the functions a RosPump calls (``ROS_PUMP_FUNCTIONS``: rcl's, rmw's,
    rcutils' and libzmq's), by name, or None (logged once why)."""
    native = extension()
    if native is None:
        return None
    path, rmw = libzmq_path(), _rmw_library()
    if path is None or rmw is None:
        return None
    libraries = {**_ROS_LIBRARIES, "zmq": path, "rmw": rmw}
    found, problem = find_functions(native.ROS_PUMP_FUNCTIONS, libraries)
    if not found:
        _LOG.warning("ROS -> Gazebo channels convert in Python: %s", problem)
    return found or None


def _rmw_library() -> str | None:
    """The loaded rmw library that has ``rmw_get_gid_for_publisher``: rmw_implementation's
    dispatcher where rcl goes through it (a ROS install), else the implementation rcl is
    linked with (the PyPI wheels link rmw_fastrtps_cpp)."""
    candidates = [path for path in loaded_libraries() if "/librmw" in path]
    candidates.sort(key=lambda path: "rmw_implementation" not in path)
    for candidate in candidates:
        with contextlib.suppress(OSError, AttributeError):
            ctypes.CDLL(candidate).rmw_get_gid_for_publisher  # noqa: B018 - does it have it?
            return candidate
    _LOG.warning("ROS -> Gazebo channels convert in Python: no loaded rmw library gives GIDs")
    return None
