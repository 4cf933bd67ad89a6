"""The one thread that runs every native ROS -> Gazebo channel of the process (docs/native.md §7).

:func:`shared_loop` starts it on first use ("ros-loop"). Its C side (``RosLoop``, ros_loop.c)
waits on every attached channel's eventfd at once and, the GIL released, takes and sends each
channel's messages with a budget per round. Between two runs, the thread does in Python what a
channel needs, and only for the channels that need it: the spellings and own publishers of those
that asked (:meth:`RosLoop.wake`), and the counters, the messages left to Python and the failures
of those the C side says moved. A run returns when a channel left messages to Python, when
woken, and otherwise after :data:`TURN` seconds, or :data:`QUIET_TURN` after a run in which no
channel moved.
"""

from __future__ import annotations

import logging
import threading
import time
from collections.abc import Callable
from typing import Any, Protocol

from ros_gz_bridge_py.libc import name_os_thread
from ros_gz_bridge_py.native import extension

_LOG = logging.getLogger("ros_gz_bridge_py.native")
#: Longest time (s) between two turns of the Python side while messages come.
TURN = 0.25
#: The same after a run in which no channel moved: changes are pushed (:meth:`RosLoop.wake`),
#: so this is only a safety net, and an idle loop costs one wake-up per QUIET_TURN whatever the
#: number of channels.
QUIET_TURN = 2.0


class LoopChannel(Protocol):
    """What the loop asks of a channel (``RosChannelPump``)."""

    @property
    def pump(self) -> Any:
        """The channel's C ``RosPump``."""
        ...

    def sync(self) -> None:
        """Tell the C side the spellings subscribers take and the publishers to skip."""

    def turn(self, refused: list[bytes], failure: int) -> None:
        """The channel moved: count, convert what was left to Python, report a failure."""


class RosLoop:
    """The shared loop (see the module docstring). Channels attach and detach while it runs;
    :meth:`detach` returns once neither the C side nor the thread's Python side works for the
    channel any more."""

    def __init__(self, native: Any) -> None:
        self._loop = native.RosLoop()
        #: Attached channels by their C pump (read by the thread, changed by any thread).
        self._channels: dict[Any, LoopChannel] = {}
        self._pending: set[LoopChannel] = set()
        self._lock = threading.Lock()
        #: Held by the thread while it works for channels in Python; detach waits for it.
        self._turn = threading.RLock()
        self._thread = threading.Thread(target=self._run, name="ros-loop", daemon=True)
        self._thread.start()

    def attach(self, channel: LoopChannel) -> None:
        """Serve ``channel`` from now on (synced once more on the loop's thread, for a change
        made while it joined)."""
        with self._lock:
            self._channels[channel.pump] = channel
            self._pending.add(channel)
        try:
            self._loop.add(channel.pump)
        except Exception:
            with self._lock:
                self._channels.pop(channel.pump, None)
                self._pending.discard(channel)
            raise

    def detach(self, channel: LoopChannel) -> None:
        """Stop serving ``channel``; after this no thread of the loop touches it (idempotent)."""
        self._loop.remove(channel.pump)
        # After a turn of the thread that may be working for the channel:
        with self._turn, self._lock:
            self._channels.pop(channel.pump, None)
            self._pending.discard(channel)

    def wake(self, channel: LoopChannel) -> None:
        """Sync ``channel`` soon (any thread; quick)."""
        with self._lock:
            if channel.pump not in self._channels:
                return
            self._pending.add(channel)
        self._loop.wake()

    def size(self) -> int:
        """How many channels are attached."""
        return int(self._loop.size())

    def _run(self) -> None:
        name_os_thread(self._thread.name)
        moved: list[tuple[Any, list[bytes], int]] = []
        while True:
            try:
                self._sync_pending()
                timeout = TURN if moved else QUIET_TURN
                _status, moved = self._loop.run(int(timeout * 1000))
                self._turns(moved)
            except Exception:  # the loop must outlive anything, as the readers do
                _LOG.exception("unexpected error in the native ROS -> Gazebo loop")
                time.sleep(TURN)  # and not spin on an error that stays

    def _sync_pending(self) -> None:
        with self._lock:
            pending, self._pending = self._pending, set()
        with self._turn:
            for channel in pending:
                if channel.pump in self._channels:
                    _guarded(channel, channel.sync)

    def _turns(self, moved: list[tuple[Any, list[bytes], int]]) -> None:
        with self._turn:
            for pump, refused, failure in moved:
                channel = self._channels.get(pump)
                if channel is not None:
                    _guarded(channel, channel.turn, refused, failure)


def _guarded(channel: LoopChannel, work: Callable[..., None], *args: Any) -> None:
    """One channel's error stays the channel's: the others keep their turns."""
    try:
        work(*args)
    except Exception:
        _LOG.exception("unexpected error in the native loop of %s", channel)


_shared: RosLoop | None = None
_shared_lock = threading.Lock()


def shared_loop() -> RosLoop:
    """The process's loop, started on first use.

    Raises:
        RuntimeError: the native extension is not built.
    """
    global _shared  # noqa: PLW0603 - one loop per process, made on first use
    with _shared_lock:
        if _shared is None:
            native = extension()
            if native is None:
                msg = "no native extension"
                raise RuntimeError(msg)
            _shared = RosLoop(native)
        return _shared
