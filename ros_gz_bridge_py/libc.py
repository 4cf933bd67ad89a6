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


#: ``mallopt``'s option of the trim threshold (glibc malloc.h).
M_TRIM_THRESHOLD = -1
#: The trim threshold given to ``mallopt`` (:func:`set_trim_threshold`); empty while glibc's
#: own, dynamic one applies.
_trim_threshold: list[int] = []


def set_trim_threshold(size: int) -> bool:
    """``mallopt(M_TRIM_THRESHOLD, size)``, remembered for :func:`shrink_thread_arena`."""
    mallopt = libc_function("mallopt")
    if mallopt is None or not mallopt(M_TRIM_THRESHOLD, size):
        return False
    _trim_threshold[:] = [size]
    return True


#: The threshold while the calling thread's arena shrinks, and the block that makes it.
_SHRINK_THRESHOLD = 1024 * 1024
_SHRINK_PROBE = 256 * 1024


def shrink_thread_arena() -> None:
    """Give back the free top of the calling thread's malloc arena, where a raised trim
    threshold keeps it (glibc: ``malloc_trim`` gives back free pages inside every arena but
    not the top of a thread's arena, which only ``free`` trims, past the threshold).

    The threshold is lowered for a moment and a block is taken from the top and freed into
    it again, which trims it; nothing is done while glibc's own threshold applies."""
    if not _trim_threshold:
        return
    mallopt, malloc, free = (libc_function(n) for n in ("mallopt", "malloc", "free"))
    if mallopt is None or malloc is None or free is None:
        return
    malloc.restype = ctypes.c_void_p
    malloc.argtypes = [ctypes.c_size_t]
    free.argtypes = [ctypes.c_void_p]
    mallopt(M_TRIM_THRESHOLD, _SHRINK_THRESHOLD)
    try:
        free(malloc(_SHRINK_PROBE))
    finally:
        mallopt(M_TRIM_THRESHOLD, _trim_threshold[0])


def libc_function(name: str) -> Any | None:
    """The C function ``name`` of this process's C library, or None where there is none."""
    symbols = _own_symbols()
    return None if symbols is None else getattr(symbols, name, None)


#: ``prctl``'s option that names the calling thread (linux/prctl.h).
PR_SET_NAME = 15


def name_os_thread(name: str) -> None:
    """Give the calling thread ``name`` in the OS too (``top -H``, /proc/<pid>/task/*/comm; at
    most 15 bytes), where the C library has ``prctl``."""
    prctl = libc_function("prctl")
    if prctl is not None:
        prctl(PR_SET_NAME, name.encode()[:15], 0, 0, 0)
