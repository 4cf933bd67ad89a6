"""The one thread on which every native channel's fallback runs, in both directions
(docs/native.md §5, §7).

A payload no program took (a transcoder left it to Python: a string with a NUL, a number out of
its ROS type's range, an output over the bound) goes to its channel's Python path, which
converts and publishes it or says why not. That can be slow (a Pose_V of 4 M empty poses: a
second of parsing), so it never runs on a loop's thread; and it must not cost a thread per
channel either, or a rogue whose payloads fall back on many topics would add a thread to the
process for each of them. So every channel has a :class:`FallbackLane` (its own drop-oldest
queue, of the channel's bounds in messages and bytes, its drops counted; on the worker from its
first payload) on the process's one :class:`FallbackWorker`, whose thread serves the lanes that
hold something one payload each in turn: a channel's payload waits
at most for the one being handled and one of each other lane whose turn came first, so a flood
on one channel's fallback does not hold up another's behind its whole queue.

The thread starts with the first lane (a channel's first fallback) and ends with the last (the
channel closed). It trims the heap once it has been quiet for a second after handling
:data:`FALLBACK_TRIM_AFTER` bytes (``transport/heap.py``), and sleeps without a timeout
otherwise: at rest it does no work at all.
"""

from __future__ import annotations

import collections
import functools
import logging
import queue
import threading
from collections.abc import Callable
from typing import Any, Generic, TypeVar

from ros_gz_bridge_py.libc import name_os_thread
from ros_gz_bridge_py.transport.delivery import DropOldestQueue
from ros_gz_bridge_py.transport.heap import BurstTrimmer

_LOG = logging.getLogger("ros_gz_bridge_py.native")
#: Payload bytes the fallback thread handles before a quiet second is worth a trim: far fewer
#: than a reader's, because the Python path can build objects many times a payload's size (a
#: Pose_V of 4 M empty poses: 8 MB, some 300 MB parsed, left on the thread's own heap).
FALLBACK_TRIM_AFTER = 1024 * 1024
#: Seconds between two looks at the trimmer while a burst waits for its trim.
IDLE_EVERY = 0.25
#: The thread's name (in Python and in the OS, for ``top -H``).
THREAD_NAME = "native-fallback"

#: What a lane's handler is told with each payload (a Gazebo message's info, or nothing).
Info = TypeVar("Info")


def _payload_size(item: tuple[bytes, object]) -> int:
    return len(item[0])


class FallbackLane(Generic[Info]):
    """One channel's queue on the fallback thread, which it joins at its first payload (a
    channel whose payloads never fall back costs no thread): :meth:`put` from the loop's
    thread, :meth:`close` from any."""

    def __init__(
        self,
        worker: FallbackWorker,
        handler: Callable[[bytes, Info], None],
        size: int,
        max_bytes: int,
        name: str,
    ) -> None:
        self._worker = worker
        self.handler = handler
        self.name = name
        self.queue: DropOldestQueue[tuple[bytes, Info]] = DropOldestQueue(
            size, weigh=_payload_size, max_bytes=max_bytes
        )
        # Written under the worker's lock:
        self.closed = False
        self.joined = False  # among the worker's lanes (from its first payload)
        self.waiting = False  # in the worker's turn order

    @property
    def dropped(self) -> int:
        """Payloads dropped so far, oldest first (over the lane's count or bytes)."""
        return self.queue.dropped

    def put(self, payload: bytes, info: Info) -> None:
        """Queue ``payload`` for the handler (nothing once closed)."""
        if self.closed:
            return
        self.queue.put((payload, info))
        self._worker.wake(self)

    def close(self) -> None:
        """No handler call starts after this returns; it waits for one of this lane's that
        runs (never for another lane's). Pending payloads are discarded. Idempotent."""
        self._worker.close(self)


class FallbackWorker:
    """The thread that serves every lane in turn (see the module docstring)."""

    def __init__(self, trimmer: BurstTrimmer | None = None, *, name: str = THREAD_NAME) -> None:
        self._trimmer = trimmer or BurstTrimmer(trim_after=FALLBACK_TRIM_AFTER)
        self._name = name
        self._changed = threading.Condition()
        self._lanes: set[FallbackLane[Any]] = set()  # open
        self._turns: collections.deque[FallbackLane[Any]] = collections.deque()  # holding some
        self._serving: FallbackLane[Any] | None = None
        self._thread: threading.Thread | None = None

    @property
    def thread(self) -> threading.Thread | None:
        """The thread while there are lanes."""
        return self._thread

    def lane(
        self, handler: Callable[[bytes, Info], None], size: int, max_bytes: int, name: str
    ) -> FallbackLane[Info]:
        """A new lane (of channel ``name``) whose payloads go to ``handler``, keeping the newest
        ``size`` and at most ``max_bytes`` of them (always one)."""
        return FallbackLane(self, handler, size, max_bytes, name)

    def wake(self, lane: FallbackLane[Any]) -> None:
        """``lane`` holds a payload: give it a turn; at its first, it joins the lanes, and the
        thread starts if it is not running."""
        with self._changed:
            if lane.closed or lane.waiting:
                return
            if not lane.joined:
                lane.joined = True
                self._lanes.add(lane)
                if self._thread is None:
                    self._thread = threading.Thread(target=self._run, name=self._name, daemon=True)
                    self._thread.start()
            lane.waiting = True
            self._turns.append(lane)
            self._changed.notify()

    def close(self, lane: FallbackLane[Any]) -> None:
        """See :meth:`FallbackLane.close`."""
        with self._changed:
            if lane.closed:
                return
            lane.closed = True
            self._lanes.discard(lane)
            if lane.waiting:
                lane.waiting = False
                self._turns.remove(lane)
            self._changed.notify_all()
            if threading.current_thread() is not self._thread:
                while self._serving is lane:
                    self._changed.wait()
        while True:  # the payloads it held go now, not when the lane does
            try:
                lane.queue.get(block=False)
            except queue.Empty:
                break

    def _run(self) -> None:
        name_os_thread(self._name)
        while True:
            with self._changed:
                if not self._turns:
                    if not self._lanes:
                        self._thread = None
                        return
                    self._changed.wait(IDLE_EVERY if self._trimmer.pending else None)
                lane = self._turns.popleft() if self._turns else None
                if lane is not None:
                    lane.waiting = False
                    self._serving = lane
            if lane is None:
                self._trimmer.idle()
            else:
                self._serve(lane)

    def _serve(self, lane: FallbackLane[Any]) -> None:
        """One payload of ``lane`` to its handler; the lane's next turn if it holds more."""
        try:
            self._handle(lane)
        finally:
            with self._changed:
                self._serving = None
                if not lane.closed and not lane.waiting and len(lane.queue):
                    lane.waiting = True
                    self._turns.append(lane)
                self._changed.notify_all()

    def _handle(self, lane: FallbackLane[Any]) -> None:
        try:
            payload, info = lane.queue.get(block=False)
        except queue.Empty:  # dropped since it was woken, or its turn came twice
            return
        try:
            lane.handler(payload, info)
        except Exception:  # the thread serves every channel: it must survive anything
            _LOG.exception("%s: the Python path of a payload that fell back failed", lane.name)
        self._trimmer.received(len(payload))


@functools.cache
def fallback_worker() -> FallbackWorker:
    """The process's fallback thread (started at the first channel's first fallback)."""
    return FallbackWorker()
