"""The C library functions the bridge calls where there is one (glibc: ``mallopt``,
``malloc_trim``, ``prctl``).

They are looked up among the process's own symbols (``dlopen(NULL)``), which include the C
library's. ``ctypes.util.find_library("c")`` would find the same library by running
``ldconfig -p`` in a subprocess: up to 0.02 s of the executables' start-up.
"""

from __future__ import annotations

import ctypes
import functools
from typing import Any


@functools.cache
def _own_symbols() -> ctypes.CDLL | None:
    try:
        return ctypes.CDLL(None)
    except OSError:
        return None


def libc_function(name: str) -> Any | None:
    """The C function ``name`` of this process's C library, or None where there is none."""
    symbols = _own_symbols()
    return None if symbols is None else getattr(symbols, name, None)
