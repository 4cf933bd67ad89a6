"""The native data plane: compiled speedups under the Python control plane (docs/native.md).

Optional, as libyaml is for PyYAML: the extension ``_native`` is built by the package where a
C compiler and Python headers exist; where it is missing, or ``ROS_GZ_BRIDGE_NATIVE=off`` (read
by the executables, ``BridgeOptions(native=False)`` when embedding), every channel takes the
Python path, which stays the reference. :func:`extension` says which, and why not.
"""

from __future__ import annotations

import functools
from typing import TYPE_CHECKING, Protocol

if TYPE_CHECKING:
    from ros_gz_bridge_py.native import _native


class Extension(Protocol):
    """What the compiled extension offers (typed in ``_native.pyi``)."""

    Program: type[_native.Program]
    Encoder: type[_native.Encoder]
    Pump: type[_native.Pump]
    RosPump: type[_native.RosPump]
    Loop: type[_native.Loop]
    EVENT_HANDED: int
    EVENT_MONITOR: int
    EVENT_BROKEN: int
    PUMP_FUNCTIONS: tuple[str, ...]
    ROS_PUMP_FUNCTIONS: tuple[str, ...]


@functools.cache
def _load() -> tuple[Extension | None, str]:
    try:
        from ros_gz_bridge_py.native import _native  # noqa: PLC0415 - optional
    except ImportError as err:
        return None, (
            f"the native extension is not built ({err}); reinstall with a C compiler and "
            "Python headers (pip install .) to build it"
        )
    return _native, ""


def extension() -> Extension | None:
    """The compiled extension, or None where it is not built."""
    return _load()[0]


def unavailable_reason() -> str:
    """Why the extension is not there ("" when it is)."""
    return _load()[1]
