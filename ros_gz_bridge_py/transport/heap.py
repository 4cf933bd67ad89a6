"""Giving freed memory back to the system after a burst of large messages.

The executables raise glibc's mmap and trim thresholds (``ros/runtime.py``: buffers up to
64 MiB stay on the heap, and up to 256 MiB of free heap is kept), so a steady camera stream
reuses its buffers instead of page-faulting them anew. After a burst of large messages that
keeps hundreds of MB resident that nothing will reuse (measured: 5 messages of 60 MB left a
bridge at 649 MB, from 169 MB). A :class:`BurstTrimmer` calls ``malloc_trim(0)`` once a
subscription that received at least :data:`TRIM_AFTER_BYTES` has been idle for
:data:`IDLE_BEFORE_TRIM` seconds: a steady stream never pauses that long, so it keeps its
buffers; a burst's memory goes back. Elsewhere than glibc it does nothing. The Python path's
readers tell it each message (``zmq/reader.py``); the native loop, which reads in C, tells it
each channel's running total of bytes read at every count (``native/loop.py``).
"""

from __future__ import annotations

import time
from collections.abc import Callable

from ros_gz_bridge_py.libc import libc_function

#: Bytes received since the last trim that make an idle pause worth a trim.
TRIM_AFTER_BYTES = 64 * 1024 * 1024
#: Seconds without a message after which a burst counts as over.
IDLE_BEFORE_TRIM = 1.0


def trim_heap() -> bool:
    """``malloc_trim(0)``: free heap pages of every arena back to the system (glibc only)."""
    trim = libc_function("malloc_trim")
    return trim is not None and bool(trim(0))


class BurstTrimmer:
    """Counts received bytes; :meth:`idle` trims once after a large burst (one thread)."""

    def __init__(self, trim: Callable[[], object] = trim_heap) -> None:
        self._trim = trim
        self._bytes = 0
        self._last = 0.0
        self._total = 0
        self.trims = 0

    def received(self, size: int) -> None:
        self._bytes += size
        self._last = time.monotonic()

    def read_so_far(self, total: int, now: float) -> None:
        """``total`` bytes received since the start: what came since the last call counts as
        received, nothing new as idle."""
        if total > self._total:
            self._bytes += total - self._total
            self._total = total
            self._last = now
        else:
            self.idle(now)

    def idle(self, now: float | None = None) -> None:
        """Call when nothing is waiting: trims after a burst that has ended."""
        if self._bytes < TRIM_AFTER_BYTES:
            return
        now = time.monotonic() if now is None else now
        if now - self._last >= IDLE_BEFORE_TRIM:
            self._bytes = 0
            self.trims += 1
            self._trim()
