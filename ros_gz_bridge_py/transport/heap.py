"""Giving freed memory back to the system after a burst of large messages.

The executables raise glibc's mmap and trim thresholds (``ros/runtime.py``: buffers up to
64 MiB stay on the heap, and up to 256 MiB of free heap is kept), so a steady camera stream
reuses its buffers instead of page-faulting them anew. After a burst of large messages that
keeps hundreds of MB resident that nothing will reuse (measured: 5 messages of 60 MB left a
bridge at 649 MB, from 169 MB). A :class:`BurstTrimmer` calls ``malloc_trim(0)`` once a
subscription that received at least :data:`TRIM_AFTER_BYTES` has been quiet for
:data:`IDLE_BEFORE_TRIM` seconds: quiet is less than :data:`QUIET_RATE` bytes a second, so a
light stream on the same topic (a real 50 Hz Odometry publisher beside a rogue's 32 MB
frames) does not hold a burst's memory, while a steady stream of large messages, never quiet
that long, keeps its buffers. Elsewhere than glibc it does nothing. The Python path's readers
tell it each message (``zmq/reader.py``); the native loop, which reads in C, has one per
channel and tells it the bytes the channel read since the last count when it moved
(``native/loop.py``); the native channels' fallback thread has one (``native/fallback.py``).
"""

from __future__ import annotations

import time
from collections.abc import Callable

from ros_gz_bridge_py.libc import libc_function, shrink_thread_arena

#: Bytes received since the last trim that make a quiet pause worth a trim.
TRIM_AFTER_BYTES = 64 * 1024 * 1024
#: Seconds of quiet after which a burst counts as over.
IDLE_BEFORE_TRIM = 1.0
#: Bytes a second below which a subscription is quiet: 1 MiB/s is a 20 kB message at 50 Hz.
QUIET_RATE = 1024 * 1024
#: Seconds over which the rate is measured (at least).
RATE_WINDOW = 0.25


def trim_heap() -> bool:
    """``malloc_trim(0)``: free heap pages of every arena back to the system (glibc only),
    after the free top of the calling thread's own arena (``libc.shrink_thread_arena``):
    call it on the thread that handled the burst."""
    trim = libc_function("malloc_trim")
    if trim is None:
        return False
    shrink_thread_arena()
    return bool(trim(0))


class BurstTrimmer:
    """Counts received bytes; :meth:`idle` trims once after a burst of ``trim_after`` bytes or
    more (one thread, the one that handled the burst)."""

    def __init__(
        self, trim: Callable[[], object] = trim_heap, trim_after: int = TRIM_AFTER_BYTES
    ) -> None:
        self._trim = trim
        self._trim_after = trim_after
        self._bytes = 0  # since the last trim
        self._window_bytes = 0
        self._window_start: float | None = None
        self._last = 0.0  # when the last window above QUIET_RATE ended
        self.trims = 0

    def received(self, size: int, now: float | None = None) -> None:
        """``size`` bytes came at ``now``. The rate window that ended before them is closed
        first, so that bytes told after a long silence (the native loop tells a channel's
        only when it moved) are not spread over the silence; a window that already holds more
        than a loud one of :data:`RATE_WINDOW` is loud as of now, before it closes."""
        now = time.monotonic() if now is None else now
        self._close_window(now)
        self._bytes += size
        self._window_bytes += size
        if self._window_bytes > QUIET_RATE * RATE_WINDOW:
            self._last = now

    @property
    def pending(self) -> bool:
        """Whether a burst was received that is not trimmed yet (:meth:`idle` will trim once
        it is over)."""
        return self._bytes >= self._trim_after

    def idle(self, now: float | None = None) -> None:
        """Call when nothing is waiting: trims after a burst that has ended."""
        now = time.monotonic() if now is None else now
        self._close_window(now)
        if self.pending and now - self._last >= IDLE_BEFORE_TRIM:
            self._bytes = 0
            self.trims += 1
            self._trim()

    def _close_window(self, now: float) -> None:
        """Ends the rate window once it is :data:`RATE_WINDOW` long; a loud one moves the
        start of the quiet to its end."""
        start = self._window_start
        if start is None:
            self._window_start = now
            return
        span = now - start
        if span < RATE_WINDOW:
            return
        if self._window_bytes > QUIET_RATE * span:
            self._last = now
        self._window_bytes = 0
        self._window_start = now
