"""Process-level plumbing shared by the executables: speed settings, executor, clean shutdown.

What the user switched off comes in as arguments: the executables read the switches
(:mod:`ros_gz_bridge_py.app.settings`). Speed settings (docs/environment.md §2,
measured on the project machines):

* The allocator: glibc maps every 1-6 MB buffer with mmap and unmaps it again, so each image is
  page-faulted anew. Raising the mmap and trim thresholds (what ``MALLOC_MMAP_THRESHOLD_`` and
  ``MALLOC_TRIM_THRESHOLD_`` do) keeps those buffers on the heap. We call ``mallopt`` at start,
  unless the user set either variable.
* The executor: rclpy's ``SingleThreadedExecutor`` costs ~250 µs per callback;
  ``rclpy.experimental.EventsExecutor`` is about four times faster and is the default
  (``make_executor(events=False)`` switches back; ``ROS_GZ_BRIDGE_EXECUTOR=single`` for the
  executables). In the Jazzy wheels its plain ``spin()`` busy-waits holding the GIL,
  ``spin_until_future_complete`` ignores its timeout, and subscription callbacks that take
  message info fail (``spin_once`` with a timeout works and idles at ~0% CPU,
  ``spin_until_future_complete`` busy-waits at 60% of a core); so we spin it step by step with
  ``spin_once`` and keep message-info callbacks on the side node (``side_node.py``).
"""

from __future__ import annotations

import functools
import os
import sys
from pathlib import Path
from typing import Any

from rclpy.clock import Clock, ClockType
from rclpy.executors import ExternalShutdownException, SingleThreadedExecutor
from rclpy.utilities import get_default_context

from ros_gz_bridge_py.libc import libc_function, set_trim_threshold
from ros_gz_bridge_py.ros.speed import apply_fastdds_profile, remove_zombie_segments
from ros_gz_bridge_py.ros.stop_signal import StopSignal

M_MMAP_THRESHOLD = -3
MMAP_THRESHOLD_BYTES = 64 * 1024 * 1024
TRIM_THRESHOLD_BYTES = 256 * 1024 * 1024


#: GIL switch interval for the executables (Python's default is 5 ms). Light channels
#: (``/clock`` at 1 kHz) and the transport's I/O thread get the interpreter back within
#: 0.5 ms even while an image channel converts and publishes megabytes.
SWITCH_INTERVAL = 0.0005


def tune_threads() -> None:
    """Shorten the GIL switch interval so a heavy channel cannot delay light ones for long."""
    sys.setswitchinterval(SWITCH_INTERVAL)


def apply_speed_settings(*, fastdds_profile: bool) -> str | None:
    """Everything the executables set before ``rclpy.init``: allocator, GIL, and the Fast DDS
    profile unless ``fastdds_profile`` is False. Returns what to log once the node exists: the
    zombie Fast DDS segments removed, if any."""
    tune_allocator()
    tune_threads()
    if apply_fastdds_profile(enabled=fastdds_profile) is None:
        return None
    removed = remove_zombie_segments()
    return removed.describe() if removed.segments else None


def tune_allocator() -> bool:
    """Raise glibc's mmap/trim thresholds unless the user chose them. True when applied."""
    if "MALLOC_MMAP_THRESHOLD_" in os.environ or "MALLOC_TRIM_THRESHOLD_" in os.environ:
        return False
    mallopt = libc_function("mallopt")
    if mallopt is None:
        return False
    ok_mmap = mallopt(M_MMAP_THRESHOLD, MMAP_THRESHOLD_BYTES)
    ok_trim = set_trim_threshold(TRIM_THRESHOLD_BYTES)
    return bool(ok_mmap and ok_trim)


#: The name prefix Fast DDS gives its timed-event threads (``dds.ev.<participant>``).
DDS_EVENT_THREAD_PREFIX = "dds.ev."


def batch_dds_event_threads(tasks: Path = Path("/proc/self/task")) -> int:
    """Put this process's Fast DDS event threads under ``SCHED_BATCH`` (see the module
    docstring); returns how many were. Where that is not possible (no such threads, another
    middleware, not Linux) nothing changes."""
    batched = 0
    for task in tasks.glob("*"):
        try:
            if not (task / "comm").read_text().startswith(DDS_EVENT_THREAD_PREFIX):
                continue
            os.sched_setscheduler(int(task.name), os.SCHED_BATCH, os.sched_param(0))
        except (OSError, ValueError, AttributeError):  # gone, or no such policy here
            continue
        batched += 1
    return batched


def make_executor(*, events: bool) -> Any:
    """The executor the executables spin: the EventsExecutor, or with ``events`` False rclpy's
    SingleThreadedExecutor."""
    if not events:
        return SingleThreadedExecutor()
    from rclpy.experimental import EventsExecutor  # noqa: PLC0415 - experimental, load on use

    return EventsExecutor()


#: Longest time one spin step blocks; bounds how long a stop request waits. Each step costs
#: the EventsExecutor some CPU: 0.1 s steps were 0.24-0.50% of a core for an idle node, 0.5 s
#: steps 0.08%. (Ending a step at a signal would take a thread: issue 28's thread budget.)
SPIN_STEP = 0.5


@functools.cache
def steady_clock() -> Clock:
    """The one clock every timer of the bridge's node runs on: the EventsExecutor keeps a
    thread for each clock object its timers use (a steady clock per timer was a thread each)."""
    return Clock(clock_type=ClockType.STEADY_TIME)


def spin_until_stopped(executor: Any, stop: StopSignal | None = None) -> None:
    """Spin ``executor`` until a stop signal or rclpy shutdown; return without a traceback.

    Spinning is a loop of ``spin_once`` steps on the calling (main) thread, so the Python
    signal handlers run between steps, at most :data:`SPIN_STEP` after the signal. With
    ``stop`` None, handlers are installed for the duration of the call.
    """
    if stop is None:
        with StopSignal() as own:
            spin_until_stopped(executor, own)
        return
    spin_once = executor.spin_once
    context = get_default_context()
    try:
        while context.ok() and not stop.requested:
            spin_once(timeout_sec=SPIN_STEP)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
