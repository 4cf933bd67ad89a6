"""Process-level plumbing shared by the executables: speed settings, executor, clean shutdown.

Speed settings (``../shared/spec/environment.md`` §5, measured on the project machines):

* The allocator: glibc maps every 1-6 MB buffer with mmap and unmaps it again, so each image is
  page-faulted anew. Raising the mmap and trim thresholds (what ``MALLOC_MMAP_THRESHOLD_`` and
  ``MALLOC_TRIM_THRESHOLD_`` do) keeps those buffers on the heap. We call ``mallopt`` at start,
  unless the user set either variable.
* The executor: rclpy's ``SingleThreadedExecutor`` costs ~250 µs per callback;
  ``rclpy.experimental.EventsExecutor`` is about four times faster and is the default
  (``ROS_GZ_BRIDGE_EXECUTOR=single`` switches back). Its plain ``spin()`` busy-waits while
  holding the GIL in the Jazzy wheels, so we always drive it with
  ``spin_until_future_complete``.
"""

from __future__ import annotations

import ctypes
import ctypes.util
import os
import signal
from collections.abc import Callable
from types import FrameType
from typing import Any

import rclpy
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.task import Future

M_TRIM_THRESHOLD = -1
M_MMAP_THRESHOLD = -3
MMAP_THRESHOLD_BYTES = 64 * 1024 * 1024
TRIM_THRESHOLD_BYTES = 256 * 1024 * 1024


def tune_allocator() -> bool:
    """Raise glibc's mmap/trim thresholds unless the user chose them. True when applied."""
    if "MALLOC_MMAP_THRESHOLD_" in os.environ or "MALLOC_TRIM_THRESHOLD_" in os.environ:
        return False
    name = ctypes.util.find_library("c")
    if name is None:
        return False
    try:
        libc = ctypes.CDLL(name)
        mallopt = libc.mallopt
    except (OSError, AttributeError):
        return False
    ok_mmap = mallopt(M_MMAP_THRESHOLD, MMAP_THRESHOLD_BYTES)
    ok_trim = mallopt(M_TRIM_THRESHOLD, TRIM_THRESHOLD_BYTES)
    return bool(ok_mmap and ok_trim)


def make_executor() -> Any:
    """The executor the executables spin: EventsExecutor unless ROS_GZ_BRIDGE_EXECUTOR=single."""
    if os.environ.get("ROS_GZ_BRIDGE_EXECUTOR", "events").lower() == "single":
        return SingleThreadedExecutor()
    from rclpy.experimental import EventsExecutor  # noqa: PLC0415 - experimental, load on use

    return EventsExecutor()


def spin_until_stopped(executor: Any, on_stop: Callable[[], None] | None = None) -> None:
    """Spin ``executor`` until SIGINT/SIGTERM or rclpy shutdown; return without a traceback.

    The signal handlers only complete a future; the executor wakes up for it and returns, and
    the caller cleans up on the main thread.
    """
    stop: Future = Future(executor=executor)
    stop.add_done_callback(lambda _f: None)

    def request_stop(_signum: int, _frame: FrameType | None) -> None:
        if not stop.done():
            stop.set_result(True)

    previous = {sig: signal.signal(sig, request_stop) for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        while rclpy.ok() and not stop.done():
            executor.spin_until_future_complete(stop, timeout_sec=0.5)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        if on_stop is not None:
            on_stop()
