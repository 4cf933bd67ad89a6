"""The native data plane: compiled speedups under the Python control plane (docs/native.md).

Optional, as libyaml is for PyYAML: the extension ``_native`` is built by the package where a
C compiler and Python headers exist; where it is missing, or ``ROS_GZ_BRIDGE_NATIVE=off`` (read
by the executables, ``BridgeOptions(native=False)`` when embedding), every channel takes the
Python path, which stays the reference. :func:`extension` says which, and why not.
"""

from __future__ import annotations

import functools
import importlib
from types import ModuleType


@functools.cache
def _load() -> tuple[ModuleType | None, str]:
    try:
        native = importlib.import_module("ros_gz_bridge_py.native._native")
    except ImportError as err:
        return None, (
            f"the native extension is not built ({err}); reinstall with a C compiler and "
            "Python headers (pip install .) to build it"
        )
    return native, ""


def extension() -> ModuleType | None:
    """The compiled extension, or None where it is not built."""
    return _load()[0]


def unavailable_reason() -> str:
    """Why the extension is not there ("" when it is)."""
    return _load()[1]
