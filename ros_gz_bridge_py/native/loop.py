"""The one thread that runs every native Gazebo -> ROS channel of the process (docs/native.md §5).

The C ``Loop`` (loop.c) reads, transcodes and publishes the messages of every attached pump
with the GIL released; this module gives it its thread and does Python's share between its
runs, for the members that need it and no others:

- a member the loop reports (messages handed back, a connection monitor event, a socket that
  cannot be read);
- a member that asked (:meth:`SharedLoop.ask`: a posted connection change, an intra-process
  message, a closing channel);
- a member whose own deadline has come (a connection to leave, messages queued in Python);
- a member whose pump read messages since the last count (``Loop.moved``), every
  :data:`COUNT_EVERY` seconds while messages flow, so the status table stays current; an idle
  bridge turns once every :data:`QUIET_COUNT_EVERY` seconds, whatever its number of channels.

At each count the bytes a moving member read since the last go to its own ``BurstTrimmer``
(``transport/heap.py``), and the trimmers that hold a burst not trimmed yet are told the time:
once a channel that read a burst of large messages has been quiet for a second, freed memory
goes back to the system; a steady stream of large messages is never quiet that long. A trimmer
per channel, not one for the loop: a fleet's many light channels add up to more than a quiet
rate, and would hold one channel's burst for ever. A member at rest, with no burst pending,
costs nothing at a count.

Members are added and removed on the loop's own thread (a command posted from any thread,
which :meth:`SharedLoop.detach` waits for), so the C loop never runs a pump whose socket is
being closed. The thread starts with the first member and ends with the last.
"""

from __future__ import annotations

import collections
import functools
import logging
import threading
import time
from collections.abc import Callable
from typing import Any, Protocol

from ros_gz_bridge_py.libc import name_os_thread
from ros_gz_bridge_py.native import extension
from ros_gz_bridge_py.transport.heap import BurstTrimmer, trim_heap

_LOG = logging.getLogger("ros_gz_bridge_py.native")
#: Seconds between two counts of the moving members while messages flow.
COUNT_EVERY = 0.25
#: The same while nothing moved at the last count.
QUIET_COUNT_EVERY = 1.0
#: Bytes a channel reads before a quiet second is worth a trim: fewer than a Python reader's,
#: because the transcoder's index and output for a large message can be many times its size
#: (4 Pose_V of 4 M empty poses, 32 MB, left 72 MB on the loop thread's own heap).
LOOP_TRIM_AFTER = 8 * 1024 * 1024


class LoopMember(Protocol):
    """What the loop runs: a C ``Pump`` and the Python share of its channel."""

    @property
    def pump(self) -> Any:
        """The C Pump."""
        ...

    @property
    def bytes_read(self) -> int:
        """Payload bytes read from its socket so far (for the trim)."""
        ...

    def loop_turn(self, events: int) -> float | None:
        """Python's share (on the loop's thread): ``events`` are the C loop's bits (0: a count,
        a deadline or a request). Returns when the member wants its next turn at the latest
        (``time.monotonic()``), or None."""
        ...


