"""The ZeroMQ context of a node's large-message subscriptions read on threads of their own
(images and point clouds on the bulk path; docs/threads.md).

A libzmq context has one I/O thread, which reads every TCP connection of its sockets. A node's
large-message subscriptions get a context of their own, so that:

- the I/O thread that reads their frames (a 1080p frame is 6 MB) is not the one that reads the
  small topics' connections (``/clock``, odometry), which then never wait behind a frame;
- that thread runs at the CPU priority of the delivery threads it feeds, which the bridge lowers
  (``ROS_GZ_BRIDGE_BULK_NICE``, ``core/gz_to_ros.py``): on a machine that cannot carry a flood
  of frames, the frames' whole path yields the CPU to the light topics, in this process and in
  the others (the Gazebo publisher's own I/O thread, which carries its ``/clock`` too, and the
  ROS subscribers). Measured with 1080p frames flooding the Gazebo process that publishes
  ``/clock``: ``benchmarks/reports/starvation.md``.

libzmq names a context's threads after a number given to the context (``ZMQ_THREAD_NAME_PREFIX``):
``<number>/ZMQbg/IO/0``; that name finds the I/O thread among the process's threads.
"""

from __future__ import annotations

import contextlib
import os
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import zmq

#: What the names of the bulk contexts' libzmq threads begin with.
THREAD_NAME_PREFIX = 6
_IO_THREAD_NAME = f"{THREAD_NAME_PREFIX}/ZMQbg/IO/"
#: How long a delivery thread looks for the I/O thread of its context at its start.
NAMED_WITHIN = 2.0


class BulkContext:
    """A context for large-message subscriptions (see the module docstring)."""

    def __init__(self) -> None:
        self.context: Any = zmq.Context(io_threads=1)
        self.context.set(zmq.THREAD_NAME_PREFIX, THREAD_NAME_PREFIX)

    def following(self, on_start: Callable[[], None] | None) -> Callable[[], None]:
        """A delivery thread's start: ``on_start`` (which may lower the thread's priority),
        then the context's I/O thread set to the priority the delivery thread has."""

        def start() -> None:
            if on_start is not None:
                on_start()
            # libzmq's I/O thread names itself once it runs, which on a busy machine can be
            # after this thread starts: until then it is not found by its name.
            deadline = time.monotonic() + NAMED_WITHIN
            while not follow_priority(threading.get_native_id()) and time.monotonic() < deadline:
                time.sleep(0.01)

        return start

    def close(self) -> None:
        """Every socket of the context goes (its readers' threads then end)."""
        self.context.destroy(linger=0)


def follow_priority(tid: int) -> bool:
    """The bulk contexts' I/O threads at thread ``tid``'s CPU priority (Linux; elsewhere, or
    where a priority cannot be raised back without privilege, nothing changes). False when
    no I/O thread was found (yet)."""
    try:
        nice = os.getpriority(os.PRIO_PROCESS, tid)
        found = io_threads()
    except (OSError, AttributeError):  # no per-thread priorities here
        return True
    for io_tid in found:
        with contextlib.suppress(OSError):
            if os.getpriority(os.PRIO_PROCESS, io_tid) != nice:
                os.setpriority(os.PRIO_PROCESS, io_tid, nice)
    return bool(found)


def io_threads() -> list[int]:
    """The ids of this process's bulk-context I/O threads."""
    found = []
    for task in Path("/proc/self/task").iterdir():
        with contextlib.suppress(OSError):
            if (task / "comm").read_text().startswith(_IO_THREAD_NAME):
                found.append(int(task.name))
    return found
