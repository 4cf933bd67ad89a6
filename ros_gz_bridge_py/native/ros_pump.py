"""The native input of one ROS -> Gazebo channel, a member of the ROS -> Gazebo loop
(docs/native.md §7).

:class:`RosChannelPump` holds the C ``RosPump`` (ros_pump.c) of one channel's input: the rclpy
subscription it takes from (on a node no executor spins, so nothing else takes its messages),
the channel's Gazebo publisher with a PUB socket of its own, and the encoder of each spelling.
The process's ROS -> Gazebo loop (``loop.py``) runs it; the pump asks that loop for a turn when
the spellings Gazebo subscribers take or the bridge's own publishers on the topic change, and
its turns, on the loop's thread, sync them, count, and hand the messages an encoder left to
Python to the channel's Python path on the process's one fallback thread (``fallback.py``), as
the Gazebo -> ROS channels do. The socket is used by one thread at a time: what the fallback
thread publishes is sent through the C pump, under the loop's mutex (``ZmqPublisher.sender``).
"""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

import zmq

from ros_gz_bridge_py.native import extension
from ros_gz_bridge_py.native.abi import ros_functions
from ros_gz_bridge_py.native.fallback import FallbackLane, fallback_worker
from ros_gz_bridge_py.native.loop import ROS_TO_GZ, PumpMember, shared_loop
from ros_gz_bridge_py.transport.delivery import Payload

if TYPE_CHECKING:
    from ros_gz_bridge_py.native._native import Encoder, RosPump, RosPumpCounts


class RosChannelPump(PumpMember):
    """The native input of one ROS -> Gazebo channel (see the module docstring).

    ``refused(cdr)``: the channel's Python path for one admitted message (on the fallback
    thread); ``capacity`` and ``max_bytes``: the bounds of its queue there;
    ``counted(received, own_skipped, rate_limited, published, send_failures)``: what the loop
    did since it last said; ``lost(count)``: messages for the Python path that were dropped
    (no memory to copy them, or over the queue's bounds) since it last said;
    ``failed(reason)``: the channel's socket failed and the loop took the channel off (nothing
    more is taken); ``own_publishers()``: the rcl publishers of the bridge on the topic, and
    ``watch_own_publishers(changed)`` calls ``changed()`` when they change (it returns the
    function that stops it). The publisher's ``watch_wire_types`` does the same for the
    spellings. Closing the publisher (or its node) first takes the channel off the loop.
    """

    def __init__(
        self,
        *,
        subscription: Any,
        publisher: Any,
        encoders: Mapping[str, Encoder],
        max_rate: float,
        refused: Callable[[bytes], None],
        capacity: int,
        max_bytes: int,
        counted: Callable[[int, int, int, int, int], None],
        lost: Callable[[int], None],
        failed: Callable[[str], None],
        own_publishers: Callable[[], frozenset[int]],
        watch_own_publishers: Callable[[Callable[[], None]], Callable[[], None]],
        name: str,
    ) -> None:
        native, functions = extension(), ros_functions()
        if native is None or functions is None:
            msg = "no native extension or foreign functions"
            raise RuntimeError(msg)
        order = [publisher.msg_type, *(t for t in encoders if t != publisher.msg_type)]
        spellings = []
        for wire_type in order:
            topic, sender, _payload, type_frame = publisher.wire_frames[wire_type]
            spellings.append((type_frame, topic, sender, encoders[wire_type]))
        self.name = name
        self._publisher = publisher
        self.pump: RosPump = native.RosPump(
            functions, subscription.handle.pointer, publisher.sock.underlying, spellings, max_rate
        )
        self._fallback: FallbackLane[None] = fallback_worker().lane(
            lambda cdr, _none: refused(cdr), capacity, max_bytes, name
        )
        self._counted = counted
        self._lost = lost
        self._failed = failed
        self._own_publishers = own_publishers
        self._seen = self.pump.counts()
        self._fallback_dropped = 0
        self._active: frozenset[str] | None = None
        self._ignored: frozenset[int] | None = None
        self._closed = False
        self._close_lock = threading.Lock()
        self._loop = shared_loop(ROS_TO_GZ)
        publisher.sender = self._send
        self._unwatch = (
            publisher.watch_wire_types(self.wake),
            watch_own_publishers(self.wake),
            publisher.before_close(self.close),
        )
        # In use while attached: a destroy meanwhile (rclpy's) waits for close.
        self._in_use = contextlib.ExitStack()
        self._in_use.enter_context(subscription.handle)
        self.sync()  # before the loop takes a message: a subscriber's spelling is not missed
        self._join()

    def __repr__(self) -> str:
        return f"<native ROS -> Gazebo channel {self.name}>"

    def wake(self) -> None:
        """Have the loop read the spellings and own publishers again soon (any thread; quick;
        nothing after :meth:`close`)."""
        if not self._closed:
            self._loop.ask(self)

    def close(self) -> None:
        """Take the channel off the loop and stop rcl's callback, and after the message being
        converted, the fallback thread; idempotent. The subscription and the publisher's
        socket may go after: a second caller (the channel and the node's close at once)
        returns only when the first is done."""
        with self._close_lock:
            if self._closed:
                return
            self._closed = True
            self._loop.detach(self)
            self._count()  # what the loop did after its last turn of the channel
            self._release()

    def _release(self) -> None:
        for unwatch in self._unwatch:
            unwatch()
        self._fallback.close()
        self._publisher.sender = None
        self._in_use.close()

    def sync(self) -> None:
        """Tell the C side the spellings subscribers take and the publishers to skip."""
        active = self._publisher.wire_types()
        if active != self._active:
            self.pump.set_active({name.encode() for name in active})
            self._active = active
        ignored = self._own_publishers()
        if ignored != self._ignored:
            self.pump.ignore(sorted(ignored))
            self._ignored = ignored

    def _send(self, type_frame: bytes, payload: Payload) -> None:
        """What the channel's Python path publishes, sent by the C pump (the fallback thread)."""
        if not self.pump.send(type_frame, payload) and self.pump.failure:
            self._loop.ask(self)  # its socket failed: the loop takes it off

    # --- the loop's thread (loop.py LoopMember) --------------------------------------------

    def turn(self, *, handed: bool, monitor: bool, broken: bool) -> float | None:
        """The messages an encoder left to Python (to the fallback thread), the counters, the
        spellings and own publishers, and the failure of the channel's socket."""
        del monitor, broken  # no connection monitor; a broken pump says why in `failure`
        for cdr in self.pump.take_handed() if handed else ():
            self._fallback.put(cdr, None)
        self._count()
        self.sync()  # a channel that moved has subscribers: a cheap safety net for them
        failure = self.pump.failure
        if failure:
            self._failed(
                f"its Gazebo socket failed ({zmq.strerror(failure)}); the channel takes no more "
                "ROS messages (restart the bridge)"
            )
            # Off the loop now; the rest when the channel closes. Not close(): a close
            # waiting for this turn on another thread holds its lock.
            self._loop.detach(self)
        return None

    def _count(self) -> None:
        names = "received", "own_skipped", "rate_limited", "published", "send_failures", "lost"
        *deltas, lost = self._deltas(*names)
        if any(deltas):
            self._counted(*deltas)
        fallback_dropped = self._fallback.dropped
        lost += fallback_dropped - self._fallback_dropped
        self._fallback_dropped = fallback_dropped
        if lost:
            self._lost(lost)

    def counts(self) -> RosPumpCounts:
        """The C pump's counts so far."""
        return self.pump.counts()