class SharedLoop:
    """The process's loop thread for native Gazebo -> ROS channels (see the module docstring)."""

    def __init__(self, native: Any, *, trim: Callable[[], object] = trim_heap) -> None:
        self._loop = native.Loop()
        self._trim = trim  # what each channel's trimmer calls
        self.monitor_event = int(native.EVENT_MONITOR)
        self.handed_event = int(native.EVENT_HANDED)
        self.broken_event = int(native.EVENT_BROKEN)
        self._lock = threading.Lock()
        self._thread: threading.Thread | None = None
        self._commands: collections.deque[Callable[[], None]] = collections.deque()
        self._asked: set[LoopMember] = set()
        self._members: dict[Any, LoopMember] = {}  # by pump
        self._deadlines: dict[LoopMember, float] = {}
        self._handles: dict[LoopMember, Any] = {}
        self._trimmers: dict[Any, BurstTrimmer] = {}  # by pump
        self._bytes_read: dict[Any, int] = {}  # by pump, at the last count
        self._pending: set[Any] = set()  # pumps whose trimmer holds a burst
        self._touched: list[Any] = []

    # --- from any thread ----------------------------------------------------------------------

    def attach(self, member: LoopMember, sock: int, monitor: int, handle: Any) -> None:
        """Run ``member`` on the ZeroMQ socket ``sock`` with its connection ``monitor`` (socket
        addresses); ``handle`` (the rclpy publisher's, a context manager) is held while it runs.
        On the loop's thread (a reader that replaced its socket in its turn) it is done at once,
        so that a close posted meanwhile from another thread comes after it."""
        if threading.current_thread() is self._thread:
            self._guarded(lambda: self._add(member, sock, monitor, handle))
            return
        self._post(lambda: self._add(member, sock, monitor, handle))

    def detach(self, member: LoopMember) -> None:
        """Stop running ``member``; returns once the loop no longer touches its sockets."""
        if threading.current_thread() is self._thread:
            self._remove(member)
            return
        done = threading.Event()

        def remove() -> None:
            try:
                self._remove(member)
            finally:
                done.set()

        self._post(remove)
        done.wait()

    def ask(self, member: LoopMember) -> None:
        """Turn ``member`` soon (from any thread)."""
        with self._lock:
            self._asked.add(member)
        self._loop.wake()

    @property
    def thread(self) -> threading.Thread | None:
        """The loop's thread while it has members."""
        return self._thread

    def _post(self, command: Callable[[], None]) -> None:
        with self._lock:
            self._commands.append(command)
            if self._thread is None:
                self._thread = threading.Thread(target=self._run, name="gz-native", daemon=True)
                self._thread.start()
        self._loop.wake()

    # --- the loop's thread --------------------------------------------------------------------

    def _add(self, member: LoopMember, sock: int, monitor: int, handle: Any) -> None:
        member.pump.forget()
        handle.__enter__()  # the publisher stays while the loop publishes on it
        try:
            self._loop.add(member.pump, sock, monitor)
        except Exception:
            handle.__exit__(None, None, None)
            raise
        self._members[member.pump] = member
        self._handles[member] = handle
        self._trimmers[member.pump] = BurstTrimmer(self._trim, trim_after=LOOP_TRIM_AFTER)
        self._bytes_read[member.pump] = member.bytes_read

    def _remove(self, member: LoopMember) -> None:
        if self._members.pop(member.pump, None) is None:
            return
        self._loop.remove(member.pump)
        self._trimmers.pop(member.pump, None)
        self._bytes_read.pop(member.pump, None)
        self._pending.discard(member.pump)
        self._deadlines.pop(member, None)
        self._asked.discard(member)
        self._handles.pop(member).__exit__(None, None, None)

    def _run(self) -> None:
        name_os_thread("gz-native")
        next_count = time.monotonic() + COUNT_EVERY
        while True:
            with self._lock:
                commands, self._commands = self._commands, collections.deque()
                asked, self._asked = self._asked, set()
                if not commands and not self._members:
                    self._thread = None
                    return
            try:
                next_count = self._iterate(commands, asked, next_count)
            except Exception:  # the loop must survive anything: every native channel is on it
                _LOG.exception("the native loop's turn failed")
                time.sleep(0.01)

    def _iterate(
        self,
        commands: collections.deque[Callable[[], None]],
        asked: set[LoopMember],
        next_count: float,
    ) -> float:
        """One turn: the commands, the members due, one C run, what it reported; returns when
        the moving members are counted next."""
        for command in commands:
            self._guarded(command)
        now = time.monotonic()
        due = asked | {member for member, at in self._deadlines.items() if at <= now}
        for member in due:
            self._turn(member, 0)
        wait = min([next_count, *self._deadlines.values()]) - now
        _woken, reported = self._loop.run(max(0, int(wait * 1000) + 1), self._touched)
        self._touched = []
        for pump, events in reported:
            self._turn(self._members.get(pump), events)
        now = time.monotonic()
        if now < next_count:
            return next_count
        moved = self._loop.moved()
        for pump in moved:
            self._turn(self._members.get(pump), 0)
        self._count_bytes(moved, now)
        return now + (COUNT_EVERY if moved else QUIET_COUNT_EVERY)

    def _count_bytes(self, moved: list[Any], now: float) -> None:
        """The bytes each of the ``moved`` pumps read since the last count to its trimmer;
        then the trimmers holding a burst trim if it is over."""
        for pump in moved:
            member = self._members.get(pump)
            if member is None:
                continue  # removed since
            total = member.bytes_read
            trimmer = self._trimmers[pump]
            trimmer.received(total - self._bytes_read[pump], now)
            self._bytes_read[pump] = total
            if trimmer.pending:
                self._pending.add(pump)
        for pump in list(self._pending):
            trimmer = self._trimmers[pump]
            trimmer.idle(now)
            if not trimmer.pending:
                self._pending.discard(pump)

    def _turn(self, member: LoopMember | None, events: int) -> None:
        if member is None or member.pump not in self._members:
            return  # removed since
        self._touched.append(member.pump)
        deadline: float | None = None
        try:
            deadline = member.loop_turn(events)
        except Exception:
            _LOG.exception("a native channel's turn failed")
        if member.pump not in self._members:
            return
        if deadline is None:
            self._deadlines.pop(member, None)
        else:
            self._deadlines[member] = deadline

    @staticmethod
    def _guarded(command: Callable[[], None]) -> None:
        try:
            command()
        except Exception:
            _LOG.exception("a native channel could not be added to or removed from the loop")


@functools.cache
def shared_loop() -> SharedLoop:
    """The process's loop (made at the first native channel)."""
    native = extension()
    if native is None:
        msg = "no native extension"
        raise RuntimeError(msg)
    return SharedLoop(native)
